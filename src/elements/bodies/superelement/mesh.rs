//! The deformed FE mesh of a superelement for ParaView (issue 38 §4): each FE node's place
//! recovered from the floating frame and the elastic coordinates,
//!
//! ```text
//!   x_p = x_f + R (s_p + Φ_p q),     v_p = v_f + R (ω × (s_p + Φ_p q) + Φ_p q̇),
//!   R_p = R exp(Θ_p q),              ω_p = R (ω + Θ_p q̇)   (spatial)
//! ```
//!
//! (`s_p` the node's place relative to the frame node at rest, `Φ_p`, `Θ_p` the basis's
//! rows of its translations and small rotations, `R`, `ω` the frame node's rotation and
//! material angular velocity): the kinematics of the floating frame the element's
//! equations use (docs/superelements.md, "Floating frame"), its linear elasticity included
//! (`exp(Θ_p q)` is the small rotation's exact map, consistent to first order in `q`). The
//! FE files carry no cells, so the mesh is drawn as the graph of `K`: a line between every
//! two nodes `K` couples — the element edges, and the diagonals of an element that couples
//! all its nodes (a quadrilateral's).

use super::fe::FeModel;
use crate::elements::{ElementMesh, NodeState};
use crate::rotation;
use nalgebra::{DMatrix, Vector3};

/// What the recovery needs: per FE node (with dofs) its place and basis rows.
#[derive(Debug, Clone)]
pub struct MeshShape {
    /// Places relative to the frame node at rest (FE axes = the frame's at rest).
    s: Vec<Vector3<f64>>,
    /// Translation rows `Φ_p` (3 per node, `n` columns), zero for a component without a dof.
    t: DMatrix<f64>,
    /// Small-rotation rows `Θ_p`, zero for a component without a dof.
    th: DMatrix<f64>,
    /// Pairs of mesh points `K` couples.
    edges: Vec<(usize, usize)>,
    /// The frame node's place at rest in the model.
    origin: Vector3<f64>,
}

impl MeshShape {
    /// The shape of `fe` for the basis `basis` (FE dofs × elastic coordinates) about the FE
    /// node `frame`, whose model node is at `origin` at rest.
    pub fn new(fe: &FeModel, basis: &DMatrix<f64>, frame: u32, origin: Vector3<f64>) -> MeshShape {
        let x_f = fe.nodes[&frame];
        let mut index = std::collections::HashMap::new();
        let mut s = Vec::new();
        for &(p, _) in &fe.dofs {
            index.entry(p).or_insert_with(|| {
                s.push(fe.nodes[&p] - x_f);
                s.len() - 1
            });
        }
        let n = basis.ncols();
        let (mut t, mut th) = (
            DMatrix::zeros(3 * s.len(), n),
            DMatrix::zeros(3 * s.len(), n),
        );
        for (r, &(p, c)) in fe.dofs.iter().enumerate() {
            let (target, c) = match c {
                0..3 => (&mut t, c as usize),
                _ => (&mut th, c as usize - 3),
            };
            target.row_mut(3 * index[&p] + c).copy_from(&basis.row(r));
        }
        let node_of = |r: usize| index[&fe.dofs[r].0];
        let mut edges: Vec<(usize, usize)> =
            fe.k.entries
                .iter()
                .filter(|e| e.2 != 0.0)
                .map(|&(i, j, _)| {
                    let (a, b) = (node_of(i), node_of(j));
                    (a.min(b), a.max(b))
                })
                .filter(|(a, b)| a != b)
                .collect();
        edges.sort_unstable();
        edges.dedup();
        MeshShape {
            s,
            t,
            th,
            edges,
            origin,
        }
    }

    /// Number of mesh points.
    pub fn len(&self) -> usize {
        self.s.len()
    }

    /// Whether the mesh has no point.
    pub fn is_empty(&self) -> bool {
        self.s.is_empty()
    }

    /// The mesh at the frame node's state `f` with elastic coordinates `q` and rates `qd`.
    pub fn at(&self, f: &NodeState, q: &[f64], qd: &[f64]) -> ElementMesh {
        let q = nalgebra::DVector::from_column_slice(q);
        let qd = nalgebra::DVector::from_column_slice(qd);
        let (u, ud) = (&self.t * &q, &self.t * &qd);
        let (th, thd) = (&self.th * &q, &self.th * &qd);
        let v3 = |a: &nalgebra::DVector<f64>, p: usize| {
            Vector3::new(a[3 * p], a[3 * p + 1], a[3 * p + 2])
        };
        let mut m = ElementMesh {
            points: Vec::with_capacity(self.s.len()),
            displacement: Vec::with_capacity(self.s.len()),
            rotation: Vec::with_capacity(self.s.len()),
            velocity: Vec::with_capacity(self.s.len()),
            angular_velocity: Vec::with_capacity(self.s.len()),
            lines: self.edges.clone(),
        };
        for (p, s) in self.s.iter().enumerate() {
            let local = s + v3(&u, p);
            let x = f.x + f.r * local;
            m.points.push(x);
            m.displacement.push(x - self.origin - s);
            m.velocity
                .push(f.v + f.r * (f.w.cross(&local) + v3(&ud, p)));
            m.rotation
                .push(rotation::log(&(f.r * rotation::exp(&v3(&th, p)))));
            m.angular_velocity.push(f.r * (f.w + v3(&thd, p)));
        }
        m
    }
}
