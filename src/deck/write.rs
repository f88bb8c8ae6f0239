//! The canonical writer: [`Model`] → deck text that parses back to the same model.
//!
//! Floats are printed with `{:?}` (shortest representation that reads back exactly);
//! generated nodes and elements are written one per line; every analysis setting is
//! written explicitly.

use crate::model::{
    Analysis, ElementId, Function, Model, NodeId, Scheme, Section, SectionData, Selection,
};
use std::collections::HashSet;
use std::fmt::Write;

use super::build::v3;

fn dofs(fixed: &[bool; 6]) -> String {
    if fixed.iter().all(|f| *f) {
        return "ALL".into();
    }
    const NAMES: [&str; 6] = ["X", "Y", "Z", "RX", "RY", "RZ"];
    let names: Vec<&str> = NAMES
        .iter()
        .zip(fixed)
        .filter(|(_, f)| **f)
        .map(|(n, _)| *n)
        .collect();
    names.join(" ")
}

fn selection<T>(s: &Selection<T>, num: impl Fn(&T) -> u32) -> String {
    match s {
        Selection::All => "ALL".into(),
        Selection::None => "NONE".into(),
        Selection::Default => String::new(),
        Selection::List(v) => {
            let n: Vec<String> = v.iter().map(|x| num(x).to_string()).collect();
            n.join(" ")
        }
    }
}

/// ` t f` pairs, eight to a line (continued with `&`: a line holds at most 16 KiB).
fn points(s: &mut String, pts: &[(f64, f64)]) {
    for (k, (t, v)) in pts.iter().enumerate() {
        if k > 0 && k % 8 == 0 {
            s.push_str(" &\n   ");
        }
        let _ = write!(s, " {t:?} {v:?}");
    }
}

/// Writes `model` as a deck in canonical form: `parse_deck(&write_deck(&m), _)` gives `m`
/// back (spans aside) for every model `parse_deck` can produce.
pub fn write_deck(model: &Model) -> String {
    let mut s = String::new();
    // Generated nodes and elements (DIVIDE, ORDER) are not written: the BEAM card's DIVIDE
    // and ORDER regenerate them with the same numbers.
    let gen_nodes: HashSet<NodeId> = model
        .divisions
        .values()
        .flat_map(|d| d.interior.iter().copied())
        .chain(model.order_nodes.values().flatten().copied())
        .chain(model.modal_nodes())
        .collect();
    let gen_elements: HashSet<ElementId> = model
        .divisions
        .values()
        .flat_map(|d| d.elements.iter().skip(1).copied())
        .collect();
    let _ = writeln!(s, "TITLE {}", model.title);
    // Parameters with their values in force; every field below is written with its value.
    if !model.parameters.is_empty() {
        s.push_str("PARAMETERS\n");
        for (name, v) in &model.parameters {
            let _ = writeln!(s, "  {name} {v:?}");
        }
    }
    if !model.materials.is_empty() {
        s.push_str("MATERIALS\n");
        for m in model.materials.values() {
            let _ = write!(
                s,
                "  {} E {:?} G {:?} RHO {:?}",
                m.id.0, m.young, m.shear, m.density
            );
            if m.damping != 0.0 {
                let _ = write!(s, " DAMPING {:?}", m.damping);
            }
            s.push('\n');
        }
    }
    if !model.sections.is_empty() {
        s.push_str("SECTIONS\n");
        for x in model.sections.values() {
            write_section(&mut s, x);
        }
    }
    if !model.nodes.is_empty() {
        s.push_str("NODES\n");
        for n in model.nodes.values().filter(|n| !gen_nodes.contains(&n.id)) {
            let _ = write!(s, "  {} {}", n.id.0, v3(&n.position));
            if n.fixed.iter().any(|f| *f) {
                let _ = write!(s, " FIX {}", dofs(&n.fixed));
            }
            s.push('\n');
        }
    }
    if !model.functions.is_empty() {
        s.push_str("FUNCTIONS\n");
        for f in model.functions.values() {
            match &f.function {
                Function::Constant(v) => {
                    let _ = writeln!(s, "  {} CONSTANT {v:?}", f.id.0);
                }
                Function::Haversine { start, duration } => {
                    let _ = writeln!(s, "  {} HAVERSINE {start:?} {duration:?}", f.id.0);
                }
                Function::Table(pts) => {
                    let _ = write!(s, "  {} TABLE", f.id.0);
                    points(&mut s, pts);
                    s.push('\n');
                }
                Function::Spline(sp) => {
                    let _ = write!(s, "  {} SPLINE", f.id.0);
                    points(&mut s, sp.points());
                    if let Some((s0, sn)) = sp.slopes() {
                        let _ = write!(s, " SLOPES {s0:?} {sn:?}");
                    }
                    s.push('\n');
                }
                Function::Harmonic {
                    cosine,
                    amplitude,
                    omega,
                    phase,
                    start,
                } => {
                    let kind = if *cosine { "COSINE" } else { "SINE" };
                    let _ = write!(s, "  {} {kind} {amplitude:?} OMEGA {omega:?}", f.id.0);
                    if *phase != 0.0 {
                        let _ = write!(s, " PHASE {phase:?}");
                    }
                    if let Some(t0) = start {
                        let _ = write!(s, " START {t0:?}");
                    }
                    s.push('\n');
                }
                Function::Ramp { t0, f0, t1, f1 } => {
                    let _ = writeln!(s, "  {} RAMP {t0:?} {f0:?} {t1:?} {f1:?}", f.id.0);
                }
                Function::Expr(e) => {
                    // As written: the same field reads back to the same tree.
                    let _ = writeln!(s, "  {} EXPR {}", f.id.0, e.text);
                }
            }
        }
    }
    if !model.elements.is_empty() {
        s.push_str("ELEMENTS\n");
        for e in model.elements.values() {
            if gen_elements.contains(&e.id) {
                continue;
            }
            // Each kind writes its own card (`crate::kinds`).
            if !super::build::write_element(model, e, &mut s) {
                // Not reachable for a model the deck built (every kind has a card,
                // `tests/deck/kinds_registry.rs`): said in the text rather than lost.
                let _ = write!(
                    s,
                    "! element {}: no card writes {}",
                    e.id.0,
                    e.kind.keyword()
                );
            }
            s.push('\n');
        }
    }
    if model.gravity.is_some() || !model.loads.is_empty() {
        s.push_str("LOADS\n");
        if let Some(g) = &model.gravity {
            let _ = writeln!(s, "  GRAVITY {}", v3(g));
        }
        for l in &model.loads {
            let kw = if l.moment { "MOMENT" } else { "FORCE" };
            let _ = write!(s, "  {kw} {} {}", l.node.0, v3(&l.value));
            if let Some(f) = l.function {
                let _ = write!(s, " FUNCTION {}", f.0);
            }
            s.push('\n');
        }
    }
    if model.initial.iter().any(|iv| !gen_nodes.contains(&iv.node)) {
        s.push_str("INITIAL\n");
        for iv in model
            .initial
            .iter()
            .filter(|iv| !gen_nodes.contains(&iv.node))
        {
            let _ = writeln!(
                s,
                "  {} V {} W {}",
                iv.node.0,
                v3(&iv.velocity),
                v3(&iv.angular)
            );
        }
    }
    match (&model.analysis, model.modes) {
        // `ANALYSIS MODES n` parses to the default static analysis of one step: the card
        // alone gives the model back.
        (_, Some(n)) => {
            let rot = match &model.analysis {
                _ if model.modes_rotating => " ROTATING".to_string(),
                Analysis::Static {
                    steps,
                    proportional,
                    ..
                } if model.modes_static => {
                    let p = if *proportional { " PROPORTIONAL" } else { "" };
                    format!(" STATIC STEPS {steps}{p}")
                }
                _ => String::new(),
            };
            let _ = writeln!(s, "ANALYSIS MODES {n}{rot}");
        }
        (
            Analysis::Dynamic {
                scheme,
                step,
                end,
                min_step,
                max_step,
                adaptive,
                newton,
            },
            None,
        ) => {
            let _ = match scheme {
                Scheme::Hht { alpha } => write!(s, "ANALYSIS DYNAMIC ALPHA {alpha:?}"),
                Scheme::GeneralizedAlpha { rho_inf } => {
                    write!(s, "ANALYSIS DYNAMIC GENALPHA RHOINF {rho_inf:?}")
                }
                Scheme::Esdirk3 | Scheme::Esdirk5 => write!(
                    s,
                    "ANALYSIS DYNAMIC {}",
                    scheme.esdirk_keyword().unwrap_or_default()
                ),
            };
            let _ = write!(
                s,
                " STEP {step:?} END {end:?} &\n  MINSTEP {min_step:?} MAXSTEP {max_step:?}"
            );
            if let Some(a) = adaptive {
                let _ = write!(
                    s,
                    " ADAPTIVE TOLPOS {:?} TOLROT {:?} GROWTH {:?}",
                    a.tol_position, a.tol_rotation, a.max_growth
                );
                if a.carry == crate::model::Carry::Modes {
                    s.push_str(" CARRY MODES");
                }
            }
            let _ = writeln!(
                s,
                " &\n  TOL {:?} TOLINC {:?} MAXIT {} NEWTON {}",
                newton.tol_residual,
                newton.tol_increment,
                newton.max_iterations,
                newton_kind(newton)
            );
        }
        (
            Analysis::Static {
                steps,
                newton,
                proportional,
            },
            None,
        ) => {
            let p = if *proportional { " PROPORTIONAL" } else { "" };
            let _ = writeln!(
                s,
                "ANALYSIS STATIC STEPS {steps}{p} TOL {:?} TOLINC {:?} MAXIT {} NEWTON {}",
                newton.tol_residual,
                newton.tol_increment,
                newton.max_iterations,
                newton_kind(newton)
            );
        }
    }
    let o = &model.output;
    s.push_str("OUTPUT");
    // The default selection is written as no field (parsing gives it back).
    if o.nodes != Selection::Default {
        let _ = write!(s, " NODES {}", selection(&o.nodes, |n| n.0));
    }
    if o.elements != Selection::Default {
        let _ = write!(s, " ELEMENTS {}", selection(&o.elements, |e| e.0));
    }
    let _ = write!(s, " EVERY {}", o.every);
    if o.substeps {
        s.push_str(" SUBSTEPS");
    }
    if let Some(d) = &o.dir {
        let _ = write!(s, " DIR {d}");
    }
    if o.vtk {
        s.push_str(" VTK");
    }
    if o.netcdf {
        s.push_str(" FORMAT NETCDF");
    }
    s.push_str("\nEND\n");
    s
}

fn newton_kind(n: &crate::model::NewtonSettings) -> &'static str {
    if n.modified { "MODIFIED" } else { "FULL" }
}

/// One `SECTIONS` card: the geometry (`A I2 I3 J K`) or the properties per unit length
/// (`PROPERTIES EA … RHOI3 [DAMPING η]`; a rigid one lists only its inertia).
fn write_section(s: &mut String, x: &Section) {
    let _ = write!(s, "  {}", x.id.0);
    if x.rigid {
        s.push_str(" RIGID");
    }
    match &x.data {
        SectionData::Geometry(g) => {
            let _ = write!(
                s,
                " A {:?} I2 {:?} I3 {:?} J {:?}",
                g.area, g.i2, g.i3, g.torsion
            );
            if !x.rigid {
                let _ = write!(s, " K {:?}", g.shear_factor);
            }
        }
        SectionData::Properties { props: p, damping } => {
            s.push_str(" PROPERTIES");
            if !x.rigid {
                let (n, m) = (p.cn, p.cm);
                let _ = write!(s, " EA {:?} GA2 {:?} GA3 {:?}", n.x, n.y, n.z);
                let _ = write!(s, " GJ {:?} EI2 {:?} EI3 {:?}", m.x, m.y, m.z);
            }
            let i = p.inertia;
            let _ = write!(s, " RHOA {:?} RHOJ {:?}", p.mass, i.x);
            let _ = write!(s, " RHOI2 {:?} RHOI3 {:?}", i.y, i.z);
            if *damping != 0.0 {
                let _ = write!(s, " DAMPING {damping:?}");
            }
        }
    }
    s.push('\n');
}
