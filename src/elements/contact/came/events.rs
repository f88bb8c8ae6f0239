//! Events of the contact: touch, separation and impact resolution (the step limit), the
//! contact frequency estimate, and the roots that time the events.

use super::{Came, ContactState, EVENT_TOL, LAND, LIMIT_SLACK};
use crate::elements::{EvalContext, NodeState, StepLimit};
use std::sync::atomic::Ordering;

impl Came {
    /// Gap tolerance of a touch event: the event time is met within [`EVENT_TOL`] of the
    /// step `h` (or of the impact step if shorter), i.e. `EVENT_TOL · h · |q̇_n|`.
    pub(super) fn touch_tolerance(&self, h: f64, gap_rate: f64) -> f64 {
        let h_imp = if self.omega > 0.0 {
            std::f64::consts::PI / (self.omega * f64::from(self.impact_steps))
        } else {
            f64::INFINITY
        };
        EVENT_TOL * h.min(h_imp) * gap_rate.abs()
    }

    /// Event control. **Touch** (apart at the start, penetrating at the end): the step is
    /// refused unless it ends within the landing tolerance of the event
    /// ([`EVENT_TOL`] of a step), and retried with the event time found by cubic Hermite
    /// interpolation of the gap between the two ends (the end state is computed with the
    /// spring alone, so it is close to the free flight). A step that lands is *at* the
    /// event: the dashpot's force jump acts from the next step on, after the integrator
    /// restarted its accelerations ([`crate::elements::Element::restart`]) — the step never straddles the
    /// jump, and the impact is resolved at the order of the scheme. **In contact**: steps
    /// no longer than `π/(ω · impact_steps)`. **Separation**: the step ends just past it.
    /// A step that jumped over a whole impact is refused.
    pub(super) fn event_limit(
        &self,
        ctx: &EvalContext,
        old: &[NodeState],
        new: &[NodeState],
    ) -> Option<StepLimit> {
        let h = ctx.h;
        let (st0, st1) = (self.full_state(old), self.full_state(new));
        let in0 = self.touching;
        let in1 = self.closed(&st1);
        if let Some(w) = Some(st1)
            .filter(|_| in1)
            .and_then(|s| self.omega_estimate(new, &s))
        {
            self.omega_trial.store(w.to_bits(), Ordering::Relaxed);
        }
        let omega = match f64::from_bits(self.omega_trial.load(Ordering::Relaxed)) {
            w if in1 && w > 0.0 => w,
            _ => self.omega,
        };
        // Steps per impact: π/ω split in `impact_steps`; unknown before the first contact.
        let h_imp = if omega > 0.0 {
            std::f64::consts::PI / (omega * f64::from(self.impact_steps))
        } else {
            f64::INFINITY
        };
        let land = if h_imp.is_finite() { LAND * h_imp } else { 0.0 };
        // Estimates of the time to the next event (contact or separation) from a state.
        let time_to_event = |st: &ContactState<f64>, nodes: &[NodeState]| -> Option<f64> {
            if st.gap >= 0.0 {
                // Quadratic in time with the gap acceleration (gravity bends the approach).
                let acc = self.gap_acceleration(nodes, &st.normal);
                return first_root(st.gap, st.gap_rate, acc);
            }
            let mut t = (st.gap_rate > 0.0).then(|| -st.gap / st.gap_rate + land.max(0.0));
            if self.clip {
                let p = -(self.k * st.gap + self.c * st.gap_rate);
                let pdot =
                    -(self.k * st.gap_rate + self.c * self.gap_acceleration(nodes, &st.normal));
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
        if !in0 && st1.gap < 0.0 {
            // Touch inside the step: land on it, or retry at its interpolated time.
            let tol = self.touch_tolerance(h, st1.gap_rate);
            if -st1.gap > tol {
                let tau = hermite_root(st0.gap, st0.gap_rate, st1.gap, st1.gap_rate, h);
                return refuse(tau.unwrap_or(0.5 * h).min(h_imp));
            }
        } else if in0 && !in1 && !self.clip {
            // Separation inside the step without clipping: the dashpot's pull `c q̇_n` drops
            // to zero there, a jump like the touch's: land on it (within the tolerance
            // the touch was landed with) or retry at its interpolated time.
            let tau = hermite_root(-st0.gap.min(0.0), -st0.gap_rate, -st1.gap, -st1.gap_rate, h);
            return refuse(tau.unwrap_or(0.5 * h).min(h_imp));
        } else if in0 && !in1 {
            // Separation inside the step (the clipped force is already zero there, only its
            // slope jumps): land just past it.
            let past = if st1.gap_rate == 0.0 {
                0.0
            } else {
                (st1.gap / st1.gap_rate).abs()
            };
            if h_imp.is_finite() && past > 2.0 * LAND * h_imp + 1e-12 {
                let retry = match time_to_event(&st0, old) {
                    Some(t) if t < h => t,
                    _ => h / 4.0,
                };
                return refuse(retry.min(h_imp));
            }
        } else if !in0 && !in1 {
            // Apart at both ends: did the step jump over a whole impact?
            if st0.gap_rate < 0.0 && st1.gap_rate > 0.0 && st0.gap + st0.gap_rate * h < 0.0 {
                let retry = match time_to_event(&st0, old) {
                    Some(t) if t < h => t,
                    _ => h / 4.0,
                };
                return Some(StepLimit {
                    unresolved: true,
                    ..refuse(retry.min(h_imp))?
                });
            }
        } else if h > LIMIT_SLACK * h_imp {
            return refuse(h_imp);
        }
        // Accepted: cap the next step at the impact resolution and at the next event.
        let closed_next = in1 || st1.gap < 0.0;
        let mut next = if closed_next { h_imp } else { f64::INFINITY };
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

    /// `ω = √(k / m_eff)`, `m_eff = P / q̈_n`, when the converged state allows it.
    pub(super) fn omega_estimate(
        &self,
        nodes: &[NodeState],
        st: &ContactState<f64>,
    ) -> Option<f64> {
        let p = self.applied(st);
        let acc = self.gap_acceleration(nodes, &st.normal);
        (p > 0.0 && acc > 0.0).then(|| (self.k * acc / p).sqrt())
    }
}

/// Smallest positive root of `g + ġ τ + ½ g̈ τ²` (the time a gap closes), if any.
pub(crate) fn first_root(g: f64, gd: f64, gdd: f64) -> Option<f64> {
    let (a, b, c) = (0.5 * gdd, gd, g);
    if a == 0.0 {
        return (b < 0.0).then(|| -c / b);
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    // Stable forms of the two roots.
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let roots = [q / a, if q != 0.0 { c / q } else { f64::NAN }];
    roots
        .into_iter()
        .filter(|t| t.is_finite() && *t > 0.0)
        .min_by(f64::total_cmp)
}

/// The time in `(0, h)` where the cubic Hermite interpolant of a gap through
/// `(0, g0, ġ0)` and `(h, g1, ġ1)` vanishes (`g0 ≥ 0 > g1`), by bisection.
pub(crate) fn hermite_root(g0: f64, gd0: f64, g1: f64, gd1: f64, h: f64) -> Option<f64> {
    if !(g0 >= 0.0 && g1 < 0.0 && h > 0.0) {
        return None;
    }
    let p = |s: f64| {
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * g0
            + (s3 - 2.0 * s2 + s) * h * gd0
            + (-2.0 * s3 + 3.0 * s2) * g1
            + (s3 - s2) * h * gd1
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if p(mid) >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi) * h)
}
