//! The time law of a driver, `a f(t)` with its exact time derivatives (model/drive.rs):
//! what a driven `HINGE`/`PRISMATIC` ([`super::joints`]) and a `PRESCRIBED` element
//! ([`super::prescribed`]) subtract from their rheonomic constraint `g(q) − a f(t) = 0`.
//!
//! The constraint is separable (its Jacobian `B = ∂g/∂q` does not depend on time), so
//! its time derivatives are those of the law alone: `Φ_t = −a ḟ`, `Φ_tt = −a f̈`; the
//! velocity and acceleration levels are `B v = a ḟ` and `B v̇ + Ḃ v = a f̈`
//! (Géradin & Cardona 2001, §5.9, rheonomic constraints), which the integrator's start
//! ([`crate::solver::Integrator::consistent_accelerations`]) imposes.

use crate::model::{self, Function, Model};

/// `a f(t)`: the value a driver prescribes.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeLaw {
    function: Function,
    amplitude: f64,
    /// A value set between steps by a program driving the run, replacing `a f(t)` from
    /// its start on ([`TimeLaw::set_value`]).
    set: Option<Transition>,
    /// The law's last evaluations.
    last: Last,
}

/// The last two `(t, [a f, a ḟ, a f̈])` of a law: every Newton iteration of a step asks for
/// the same time, and the accepted step's powers for its two ends; an expression's jet
/// costs microseconds (Kane's spin-up of benches/peers/: 27 % of its run evaluated its
/// driver's law again at each iteration). A pure function of `t`, so the value kept is the
/// value computed. Shared between threads (elements are `Sync`): a lock that is taken
/// computes afresh. A copy starts empty; it is not part of a law's identity.
/// (Boxed: a law is held by value in larger enums, as the PID controller's target.)
#[derive(Debug, Default)]
struct Last(Box<std::sync::Mutex<[Kept; 2]>>);

/// A time and the law's `[a f, a ḟ, a f̈]` there.
type Kept = Option<(f64, [f64; 3])>;

impl Clone for Last {
    fn clone(&self) -> Self {
        Last::default()
    }
}

impl PartialEq for Last {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// A driver's value set between steps (issue 36 §5): from the time `t0` it was set, the
/// prescribed value goes from the state `(p0, ṗ0, p̈0)` the law had there to the `target`
/// held at rest, along the quintic `p(s)`, `s = t − t0`, that matches value, rate and
/// acceleration at both ends (`p(T) = target`, `ṗ(T) = p̈(T) = 0`, `T = t1 − t0`): the
/// prescribed motion stays C², so the rheonomic velocity and acceleration terms `ṗ`, `p̈`
/// are continuous and no impulse is needed (a jump in value or rate is refused:
/// [`TimeLaw::set_value`]). From `t1` on, `(target, 0, 0)`. With
/// `Δ = target − p0 − ṗ0 T − p̈0 T²/2`, `Δ₁ = −ṗ0 − p̈0 T`, `Δ₂ = −p̈0`, the quintic is
/// `p0 + ṗ0 s + p̈0 s²/2 + c3 s³ + c4 s⁴ + c5 s⁵`, `c3 = (10Δ − 4Δ₁T + Δ₂T²/2)/T³`,
/// `c4 = (−15Δ + 7Δ₁T − Δ₂T²)/T⁴`, `c5 = (6Δ − 3Δ₁T + Δ₂T²/2)/T⁵` (Hermite's
/// interpolation of degree 5).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Transition {
    /// When it was set, s.
    pub t0: f64,
    /// When the target is reached, s (`t1 ≥ t0`).
    pub t1: f64,
    /// The law's value, rate and acceleration at `t0`.
    pub start: [f64; 3],
    /// The value held from `t1` on (rad or m).
    pub target: f64,
}

impl Transition {
    /// `[p, ṗ, p̈]` at `t` (the start state before `t0`, which a run never asks for).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let [p0, v0, a0] = self.start;
        let big_t = self.t1 - self.t0;
        if t >= self.t1 || big_t <= 0.0 {
            return [self.target, 0.0, 0.0];
        }
        let s = (t - self.t0).max(0.0);
        let d = self.target - p0 - v0 * big_t - 0.5 * a0 * big_t * big_t;
        let d1 = -v0 - a0 * big_t;
        let d2 = -a0;
        let (t2, t3) = (big_t * big_t, big_t * big_t * big_t);
        let c3 = (10.0 * d - 4.0 * d1 * big_t + 0.5 * d2 * t2) / t3;
        let c4 = (-15.0 * d + 7.0 * d1 * big_t - d2 * t2) / (t3 * big_t);
        let c5 = (6.0 * d - 3.0 * d1 * big_t + 0.5 * d2 * t2) / (t3 * t2);
        let (s2, s3) = (s * s, s * s * s);
        [
            p0 + v0 * s + 0.5 * a0 * s2 + c3 * s3 + c4 * s3 * s + c5 * s3 * s2,
            v0 + a0 * s + 3.0 * c3 * s2 + 4.0 * c4 * s3 + 5.0 * c5 * s2 * s2,
            a0 + 6.0 * c3 * s + 12.0 * c4 * s2 + 20.0 * c5 * s3,
        ]
    }
}

/// Why a driver's value cannot be set ([`TimeLaw::set_value`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetDriveError {
    /// A value, rate or duration that is not finite, or a negative duration.
    #[error("the value {value} and the duration {over} s must be finite, the duration >= 0")]
    NotFinite {
        /// The value asked for.
        value: f64,
        /// The duration asked for.
        over: f64,
    },
    /// A change at once (`over = 0`) that would make the prescribed value or its rate jump.
    #[error(
        "the driver's prescribed value would jump at t = {t} s from {from:.9e} (rate {rate:.3e}, acceleration {acc:.3e}) to {to:.9e} held at rest: a prescribed motion must be continuous with its velocity (a jump needs an impulse, which no step can apply); give a duration over which it moves there (a C² quintic from the present value, rate and acceleration)"
    )]
    Jump {
        /// The time.
        t: f64,
        /// The law's value now.
        from: f64,
        /// Its rate now.
        rate: f64,
        /// Its acceleration now.
        acc: f64,
        /// The value asked for.
        to: f64,
    },
}

impl TimeLaw {
    /// The law of a model drive (its function validated by the deck: it has derivatives).
    pub fn from_model(model: &Model, drive: &model::Drive) -> Self {
        TimeLaw {
            function: model.functions[&drive.function].function.clone(),
            amplitude: drive.amplitude,
            set: None,
            last: Last::default(),
        }
    }

    /// A law from its parts (tests).
    pub fn new(function: Function, amplitude: f64) -> Self {
        TimeLaw {
            function,
            amplitude,
            set: None,
            last: Last::default(),
        }
    }

    /// From `t` on, the value `target` reached over `over` seconds ([`Transition`]); with
    /// `over = 0`, at once, which only a law already at `(target, 0, 0)` allows (to 1e-12 of
    /// the value's scale, and 1e-9 of it per second for the rate).
    pub fn set_value(&mut self, t: f64, target: f64, over: f64) -> Result<(), SetDriveError> {
        if !(target.is_finite() && over.is_finite() && over >= 0.0 && t.is_finite()) {
            return Err(SetDriveError::NotFinite {
                value: target,
                over,
            });
        }
        let start = self.at(t);
        if over == 0.0 {
            let scale = target.abs().max(start[0].abs()).max(1.0);
            if (start[0] - target).abs() > 1e-12 * scale
                || start[1].abs() > 1e-9 * scale
                || start[2].abs() > 1e-9 * scale
            {
                return Err(SetDriveError::Jump {
                    t,
                    from: start[0],
                    rate: start[1],
                    acc: start[2],
                    to: target,
                });
            }
        }
        self.set = Some(Transition {
            t0: t,
            t1: t + over,
            start,
            target,
        });
        Ok(())
    }

    /// The value set between steps, if any.
    pub fn transition(&self) -> Option<Transition> {
        self.set
    }

    /// Puts back a value set between steps (a restart from a checkpoint).
    pub fn restore_transition(&mut self, set: Option<Transition>) {
        self.set = set;
    }

    /// `[a f, a ḟ, a f̈]` at `t`, or the value set between steps (zeros for a function without derivatives, which the deck
    /// refuses for a driver).
    pub fn at(&self, t: f64) -> [f64; 3] {
        if let Some(s) = &self.set {
            return s.at(t);
        }
        let mut last = self.last.0.try_lock().ok();
        if let Some(kept) = last.as_deref_mut()
            && let Some(i) = kept
                .iter()
                .position(|k| k.is_some_and(|(u, _)| u.to_bits() == t.to_bits()))
        {
            // The one used last goes first, so that the next new time replaces the other:
            // a step asks for t_{n+1} (Newton), then t_n and t_{n+1} (the accepted step's
            // powers), then t_{n+2}: kept by first use, t_n would push t_{n+1} out before
            // the next step's t_n was asked, one evaluation more per step.
            kept.swap(0, i);
            return kept[0].map_or([0.0; 3], |(_, v)| v);
        }
        let [f, fd, fdd] = self.function.derivatives(t).unwrap_or([0.0; 3]);
        let v = [
            self.amplitude * f,
            self.amplitude * fd,
            self.amplitude * fdd,
        ];
        if let Some(kept) = last.as_deref_mut() {
            *kept = [Some((t, v)), kept[0]];
        }
        v
    }

    /// `a f(t)`.
    pub fn value(&self, t: f64) -> f64 {
        self.at(t)[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The transition's quintic meets its six end conditions, its rate and acceleration
    /// are the derivatives of its value (central differences, error O(δ²) ≈ 1e-9), and a
    /// change at once is refused unless the law is already at rest at the target.
    /// The kept last evaluation gives what a fresh evaluation gives, bit for bit, at the
    /// same time and after others; a value set between steps replaces it from its time on.
    #[test]
    fn the_last_evaluation_kept_is_the_law() {
        let f = Function::Harmonic {
            cosine: false,
            amplitude: 1.0,
            omega: 2.0,
            phase: 0.1,
            start: None,
        };
        let mut law = TimeLaw::new(f.clone(), 0.5);
        let fresh = |t: f64| TimeLaw::new(f.clone(), 0.5).at(t);
        for t in [0.3, 0.3, 0.7, 0.3, 0.3] {
            assert_eq!(law.at(t).map(f64::to_bits), fresh(t).map(f64::to_bits));
        }
        assert_eq!(law.value(0.3), fresh(0.3)[0]);
        // A run's order: t_{n+1} by Newton, then t_n and t_{n+1} for the step's powers,
        // then t_{n+2}: the step's end stays kept for the next step's start.
        for t in [1.0, 0.9, 1.0, 1.1] {
            law.at(t);
        }
        let kept = *law.last.0.lock().unwrap();
        assert_eq!(kept.map(|k| k.map(|(t, _)| t)), [Some(1.1), Some(1.0)]);
        law.set_value(0.3, 0.2, 0.4).unwrap();
        assert_eq!(law.at(0.9), [0.2, 0.0, 0.0]);
        assert_ne!(law.at(0.5), fresh(0.5));
    }

    #[test]
    fn transition_is_c2_at_both_ends() {
        let mut law = TimeLaw::new(
            Function::Harmonic {
                cosine: false,
                amplitude: 1.0,
                omega: 2.0,
                phase: 0.0,
                start: None,
            },
            0.5,
        );
        let t0 = 0.3;
        let before = law.at(t0);
        assert!(matches!(
            law.set_value(t0, 0.2, 0.0),
            Err(SetDriveError::Jump { .. })
        ));
        law.set_value(t0, 0.2, 0.4).unwrap();
        let start = law.at(t0);
        for k in 0..3 {
            assert!(
                (start[k] - before[k]).abs() <= 1e-14,
                "{k}: {start:?} {before:?}"
            );
        }
        let end = law.at(0.7);
        for (k, want) in [0.2, 0.0, 0.0].iter().enumerate() {
            assert!((end[k] - want).abs() <= 1e-12, "{k}: {end:?}");
        }
        assert_eq!(law.at(1.5), [0.2, 0.0, 0.0]);
        let d = 1e-5;
        for t in [0.35, 0.5, 0.65] {
            let (m, p, c) = (law.at(t - d), law.at(t + d), law.at(t));
            assert!(
                ((p[0] - m[0]) / (2.0 * d) - c[1]).abs() < 1e-8,
                "rate at {t}"
            );
            assert!(
                ((p[1] - m[1]) / (2.0 * d) - c[2]).abs() < 1e-7,
                "acc at {t}"
            );
        }
        // At rest at the target: a change at once is the same value held.
        law.set_value(2.0, 0.2, 0.0).unwrap();
        assert_eq!(law.at(2.5), [0.2, 0.0, 0.0]);
        assert!(law.set_value(2.0, f64::NAN, 0.0).is_err());
        assert!(law.set_value(2.0, 0.1, -1.0).is_err());
    }
}
