//! [`BeamP`] as the solver sees it ([`Element`]): the internal forces and their exact
//! tangent (the parent module), the damping, the inertia of the paper's eqs. [10]–[11] — the
//! consistent translational mass and the nodes' rotary inertia with its gyroscopic force —
//! and gravity assembled into the element's residual and matrix; its force scale, energies
//! and output row.

use super::BeamP;
use crate::elements::{Element, Energies, EvalContext, Local, NodeState, rx, tx};
use crate::model::ElementId;
use crate::rotation::skew;
use nalgebra::{Matrix3, Vector3};

impl Element for BeamP {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn turns_with_its_nodes(&self) -> bool {
        true
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        self.internal(nodes, tangent, out);
        let n = self.nodes.len();
        for k in 0..n {
            out.add_res(tx(k), &(-ctx.gravity * self.lumped[k]));
        }
        if !ctx.dynamic {
            return;
        }
        if self.eta > 0.0 {
            self.add_damping(ctx, nodes, tangent, out);
        }
        for i in 0..n {
            let mut f = Vector3::zeros();
            for j in 0..n {
                f += nodes[self.nodes[j]].a * self.mass[i * n + j];
            }
            out.add_res(tx(i), &f);
            let s = &nodes[self.nodes[i]];
            let jw = self.j_node[i] * s.w;
            out.add_res(rx(i), &(self.j_node[i] * s.wd + s.w.cross(&jw)));
        }
        if tangent {
            for i in 0..n {
                for j in 0..n {
                    let mij = Matrix3::identity() * (ctx.c_a * self.mass[i * n + j]);
                    out.add_rate_block(tx(i), tx(j), &mij);
                }
                let (s, jn) = (&nodes[self.nodes[i]], &self.j_node[i]);
                let gyro = skew(&s.w) * jn - skew(&(jn * s.w));
                out.add_rate_block(rx(i), rx(i), &(jn * ctx.c_a + gyro * ctx.c_v));
            }
        }
    }

    fn force_scale(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> f64 {
        let mut f2: f64 = 0.0;
        for (k, &i) in self.nodes.iter().enumerate() {
            let (s, m, j) = (&nodes[i], self.lumped[k], &self.j_node[k]);
            f2 = f2
                .max(m * m * gravity.norm_squared())
                .max(m * m * s.a.norm_squared())
                .max((j * s.wd).norm_squared())
                .max(s.w.cross(&(j * s.w)).norm_squared());
        }
        f2.sqrt()
    }

    fn energies(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        let n = self.nodes.len();
        let strain = self.with_locals(nodes, |sc, n| {
            let z = &sc.z;
            self.stiff
                .iter()
                .map(|q| q.wj * self.density_f64(q, &Self::point_vars(q, &z[..n])))
                .sum::<f64>()
        });
        let mut kinetic = 0.0;
        let mut grav = 0.0;
        for i in 0..n {
            let s = &nodes[self.nodes[i]];
            for j in 0..n {
                kinetic += 0.5 * self.mass[i * n + j] * s.v.dot(&nodes[self.nodes[j]].v);
            }
            kinetic += 0.5 * s.w.dot(&(self.j_node[i] * s.w));
            grav -= self.lumped[i] * gravity.dot(&s.x);
        }
        Energies {
            kinetic,
            strain,
            gravity: grav,
        }
    }

    fn dissipated_power(&self, nodes: &[NodeState]) -> f64 {
        if self.eta > 0.0 {
            self.damping_power(nodes)
        } else {
            0.0
        }
    }

    fn output_header(&self) -> Vec<String> {
        [
            "n1", "n2", "n3", "m1", "m2", "m3", "gamma1", "gamma2", "gamma3", "k1", "k2", "k3",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    }

    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let (g, k) = self.strains(nodes);
        let nn = g.component_mul(&self.props.cn);
        let mm = k.component_mul(&self.props.cm);
        for v in [nn, mm, g, k] {
            row.extend_from_slice(v.as_slice());
        }
    }
}
