//! The energy guard: a step whose end state holds far more energy than its start state
//! and the work done on the system over the step can pay for is refused, whatever its
//! Newton residual said.
//!
//! Over one step from state n to trial state n+1, with `E = T + U + V_g` (kinetic,
//! strain and contact-spring, gravity potential) and the trapezoidal work of the applied
//! loads and drivers `ΔW` and of the dampers `ΔD` (as `output::Writer` accounts them), the energy the
//! step *created* is `C = (E_{n+1} − E_n) − (ΔW − ΔD)`. HHT with `α ≤ 0` is dissipative
//! for linear systems and creates, on a resolved nonlinear step, a small fraction of the
//! energy in play (O(ωh) of it). A step is refused when both
//! - `C > ½ (T + |U| + |V_g|)_{n+1}`: most of the end state's energy was created by the
//!   step (a step with a resolved motion creates O(ωh) ≪ ½ of it), and
//! - `C > 100 ((T + |U| + |V_g|)_n + |ΔW| + |ΔD|)`: two orders of magnitude more than the
//!   energy the start state held and the work of the step, plus `floor`: the work of the
//!   residual's round-off floor over the model's size (`Integrator::residual_floor ×
//!   ref_length`), below which an energy difference is round-off of the equilibrium.
//!
//! The first bound alone would refuse the first steps of a run from rest (the energies
//! start at zero); the second alone would refuse them too (`C > 0 = 100·0`). Together
//! they hold for every step of a motion that the step resolves and fail for a jump such as
//! the one `docs/stability.md` ("An energy jump in a grazing contact") measured: 18 J to
//! 2.0e11 J in a step of 1e-7 s with 10.8 J of work done over the whole run.

use super::system::System;
use crate::elements::NodeState;

/// Both bounds of the module docs: the fraction of the end state's energy, and the factor
/// over the start state's energy plus the step's work.
const FRACTION_OF_END: f64 = 0.5;
const FACTOR_OVER_START: f64 = 100.0;

/// An energy jump found in a step: the energies in play before and after, the work of the
/// step, and the energy it created, J.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyJump {
    /// `(T + |U| + |V_g|)` at the start of the step, J.
    pub before: f64,
    /// `(T + |U| + |V_g|)` at its end, J.
    pub after: f64,
    /// `|ΔW| + |ΔD|` over the step, J.
    pub work: f64,
    /// Energy created by the step, `C`, J.
    pub created: f64,
}

/// `(T + |U| + |V_g|, E)` of the nodes' state.
fn energy_of(sys: &System, nodes: &[NodeState]) -> (f64, f64) {
    let (mut t, mut u, mut g) = (0.0, 0.0, 0.0);
    for el in &sys.elements {
        let e = el.energies(nodes, &sys.gravity);
        t += e.kinetic;
        u += e.strain;
        g += e.gravity;
    }
    (t.abs() + u.abs() + g.abs(), t + u + g)
}

/// The jump of the step from `old` (at `t0`) to `new` (at `t0 + h`), if it is one
/// (module docs). A non-finite energy counts as a jump.
pub fn check(
    sys: &System,
    old: &[NodeState],
    new: &[NodeState],
    t0: f64,
    h: f64,
    floor: f64,
) -> Option<EnergyJump> {
    check_driven(sys, old, new, t0, h, floor, 0.0)
}

/// [`check`] with the work the drivers did over the step (`driver_work`, J: their power
/// needs the multipliers, which the nodes' states do not hold).
pub fn check_driven(
    sys: &System,
    old: &[NodeState],
    new: &[NodeState],
    t0: f64,
    h: f64,
    floor: f64,
    driver_work: f64,
) -> Option<EnergyJump> {
    let (before, e_old) = energy_of(sys, old);
    let (after, e_new) = energy_of(sys, new);
    let w = 0.5 * (sys.external_power(t0, old) + sys.external_power(t0 + h, new)) * h + driver_work;
    let power = |nodes: &[NodeState]| -> f64 {
        sys.elements.iter().map(|e| e.dissipated_power(nodes)).sum()
    };
    let d = 0.5 * (power(old) + power(new)) * h;
    let created = (e_new - e_old) - (w - d);
    let work = w.abs() + d.abs();
    let jump = !created.is_finite()
        || (created > FRACTION_OF_END * after
            && created > FACTOR_OVER_START * (before + work) + floor);
    jump.then_some(EnergyJump {
        before,
        after,
        work,
        created,
    })
}
