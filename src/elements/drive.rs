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
}

impl TimeLaw {
    /// The law of a model drive (its function validated by the deck: it has derivatives).
    pub fn from_model(model: &Model, drive: &model::Drive) -> Self {
        TimeLaw {
            function: model.functions[&drive.function].function.clone(),
            amplitude: drive.amplitude,
        }
    }

    /// A law from its parts (tests).
    pub fn new(function: Function, amplitude: f64) -> Self {
        TimeLaw {
            function,
            amplitude,
        }
    }

    /// `[a f, a ḟ, a f̈]` at `t` (zeros for a function without derivatives, which the deck
    /// refuses for a driver).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let [f, fd, fdd] = self.function.derivatives(t).unwrap_or([0.0; 3]);
        [
            self.amplitude * f,
            self.amplitude * fd,
            self.amplitude * fdd,
        ]
    }

    /// `a f(t)`.
    pub fn value(&self, t: f64) -> f64 {
        self.at(t)[0]
    }
}
