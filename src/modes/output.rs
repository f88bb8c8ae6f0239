//! The files of a modal analysis: `modes.csv` (one row per mode), `modes_shapes.csv` (the
//! shapes at the requested nodes) and `summary.json`. Everything is computed before the
//! first file is opened, so a failed analysis writes nothing; no NaN or infinity reaches a
//! file (an absent period is an empty field).

use super::hht::{self, Resolution};
use super::{ModalAnalysis, Mode};
use crate::elements::NodeState;
use crate::solver::system::{FIXED, System};
use std::fmt::Write as _;
use std::path::Path;

/// The deck's time step and integration scheme, when it is a dynamic deck: what
/// [`step_resolution`] judges the modes against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeckStep {
    /// The time integration scheme.
    pub scheme: crate::model::Scheme,
    /// Time step, s.
    pub h: f64,
}

/// The step-resolution table: for each elastic mode of `analysis`, and for the mesh's
/// highest frequency (last row), samples per period, the scheme's damping and period error.
pub fn step_resolution(analysis: &ModalAnalysis, step: DeckStep) -> Vec<Resolution> {
    let mut rows: Vec<Resolution> = analysis
        .modes
        .iter()
        .filter(|m| m.natural_hz > 0.0 && m.kind == super::ModeKind::Elastic)
        .map(|m| hht::resolution(&step.scheme, step.h, m.natural_hz))
        .collect();
    if analysis.highest_hz > 0.0 {
        rows.push(hht::resolution(&step.scheme, step.h, analysis.highest_hz));
    }
    rows
}

fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// `modes.csv`'s text.
pub fn modes_csv(a: &ModalAnalysis) -> String {
    let mut s = String::from("mode,kind,frequency_hz,natural_hz,damping_ratio,period_s");
    for g in &a.groups {
        let _ = write!(s, ",kinetic_{g},strain_{g}");
    }
    s.push('\n');
    for (i, m) in a.modes.iter().enumerate() {
        let kind = match m.kind {
            super::ModeKind::Rigid => "rigid",
            super::ModeKind::Elastic => "elastic",
            super::ModeKind::Unstable => "unstable",
        };
        let _ = write!(
            s,
            "{},{kind},{},{},{},{}",
            i + 1,
            num(m.frequency_hz),
            num(m.natural_hz),
            num(m.damping_ratio),
            m.period().map_or(String::new(), num)
        );
        for (k, st) in m.kinetic_share.iter().zip(&m.strain_share) {
            let _ = write!(s, ",{},{}", num(*k), num(*st));
        }
        s.push('\n');
    }
    s
}

/// A mode's shape at node `node` (6 components, fixed ones 0).
fn node_shape(sys: &System, m: &Mode, node: usize) -> [f64; 6] {
    sys.node_dofs[node].map(|d| if d == FIXED { 0.0 } else { m.shape[d] })
}

/// `modes_shapes.csv`'s text: the shapes at dense nodes `nodes`, each mode scaled so that
/// its largest translation over all nodes is +1 (its largest rotation when it has no
/// translation), and the nodes' positions `x, y, z` at the state (`states`).
pub fn shapes_csv(
    a: &ModalAnalysis,
    sys: &System,
    nodes: &[usize],
    states: &[NodeState],
) -> String {
    let mut s = String::from("mode,node,ux,uy,uz,rx,ry,rz,x,y,z\n");
    for (i, m) in a.modes.iter().enumerate() {
        let all: Vec<[f64; 6]> = (0..sys.node_ids.len())
            .map(|n| node_shape(sys, m, n))
            .collect();
        let pick = |range: std::ops::Range<usize>| {
            all.iter()
                .flat_map(|v| v[range.clone()].to_vec())
                .max_by(|a, b| a.abs().total_cmp(&b.abs()))
                .unwrap_or(0.0)
        };
        let big = match pick(0..3) {
            t if t != 0.0 => t,
            _ => pick(3..6),
        };
        let scale = if big != 0.0 { 1.0 / big } else { 1.0 };
        for &n in nodes {
            let v = all[n];
            let _ = write!(s, "{},{}", i + 1, sys.node_ids[n].0);
            for c in v {
                let _ = write!(s, ",{}", num(c * scale));
            }
            for c in states[n].x.iter() {
                let _ = write!(s, ",{}", num(*c));
            }
            s.push('\n');
        }
    }
    s
}

/// `summary.json`'s value.
pub fn summary(
    a: &ModalAnalysis,
    deck: &str,
    state: &str,
    time: f64,
    step: Option<DeckStep>,
) -> serde_json::Value {
    let modes: Vec<serde_json::Value> = a
        .modes
        .iter()
        .enumerate()
        .map(|(i, m)| {
            serde_json::json!({
                "mode": i + 1,
                "kind": m.kind,
                "frequency_hz": m.frequency_hz,
                "natural_hz": m.natural_hz,
                "damping_ratio": m.damping_ratio,
                "period_s": m.period(),
            })
        })
        .collect();
    let resolution = step.map(|st| {
        serde_json::json!({
            "integrator": st.scheme.name(),
            "alpha": st.scheme.hht_alpha(),
            "high_frequency_radius": st.scheme.rho_inf(),
            "step": st.h,
            "modes": step_resolution(a, st),
            "note": "last row: the mesh's highest frequency; period_error null = not resolved",
        })
    });
    serde_json::json!({
        "deck": deck,
        "state": state,
        "time": time,
        "method": a.method,
        "free_unknowns": a.free_unknowns,
        "constraint_equations": a.constraints.0,
        "constraint_rank": a.constraints.1,
        "rigid_modes": a.rigid_modes,
        "finite_modes": a.finite_modes,
        "highest_frequency_hz": a.highest_hz,
        "stiffness_asymmetry": a.asymmetry,
        "groups": a.groups,
        "modes": modes,
        "step_resolution": resolution,
        "complete": true,
    })
}

/// Writes the three files into `dir` (created if needed).
pub fn write_all(
    dir: &Path,
    a: &ModalAnalysis,
    sys: &System,
    nodes: &[usize],
    states: &[NodeState],
    summary: &serde_json::Value,
) -> std::io::Result<()> {
    let csv = modes_csv(a);
    let shapes = shapes_csv(a, sys, nodes, states);
    let json = serde_json::to_string_pretty(summary).map_err(std::io::Error::other)?;
    std::fs::create_dir_all(dir)?;
    crate::safe_file::write(&dir.join("modes.csv"), csv.as_bytes())?;
    crate::safe_file::write(&dir.join("modes_shapes.csv"), shapes.as_bytes())?;
    crate::safe_file::write(&dir.join("summary.json"), (json + "\n").as_bytes())?;
    Ok(())
}
