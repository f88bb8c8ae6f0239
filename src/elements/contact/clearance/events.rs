//! Events of the joint — touch, separation, impacts resolved by the step — as CAME's
//! (`came/events.rs`, whose roots and constants this reuses), with the gap `g = −δ`.

use super::{Clearance, JointState};
use crate::elements::came::events::{first_root, hermite_root};
use crate::elements::came::{EVENT_TOL, LAND, LIMIT_SLACK};
use crate::elements::{EvalContext, NodeState, StepLimit};
use crate::model::ContactLaw;
use std::f64::consts::PI;
use std::sync::atomic::Ordering;

impl Clearance {
    /// Whether the joint is closed at a state: penetrating, or within the landing
    /// tolerance of a touch event the committed state sits on.
    pub(super) fn closed(&self, st: &JointState<f64>) -> bool {
        st.pen > 0.0 || (self.touching && -st.pen <= self.touch_tol)
    }

    /// The normal force actually applied (compressive, clipped at zero), N.
    pub(super) fn applied(&self, st: &JointState<f64>) -> f64 {
        if self.closed(st) {
            st.force.max(0.0)
        } else {
            0.0
        }
    }

    /// Dissipated power (hysteresis or dashpot, clipped spring energy, friction), W:
    /// `(F − F_el) δ̇ + μ F |v_t|²/√(|v_t|² + v_reg²)`, minus the power of the contact
    /// forces on the bodies less the rate of the contact energy.
    pub(super) fn power(&self, st: &JointState<f64>) -> f64 {
        if !self.closed(st) {
            return 0.0;
        }
        let f = self.applied(st);
        let normal = (f - st.elastic) * st.pen_rate;
        let fric = if self.mu > 0.0 {
            let s2 = st.slip.norm_squared();
            self.mu * f * s2 / (s2 + self.vreg * self.vreg).sqrt()
        } else {
            0.0
        };
        normal + fric
    }

    /// Contact strain energy `½ k δ²` or `K δⁿ⁺¹/(n + 1)` (δ > 0), J.
    pub(super) fn contact_energy(&self, pen: f64) -> f64 {
        if pen <= 0.0 {
            return 0.0;
        }
        match self.law {
            ContactLaw::KelvinVoigt { k, .. } => 0.5 * k * pen * pen,
            ContactLaw::LankaraniNikravesh { k, exponent, .. } => {
                k * pen.powf(exponent + 1.0) / (exponent + 1.0)
            }
        }
    }

    /// Tangent stiffness of the elastic part, `∂F_el/∂δ`, N/m.
    fn contact_stiffness(&self, pen: f64) -> f64 {
        match self.law {
            ContactLaw::KelvinVoigt { k, .. } => k,
            ContactLaw::LankaraniNikravesh { k, exponent, .. } => {
                k * exponent * pen.max(0.0).powf(exponent - 1.0)
            }
        }
    }

    /// `ω = √(k_t / m_eff)`, `m_eff = F / n·(ẍ_j − ẍ_b)`, when the state allows it.
    pub(super) fn omega_estimate(&self, nodes: &[NodeState], st: &JointState<f64>) -> Option<f64> {
        let f = self.applied(st);
        let acc = -self.normal_acceleration(nodes, &st.normal);
        let kt = self.contact_stiffness(st.pen);
        (f > 0.0 && acc > 0.0 && kt > 0.0).then(|| (kt * acc / f).sqrt())
    }

    /// The impact step `π/(ω · IMPACT_STEPS)` for a contact frequency (∞ when unknown).
    pub(super) fn impact_step(&self, omega: f64) -> f64 {
        if omega > 0.0 {
            PI / (omega * f64::from(self.impact_steps))
        } else {
            f64::INFINITY
        }
    }

    /// Gap tolerance of a touch event: `EVENT_TOL · min(h, h_imp) · |δ̇|`.
    pub(super) fn touch_tolerance(&self, h: f64, rate: f64) -> f64 {
        EVENT_TOL * h.min(self.impact_step(self.omega)) * rate.abs()
    }

    /// Event control of a converged step (CAME's rules, `came/events.rs`): a touch inside
    /// the step is landed on (retry at the Hermite root of the gap); in contact, steps of
    /// at most `π/(ω · IMPACT_STEPS)`; a separation is landed just past; a step that
    /// jumped over a whole impact is refused.
    pub(super) fn event_limit(
        &self,
        ctx: &EvalContext,
        old: &[NodeState],
        new: &[NodeState],
    ) -> Option<StepLimit> {
        let h = ctx.h;
        let (st0, st1) = (
            self.kernel_at(old, false, true),
            self.kernel_at(new, false, true),
        );
        let in0 = self.touching;
        let in1 = self.closed(&st1);
        if in1 && let Some(w) = self.omega_estimate(new, &st1) {
            self.omega_trial.store(w.to_bits(), Ordering::Relaxed);
        }
        let omega = match f64::from_bits(self.omega_trial.load(Ordering::Relaxed)) {
            w if in1 && w > 0.0 => w,
            _ => self.omega,
        };
        let h_imp = self.impact_step(omega);
        let land = if h_imp.is_finite() { LAND * h_imp } else { 0.0 };
        // Time to the next event from a state: the touch (gap g = −δ closing, quadratic
        // with the free-flight acceleration), or the release.
        let time_to_event = |st: &JointState<f64>, nodes: &[NodeState]| -> Option<f64> {
            if st.pen <= 0.0 {
                let acc = self.pen_acceleration(nodes, st);
                return first_root(-st.pen, -st.pen_rate, -acc);
            }
            let mut t = (st.pen_rate < 0.0).then(|| st.pen / -st.pen_rate + land);
            if let ContactLaw::KelvinVoigt { k, c } = self.law {
                let p = k * st.pen + c * st.pen_rate;
                let pdot = k * st.pen_rate + c * self.pen_acceleration(nodes, st);
                if p > 0.0 && pdot < 0.0 {
                    t = Some(t.map_or(p / -pdot, |t: f64| t.min(p / -pdot)));
                }
            }
            t
        };
        // Longer than the impact's resolution: a refusal the smallest step cannot waive.
        let too_long = h > LIMIT_SLACK * h_imp;
        let refuse = |retry: f64| {
            Some(StepLimit {
                accept_up_to: 0.0,
                retry,
                next: retry,
                unresolved: too_long,
            })
        };
        let retry_from_start = || match time_to_event(&st0, old) {
            Some(t) if t < h => t,
            _ => h / 4.0,
        };
        if !in0 && st1.pen > 0.0 {
            // Touch inside the step: land on it, or retry at its interpolated time.
            if st1.pen > self.touch_tolerance(h, st1.pen_rate) {
                let tau = hermite_root(-st0.pen, -st0.pen_rate, -st1.pen, -st1.pen_rate, h);
                return refuse(tau.unwrap_or(0.5 * h).min(h_imp));
            }
        } else if in0 && !in1 {
            // Separation inside the step (the clipped force is already zero there, only
            // its slope jumps): land just past it.
            let past = if st1.pen_rate == 0.0 {
                0.0
            } else {
                (st1.pen / st1.pen_rate).abs()
            };
            if h_imp.is_finite() && past > 2.0 * LAND * h_imp + 1e-12 {
                return refuse(retry_from_start().min(h_imp));
            }
        } else if !in0 && !in1 {
            // Apart at both ends: did the step jump over a whole impact?
            if st0.pen_rate > 0.0 && st1.pen_rate < 0.0 && st0.pen + st0.pen_rate * h > 0.0 {
                return Some(StepLimit {
                    unresolved: true,
                    ..refuse(retry_from_start().min(h_imp))?
                });
            }
        } else if h > LIMIT_SLACK * h_imp {
            return refuse(h_imp);
        }
        // Accepted: cap the next step at the impact resolution and at the next event.
        let mut next = if in1 || st1.pen > 0.0 {
            h_imp
        } else {
            f64::INFINITY
        };
        if let Some(t) = time_to_event(&st1, new) {
            next = next.min(t);
        }
        next.is_finite().then_some(StepLimit {
            accept_up_to: f64::INFINITY,
            retry: next,
            next,
            unresolved: false,
        })
    }
}
