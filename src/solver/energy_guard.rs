//! The energy guard: a step, or a run of steps, that creates more energy than no work
//! paid for and than the scheme's own error allows is refused (retried shorter, or the
//! run stops with the diagnosis), whatever Newton's residual said.
//!
//! With `E = T + U + V_g` (kinetic, strain and contact-spring, gravity potential), `W` the
//! trapezoidal work of the loads and drivers and `D` that of the dampers (as
//! `output::Writer` accounts them), the *balance residual* `R = E − E(0) − W + D` is the
//! energy the integration created (`−R` is its numerical dissipation). After every
//! converged step the guard asks that `R` has not risen above its smallest earlier value
//! `R(s)` (at `s`, the start of the run of steps checked) by more than
//!
//! ```text
//! g · E_osc(s)  +  Θ  +  min( Σ_{steps since s} [h (|ΔP_ext| + |ΔP_drive| + |ΔP_damp|) + N],
//!                             max_{steps since s} E_osc / 12  +  N_this step )  +  floor,
//! Θ = max_{steps since s} min(|Ω|_max h, ½)² T
//! ```
//!
//! (`docs/stability.md`, "The energy guard's bound", derives it):
//! - `g` ([`bound::run_bound`]): on a linear system the physical energy of the modes an α
//!   scheme's step represents as oscillations (`ωh ≤ π`) rises along the scheme's own orbit
//!   by at most the factor `1 + g` over any run of steps at one step size (the acceleration
//!   history holds the rest; HHT α = −0.1: `g = 0.222`; the trapezoidal rule and the stage
//!   schemes: `g = 0`). `E_osc = T + |U|` is the energy of those oscillations (the
//!   gravity potential, relative to a datum, is left out).
//! - The work and the dampers' dissipation are trapezoidal sums: over a step on which a
//!   power is monotone its integral lies between the two one-sided rules, `h P_n` and
//!   `h P_{n+1}`, a bracket of width `h |ΔP|` around the trapezoid (which errs by at most
//!   half of it there; the whole width also covers a power that bends within the step:
//!   the torque pulse of `pendulum_converged.dat`, ESDIRK5, needs 0.68 of it).
//! - `N`, what Newton leaves of each step: states within δ (the last increment, at most
//!   the tolerance) of the discrete solution, whose energies are uncertain by
//!   `c_v δ (L_ref √(2T M) + √(2T J)) + δ L_ref n f_ref` (`c_v = ∂v/∂u` of the step); each
//!   step starts from the state the previous one left, so these add up.
//! - The rotation update `R exp(hΩ)` of a body whose `Ω` turns is second order: the
//!   energy it conserves differs from `T` by `O((|Ω| h)²) T` (the free rigid body's energy
//!   error, bounded and oscillating: Simo & Wong 1991), which a run of steps may show. The
//!   estimate is asymptotic: it is used up to [`ROTATION_RESOLVED`] rad per step.
//! - **The ceiling.** These allowances are sums over the steps since `s`, and a long run
//!   of steps (1.5e5 steps of 1e-7 s: the fuzzer's case 11_4566) or powers that swing
//!   within a step (11_883) make them exceed the energy the system ever had. Whatever
//!   they add up to, each source of error has its own share of the energy in play: the
//!   scheme's `g E_osc(s)`, the rotation's term, and the trapezoid's
//!   [`QUADRATURE_SHARE`] of the largest `E_osc` since `s` (over a run of steps the
//!   composite trapezoid errs by `h²[Ṗ]/12`, Euler–Maclaurin: it does not add up step
//!   after step). The bound is the smaller of the sum and this ceiling (with this step's
//!   own Newton term). A burst creates energy no source accounts for, however many steps
//!   it spreads over, and it counts in the largest `E_osc`: a burst `B` from `E₀` in play
//!   is refused once `B > (g + ¼) E₀ + (E₀ + B)/12`.
//! - **At the smallest step.** A rise above the ceiling but within the summed bound is
//!   refused and the step retried shorter, down to `MINSTEP`: a step that resolves the
//!   powers brings it under the ceiling. One that cannot — a mode the step cannot follow
//!   at any length the deck allows, such as a PID's derivative gain on a hub of almost no
//!   inertia from rest (`tests/deck/fuzz/pid_flexible_arm_dense_eigen_hang.dat`: a time
//!   constant of 5e-8 s against a smallest step of 1e-6 s: the trapezoid of `u θ̇` counts
//!   0.026 J created over its first 50 steps, where the HHT scheme's own work
//!   `f_{n+1+α}·Δq` shows 4.1e-3 J dissipated by the run's end) — is
//!   accepted at the smallest step: what it created above the ceiling is added to the
//!   run's *unverified* energy ([`Balance::unverified`]), the run of steps checked starts
//!   afresh, and the run ends with a warning (`Notice::CoarseBalance`). Above the summed
//!   bound a step is refused at any length.
//! - `floor`: the round-off of the equilibrium (`Integrator::residual_floor` over the
//!   model's size) and of the energies' sums (`64 ε n_elements E_play`).
//!
//! A step that fails it is refused and retried shorter (its modes back under `ωh ≤ π`,
//! where the bound holds); at the smallest step the run stops with the diagnosis (above
//! the summed bound) or goes on and says so (above the ceiling only). A
//! spurious Newton root (1e5 J from 179 J, issue 28) fails it by orders of magnitude; so
//! does the burst of issue 35 (66 J created in 2 ms on the seed's scene); a run the steps
//! resolve never comes near it (`tests/stability/`).

pub mod bound;

use super::system::System;
use crate::elements::NodeState;

/// The largest turn per step, rad, for which the rotation update's energy error is
/// allowed its asymptotic size `(|Ω| h)² T`: a step that turns a node further resolves
/// nothing of its rotation, and gets no more allowance than this turn's (a quarter of `T`),
/// so that energy created there is refused and the step retried shorter.
pub const ROTATION_RESOLVED: f64 = 0.5;

/// The share of the largest energy of the oscillations that the trapezoidal work may err
/// by over a run of steps that resolve the powers: the composite rule errs by `h²|Ṗ(b) − Ṗ(a)|/12`
/// (Euler–Maclaurin); a power exchanging `E` at `ω` has `|Ṗ| ≤ 2ω²E`, so at `ωh ≤ ½`
/// ([`ROTATION_RESOLVED`]) the error is at most `E/12`.
pub const QUADRATURE_SHARE: f64 = 1.0 / 12.0;

/// An energy the guard refused: what a step or a run of steps created, against its bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyJump {
    /// `E_play` at the start of the step, J.
    pub before: f64,
    /// `E_play` at its end, J.
    pub after: f64,
    /// `|ΔW| + |ΔD|` over the step, J.
    pub work: f64,
    /// Energy created since `since` (the rise of the balance residual), J.
    pub created: f64,
    /// Its bound, J.
    pub bound: f64,
    /// Energy the refused step alone created, J.
    pub by_step: f64,
    /// When the run of steps began (the balance residual's smallest value), s.
    pub since: f64,
}

/// What the guard reads of a state: energies, the rates of the module docs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Measure {
    /// `E = T + U + V_g`, J.
    pub energy: f64,
    /// `E_play = T + |U| + |V_g|`, J.
    pub play: f64,
    /// `T`, J.
    pub kinetic: f64,
    /// `U`, J.
    pub strain: f64,
    /// `E_osc = T + |U|`, J: the energy of the oscillations about the gravity field (the
    /// gravity potential is left out: it is relative to a datum, the initial configuration).
    pub osc: f64,
    /// Power of the loads, W.
    pub p_ext: f64,
    /// Power dissipated by the dampers, W.
    pub p_damp: f64,
    /// Largest angular velocity of a node, rad/s.
    pub w_max: f64,
}

/// The guard's record along a run (checkpointed with the integrator's state).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Balance {
    /// `E` at the start of the run (set at its first step), J.
    pub e0: Option<f64>,
    /// The balance residual `R` at the last accepted state, J.
    pub residual: f64,
    /// The smallest `R` so far, J (the start `s` of the run of steps checked).
    pub min: f64,
    /// Time of `min`, s.
    pub t_min: f64,
    /// `E_osc = T + |U|` at `t_min`, J.
    pub osc: f64,
    /// `Σ [h(|ΔP_ext| + |ΔP_drive| + |ΔP_damp|) + N]` over the steps since `t_min`, J.
    pub quadrature: f64,
    /// Largest `(|Ω|_max h)² T` since `t_min`, J.
    pub rotation: f64,
    /// The largest rise of `R` above its running minimum accepted, J.
    pub largest_rise: f64,
    /// The bound the largest rise was checked against, J.
    pub its_bound: f64,
    /// The largest `E_osc` since `t_min`, J.
    pub osc_max: f64,
    /// The largest `E_osc` of the run's accepted steps, J.
    pub largest_osc: f64,
    /// What steps at the smallest step created above the ceiling, within the summed
    /// bound, summed over the run, J (module docs, "At the smallest step").
    pub unverified: f64,
    /// How many such steps were accepted.
    pub unverified_steps: u64,
    /// When the first of them ended, s.
    pub first_unverified: f64,
}

/// A converged step, as the guard checks it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Step {
    /// The measure at its start.
    pub old: Measure,
    /// The measure at its end.
    pub new: Measure,
    /// The drivers' and controlled inputs' powers at both ends, W.
    pub drive: (f64, f64),
    /// Its length, s.
    pub h: f64,
    /// Its end time, s.
    pub t_new: f64,
    /// What Newton left of it (module docs), J.
    pub newton: f64,
    /// Whether it is as short as a step may be cut (`MINSTEP`): the ceiling is then no
    /// longer a reason to refuse it (module docs, "At the smallest step").
    pub at_floor: bool,
}

/// A step the guard passed: the record to keep if the step is accepted.
#[derive(Debug, Clone, Copy)]
pub struct Passed(Balance);

/// The [`Measure`] of `nodes` at time `t`.
pub fn measure(sys: &System, nodes: &[NodeState], t: f64) -> Measure {
    let (mut kinetic, mut u, mut g) = (0.0, 0.0, 0.0);
    for el in &sys.elements {
        let e = el.energies(nodes, &sys.gravity);
        kinetic += e.kinetic;
        u += e.strain;
        g += e.gravity;
    }
    Measure {
        energy: kinetic + u + g,
        play: kinetic.abs() + u.abs() + g.abs(),
        kinetic,
        strain: u,
        osc: kinetic.abs() + u.abs(),
        p_ext: sys.external_power(t, nodes),
        p_damp: sys.elements.iter().map(|e| e.dissipated_power(nodes)).sum(),
        w_max: nodes.iter().map(|n| n.w.norm()).fold(0.0, f64::max),
    }
}

/// The `step` checked against the run's record (module docs) with the scheme's `g` and
/// the round-off `floor`, J, of a model of `n_elements`. A non-finite energy is refused.
pub fn check(
    record: &Balance,
    step: &Step,
    g: f64,
    floor: f64,
    n_elements: usize,
) -> Result<Passed, EnergyJump> {
    let Step {
        old,
        new,
        drive,
        h,
        t_new,
        newton,
        at_floor,
    } = *step;
    let (old, new) = (&old, &new);
    let mut b = *record;
    if b.e0.is_none() {
        b.e0 = Some(old.energy);
        b.residual = 0.0;
        b.min = 0.0;
        b.t_min = t_new - h;
        b.osc = old.osc;
    }
    let work = 0.5 * (old.p_ext + new.p_ext) * h + 0.5 * (drive.0 + drive.1) * h;
    let damp = 0.5 * (old.p_damp + new.p_damp) * h;
    let by_step = (new.energy - old.energy) - work + damp;
    let residual = b.residual + by_step;
    let quadrature = b.quadrature
        + h * ((new.p_ext - old.p_ext).abs()
            + (drive.1 - drive.0).abs()
            + (new.p_damp - old.p_damp).abs())
        + newton;
    let turn = (old.w_max.max(new.w_max) * h).min(ROTATION_RESOLVED);
    let rotation = b.rotation.max(turn.powi(2) * old.kinetic.max(new.kinetic));
    let floor = floor + 64.0 * f64::EPSILON * n_elements as f64 * old.play.max(new.play);
    let rise = residual - b.min;
    // The ceiling (module docs): the scheme's and the rotation's terms, the trapezoid's
    // share of the largest energy of the oscillations since `s`, this step's Newton term.
    let osc_max = b.osc_max.max(b.osc).max(old.osc).max(new.osc);
    let ceiling = g * b.osc + rotation + QUADRATURE_SHARE * osc_max + newton + floor;
    let summed = g * b.osc + quadrature + rotation + floor;
    // Above the ceiling but within the summed bound, a step is refused and retried shorter
    // until it is as short as it may be; there it is accepted, and said (module docs).
    let over_ceiling = rise > ceiling && rise <= summed;
    let bound = if over_ceiling && at_floor {
        summed
    } else {
        summed.min(ceiling)
    };
    // Dampers cannot take more than the energy in play and the work of the step: a
    // trapezoidal dissipation beyond that is the quadrature of a power the step does not
    // resolve (the fuzzer's case 11:3199: 34.9 J "dissipated" in one step of a 0.58 J
    // system, inside a bracket h|ΔP_damp| of 69 J), refused like an energy created.
    let available = old.play + new.play + work.abs() + floor;
    let unresolved = damp > available;
    if !residual.is_finite() || !rise.is_finite() || rise > bound || unresolved {
        let bound = if unresolved {
            available.min(bound)
        } else {
            bound
        };
        return Err(EnergyJump {
            before: old.play,
            after: new.play,
            work: work.abs() + damp.abs(),
            created: rise,
            bound,
            by_step,
            since: b.t_min,
        });
    }
    b.residual = residual;
    b.largest_osc = b.largest_osc.max(old.osc).max(new.osc);
    if rise > b.largest_rise {
        b.largest_rise = rise;
        b.its_bound = bound;
    }
    if over_ceiling {
        // Accepted at the smallest step: what it created above the ceiling is counted
        // and said, and the run of steps checked starts afresh here, so that the next
        // steps are not cut again for what this one could not resolve.
        if b.unverified_steps == 0 {
            b.first_unverified = t_new;
        }
        b.unverified += rise - ceiling;
        b.unverified_steps += 1;
    }
    if residual < b.min || over_ceiling {
        b.min = residual;
        b.t_min = t_new;
        b.osc = new.osc;
        b.quadrature = 0.0;
        b.rotation = 0.0;
        b.osc_max = new.osc;
    } else {
        b.quadrature = quadrature;
        b.rotation = rotation;
        b.osc_max = osc_max;
    }
    Ok(Passed(b))
}

impl Balance {
    /// What `summary.json` says of the guard (its `energy` object's entries).
    pub fn summary(&self) -> GuardSummary {
        GuardSummary {
            largest_created: self.largest_rise,
            its_bound: self.its_bound,
            largest_oscillation: self.largest_osc,
            unverified: self.unverified,
            unverified_steps: self.unverified_steps,
        }
    }
}

/// What `summary.json` says of the energy guard, J.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GuardSummary {
    /// The largest rise of the balance residual accepted.
    pub largest_created: f64,
    /// The bound it was checked against.
    pub its_bound: f64,
    /// The largest `E_osc = T + |U|` of the run's steps.
    pub largest_oscillation: f64,
    /// Energy created above the ceiling by steps accepted at the smallest step.
    pub unverified: f64,
    /// How many such steps.
    pub unverified_steps: u64,
}

impl Passed {
    /// The record to keep once the step is accepted.
    pub fn record(self) -> Balance {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(old: Measure, new: Measure, h: f64, t_new: f64) -> Step {
        Step {
            old,
            new,
            h,
            t_new,
            ..Step::default()
        }
    }

    fn m(energy: f64, p_ext: f64) -> Measure {
        Measure {
            energy,
            play: energy.abs(),
            osc: energy.abs(),
            kinetic: energy.abs(),
            p_ext,
            ..Measure::default()
        }
    }

    /// A run of steps: the record follows the residual's minimum; energy created beyond
    /// `g E_osc(s)` plus the allowances since the minimum `s` is refused, also when no
    /// single step would be (a run of steps); a step whose load power changes gets its
    /// quadrature's allowance; a non-finite energy is refused.
    #[test]
    fn a_run_of_small_creations_is_refused_once_it_exceeds_the_bound() {
        let g = 0.1;
        let mut rec = Balance::default();
        // A dissipative step: the minimum moves, E_osc(s) = 99 J.
        let p = check(
            &rec,
            &step(m(100.0, 0.0), m(99.0, 0.0), 1e-3, 1e-3),
            g,
            0.0,
            1,
        )
        .unwrap()
        .record();
        assert_eq!((p.min, p.t_min, p.osc), (-1.0, 1e-3, 99.0));
        rec = p;
        // Steps creating 2 J each against g E_osc(s) = 9.9 J: four pass, the fifth is refused.
        let mut e = 99.0;
        let mut refused = None;
        for k in 0..10 {
            match check(
                &rec,
                &step(m(e, 0.0), m(e + 2.0, 0.0), 1e-3, 0.0),
                g,
                0.0,
                1,
            ) {
                Ok(p) => {
                    rec = p.record();
                    e += 2.0;
                }
                Err(j) => {
                    refused = Some((k, j));
                    break;
                }
            }
        }
        let (k, j) = refused.expect("a run of steps creating energy is refused");
        assert_eq!(k, 4, "{j:?}");
        assert!(
            j.created > j.bound && (j.by_step - 2.0).abs() < 1e-12,
            "{j:?}"
        );
        assert!((j.bound - 9.9).abs() < 1e-9, "{j:?}");
        // A load whose power changes by 6e3 W over the step: h |ΔP| = 6 J of allowance
        // (and its trapezoidal work, 3 J, paid for 3 of the 6 J the step adds).
        let ok = check(
            &rec,
            &step(m(e, 0.0), m(e + 6.0, 6e3), 1e-3, 0.0),
            g,
            0.0,
            1,
        );
        assert!(ok.is_ok(), "{ok:?}");
        assert!(
            check(
                &rec,
                &step(m(e, 0.0), m(f64::NAN, 0.0), 1e-3, 0.0),
                g,
                0.0,
                1
            )
            .is_err()
        );
    }

    /// Powers that swing by 2e6 W within each step (a driver's, alternating in sign: the
    /// fuzzer's case 11_883) make the summed brackets 2e3 J a step; the energy a run of
    /// such steps creates is still refused once it passes the ceiling, `g E_osc(s)` plus
    /// the trapezoid's share of the largest `E_osc`, 1/12 — here at the second step.
    #[test]
    fn brackets_of_unresolved_powers_do_not_lift_the_ceiling() {
        let g = 0.1;
        let mut rec = Balance::default();
        let mut e = 10.0;
        let mut created = 0.0;
        for k in 0..20 {
            // Net driver work zero over the step (±1e6 W), 1.2 J created.
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            let mut s = step(m(e, 0.0), m(e + 1.2, 0.0), 1e-3, (k + 1) as f64 * 1e-3);
            s.drive = (sign * 1e6, -sign * 1e6);
            match check(&rec, &s, g, 0.0, 1) {
                Ok(p) => {
                    rec = p.record();
                    e += 1.2;
                    created += 1.2;
                }
                Err(j) => {
                    // The sum of the brackets alone would have allowed 2e3 J a step;
                    // the ceiling is 1 J + 12.4 J / 12.
                    assert!(
                        (j.bound - (0.1 * 10.0 + (e + 1.2) / 12.0)).abs() < 1e-9,
                        "{j:?}"
                    );
                    assert!(j.created > j.bound, "{j:?}");
                    assert!((created - 1.2f64).abs() < 1e-12, "{j:?}");
                    return;
                }
            }
        }
        panic!("20 J created in a 10 J system with no work was accepted");
    }

    /// "At the smallest step": a rise above the ceiling but within the summed bound is
    /// refused at any step the stepper may still cut, accepted at `MINSTEP`, counted as
    /// unverified, and the run of steps checked starts afresh after it; above the summed
    /// bound a step is refused at the smallest step too.
    #[test]
    fn the_ceiling_cuts_steps_down_to_the_smallest_then_says_so() {
        let g = 0.1;
        let rec = Balance::default();
        // 10 J in play, 2.5 J created, the powers' brackets allow 2e3 J: above the
        // ceiling, g E_osc(s) + E_osc,max / 12 = 1 J + 12.5 J / 12 = 2.04 J.
        let mut s = step(m(10.0, 0.0), m(12.5, 0.0), 1e-3, 1e-3);
        s.drive = (1e6, -1e6);
        let j = check(&rec, &s, g, 0.0, 1).expect_err("above the ceiling, not at the floor");
        let ceiling = 0.1 * 10.0 + 12.5 / 12.0;
        assert!((j.bound - ceiling).abs() < 1e-12, "{j:?}");
        s.at_floor = true;
        let rec = check(&rec, &s, g, 0.0, 1)
            .expect("within the summed bound at the smallest step")
            .record();
        assert_eq!(rec.unverified_steps, 1);
        assert!((rec.unverified - (2.5 - ceiling)).abs() < 1e-12, "{rec:?}");
        assert!((rec.first_unverified - 1e-3).abs() < 1e-15);
        // The run of steps checked starts afresh: a next step that creates nothing passes
        // at the stepper's full length.
        let next = step(m(12.5, 0.0), m(12.5, 0.0), 1e-3, 2e-3);
        let rec = check(&rec, &next, g, 0.0, 1)
            .expect("nothing created")
            .record();
        assert_eq!(rec.unverified_steps, 1);
        // Above the summed bound (no brackets: g E_osc + 1/12 only), refused at the floor.
        let mut burst = step(m(12.5, 0.0), m(40.0, 0.0), 1e-3, 3e-3);
        burst.at_floor = true;
        assert!(check(&rec, &burst, g, 0.0, 1).is_err());
    }
}
