//! Control (issue 36 §5–6): sensors that read the state, and inputs whose value depends
//! on it — a hinge torque or a nodal force `u(t, s)` of sensor values `s`.
//!
//! A [`ControlData`] is an element of the model ([`super::ElementKind::Control`]): an
//! [`Actuator`] (where `u` acts), the [`Sensor`]s its law reads, and the [`ControlLaw`]:
//! a value held over each step (set between steps by a program driving the run), a PID
//! on a hinge's angle (the deck's `PID` card), or an external law evaluated inside the
//! step at the iterate (a library user's, e.g. a Python callable). The solver element is
//! `crate::elements::control`.

use super::{ElementId, FunctionId, NodeId};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// A scalar the state is read into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sensor {
    /// A HINGE's relative angle θ, rad, whole turns counted (as `RSPRING`'s).
    HingeAngle(ElementId),
    /// A HINGE's relative angular rate θ̇, rad/s.
    HingeRate(ElementId),
    /// A node's global coordinate `x`, `y` or `z` (axis 0, 1, 2), m.
    Coordinate(NodeId, usize),
    /// A node's global velocity component (axis 0, 1, 2), m/s.
    Velocity(NodeId, usize),
}

/// Where a controlled input acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Actuator {
    /// A torque `u` about a HINGE's axis, N·m, driving its angle positively (on the
    /// hinge's second node, and `−u` on its first).
    HingeTorque(ElementId),
    /// A force `u` on a node along a global axis (0, 1, 2), N.
    NodeForce(NodeId, usize),
}

/// An input's law `u(t, s)` for a library user: evaluated inside the step at each Newton
/// iterate (and each stage of the ESDIRK schemes), with its derivatives with respect to
/// the sensor values (the element's tangent: "differentiated").
pub trait Law: Send + Sync {
    /// `u(t, s)`; when `grad` is given, `∂u/∂sᵢ` into it (same length as `s`). A law that
    /// cannot be evaluated returns NaN (the step is refused) and may ask the run to stop
    /// (the integrator's `abort` flag).
    fn eval(&self, t: f64, s: &[f64], grad: Option<&mut [f64]>) -> f64;
}

/// A value shared between the element and the program that sets it between steps.
#[derive(Debug, Default)]
pub struct HeldValue(AtomicU64);

impl HeldValue {
    /// A held value `v`.
    pub fn new(v: f64) -> Arc<Self> {
        Arc::new(HeldValue(AtomicU64::new(v.to_bits())))
    }

    /// The value.
    pub fn get(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }

    /// Sets the value (used from the next evaluation on).
    pub fn set(&self, v: f64) {
        self.0.store(v.to_bits(), Ordering::Relaxed);
    }
}

/// A PID controller on a sensor `s` with its rate `ṡ`: `e = a f(t) − s`, `ė = a ḟ(t) − ṡ`,
/// `u = k_p e + k_i ∫₀ᵗ e dτ + k_d ė` (the integral by the trapezoidal rule over each step).
#[derive(Debug, Clone, PartialEq)]
pub struct Pid {
    /// Proportional gain (N·m/rad for a hinge).
    pub kp: f64,
    /// Integral gain (N·m/(rad·s)).
    pub ki: f64,
    /// Derivative gain (N·m·s/rad).
    pub kd: f64,
    /// The target's time function `f` (it must have exact derivatives).
    pub target: FunctionId,
    /// The target's amplitude `a` (rad; default 1).
    pub amplitude: f64,
}

/// The law of a controlled input.
#[derive(Clone)]
pub enum ControlLaw {
    /// A value held over each step, set between steps ([`HeldValue`]): the input is
    /// explicit in time (a zero-order hold), first-order accurate when it follows the state.
    Held(Arc<HeldValue>),
    /// A PID on the first sensor, whose rate is the second ([`Pid`]).
    Pid(Pid),
    /// An external law evaluated at every iterate with its derivatives ([`Law`]).
    External(Arc<dyn Law>),
    /// The deck's `CONTROL … LAW <expression>`: an expression of `t` and of the sensors
    /// (its [`super::Expr::Sensor`] `k` is `sensors[k]`), evaluated at every iterate with
    /// its exact derivatives with respect to the sensors ([`super::Expr::law`]).
    Expr(super::TimeExpr),
}

impl std::fmt::Debug for ControlLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ControlLaw::Held(v) => write!(f, "Held({})", v.get()),
            ControlLaw::Pid(p) => write!(f, "{p:?}"),
            ControlLaw::External(_) => write!(f, "External"),
            ControlLaw::Expr(e) => write!(f, "Expr({})", e.text),
        }
    }
}

impl PartialEq for ControlLaw {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (ControlLaw::Held(a), ControlLaw::Held(b)) => Arc::ptr_eq(a, b),
            (ControlLaw::Pid(a), ControlLaw::Pid(b)) => a == b,
            (ControlLaw::External(a), ControlLaw::External(b)) => Arc::ptr_eq(a, b),
            (ControlLaw::Expr(a), ControlLaw::Expr(b)) => a == b,
            _ => false,
        }
    }
}

/// A controlled input: where it acts, what it reads, its law.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlData {
    /// Where `u` acts.
    pub actuator: Actuator,
    /// The sensors the law reads, in the order of its argument `s`.
    pub sensors: Vec<Sensor>,
    /// The law.
    pub law: ControlLaw,
}

impl ControlData {
    /// The nodes the input touches: the actuator's and the sensors' (hinges: their two
    /// nodes), each once, in order of first appearance; `hinge_nodes` gives a hinge's.
    pub fn nodes(&self, hinge_nodes: impl Fn(ElementId) -> Option<[NodeId; 2]>) -> Vec<NodeId> {
        let mut out: Vec<NodeId> = Vec::new();
        let mut add = |n: NodeId| {
            if !out.contains(&n) {
                out.push(n);
            }
        };
        let of_hinge = |h: ElementId, add: &mut dyn FnMut(NodeId)| {
            if let Some([a, b]) = hinge_nodes(h) {
                add(a);
                add(b);
            }
        };
        match self.actuator {
            Actuator::HingeTorque(h) => of_hinge(h, &mut add),
            Actuator::NodeForce(n, _) => add(n),
        }
        for s in &self.sensors {
            match *s {
                Sensor::HingeAngle(h) | Sensor::HingeRate(h) => of_hinge(h, &mut add),
                Sensor::Coordinate(n, _) | Sensor::Velocity(n, _) => add(n),
            }
        }
        out
    }
}

/// Why a controlled input cannot be added to a model ([`super::Model::add_control`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    /// The element number is taken.
    #[error("element {0} already exists")]
    Taken(u32),
    /// A node that does not exist.
    #[error("node {0} does not exist")]
    NoNode(u32),
    /// An element that is not a HINGE where a hinge is needed.
    #[error("element {0} is not a HINGE")]
    NotAHinge(u32),
    /// An axis other than 0, 1, 2.
    #[error("axis {0} is not 0 (x), 1 (y) or 2 (z)")]
    Axis(usize),
}

impl super::Model {
    /// A HINGE's two nodes, `None` if `h` is not a HINGE.
    pub fn hinge_nodes(&self, h: ElementId) -> Option<[NodeId; 2]> {
        let e = self.elements.get(&h)?;
        match e.kind {
            super::ElementKind::Hinge { .. } => Some([e.nodes[0], e.nodes[1]]),
            _ => None,
        }
    }

    /// Adds the controlled input `data` as element `id` (its nodes: the actuator's and the
    /// sensors'), after checking every reference.
    pub fn add_control(&mut self, id: ElementId, data: ControlData) -> Result<(), ControlError> {
        if self.elements.contains_key(&id) {
            return Err(ControlError::Taken(id.0));
        }
        let node = |n: NodeId, a: usize| {
            if !self.nodes.contains_key(&n) {
                Err(ControlError::NoNode(n.0))
            } else if a > 2 {
                Err(ControlError::Axis(a))
            } else {
                Ok(())
            }
        };
        let hinge = |h: ElementId| {
            self.hinge_nodes(h)
                .map(|_| ())
                .ok_or(ControlError::NotAHinge(h.0))
        };
        match data.actuator {
            Actuator::HingeTorque(h) => hinge(h)?,
            Actuator::NodeForce(n, a) => node(n, a)?,
        }
        for s in &data.sensors {
            match *s {
                Sensor::HingeAngle(h) | Sensor::HingeRate(h) => hinge(h)?,
                Sensor::Coordinate(n, a) | Sensor::Velocity(n, a) => node(n, a)?,
            }
        }
        let nodes = data.nodes(|h| self.hinge_nodes(h));
        self.elements.insert(
            id,
            super::Element {
                id,
                nodes,
                kind: super::ElementKind::Control(Box::new(data)),
                span: super::Span::default(),
            },
        );
        Ok(())
    }
}
