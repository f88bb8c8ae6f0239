//! Which files a model's OUTPUT writes: the CSVs of the selected nodes and elements
//! (with the default selection of a large model, issue 29), or the groups of
//! `histories.nc`.

use super::netcdf::Group;
use super::{ENERGY_HEADER, NODE_HEADER};
use crate::model::{ElementId, LARGE_MODEL, Model, Selection};
use crate::solver::System;
use std::path::{Path, PathBuf};

/// The files a model's OUTPUT asks for: (dense node, file, header), (dense element,
/// file, header).
pub(super) type Plan = (Vec<(usize, PathBuf)>, Vec<(usize, PathBuf, String)>);

pub(super) fn plan(dir: &Path, model: &Model, sys: &System) -> Plan {
    let large = model.nodes.len() + model.elements.len() > LARGE_MODEL;
    let gen_elements: std::collections::HashSet<ElementId> = model
        .divisions
        .values()
        .flat_map(|d| d.elements.iter().skip(1).copied())
        .collect();
    let node_idx = model.output_node_indices();
    let nodes = node_idx
        .into_iter()
        .map(|i| (i, dir.join(format!("node_{}.csv", sys.node_ids[i].0))))
        .collect();
    let elem_idx: Vec<usize> = match &model.output.elements {
        Selection::Default if large => (0..model.elements.len())
            .filter(|&e| !gen_elements.contains(&sys.elements[e].id()))
            .collect(),
        Selection::All | Selection::Default => (0..model.elements.len()).collect(),
        Selection::None => Vec::new(),
        Selection::List(l) => l
            .iter()
            .filter_map(|id| model.elements.get_index_of(id))
            .collect(),
    };
    let mut elements = Vec::new();
    for e in elem_idx {
        let el = &sys.elements[e];
        let header = el.output_header();
        if header.is_empty() {
            continue;
        }
        elements.push((
            e,
            dir.join(format!("element_{}.csv", el.id().0)),
            format!("t,{}", header.join(",")),
        ));
    }
    (nodes, elements)
}

/// The groups of `histories.nc` for a plan: the nodes, then the elements grouped by
/// header (first appearance order), then the energy; with the dense indices of the nodes
/// and of the elements in the file's order.
pub(super) fn groups(plan: &Plan, sys: &System) -> (Vec<Group>, Vec<usize>, Vec<usize>) {
    let cols = |h: &str| h.split(',').skip(1).map(str::to_string).collect::<Vec<_>>();
    let mut out = Vec::new();
    let nodes: Vec<usize> = plan.0.iter().map(|(i, _)| *i).collect();
    if !nodes.is_empty() {
        out.push(Group {
            name: "node".into(),
            ids: nodes.iter().map(|i| sys.node_ids[*i].0).collect(),
            columns: cols(NODE_HEADER),
        });
    }
    let mut headers: Vec<&str> = Vec::new();
    for (_, _, h) in &plan.1 {
        if !headers.contains(&h.as_str()) {
            headers.push(h);
        }
    }
    let mut elements = Vec::new();
    for (k, h) in headers.iter().enumerate() {
        let members: Vec<usize> = plan
            .1
            .iter()
            .filter(|(_, _, x)| x == h)
            .map(|(e, _, _)| *e)
            .collect();
        out.push(Group {
            name: format!("element_{}", k + 1),
            ids: members.iter().map(|e| sys.elements[*e].id().0).collect(),
            columns: cols(h),
        });
        elements.extend(members);
    }
    out.push(Group {
        name: "energy".into(),
        ids: Vec::new(),
        columns: cols(ENERGY_HEADER),
    });
    (out, nodes, elements)
}

/// What an OUTPUT selection writes (`mecano-rs --check`, issue 29).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Volume {
    /// Files written (histories, energy, summary).
    pub files: usize,
    /// Rows (instants) written per second of simulated time: `1 / (EVERY · STEP)` (the
    /// initial step when adaptive); for a static analysis, per load step.
    pub rows_per_second: f64,
    /// Bytes per written instant, all files together (CSV numbers at
    /// [`CSV_NUMBER_BYTES`] each, NetCDF at 8).
    pub bytes_per_row: f64,
    /// Bytes for the whole run (`end` seconds, or every load step).
    pub total_bytes: f64,
}

/// Mean length of a number in a CSV, with its comma: Ryū's shortest form of a double
/// that is not round is 17 significant digits, a point, a sign half the time and often an
/// exponent (`e-5`): 21 characters is what the seed's histories average.
pub const CSV_NUMBER_BYTES: f64 = 21.0;

/// The volume a model's OUTPUT writes (files in `dir` are only named, not created).
pub fn volume(model: &Model, sys: &System) -> Volume {
    let (nodes, elements) = plan(Path::new("."), model, sys);
    let ncols = |h: &str| h.split(',').count() as f64;
    let values = nodes.len() as f64 * ncols(NODE_HEADER)
        + elements.iter().map(|(_, _, h)| ncols(h)).sum::<f64>();
    let energy = ncols(ENERGY_HEADER) * CSV_NUMBER_BYTES;
    let (files, bytes_per_row) = if model.output.netcdf {
        // Columns after t, doubles, plus t and the energy's numbers in both files.
        let nc = 8.0 * (values - nodes.len() as f64 - elements.len() as f64);
        (3, nc + energy + 8.0 * ncols(ENERGY_HEADER))
    } else {
        (
            nodes.len() + elements.len() + 2,
            values * CSV_NUMBER_BYTES + energy,
        )
    };
    let every = f64::from(model.output.every.max(1));
    let (rows_per_second, rows) = match model.analysis {
        crate::model::Analysis::Dynamic { step, end, .. } => {
            (1.0 / (every * step), (end / (every * step)).ceil() + 1.0)
        }
        crate::model::Analysis::Static { steps, .. } => (f64::from(steps), f64::from(steps) + 1.0),
    };
    Volume {
        files,
        rows_per_second,
        bytes_per_row,
        total_bytes: bytes_per_row * rows,
    }
}
