//! `SUPERELEMENT`: a linear elastic body of any shape, reduced from a finite-element
//! model by Hurty–Craig–Bampton ([`reduce`]), in large rigid motion in a floating frame of
//! reference with its full inertia coupling ([`invariants`], [`kernel`]; docs/superelements.md).
//!
//! **Design.** The frame is the first interface node's (a model node: position `x₀`,
//! rotation `R`); its six constraint modes are the rigid motions and are not kept. The
//! other interface nodes are model nodes tied to the body by six constraint equations
//! each (multipliers, as a CLAMP's), so joints, springs, drivers and contact attach to
//! them as to any node. The elastic coordinates — the other interface dofs relative to
//! the frame, then the fixed-interface modal amplitudes — are the translations of
//! generated *modal nodes* (at the origin: a modal node's position is its three
//! coordinates; rotations fixed), so every integrator advances them unchanged and the
//! run writes them as those nodes' histories. The iteration matrix is exact: the residual
//! ([`kernel::residual`]) evaluated in `Dual<2>` per local direction, one part for
//! `∂r/∂q`, one for `c_v ∂r/∂v + c_a ∂r/∂a`.

pub mod cache;
pub mod fe;
pub mod frame_model;
pub mod invariants;
pub mod kernel;
pub mod mesh;
pub mod mtx;
pub mod origin;
pub mod rbe;
#[cfg(test)]
mod rbe_tests;
pub mod reduce;
pub mod reduced;
pub mod sparse;
#[cfg(test)]
mod sparse_tests;
pub mod spin;
#[cfg(test)]
mod tests;

use crate::dual::Dual;
use crate::elements::registry::{Kind, not_mine};
use crate::elements::{BuildError, Element, Energies, EvalContext, Local, NodeState, RotationUse};
use crate::model::{ElementId, ElementKind, Model, SuperelementData};
use invariants::Body;
use kernel::{Layout, Pre, State};
use nalgebra::{Matrix3, Vector3};

/// Tolerance on an interface node's place: the model node and the FE node must be at the
/// same place relative to the frame node, to this fraction of the mesh's size (the
/// coordinates files and decks carry 6 to 17 digits).
const PLACE_TOL: f64 = 1e-6;

/// The superelement as the solver sees it.
#[derive(Debug, Clone)]
pub struct Superelement {
    id: ElementId,
    /// Frame node, other interface nodes, modal nodes (solver indices).
    nodes: Vec<usize>,
    lay: Layout,
    body: Body,
    /// The modal nodes' reference positions (the coordinates are `x − x_ref`).
    q_ref: Vec<Vector3<f64>>,
    /// Its rotation against its lowest elastic frequency (`spin`).
    spin: spin::SpinWatch,
    /// Where its body came from (`summary.json`).
    source: cache::Source,
    /// The FE mesh's recovery, when the deck writes VTK output.
    shape: Option<mesh::MeshShape>,
}

impl Superelement {
    /// Builds the element from its FE model: reads the files, reduces, computes the
    /// invariants. Errors name the file, line and column, or what does not fit.
    pub fn from_model(
        model: &Model,
        id: ElementId,
        nodes: Vec<usize>,
        d: &SuperelementData,
    ) -> Result<Self, BuildError> {
        let (body, shape, source) = origin::body_of(model, id, &nodes, d)?;
        let nb = d.interface.len() - 1;
        let nm = d.modal.len();
        let q_ref = nodes[1 + nb..]
            .iter()
            .map(|&i| model.nodes[i].position)
            .collect();
        Ok(Superelement {
            id,
            nodes,
            lay: Layout { nb, nm },
            spin: spin::SpinWatch::new(&body),
            body,
            q_ref,
            source,
            shape,
        })
    }

    /// The element for a body already reduced (tests, library users).
    pub fn new(id: ElementId, nodes: Vec<usize>, body: Body, q_ref: Vec<Vector3<f64>>) -> Self {
        let nb = body.s_iface.len();
        let nm = q_ref.len();
        Superelement {
            id,
            nodes,
            lay: Layout { nb, nm },
            spin: spin::SpinWatch::new(&body),
            body,
            q_ref,
            source: cache::Source::Uncached,
            shape: None,
        }
    }

    /// The reduced body.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// Where the reduced body came from: reduced (and cached or not), the cache, a
    /// reduced set.
    pub fn source(&self) -> &cache::Source {
        &self.source
    }

    /// The elastic coordinates at a state.
    pub fn coordinates(&self, nodes: &[NodeState]) -> Vec<f64> {
        self.field(nodes, |s, j| s.x - self.q_ref[j])
    }

    fn field(
        &self,
        nodes: &[NodeState],
        f: impl Fn(&NodeState, usize) -> Vector3<f64>,
    ) -> Vec<f64> {
        let n = self.body.n;
        let mut out = Vec::with_capacity(n);
        for (j, &i) in self.nodes[1 + self.lay.nb..].iter().enumerate() {
            let v = f(&nodes[i], j);
            for c in 0..3 {
                if out.len() < n {
                    out.push(v[c]);
                }
            }
        }
        out
    }

    /// The state in `f64`.
    fn state(&self, nodes: &[NodeState], lambda: &[f64]) -> State<f64> {
        let f = &nodes[self.nodes[0]];
        let iface = &self.nodes[1..1 + self.lay.nb];
        State {
            x0: f.x,
            r: f.r,
            v0: f.v,
            w: f.w,
            a0: f.a,
            wd: f.wd,
            q: self.coordinates(nodes),
            qd: self.field(nodes, |s, _| s.v),
            qdd: self.field(nodes, |s, _| s.a),
            xi: iface.iter().map(|&i| nodes[i].x).collect(),
            ri: iface.iter().map(|&i| nodes[i].r).collect(),
            lam: lambda.to_vec(),
        }
    }

    /// The state in `Dual<2>` seeded along local direction `dir`: `ε₀` the configuration
    /// (`x + ε₀e`, `R(I + ε₀ẽ)`, `λ̂ + ε₀e`), `ε₁` the rates (`v + c_v ε₁e`, `a + c_a ε₁e`).
    fn seeded(&self, st: &State<f64>, dir: usize, ctx: &EvalContext) -> State<Dual<2>> {
        let cst = Dual::<2>::constant;
        let v3 = |v: &Vector3<f64>| v.map(cst);
        let m3 = |m: &Matrix3<f64>| m.map(cst);
        let mut d = State {
            x0: v3(&st.x0),
            r: m3(&st.r),
            v0: v3(&st.v0),
            w: v3(&st.w),
            a0: v3(&st.a0),
            wd: v3(&st.wd),
            q: st.q.iter().map(|&x| cst(x)).collect(),
            qd: st.qd.iter().map(|&x| cst(x)).collect(),
            qdd: st.qdd.iter().map(|&x| cst(x)).collect(),
            xi: st.xi.iter().map(v3).collect(),
            ri: st.ri.iter().map(m3).collect(),
            lam: st.lam.iter().map(|&x| cst(x)).collect(),
        };
        let conf = |re: f64| Dual {
            re,
            eps: [1.0, 0.0],
        };
        let rate = |re: f64, c: f64| Dual { re, eps: [0.0, c] };
        let lay = self.lay;
        if dir >= lay.lambda_row() {
            let k = dir - lay.lambda_row();
            d.lam[k] = conf(st.lam[k]);
            return d;
        }
        let (node, comp) = (dir / 6, dir % 6);
        let spin = |r: &mut Matrix3<Dual<2>>, e: usize| {
            // R (I + ε ẽ): the column j of R ẽ is R (e × e_j).
            let mut de = Vector3::zeros();
            de[e] = 1.0;
            let rr = r.map(|x| x.re);
            let d = rr * crate::rotation::skew(&de);
            for i in 0..3 {
                for j in 0..3 {
                    r[(i, j)].eps[0] += d[(i, j)];
                }
            }
        };
        if node == 0 {
            if comp < 3 {
                d.x0[comp] = conf(st.x0[comp]);
                d.v0[comp] = rate(st.v0[comp], ctx.c_v);
                d.a0[comp] = rate(st.a0[comp], ctx.c_a);
            } else {
                spin(&mut d.r, comp - 3);
                d.w[comp - 3] = rate(st.w[comp - 3], ctx.c_v);
                d.wd[comp - 3] = rate(st.wd[comp - 3], ctx.c_a);
            }
        } else if node <= lay.nb {
            let b = node - 1;
            if comp < 3 {
                d.xi[b][comp] = conf(st.xi[b][comp]);
            } else {
                spin(&mut d.ri[b], comp - 3);
            }
        } else if comp < 3 {
            let k = 3 * (node - 1 - lay.nb) + comp;
            d.q[k] = conf(st.q[k]);
            d.qd[k] = rate(st.qd[k], ctx.c_v);
            d.qdd[k] = rate(st.qdd[k], ctx.c_a);
        }
        d
    }

    /// The elastic coordinate local direction `dir` moves, if any.
    fn coordinate_of(&self, dir: usize) -> Option<usize> {
        let lay = self.lay;
        if dir >= lay.lambda_row() || dir < 6 * (1 + lay.nb) || dir % 6 >= 3 {
            return None;
        }
        let k = 3 * (dir / 6 - 1 - lay.nb) + dir % 6;
        (k < self.body.n).then_some(k)
    }

    /// Whether local direction `dir` is one the element depends on (not a modal node's
    /// rotation or unused translation).
    fn active(&self, dir: usize) -> bool {
        let lay = self.lay;
        if dir >= lay.lambda_row() || dir < 6 * (1 + lay.nb) {
            return true;
        }
        let (node, comp) = (dir / 6, dir % 6);
        comp < 3 && 3 * (node - 1 - lay.nb) + comp < self.body.n
    }

    /// `½ νᵀ𝕄(q)ν`, `½ qᵀKq` and `−gᵀ(m x₀ + R c(q))` at a state.
    fn energy_parts(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        let st = self.state(nodes, &[]);
        let b = &self.body;
        let n = b.n;
        let vv = st.r.transpose() * st.v0;
        let nu: Vec<f64> = vv
            .iter()
            .chain(st.w.iter())
            .chain(st.qd.iter())
            .copied()
            .collect();
        let mut mq = b.m0.clone();
        for k in 0..n {
            let gk = b.g.columns(3 * k, 3) * st.q[k];
            for i in 0..6 + n {
                for j in 0..3 {
                    mq[(i, 3 + j)] += gk[(i, j)];
                    mq[(3 + j, i)] += gk[(i, j)];
                }
            }
        }
        let hqq = b.h_of(&st.q, &st.q);
        for i in 0..3 {
            for j in 0..3 {
                mq[(3 + i, 3 + j)] += hqq[(i, j)];
            }
        }
        let nuv = nalgebra::DVector::from_vec(nu);
        let qv = nalgebra::DVector::from_vec(st.q.clone());
        Energies {
            kinetic: 0.5 * nuv.dot(&(&mq * &nuv)),
            strain: 0.5 * qv.dot(&(&b.k * &qv)),
            gravity: -gravity.dot(&(st.x0 * b.mass + st.r * b.first_moment(&st.q))),
        }
    }
}

/// The element half of `SUPERELEMENT` (`crate::kinds`).
pub const KIND: Kind = Kind {
    types: &["SUPERELEMENT"],
    build: |model, el| match &el.kind {
        ElementKind::Superelement(d) => from_model(model, el, d),
        _ => Err(not_mine(el, "SUPERELEMENT")),
    },
};

/// Builds a model's `SUPERELEMENT`.
pub fn from_model(
    model: &Model,
    el: &crate::model::Element,
    d: &SuperelementData,
) -> Result<Box<dyn Element>, BuildError> {
    let nodes = el
        .nodes
        .iter()
        .map(|n| model.nodes.get_index_of(n).expect("validated model"))
        .collect();
    Ok(Box::new(Superelement::from_model(model, el.id, nodes, d)?))
}

impl Element for Superelement {
    fn id(&self) -> ElementId {
        self.id
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn multipliers(&self) -> usize {
        6 * self.lay.nb
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let st = self.state(nodes, lambda);
        let size = self.lay.size();
        let mut r = vec![0.0; size];
        let pre = Pre::new(&self.body, &st);
        kernel::residual(&self.body, self.lay, &st, &pre, ctx, &mut r);
        for (o, v) in out.res.iter_mut().zip(&r) {
            *o += v;
        }
        if !tangent {
            return;
        }
        let mut rd = vec![Dual::<2>::constant(0.0); size];
        for col in (0..size).filter(|&c| self.active(c)) {
            let sd = self.seeded(&st, col, ctx);
            let pd = pre.seeded(&self.body, self.coordinate_of(col), ctx.c_v);
            rd.iter_mut().for_each(|x| *x = Dual::constant(0.0));
            kernel::residual(&self.body, self.lay, &sd, &pd, ctx, &mut rd);
            for (row, v) in rd.iter().enumerate() {
                let (dq, rate) = (v.eps[0], v.eps[1]);
                if dq != 0.0 || rate != 0.0 {
                    out.tan[col * size + row] += dq + rate;
                }
                if rate != 0.0 {
                    out.rate[col * size + row] += rate;
                    out.has_rate = true;
                }
            }
        }
    }

    fn energies(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> Energies {
        self.energy_parts(nodes, gravity)
    }

    fn output_header(&self) -> Vec<String> {
        let nb = self.lay.nb;
        let mut h = Vec::with_capacity(self.body.n + 1);
        for b in 0..nb {
            for c in ["ux", "uy", "uz", "rx", "ry", "rz"] {
                h.push(format!("interface{}_{c}", b + 2));
            }
        }
        for k in 0..self.body.n - 6 * nb {
            h.push(format!("mode{}", k + 1));
        }
        h.push("strain_energy".into());
        h
    }

    fn write_output_row(
        &self,
        _ctx: &EvalContext,
        nodes: &[NodeState],
        _lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let q = self.coordinates(nodes);
        let kq = &self.body.k * nalgebra::DVector::from_column_slice(&q);
        let e = 0.5 * q.iter().zip(kq.iter()).map(|(a, b)| a * b).sum::<f64>();
        row.extend(q);
        row.push(e);
    }

    fn constraint_violation(&self, nodes: &[NodeState]) -> f64 {
        let st = self.state(nodes, &vec![0.0; 6 * self.lay.nb]);
        let ctx = EvalContext {
            t: 0.0,
            c_v: 0.0,
            c_a: 0.0,
            dynamic: false,
            gravity: Vector3::zeros(),
            constraint_scale: 1.0,
            penalty: 0.0,
            h: 0.0,
        };
        let mut r = vec![0.0; self.lay.size()];
        let pre = Pre::new(&self.body, &st);
        kernel::residual(&self.body, self.lay, &st, &pre, &ctx, &mut r);
        r[self.lay.lambda_row()..]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    fn force_scale(&self, nodes: &[NodeState], gravity: &Vector3<f64>) -> f64 {
        let st = self.state(nodes, &[]);
        let b = &self.body;
        let kq = &b.k * nalgebra::DVector::from_column_slice(&st.q);
        let lever = b.c0.norm() / b.mass.max(1e-300);
        let w2 = st.w.norm_squared() * lever;
        b.mass * (st.a0.norm() + gravity.norm() + st.wd.norm() * lever + w2) + kq.amax()
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        let id = self.id.0;
        let what = || format!("element {id} (SUPERELEMENT)");
        if let Some(msg) = self.spin.check(what, ctx.t, &nodes[self.nodes[0]].w) {
            eprintln!("warning: {msg}");
        }
    }

    fn mesh(&self, nodes: &[NodeState]) -> Option<crate::elements::ElementMesh> {
        let shape = self.shape.as_ref()?;
        let q = self.coordinates(nodes);
        let qd = self.field(nodes, |s, _| s.v);
        Some(shape.at(&nodes[self.nodes[0]], &q, &qd))
    }

    fn own_modes_hz(&self) -> Option<Vec<f64>> {
        Some(
            self.body
                .omega2
                .iter()
                .map(|w2| w2.sqrt() / (2.0 * std::f64::consts::PI))
                .collect(),
        )
    }

    fn summary(&self) -> Option<serde_json::Value> {
        let b = &self.body;
        let hz = self.own_modes_hz().unwrap_or_default();
        Some(serde_json::json!({
            "mass_kg": b.mass,
            "elastic_coordinates": b.n,
            "interface_nodes": self.lay.nb + 1,
            "fixed_interface_modes_hz": hz,
            "reduction": self.source.json(),
        }))
    }

    fn rotation_use(&self, k: usize) -> RotationUse {
        if k > self.lay.nb {
            RotationUse::Never
        } else {
            RotationUse::AsEvaluated
        }
    }
}
