//! `CONTROL`/`PID`: an input that depends on the state (issue 36 §5–6) — a torque about a
//! HINGE's axis or a force on a node along a global axis, of value `u(t, s)`, `s` the
//! values of sensors of the state ([`crate::model::control`]).
//!
//! # Sensors
//! A node's coordinate `x_a` or velocity `v_a`; a HINGE's relative angle θ (whole turns
//! counted from the last accepted state) and rate θ̇, with the formula of `RSPRING`
//! ([`super::rspring`]): with `(p, q, a)` the triad on the hinge axis, `Q = R₁ᵀR₂`,
//! `u = Q p`, `θ = atan2(q·u, p·u) + 2πn`, `δθ = g·(δΘ₁, δΘ₂)`, `θ̇ = g·(Ω₁, Ω₂)`.
//!
//! # Residual and tangent ("differentiated")
//! With `d` the actuator's direction on the element's local vector (`g` for a hinge
//! torque, `e_a` on the node's translation for a force), the virtual work `u d·δq` of the
//! input enters the residual (internal − external) as `−u d`. Its iteration matrix is exact
//! given the law's derivatives: `−u ∂d/∂q − d ⊗ Σᵢ (∂u/∂sᵢ) ∂sᵢ/∂q` in the stiffness and
//! `−c_v d ⊗ Σᵢ (∂u/∂sᵢ) ∂sᵢ/∂v` in the velocity block, where `∂θ/∂q = g`,
//! `∂θ̇/∂q = Jᵀ(Ω₁, Ω₂)` (`J = ∂g/∂Θ` by dual numbers), `∂θ̇/∂Ω = g`. The input is evaluated
//! at every iterate, so the converged step satisfies the closed loop at the step's end:
//! the scheme keeps its order. A held value ([`ControlLaw::Held`]) has no derivative: it
//! is constant over the step (a zero-order hold, explicit in time: first order).
//!
//! # PID
//! `e = a f(t) − θ`, `ė = a ḟ(t) − θ̇`, `u = k_p e + k_i I + k_d ė` with
//! `I(t) = I_n + ½ (t − t_n)(e_n + e)` (trapezoidal rule from the last accepted state, so
//! that the stages of the ESDIRK schemes integrate from the step's start too):
//! `∂u/∂θ = −k_p − ½ k_i (t − t_n)`, `∂u/∂θ̇ = −k_d`.
//!
//! # A deck's law (`CONTROL … LAW`)
//! `u(t, s)` an expression of the time and the sensors (`model::Expr`), its derivatives
//! `∂u/∂sₖ` exact by forward-mode jets, one pass per sensor ([`crate::model::Expr::law`]).
//!
//! # Work
//! The input's power `u ḋ` (`u θ̇`, `u v_a`) counts as external work in the energy balance
//! ([`Element::input_power`]), so the energy guard pays for what a controller puts in.

use crate::dual::{Dual, Real};
use crate::elements::drive::TimeLaw;
use crate::elements::joints::normals;
use crate::elements::registry::{Kind, not_mine};
use crate::elements::{
    Element, ElementState, EvalContext, Local, NodeState, StateMismatch, rx, tx,
};
use crate::model::control::{Actuator, ControlData, ControlLaw, Law, Sensor};
use crate::model::{ElementId, ElementKind, Model, NodeId};
use crate::rotation::{c, mm, mtm, mtv, mv, skew};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use std::sync::Arc;

type D6 = Dual<6>;

/// A hinge's axes and its two nodes (local indices in the element).
#[derive(Debug, Clone, Copy)]
struct HingeAt {
    k: [usize; 2],
    p: Vector3<f64>,
    q: Vector3<f64>,
}

/// What a sensor reads (local node indices).
#[derive(Debug, Clone, Copy)]
enum Reads {
    Angle(HingeAt, usize),
    Rate(HingeAt),
    Coordinate(usize, usize),
    Velocity(usize, usize),
}

/// The law, resolved.
enum Resolved {
    Held(Arc<crate::model::control::HeldValue>),
    Pid {
        kp: f64,
        ki: f64,
        kd: f64,
        target: TimeLaw,
    },
    External(Arc<dyn Law>),
    Expr(crate::model::Expr),
}

/// The element half of `PID` and `CONTROL` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["PID", "CONTROL"],
    build: |model, el| match &el.kind {
        ElementKind::Control(data) => Ok(Box::new(Control::from_model(model, el, data)?)),
        _ => Err(not_mine(el, "CONTROL")),
    },
};

/// The controlled input element (see the module docs).
pub struct Control {
    id: ElementId,
    nodes: Vec<usize>,
    actuator: Reads,
    sensors: Vec<Reads>,
    law: Resolved,
    /// Angle of each angle sensor at the last accepted state, rad (turns counted).
    angles: Vec<f64>,
    /// PID: `I_n`, `e_n`, `t_n` at the last accepted state.
    pid: [f64; 3],
    /// Time of the last accepted state, s (for a diagnosis).
    t_last: f64,
}

impl std::fmt::Debug for Control {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Control({})", self.id)
    }
}

fn dot<S: Real>(a: &Vector3<S>, b: &Vector3<S>) -> S {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// Wraps an angle to (−π, π].
fn wrap(x: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let y = x.rem_euclid(t);
    if y > std::f64::consts::PI { y - t } else { y }
}

impl HingeAt {
    /// `(q·u, p·u, g)` (module docs), generic in the scalar.
    fn grad<S: Real>(&self, r1: &Matrix3<S>, r2: &Matrix3<S>) -> (S, S, [S; 6]) {
        let (p, q) = (self.p.map(c::<S>), self.q.map(c::<S>));
        let qm = mtm(r1, r2);
        let u = mv(&qm, &p);
        let (s, co) = (dot(&q, &u), dot(&p, &u));
        let n2 = s * s + co * co;
        let w = (q * co - p * s) / n2;
        let g1 = mv(&skew(&w), &u);
        let g2 = mv(&skew(&p), &mtv(&qm, &w));
        (s, co, [g1.x, g1.y, g1.z, g2.x, g2.y, g2.z])
    }

    /// `(sin-like, cos-like, g)` at the nodes; `None` when `Q p` is parallel to the axis.
    fn at(
        &self,
        nodes: &[NodeState],
        dense: &[usize],
    ) -> Option<(f64, Vector6<f64>, Vector6<f64>)> {
        let (a, b) = (&nodes[dense[self.k[0]]], &nodes[dense[self.k[1]]]);
        let (s, co, g) = self.grad(&a.r, &b.r);
        let n2 = s * s + co * co;
        if n2.is_nan() || n2 <= 1e-12 {
            return None;
        }
        let om = Vector6::new(a.w.x, a.w.y, a.w.z, b.w.x, b.w.y, b.w.z);
        Some((s.atan2(co), Vector6::from_column_slice(&g), om))
    }

    /// `J = ∂g/∂Θ` (rows: components of g; columns: `δΘ₁, δΘ₂`) by dual numbers.
    fn jacobian(&self, nodes: &[NodeState], dense: &[usize]) -> Matrix6<f64> {
        let (a, b) = (&nodes[dense[self.k[0]]], &nodes[dense[self.k[1]]]);
        let rot = |r: &Matrix3<f64>, base: usize| {
            let rr: Matrix3<D6> = r.map(D6::constant);
            let e = Vector3::new(
                D6::var(0.0, base),
                D6::var(0.0, base + 1),
                D6::var(0.0, base + 2),
            );
            rr + mm(&rr, &skew(&e))
        };
        let (_, _, gd) = self.grad(&rot(&a.r, 0), &rot(&b.r, 3));
        Matrix6::from_fn(|i, j| gd[i].eps[j])
    }

    /// Local rows of the hinge's rotations.
    fn rows(&self) -> [usize; 6] {
        let (r1, r2) = (rx(self.k[0]), rx(self.k[1]));
        [r1, r1 + 1, r1 + 2, r2, r2 + 1, r2 + 2]
    }
}

/// A sensor's (or the actuator's) reading: value and its derivatives on the local vector,
/// with respect to the positions/rotations and to the velocities.
struct Reading {
    value: f64,
    dq: Vec<(usize, f64)>,
    dv: Vec<(usize, f64)>,
}

impl Control {
    /// The element of a model's `CONTROL`/`PID` element `el`.
    pub fn from_model(
        model: &Model,
        el: &crate::model::Element,
        data: &ControlData,
    ) -> Result<Self, crate::elements::BuildError> {
        let invalid = |message: String| crate::elements::BuildError::Invalid {
            element: el.id,
            message,
        };
        let dense_of = |n: &NodeId| {
            model
                .nodes
                .get_index_of(n)
                .ok_or_else(|| invalid(format!("node {} does not exist", n.0)))
        };
        let nodes: Vec<usize> = el.nodes.iter().map(dense_of).collect::<Result<_, _>>()?;
        let local = |n: &NodeId| -> Result<usize, crate::elements::BuildError> {
            let d = dense_of(n)?;
            nodes
                .iter()
                .position(|x| *x == d)
                .ok_or_else(|| invalid(format!("node {} is not one of the input's nodes", n.0)))
        };
        let hinge = |h: ElementId| -> Result<HingeAt, crate::elements::BuildError> {
            match model.elements.get(&h) {
                Some(e) => match &e.kind {
                    ElementKind::Hinge { axis } => {
                        let (p, q) = normals(axis);
                        Ok(HingeAt {
                            k: [local(&e.nodes[0])?, local(&e.nodes[1])?],
                            p,
                            q,
                        })
                    }
                    other => Err(invalid(format!(
                        "element {} is a {}, not a HINGE",
                        h.0,
                        other.keyword()
                    ))),
                },
                None => Err(invalid(format!("element {} does not exist", h.0))),
            }
        };
        let axis = |a: usize| {
            if a < 3 {
                Ok(a)
            } else {
                Err(invalid(format!("axis {a} is not 0, 1 or 2")))
            }
        };
        let mut n_angles = 0;
        let mut sensors = Vec::with_capacity(data.sensors.len());
        for s in &data.sensors {
            sensors.push(match *s {
                Sensor::HingeAngle(h) => {
                    n_angles += 1;
                    Reads::Angle(hinge(h)?, n_angles - 1)
                }
                Sensor::HingeRate(h) => Reads::Rate(hinge(h)?),
                Sensor::Coordinate(n, a) => Reads::Coordinate(local(&n)?, axis(a)?),
                Sensor::Velocity(n, a) => Reads::Velocity(local(&n)?, axis(a)?),
            });
        }
        let actuator = match data.actuator {
            Actuator::HingeTorque(h) => Reads::Angle(hinge(h)?, usize::MAX),
            Actuator::NodeForce(n, a) => Reads::Coordinate(local(&n)?, axis(a)?),
        };
        let law = match &data.law {
            ControlLaw::Held(v) => Resolved::Held(v.clone()),
            ControlLaw::External(l) => Resolved::External(l.clone()),
            ControlLaw::Expr(e) => Resolved::Expr(e.expr.clone()),
            ControlLaw::Pid(p) => {
                if !matches!(
                    data.sensors.as_slice(),
                    [Sensor::HingeAngle(_), Sensor::HingeRate(_)]
                ) {
                    return Err(invalid(
                        "a PID reads a hinge's angle and its rate".to_string(),
                    ));
                }
                let f = model
                    .functions
                    .get(&p.target)
                    .ok_or_else(|| invalid(format!("function {} does not exist", p.target.0)))?;
                Resolved::Pid {
                    kp: p.kp,
                    ki: p.ki,
                    kd: p.kd,
                    target: TimeLaw::new(f.function.clone(), p.amplitude),
                }
            }
        };
        Ok(Control {
            id: el.id,
            nodes,
            actuator,
            sensors,
            law,
            angles: vec![0.0; n_angles],
            pid: [0.0; 3],
            t_last: 0.0,
        })
    }

    /// A reading of `r` at the state; `None` where a hinge has no angle (torn apart).
    fn read(&self, r: &Reads, nodes: &[NodeState], tangent: bool) -> Option<Reading> {
        let n = &self.nodes;
        Some(match *r {
            Reads::Coordinate(k, a) => Reading {
                value: nodes[n[k]].x[a],
                dq: vec![(tx(k) + a, 1.0)],
                dv: Vec::new(),
            },
            Reads::Velocity(k, a) => Reading {
                value: nodes[n[k]].v[a],
                dq: Vec::new(),
                dv: vec![(tx(k) + a, 1.0)],
            },
            Reads::Angle(h, slot) => {
                let (theta, g, _) = h.at(nodes, n)?;
                let last = self.angles.get(slot).copied().unwrap_or(0.0);
                Reading {
                    value: last + wrap(theta - last),
                    dq: h.rows().into_iter().zip(g.iter().copied()).collect(),
                    dv: Vec::new(),
                }
            }
            Reads::Rate(h) => {
                let (_, g, om) = h.at(nodes, n)?;
                let dq = if tangent {
                    let jt_om = h.jacobian(nodes, n).transpose() * om;
                    h.rows().into_iter().zip(jt_om.iter().copied()).collect()
                } else {
                    Vec::new()
                };
                Reading {
                    value: g.dot(&om),
                    dq,
                    dv: h.rows().into_iter().zip(g.iter().copied()).collect(),
                }
            }
        })
    }

    /// `u(t, s)` and, when `grad` is given, `∂u/∂s`.
    fn law(&self, t: f64, s: &[f64], grad: Option<&mut [f64]>) -> f64 {
        match &self.law {
            Resolved::Held(v) => {
                if let Some(g) = grad {
                    g.fill(0.0);
                }
                v.get()
            }
            Resolved::Pid { kp, ki, kd, target } => {
                let [f, fd, _] = target.at(t);
                let (e, ed) = (f - s[0], fd - s[1]);
                let [i_n, e_n, t_n] = self.pid;
                let dt = t - t_n;
                if let Some(g) = grad {
                    g[0] = -kp - 0.5 * ki * dt;
                    g[1] = -kd;
                }
                kp * e + ki * (i_n + 0.5 * dt * (e_n + e)) + kd * ed
            }
            Resolved::External(l) => l.eval(t, s, grad),
            Resolved::Expr(e) => e.law(t, s, grad),
        }
    }

    /// The sensors' values at the state, `None` where one is undefined.
    fn values(&self, nodes: &[NodeState]) -> Option<Vec<f64>> {
        self.sensors
            .iter()
            .map(|r| self.read(r, nodes, false).map(|x| x.value))
            .collect()
    }

    /// The input's value at the state (NaN where a sensor is undefined), for outputs.
    pub fn value(&self, t: f64, nodes: &[NodeState]) -> f64 {
        match self.values(nodes) {
            Some(s) => self.law(t, &s, None),
            None => f64::NAN,
        }
    }

    /// The actuator's rate `ḋ·v` (θ̇ of the hinge, or `v_a` of the node).
    fn actuator_rate(&self, nodes: &[NodeState]) -> f64 {
        match self.actuator {
            Reads::Angle(h, _) => h
                .at(nodes, &self.nodes)
                .map_or(0.0, |(_, g, om)| g.dot(&om)),
            Reads::Coordinate(k, a) => nodes[self.nodes[k]].v[a],
            _ => 0.0,
        }
    }
}

impl Element for Control {
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
        let readings: Option<Vec<Reading>> = self
            .sensors
            .iter()
            .map(|r| self.read(r, nodes, tangent))
            .collect();
        let (Some(readings), Some(act)) = (readings, self.read(&self.actuator, nodes, false))
        else {
            // No angle: refuse the state, never a NaN (the hinge is torn apart).
            out.res[0] += f64::INFINITY;
            return;
        };
        let s: Vec<f64> = readings.iter().map(|r| r.value).collect();
        let mut grad = vec![0.0; s.len()];
        let u = self.law(ctx.t, &s, tangent.then_some(grad.as_mut_slice()));
        for &(i, d) in &act.dq {
            out.res[i] -= u * d;
        }
        if !tangent {
            return;
        }
        let n = out.n;
        // −u ∂d/∂q (a hinge's g turns with the rotations).
        if let Reads::Angle(h, _) = self.actuator {
            let jac = h.jacobian(nodes, &self.nodes);
            let rows = h.rows();
            for (a, &i) in rows.iter().enumerate() {
                for (b, &j) in rows.iter().enumerate() {
                    out.tan[j * n + i] -= u * jac[(a, b)];
                }
            }
        }
        // −d ⊗ Σ (∂u/∂s) ∂s/∂q, and −c_v d ⊗ Σ (∂u/∂s) ∂s/∂v in the velocity block.
        for (r, &gu) in readings.iter().zip(&grad) {
            if gu == 0.0 {
                continue;
            }
            for &(i, d) in &act.dq {
                for &(j, ds) in &r.dq {
                    out.tan[j * n + i] -= d * gu * ds;
                }
                if ctx.c_v != 0.0 {
                    for &(j, ds) in &r.dv {
                        let v = d * gu * ds * ctx.c_v;
                        out.tan[j * n + i] -= v;
                        out.rate[j * n + i] -= v;
                        out.has_rate = true;
                    }
                }
            }
        }
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        self.t_last = ctx.t;
        let s = self.values(nodes);
        if let Resolved::Pid { target, .. } = &self.law
            && let Some(s) = &s
        {
            let [i_n, e_n, t_n] = self.pid;
            let e = target.value(ctx.t) - s[0];
            self.pid = [i_n + 0.5 * (ctx.t - t_n) * (e_n + e), e, ctx.t];
        }
        for (r, v) in self.sensors.iter().zip(s.unwrap_or_default()) {
            if let Reads::Angle(_, slot) = r {
                self.angles[*slot] = v;
            }
        }
    }

    fn does_work(&self) -> bool {
        true
    }

    fn input_power(&self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) -> f64 {
        let u = self.value(ctx.t, nodes);
        if u.is_finite() {
            u * self.actuator_rate(nodes)
        } else {
            0.0
        }
    }

    fn output_header(&self) -> Vec<String> {
        let mut h = match self.law {
            Resolved::Pid { .. } => vec!["target".to_string(), "error".to_string()],
            _ => Vec::new(),
        };
        h.push(match self.actuator {
            Reads::Angle(..) => "torque".to_string(),
            _ => "force".to_string(),
        });
        h.extend((1..=self.sensors.len()).map(|k| format!("s{k}")));
        h
    }

    fn write_output_row(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let s = self
            .values(nodes)
            .unwrap_or_else(|| vec![f64::NAN; self.sensors.len()]);
        if let Resolved::Pid { target, .. } = &self.law {
            let f = target.value(ctx.t);
            row.push(f);
            row.push(f - s[0]);
        }
        row.push(self.law(ctx.t, &s, None));
        row.extend_from_slice(&s);
    }

    fn save_state(&self) -> ElementState {
        ElementState::Control {
            angles: self.angles.clone(),
            pid: self.pid,
        }
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        match state {
            ElementState::Control { angles, pid } if angles.len() == self.angles.len() => {
                self.angles.clone_from(angles);
                self.pid = *pid;
                Ok(())
            }
            _ => Err(StateMismatch { element: self.id }),
        }
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        let Some(s) = self.values(nodes) else {
            return Some(format!(
                "{} (controlled input): a hinge it reads has no angle about its axis (torn apart)",
                self.id
            ));
        };
        // The law at the state, at the last accepted time (the step's own time is not
        // known here): a law that is not finite there names its sensors' values.
        let t = self.t_last;
        let mut grad = vec![0.0; s.len()];
        let u = self.law(t, &s, Some(&mut grad));
        (!u.is_finite() || grad.iter().any(|g| !g.is_finite())).then(|| {
            format!(
                "{} (controlled input): its law is not finite at this state (value {u}, derivatives {grad:?} with the sensors s = {s:?}, t = {t} s)",
                self.id
            )
        })
    }
}

/// The value of `sensor` at `nodes` (dense, model order) of `model`'s system: a hinge's
/// angle in (−π, π] (no turns counted: the joint's own output counts them), its rate, a
/// node's coordinate or velocity component. `None` for a reference that does not resolve
/// or a hinge torn apart.
pub fn read_sensor(model: &Model, nodes: &[NodeState], sensor: Sensor) -> Option<f64> {
    let dense = |n: &NodeId| model.nodes.get_index_of(n);
    match sensor {
        Sensor::Coordinate(n, a) => Some(nodes.get(dense(&n)?)?.x[a]),
        Sensor::Velocity(n, a) => Some(nodes.get(dense(&n)?)?.v[a]),
        Sensor::HingeAngle(h) | Sensor::HingeRate(h) => {
            let e = model.elements.get(&h)?;
            let ElementKind::Hinge { axis } = &e.kind else {
                return None;
            };
            let (p, q) = normals(axis);
            let hinge = HingeAt { k: [0, 1], p, q };
            let idx = [dense(&e.nodes[0])?, dense(&e.nodes[1])?];
            let (theta, g, om) = hinge.at(nodes, &idx)?;
            Some(if matches!(sensor, Sensor::HingeAngle(_)) {
                theta
            } else {
                g.dot(&om)
            })
        }
    }
}

#[cfg(test)]
mod tests;
