//! `SPRING`: a two-node spring–damper acting along the current line of its nodes
//! (issue 25 §3; the discrete spring of Géradin & Cardona 2001, §3.3, with a damper in
//! parallel and an optional nonlinear force–deflection curve).
//!
//! # Force law
//! With `d = x₂ − x₁`, the length `ℓ = |d|`, the unit direction `e = d/ℓ`, the elongation
//! rate `ℓ̇ = e·(ẋ₂ − ẋ₁)` and the deflection `δ = ℓ − L_ref`, the tension is
//!
//! `F = P + k δ + F_c(δ) + c ℓ̇`
//!
//! (`P` the preload, `F_c` the FUNCTION named by `CURVE`, read with the deflection as its
//! abscissa). The element's residual (its internal force) is `−F e` on node 1 and `+F e` on
//! node 2: a stretched spring pulls the nodes together.
//!
//! # Tangent (exact, by hand)
//! `∂(F e)/∂x₂ = e ⊗ [(k + F_c′(δ)) e + c (I − e eᵀ) w/ℓ] + F (I − e eᵀ)/ℓ` with
//! `w = ẋ₂ − ẋ₁` (velocities held), and `∂(F e)/∂ẋ₂ = c e eᵀ`; the node-1 blocks follow by
//! `∂/∂x₁ = −∂/∂x₂`. `F_c′` is the curve's slope: the segment's slope for a TABLE (its
//! kinks are where the tangent jumps), the exact derivative for a kind that has one.
//!
//! # Energy
//! Strain energy `U = P δ + ½ k δ² + ∫₀^δ F_c(s) ds` (exact for a TABLE, Simpson's rule
//! on 256 panels for a smooth kind), dissipated power `c ℓ̇²` (`energy.csv`).
//!
//! # Zero length
//! At `ℓ = 0` the line of action is undefined. A deck whose spring starts at zero length is
//! refused; a run that brings the nodes together (`ℓ ≤ 1e-9 L`, `L` the larger of the
//! reference and initial lengths) or through each other (the line reversed since the last
//! accepted step, `d·e_n ≤ 0`) gets an infinite residual from this element, never a NaN:
//! Newton reports a non-finite solution, the step is cut, and a run that cannot avoid the
//! passage fails with this element's diagnosis ([`Element::diagnose`]).

use crate::elements::registry::Kind;
use crate::elements::{
    BuildError, Element, ElementState, Energies, EvalContext, Local, NodeState, StateMismatch, tx,
};
use crate::model::{ElementId, Function, SpringData, SpringLength};
use nalgebra::{Matrix3, Vector3};

/// The element half of `SPRING` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["SPRING"],
    build: from_model,
};

/// A SPRING element (see the module docs).
#[derive(Debug, Clone)]
pub struct Spring {
    id: ElementId,
    nodes: [usize; 2],
    k: f64,
    c: f64,
    /// `L_ref`, m.
    l_ref: f64,
    /// `P`, N.
    preload: f64,
    curve: Option<Function>,
    /// Length scale of the zero-length test, m.
    l_scale: f64,
    /// Direction `e` at the last accepted state.
    direction: Vector3<f64>,
}

/// What the element computes at a state: `(ℓ, e, ℓ̇, δ, F_c, F_c′, F)`.
struct Kin {
    l: f64,
    e: Vector3<f64>,
    w: Vector3<f64>,
    rate: f64,
    delta: f64,
    slope: f64,
    tension: f64,
}

impl Spring {
    /// A spring on dense nodes `nodes` whose reference positions are `x0`; `curve` is the
    /// function `data.curve` names. Refused when the nodes coincide at t = 0.
    pub fn new(
        id: ElementId,
        nodes: [usize; 2],
        x0: [Vector3<f64>; 2],
        data: &SpringData,
        curve: Option<Function>,
    ) -> Result<Self, BuildError> {
        let d = x0[1] - x0[0];
        let l0 = d.norm();
        if l0 == 0.0 || !l0.is_finite() {
            return Err(BuildError::Invalid {
                element: id,
                message: "a spring of zero length: its nodes coincide at t = 0".into(),
            });
        }
        let (l_ref, preload) = match data.length {
            SpringLength::Initial => (l0, 0.0),
            SpringLength::Free(l) => (l, 0.0),
            SpringLength::Preload(p) => (l0, p),
        };
        Ok(Spring {
            id,
            nodes,
            k: data.stiffness,
            c: data.damping,
            l_ref,
            preload,
            curve,
            l_scale: l0.max(l_ref),
            direction: d / l0,
        })
    }

    /// Whether the state is at or through zero length (module docs).
    fn degenerate(&self, d: &Vector3<f64>) -> bool {
        let l = d.norm();
        l.is_nan() || l <= 1e-9 * self.l_scale || d.dot(&self.direction) <= 0.0
    }

    fn kin(&self, nodes: &[NodeState]) -> Kin {
        let (a, b) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
        let d = b.x - a.x;
        let l = d.norm();
        let e = d / l;
        let w = b.v - a.v;
        let rate = e.dot(&w);
        let delta = l - self.l_ref;
        let (fc, slope) = self
            .curve
            .as_ref()
            .map_or((0.0, 0.0), |f| curve_value(f, delta));
        Kin {
            l,
            e,
            w,
            rate,
            delta,
            slope: self.k + slope,
            tension: self.preload + self.k * delta + fc + self.c * rate,
        }
    }
}

/// `(F_c(δ), F_c′(δ))`: a TABLE's value and segment slope (0 beyond its ends, where it is
/// constant), a smooth kind's exact derivative.
pub(crate) fn curve_value(f: &Function, x: f64) -> (f64, f64) {
    if let Some([v, d, _]) = f.derivatives(x) {
        return (v, d);
    }
    let v = f.eval(x);
    if let Function::Table(p) = f {
        if p.first().is_none_or(|q| x <= q.0) {
            return (v, 0.0);
        }
        for w in p.windows(2) {
            let ((t0, f0), (t1, f1)) = (w[0], w[1]);
            if x <= t1 {
                return (v, if t1 > t0 { (f1 - f0) / (t1 - t0) } else { 0.0 });
            }
        }
        return (v, 0.0);
    }
    let h = 1e-7 * (1.0 + x.abs());
    (v, (f.eval(x + h) - f.eval(x - h)) / (2.0 * h))
}

/// `∫₀^x F_c(s) ds`: exact for a TABLE (trapezoids of its segments, constant beyond its
/// ends), Simpson's rule on 256 panels otherwise.
pub(crate) fn curve_integral(f: &Function, x: f64) -> f64 {
    if let Function::Table(p) = f {
        let Some(&(t_first, f_first)) = p.first() else {
            return 0.0;
        };
        // Primitive from the first abscissa.
        let prim = |x: f64| {
            if x <= t_first {
                return (x - t_first) * f_first;
            }
            let mut acc = 0.0;
            for w in p.windows(2) {
                let ((t0, f0), (t1, f1)) = (w[0], w[1]);
                if x <= t1 {
                    let fx = if t1 > t0 {
                        f0 + (f1 - f0) * (x - t0) / (t1 - t0)
                    } else {
                        f1
                    };
                    return acc + 0.5 * (f0 + fx) * (x - t0);
                }
                acc += 0.5 * (f0 + f1) * (t1 - t0);
            }
            let (t_last, f_last) = p[p.len() - 1];
            acc + (x - t_last) * f_last
        };
        return prim(x) - prim(0.0);
    }
    let n = 256;
    let h = x / n as f64;
    let s: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f.eval(i as f64 * h)
        })
        .sum();
    s * h / 3.0
}

impl Element for Spring {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        if self.degenerate(&d) {
            // No direction: refuse the state (module docs), never a NaN.
            out.add_res(tx(1), &Vector3::repeat(f64::INFINITY));
            return;
        }
        let s = self.kin(nodes);
        let f = s.e * s.tension;
        out.add_res(tx(0), &-f);
        out.add_res(tx(1), &f);
        if !tangent {
            return;
        }
        let ee = s.e * s.e.transpose();
        let proj = Matrix3::identity() - ee;
        let grad = s.e * s.slope + proj * s.w * (self.c / s.l);
        let k = s.e * grad.transpose() + proj * (s.tension / s.l);
        blocks(&k, |i, j, m| out.add_block(i, j, m));
        if self.c > 0.0 && ctx.c_v != 0.0 {
            let r = ee * (self.c * ctx.c_v);
            blocks(&r, |i, j, m| out.add_rate_block(i, j, m));
        }
    }

    fn energies(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> Energies {
        let l = (nodes[self.nodes[1]].x - nodes[self.nodes[0]].x).norm();
        let delta = l - self.l_ref;
        let curve = self
            .curve
            .as_ref()
            .map_or(0.0, |f| curve_integral(f, delta));
        Energies {
            strain: self.preload * delta + 0.5 * self.k * delta * delta + curve,
            ..Energies::default()
        }
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        if self.c == 0.0 || self.degenerate(&d) {
            return 0.0;
        }
        let r = self.kin(nodes).rate;
        self.c * r * r
    }

    fn force_scale(&self, nodes: &[NodeState], _gravity: &Vector3<f64>) -> f64 {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        if self.degenerate(&d) {
            return 0.0;
        }
        let s = self.kin(nodes);
        (s.tension - self.c * s.rate)
            .abs()
            .max((self.c * s.rate).abs())
    }

    fn commit(&mut self, _ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        let l = d.norm();
        if l > 0.0 && l.is_finite() {
            self.direction = d / l;
        }
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        // A force–deflection law not finite where the run took the spring (beyond the
        // deflections the deck showed it finite on: deck/build/functions.rs).
        if let Some(f) = &self.curve {
            let delta = d.norm() - self.l_ref;
            let (v, slope) = curve_value(f, delta);
            if !(v.is_finite() && slope.is_finite()) {
                return Some(format!(
                    "{} (SPRING): its force–deflection curve is not finite at the deflection {delta:.6e} m (force {v:e} N, slope {slope:e} N/m)",
                    self.id
                ));
            }
        }
        self.degenerate(&d).then(|| {
            format!(
                "{} (SPRING): its nodes meet or pass through each other (length {:.3e} m, line of action reversed since the last step: {}): a spring's direction is undefined at zero length",
                self.id,
                d.norm(),
                if d.dot(&self.direction) <= 0.0 { "yes" } else { "no" }
            )
        })
    }

    fn output_header(&self) -> Vec<String> {
        ["length", "deflection", "rate", "tension", "fx", "fy", "fz"]
            .map(String::from)
            .to_vec()
    }

    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let d = nodes[self.nodes[1]].x - nodes[self.nodes[0]].x;
        if self.degenerate(&d) {
            // Never on an accepted state; zeros rather than a NaN.
            row.extend([d.norm(), d.norm() - self.l_ref, 0.0, 0.0, 0.0, 0.0, 0.0]);
            return;
        }
        let s = self.kin(nodes);
        // The force the spring exerts on node 2, global.
        let f = -s.e * s.tension;
        row.extend([s.l, s.delta, s.rate, s.tension, f.x, f.y, f.z]);
    }

    fn save_state(&self) -> ElementState {
        ElementState::Spring(self.direction.into())
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::Spring(d) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.direction = Vector3::from(*d);
        Ok(())
    }
}

pub use super::from_model;

/// Places the node-2 block `k` of a two-node element whose node-1 rows and columns are its
/// negatives: `[k, −k; −k, k]` on the translations.
fn blocks(k: &Matrix3<f64>, mut add: impl FnMut(usize, usize, &Matrix3<f64>)) {
    let m = -k;
    add(tx(0), tx(0), k);
    add(tx(1), tx(1), k);
    add(tx(0), tx(1), &m);
    add(tx(1), tx(0), &m);
}

#[cfg(test)]
#[path = "spring_tests.rs"]
mod tests;
