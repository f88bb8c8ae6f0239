//! Point mass with optional rotary inertia (paper §6: the masses `m₁`, `m₂` at the bar tips).
//!
//! Inertia forces `m ẍ − m g` and `J Ω̇ + Ω × J Ω` (Euler's equations in the node's material
//! frame; `J` is given in the global frame at t = 0, where the node frame is the global one).
//! Iteration matrix: `c_a m I` and `c_a J + c_v (Ω̃ J − (JΩ)~)`.

use crate::elements::registry::{Kind, node_index, not_mine};
use crate::elements::{BuildError, Element, Energies, EvalContext, Local, NodeState, rx, tx};
use crate::model::{self, ElementId, ElementKind, Model};
use crate::rotation::skew;
use nalgebra::{Matrix3, Vector3};

/// The element half of `MASS` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["MASS"],
    build,
};

fn build(model: &Model, el: &model::Element) -> Result<Box<dyn Element>, BuildError> {
    let ElementKind::Mass { mass, inertia } = &el.kind else {
        return Err(not_mine(el, "MASS"));
    };
    let node = node_index(model, &el.nodes[0]);
    Ok(Box::new(PointMass::new(el.id, node, *mass, *inertia)))
}

/// A point mass on one node.
#[derive(Debug, Clone)]
pub struct PointMass {
    id: ElementId,
    node: [usize; 1],
    mass: f64,
    inertia: Matrix3<f64>,
}

impl PointMass {
    /// A mass `mass` (kg) with rotary inertia `inertia` (kg·m², node frame) on `node`.
    pub fn new(id: ElementId, node: usize, mass: f64, inertia: Matrix3<f64>) -> Self {
        PointMass {
            id,
            node: [node],
            mass,
            inertia,
        }
    }
}

impl Element for PointMass {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.node
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let s = &nodes[self.node[0]];
        out.add_res(tx(0), &(-ctx.gravity * self.mass));
        if !ctx.dynamic {
            return;
        }
        out.add_res(tx(0), &(s.a * self.mass));
        let jw = self.inertia * s.w;
        out.add_res(rx(0), &(self.inertia * s.wd + s.w.cross(&jw)));
        if tangent {
            out.add_block(tx(0), tx(0), &(Matrix3::identity() * (ctx.c_a * self.mass)));
            let gyro = skew(&s.w) * self.inertia - skew(&jw);
            out.add_rate_block(rx(0), rx(0), &(self.inertia * ctx.c_a + gyro * ctx.c_v));
        }
    }

    fn force_scale(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> f64 {
        let s = &nodes[self.node[0]];
        let jw = self.inertia * s.w;
        (self.mass * s.a.norm())
            .max(self.mass * gravity.norm())
            .max((self.inertia * s.wd).norm())
            .max(s.w.cross(&jw).norm())
    }

    fn energies(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        let s = &nodes[self.node[0]];
        Energies {
            kinetic: 0.5 * self.mass * s.v.dot(&s.v) + 0.5 * s.w.dot(&(self.inertia * s.w)),
            strain: 0.0,
            gravity: -self.mass * gravity.dot(&s.x),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::testing::*;

    #[test]
    fn tangent_matches_finite_differences() {
        let j = Matrix3::new(2.0, 0.1, 0.0, 0.1, 1.0, 0.2, 0.0, 0.2, 3.0);
        let m = PointMass::new(ElementId(1), 0, 1.5, j);
        let st = random_states(&[Vector3::new(1.0, 2.0, 3.0)], 0.1, 1.0, 3);
        check_tangent(&m, &dyn_ctx(), &st, &[], 1e-7);
    }
}
