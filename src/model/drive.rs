//! Drivers: motions prescribed as functions of time (issue 25 §2).
//!
//! A driver adds one rheonomic constraint `Φ(q) − a f(t) = 0` per prescribed motion, with
//! its own Lagrange multiplier: the driving torque or force. A `HINGE` or `PRISMATIC`
//! card takes `DRIVE <function> [AMPLITUDE a]` (its relative angle or travel is `a f(t)`),
//! a `PRESCRIBED` element prescribes a component of one node's displacement, or its
//! rotation about a fixed axis (grammar.md, "Drivers").

use super::{FunctionId, Span};
use nalgebra::Vector3;

/// A prescribed value `a f(t)`: the function (which must have exact derivatives,
/// [`super::Function::has_derivatives`]) and its amplitude.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// The time function `f`.
    pub function: FunctionId,
    /// The amplitude `a` (rad, m; default 1).
    pub amplitude: f64,
    /// Where the `DRIVE` keyword (or the `PRESCRIBED` card) was written.
    pub span: Span,
}

/// What a `PRESCRIBED` element prescribes on its node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NodeMotion {
    /// Displacement along global axis `0..3` (X, Y, Z): `x_i(t) = x_i⁰ + a f(t)`.
    Displacement(usize),
    /// The node's orientation: a rotation by `a f(t)` about a fixed global unit axis,
    /// `R(t) = exp(a f(t) ñ)` (three equations).
    Rotation(Vector3<f64>),
}

impl NodeMotion {
    /// Constraint equations the motion adds.
    pub fn equations(&self) -> usize {
        match self {
            NodeMotion::Displacement(_) => 1,
            NodeMotion::Rotation(_) => 3,
        }
    }
}

impl super::Model {
    /// The functions the model's drivers follow (driven joints, `PRESCRIBED` elements):
    /// their breakpoints are where a driver's acceleration may jump.
    pub fn driver_functions(&self) -> Vec<&super::Function> {
        let prescribed = self.elements.values().filter_map(|e| match &e.kind {
            super::ElementKind::Prescribed { drive, .. } => Some(drive),
            _ => None,
        });
        self.drives
            .values()
            .chain(prescribed)
            .filter_map(|d| self.functions.get(&d.function).map(|f| &f.function))
            .collect()
    }
}
