//! The stability suite (issue 8): hard cases users of MECANO-style codes hit, each on a deck
//! from `decks/`. The tests print what they measure (`-- --nocapture`); the figures are
//! recorded in one place, docs/stability.md (with the suite's cost), not repeated here, so
//! that the two cannot disagree (issue 27 §1d). One module a kind of hard case, one test
//! binary: `cargo test --test stability stiff::` runs one of them.

#[path = "../common/mod.rs"]
mod common;

mod bursts;
mod clearance;
mod conservation;
mod damping;
mod failures;
mod stiff;

use mecano::model::{ElementId, ElementKind, Model, NodeId, Scheme};
use mecano::solver::{self, Observer, RunReport, Snapshot};
use nalgebra::{Complex, Matrix3, Vector3};
use std::f64::consts::PI;

/// The integrator the suite runs its cases with instead of the decks' (issue 26):
/// `MECANO_STABILITY_SCHEME=genalpha:0.8 cargo test --test stability` (names as
/// `study --integrator`). Unset: the decks' own, and the α each case sets. The HHT-only
/// closed form is then skipped (generalized-α's is `tests/genalpha.rs`), and the cases
/// that run a deck through the binary (clean failure) keep their decks'.
fn scheme_override() -> Option<Scheme> {
    let s = std::env::var("MECANO_STABILITY_SCHEME").ok()?;
    Some(Scheme::parse(&s).unwrap_or_else(|e| panic!("MECANO_STABILITY_SCHEME: {e}")))
}

/// `common::deck`, with the scheme of [`scheme_override`] if set.
fn deck(name: &str) -> Model {
    let mut m = common::deck(name);
    if let (Some(s), mecano::model::Analysis::Dynamic { scheme, .. }) =
        (scheme_override(), &mut m.analysis)
    {
        *scheme = s;
    }
    m
}

/// Fixed steps `h` to `t_end`, with HHT `alpha` if given — unless the suite runs with
/// another scheme ([`scheme_override`]), which the model then keeps.
fn set_steps(model: &mut Model, h: f64, t_end: f64, alpha: Option<f64>) {
    let alpha = alpha.filter(|_| scheme_override().is_none());
    assert!(
        model.set_fixed_step(h, t_end, alpha.map(|alpha| Scheme::Hht { alpha })),
        "dynamic deck expected"
    );
}

fn set_contact_stiffness(model: &mut Model, k: f64) {
    for el in model.elements.values_mut() {
        if let ElementKind::Came(d) = &mut el.kind {
            d.stiffness = k;
        }
    }
}

fn node(model: &Model, id: u32) -> usize {
    model.nodes.get_index_of(&NodeId(id)).expect("node exists")
}

/// Per accepted state: t, `E − W_ext` (kinetic + strain + gravity − work of the loads),
/// kinetic energy, node states, constraint violation, and the rows of chosen elements.
#[derive(Default)]
struct Rec {
    t: Vec<f64>,
    e: Vec<f64>,
    kin: Vec<f64>,
    nodes: Vec<Vec<mecano::elements::NodeState>>,
    viol: Vec<f64>,
    rows: Vec<Vec<f64>>,
    elem: Option<usize>,
    keep_nodes: bool,
}

impl Observer for Rec {
    fn state(&mut self, snap: &Snapshot) -> std::io::Result<()> {
        let i = snap.integ;
        let en = i.energies();
        self.t.push(i.t);
        self.e
            .push(en.kinetic + en.strain + en.gravity - i.external_work);
        self.kin.push(en.kinetic);
        self.viol.push(i.constraint_violation());
        if self.keep_nodes {
            self.nodes.push(i.nodes.clone());
        }
        if let Some(e) = self.elem {
            self.rows.push(i.sys.elements[e].output_row(
                &i.current_context(),
                &i.nodes,
                i.sys.element_lambda(e, &i.lambda),
            ));
        }
        Ok(())
    }
}

fn run(model: &Model, mut rec: Rec) -> (RunReport, Rec) {
    let report = solver::run(model, &mut rec).expect("run starts");
    (report, rec)
}

fn it_per_step(r: &RunReport) -> f64 {
    r.stats.newton_iterations as f64 / r.stats.steps.max(1) as f64
}

/// Largest rise of `E − W_ext` above its initial value.
fn rise(rec: &Rec) -> f64 {
    rec.e.iter().map(|e| e - rec.e[0]).fold(f64::MIN, f64::max)
}

/// The energy rise a case is judged on. The α schemes: [`rise`]. The stage schemes
/// (ESDIRK3, ESDIRK5) keep the resolved motion's energy to O((ωh)⁴) or better, so the
/// balance's trapezoidal work of a torque pulse errs visibly while it acts (up to
/// 1e-2 of the kinetic energy: the bound `quadrature_bound` of tests/esdirk.rs, which judges
/// that part): for them the rise is measured from the end of the decks' pulse (0.02 s), after
/// which only gravity acts, whose work is in `E`.
fn judged_rise(rec: &Rec) -> f64 {
    if !scheme_override().is_some_and(|s| s.is_esdirk()) {
        return rise(rec);
    }
    let Some(k) = rec.t.iter().position(|t| *t >= 0.02) else {
        return rise(rec);
    };
    rec.e[k..]
        .iter()
        .map(|e| e - rec.e[k])
        .fold(f64::MIN, f64::max)
}

/// Newton solves per step: one for the α schemes, the implicit stages for ESDIRK3 (3) and
/// ESDIRK5 (6), so that the per-solve bounds of the suite hold for every scheme.
fn solves_per_step() -> f64 {
    match scheme_override() {
        Some(Scheme::Esdirk3) => 3.0,
        Some(Scheme::Esdirk5) => 6.0,
        _ => 1.0,
    }
}

fn max_of(v: &[f64]) -> f64 {
    v.iter().copied().fold(0.0, f64::max)
}
