//! Rigid (RBE2-like) and averaging (RBE3-like) interfaces: an interface node of a
//! superelement joined to many FE nodes, by a change of the FE model's coordinates made
//! before the Craig–Bampton reduction (docs/superelements.md, "Interfaces over many nodes").
//!
//! Both are a linear map `u = T ũ` from new coordinates `ũ` to the FE dofs `u`: the dofs
//! that are not in a set keep their coordinate, the set's dofs `u_D` follow `u_D = T_D ũ_new`,
//! and the reduction runs on `K̃ = TᵀKT`, `M̃ = TᵀMT` with the interface node `g` (position
//! `X_g`) an FE node of six dofs; its basis is mapped back, `Φ = T Φ̃`, so the floating
//! frame's invariants are computed on the original mesh and mass.
//!
//! **RBE2** (MSC Nastran's RBE2 with `CM = 123456`; Abaqus `*KINEMATIC COUPLING`): every dof
//! of a set node `p` follows `g` rigidly, `r_p = X_p − X_g`,
//!
//! ```text
//!   u_p = u_g + θ_g × r_p,    θ_p = θ_g           (ũ_new = [u_g; θ_g])
//! ```
//!
//! so the set moves as a rigid body (infinite stiffness inside the set, its mass carried by `g`).
//!
//! **RBE3** (MSC Nastran's RBE3 with `REFC = 123456`, `Ci = 123`; Abaqus `*DISTRIBUTING
//! COUPLING`): the motion of `g` is the rigid motion that fits the set nodes' translations
//! best in weighted least squares, `S_p = [I  −r̃_p]` (3 × 6), `W = diag(w_p I₃)`,
//!
//! ```text
//!   [u_g; θ_g] = G u_s,   G = (SᵀWS)⁻¹ SᵀW     (minimises Σ_p w_p |u_p − u_g − θ_g × r_p|²)
//! ```
//!
//! It adds no stiffness: the set's translations are written `u_s = S [u_g; θ_g] + N z` with
//! `N` an orthonormal basis of `ker G` (`= (range WS)^⊥`), an invertible change of
//! coordinates (`G S = I`, `G N = 0`), so `K̃`, `M̃` are the same model and `g` reads the fit;
//! a force on `g` reaches the set as `Gᵀ f`. `SᵀWS` is singular when the set is collinear
//! (the rotation about its line is undetermined): refused.

use super::fe::FeModel;
use super::mtx::SymMatrix;
pub use crate::model::{RbeKind, SetSpec};
use nalgebra::{DMatrix, Matrix3, SymmetricEigen, Vector3};

fn kind_name(k: RbeKind) -> &'static str {
    match k {
        RbeKind::Rigid => "RBE2",
        RbeKind::Average => "RBE3",
    }
}

/// One interface over many FE nodes, resolved against the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Rbe {
    /// RBE2 or RBE3.
    pub kind: RbeKind,
    /// The FE number the interface node takes (not a node of the mesh).
    pub node: u32,
    /// Its position (the deck node's), global.
    pub at: Vector3<f64>,
    /// The FE nodes it joins.
    pub set: Vec<u32>,
    /// RBE3: the weight of each set node (empty: all 1).
    pub weights: Vec<f64>,
}

/// Smallest ratio of the principal second moments of an RBE3 set about its centroid:
/// below it the set is collinear (an offset of 3e-5 of the set's length off its line).
pub const COLLINEAR_RATIO: f64 = 1e-9;

/// Why an interface over many nodes cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RbeError {
    /// A set node the mesh does not have.
    #[error("{kind} {node}: FE node {missing} is not in nodes.csv")]
    Missing {
        /// RBE2 / RBE3.
        kind: &'static str,
        /// Interface node.
        node: u32,
        /// The set node.
        missing: u32,
    },
    /// The interface node's number is a node of the mesh.
    #[error(
        "{kind} {node}: FE node {node} is a node of the mesh; give the interface node a number nodes.csv does not use"
    )]
    Taken {
        /// RBE2 / RBE3.
        kind: &'static str,
        /// Interface node.
        node: u32,
    },
    /// No FE node in the set.
    #[error("{kind} {node}: the set is empty (no FE node within {radius:?} m)")]
    Empty {
        /// RBE2 / RBE3.
        kind: &'static str,
        /// Interface node.
        node: u32,
        /// WITHIN's radius.
        radius: f64,
    },
    /// A node in two sets, or a set node that is an interface node.
    #[error("{kind} {node}: FE node {shared} is also {other}")]
    Overlap {
        /// RBE2 / RBE3.
        kind: &'static str,
        /// Interface node.
        node: u32,
        /// The shared FE node.
        shared: u32,
        /// What else holds it.
        other: String,
    },
    /// An RBE3 set node without its three translations.
    #[error(
        "RBE3 {node}: FE node {missing} has no component {component} (an averaging interface reads the set's three translations)"
    )]
    Translation {
        /// Interface node.
        node: u32,
        /// The set node.
        missing: u32,
        /// Component, 1–3.
        component: u8,
    },
    /// An RBE3 set on one line: the rotation about it is undetermined.
    #[error(
        "RBE3 {node}: its {count} FE nodes are collinear (second moments about their centroid {ratio:.1e} of the largest, below {COLLINEAR_RATIO:e}): the rotation about their line is undetermined; add a node off the line"
    )]
    Collinear {
        /// Interface node.
        node: u32,
        /// Set size.
        count: usize,
        /// Smallest over largest second moment.
        ratio: f64,
    },
}

/// The set of `spec` in `fe`, checked: every node in the mesh, not empty.
pub fn resolve_set(
    fe: &FeModel,
    kind: RbeKind,
    node: u32,
    at: &Vector3<f64>,
    spec: &SetSpec,
) -> Result<Vec<u32>, RbeError> {
    if fe.nodes.contains_key(&node) {
        return Err(RbeError::Taken {
            kind: kind_name(kind),
            node,
        });
    }
    match spec {
        SetSpec::Nodes(v) => {
            if let Some(&missing) = v.iter().find(|p| !fe.nodes.contains_key(*p)) {
                return Err(RbeError::Missing {
                    kind: kind_name(kind),
                    node,
                    missing,
                });
            }
            Ok(v.clone())
        }
        SetSpec::Within(r) => {
            let v: Vec<u32> = fe
                .nodes
                .iter()
                .filter(|(_, x)| (*x - at).norm() <= *r)
                .map(|(p, _)| *p)
                .collect();
            if v.is_empty() {
                return Err(RbeError::Empty {
                    kind: kind_name(kind),
                    node,
                    radius: *r,
                });
            }
            Ok(v)
        }
    }
}

/// The map `u = T ũ` of a set of interfaces.
#[derive(Debug, Clone)]
pub struct Transform {
    /// Row `i` of `T` (an original dof): its non-zero `(new dof, coefficient)`.
    rows: Vec<Vec<(usize, f64)>>,
    /// The new coordinates' labels `(FE node, component)`; the null-space coordinates of an
    /// RBE3 are labelled node 0 (no FE node has number 0).
    pub dofs: Vec<(u32, u8)>,
}

/// `[I −r̃]` applied to `[u; θ]` is `u + θ × r`: the coefficient of `ũ_new[j]` in
/// component `c` of a translation.
fn rigid_row(r: &Vector3<f64>, c: usize) -> [f64; 6] {
    let mut out = [0.0; 6];
    out[c] = 1.0;
    for j in 0..3 {
        out[3 + j] = Vector3::ith(j, 1.0).cross(r)[c];
    }
    out
}

impl Transform {
    /// The transformation of `fe` by `rbes` (sets resolved). Sets must not share a node nor
    /// hold an interface node (`iface`: the FE numbers of the interface).
    pub fn new(fe: &FeModel, rbes: &[Rbe], iface: &[u32]) -> Result<Transform, RbeError> {
        let mut owner: std::collections::HashMap<u32, u32> = Default::default();
        for r in rbes {
            for &p in &r.set {
                if iface.contains(&p) {
                    return Err(RbeError::Overlap {
                        kind: kind_name(r.kind),
                        node: r.node,
                        shared: p,
                        other: "an interface node".into(),
                    });
                }
                if let Some(o) = owner.insert(p, r.node) {
                    let other = if o == r.node {
                        "named before in the same set".to_string()
                    } else {
                        format!("in the set of interface node {o}")
                    };
                    return Err(RbeError::Overlap {
                        kind: kind_name(r.kind),
                        node: r.node,
                        shared: p,
                        other,
                    });
                }
            }
        }
        // Dependent dofs: every dof of an RBE2 set node, the translations of an RBE3's.
        let dependent = |&(p, c): &(u32, u8)| {
            owner.get(&p).is_some_and(|g| {
                let r = rbes.iter().find(|r| r.node == *g);
                r.is_some_and(|r| r.kind == RbeKind::Rigid || c < 3)
            })
        };
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); fe.dofs.len()];
        let mut dofs = Vec::new();
        for (i, d) in fe.dofs.iter().enumerate() {
            if !dependent(d) {
                rows[i].push((dofs.len(), 1.0));
                dofs.push(*d);
            }
        }
        for r in rbes {
            let base = dofs.len();
            dofs.extend((0..6).map(|c| (r.node, c as u8)));
            match r.kind {
                RbeKind::Rigid => {
                    for (i, &(p, c)) in fe.dofs.iter().enumerate() {
                        if owner.get(&p) != Some(&r.node) {
                            continue;
                        }
                        let c = c as usize;
                        if c < 3 {
                            let row = rigid_row(&(fe.nodes[&p] - r.at), c);
                            rows[i].extend(
                                row.iter()
                                    .enumerate()
                                    .filter(|(_, v)| **v != 0.0)
                                    .map(|(j, v)| (base + j, *v)),
                            );
                        } else {
                            rows[i].push((base + c, 1.0));
                        }
                    }
                }
                RbeKind::Average => {
                    let (s, n) = average_basis(fe, r)?;
                    let nz = n.ncols();
                    dofs.extend((0..nz).map(|k| (0, (k % 6) as u8)));
                    for (a, &p) in r.set.iter().enumerate() {
                        for c in 0..3u8 {
                            let i = fe.dof_of(p, c).ok_or(RbeError::Translation {
                                node: r.node,
                                missing: p,
                                component: c + 1,
                            })?;
                            let row = 3 * a + c as usize;
                            for j in 0..6 {
                                if s[(row, j)] != 0.0 {
                                    rows[i].push((base + j, s[(row, j)]));
                                }
                            }
                            for k in 0..nz {
                                rows[i].push((base + 6 + k, n[(row, k)]));
                            }
                        }
                    }
                }
            }
        }
        Ok(Transform { rows, dofs })
    }

    /// New coordinates.
    pub fn len(&self) -> usize {
        self.dofs.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.dofs.is_empty()
    }

    /// `Tᵀ A T`, symmetrised (`A` symmetric, original dofs).
    pub fn congruent(&self, a: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, nt) = (a.nrows(), self.len());
        let mut at = DMatrix::zeros(n, nt);
        for (j, row) in self.rows.iter().enumerate() {
            for &(c, t) in row {
                at.column_mut(c).axpy(t, &a.column(j), 1.0);
            }
        }
        let mut b = DMatrix::zeros(nt, nt);
        for d in 0..nt {
            for (i, row) in self.rows.iter().enumerate() {
                let v = at[(i, d)];
                if v != 0.0 {
                    for &(c, t) in row {
                        b[(c, d)] += t * v;
                    }
                }
            }
        }
        (&b + b.transpose()) * 0.5
    }

    /// `Tᵀ A T` for a symmetric sparse `A` given by its lower triangle, as a lower
    /// triangle (duplicates summed): the large models' route, never densified. An entry
    /// `(i, j, v)`, `i > j`, stands for `v (e_i e_jᵀ + e_j e_iᵀ)` and adds
    /// `v (T_iᵀ T_j + T_jᵀ T_i)`; a diagonal one `v T_iᵀ T_i` (`T_i` row `i` of `T`).
    pub fn congruent_sparse(&self, a: &SymMatrix) -> SymMatrix {
        let mut out = Vec::with_capacity(a.entries.len());
        for &(i, j, v) in &a.entries {
            for &(ca, ta) in &self.rows[i] {
                for &(cb, tb) in &self.rows[j] {
                    let w = v * ta * tb;
                    if i != j {
                        // The pair (ca, cb) of T_iᵀT_j and its transpose from T_jᵀT_i: one
                        // lower entry, twice on the diagonal.
                        match ca.cmp(&cb) {
                            std::cmp::Ordering::Equal => out.push((ca, ca, 2.0 * w)),
                            _ => out.push((ca.max(cb), ca.min(cb), w)),
                        }
                    } else if ca >= cb {
                        out.push((ca, cb, w));
                    }
                }
            }
        }
        SymMatrix {
            n: self.len(),
            entries: out,
        }
    }

    /// `T Φ̃`: new coordinates back to the original dofs.
    pub fn expand(&self, phi: &DMatrix<f64>) -> DMatrix<f64> {
        let mut out = DMatrix::zeros(self.rows.len(), phi.ncols());
        for (i, row) in self.rows.iter().enumerate() {
            for &(c, t) in row {
                for k in 0..phi.ncols() {
                    out[(i, k)] += t * phi[(c, k)];
                }
            }
        }
        out
    }

    /// `T` as a dense matrix (tests).
    pub fn dense(&self) -> DMatrix<f64> {
        self.expand(&DMatrix::identity(self.len(), self.len()))
    }
}

/// An RBE3's `S` (3k × 6, rows of `u_p = u_g + θ_g × r_p`) and the orthonormal basis `N`
/// (3k × (3k − 6)) of `ker G = (range WS)^⊥`. Refuses a collinear set.
pub fn average_basis(fe: &FeModel, r: &Rbe) -> Result<(DMatrix<f64>, DMatrix<f64>), RbeError> {
    let k = r.set.len();
    let w = |a: usize| r.weights.get(a).copied().unwrap_or(1.0);
    let wsum: f64 = (0..k).map(w).sum();
    let centroid = r
        .set
        .iter()
        .enumerate()
        .fold(Vector3::zeros(), |c, (a, p)| c + fe.nodes[p] * w(a))
        / wsum;
    let mut j = Matrix3::zeros();
    for (a, p) in r.set.iter().enumerate() {
        let rho = fe.nodes[p] - centroid;
        j += (Matrix3::identity() * rho.norm_squared() - rho * rho.transpose()) * w(a);
    }
    let ev = SymmetricEigen::new(j).eigenvalues;
    let (lo, hi) = (ev.min(), ev.max());
    if k < 3 || hi.is_nan() || hi <= 0.0 || lo <= COLLINEAR_RATIO * hi {
        return Err(RbeError::Collinear {
            node: r.node,
            count: k,
            ratio: if hi > 0.0 { lo / hi } else { 0.0 },
        });
    }
    let mut s = DMatrix::zeros(3 * k, 6);
    for (a, p) in r.set.iter().enumerate() {
        let rp = fe.nodes[p] - r.at;
        for c in 0..3 {
            let row = rigid_row(&rp, c);
            for (jj, v) in row.iter().enumerate() {
                s[(3 * a + c, jj)] = *v;
            }
        }
    }
    // [WS | I] = QR: Q's first six columns span range(WS), the rest its complement.
    let mut ws_i = DMatrix::zeros(3 * k, 6 + 3 * k);
    for row in 0..3 * k {
        for c in 0..6 {
            ws_i[(row, c)] = w(row / 3) * s[(row, c)];
        }
        ws_i[(row, 6 + row)] = 1.0;
    }
    let q = ws_i.qr().q();
    let n = q.columns(6, 3 * k - 6).into_owned();
    Ok((s, n))
}

/// The Craig–Bampton reduction of `fe` (dense `k`, `m`) with its interfaces over many
/// nodes: on `TᵀKT`, `TᵀMT` when there are any (`tr`), the basis mapped back by `T`, so
/// that the returned basis is over `fe`'s own dofs (`frame` and `boundary` are rows of the
/// transformed model) and `ΦᵀKΦ` is unchanged.
pub fn reduce(
    fe: &FeModel,
    k: &DMatrix<f64>,
    m: &DMatrix<f64>,
    tr: Option<&Transform>,
    interface: &[u32],
    modes: usize,
) -> Result<super::reduce::Reduction, super::reduce::ReduceError> {
    let Some(tr) = tr else {
        return super::reduce::reduce(fe, k, m, interface, modes);
    };
    let empty = super::mtx::SymMatrix {
        n: tr.len(),
        entries: Vec::new(),
    };
    let fe_t = FeModel {
        k: empty.clone(),
        m: empty,
        nodes: fe.nodes.clone(),
        dofs: tr.dofs.clone(),
    };
    let mut red =
        super::reduce::reduce(&fe_t, &tr.congruent(k), &tr.congruent(m), interface, modes)?;
    red.basis = tr.expand(&red.basis);
    Ok(red)
}

/// The reduction with interfaces over many nodes and its inertia invariants, and the basis
/// over `fe`'s own dofs: dense ([`reduce`]) up to [`super::reduce::DENSE_UP_TO`] FE dofs (or
/// when the modes asked leave fewer than a Lanczos block beyond them), else sparse on
/// `TᵀKT`, `TᵀMT` assembled sparse ([`Transform::congruent_sparse`],
/// [`super::sparse::reduce`]), the invariants from `fe`'s own sparse `M`.
pub fn reduce_body_and_basis(
    fe: &FeModel,
    tr: &Transform,
    interface: &[u32],
    modes: usize,
) -> Result<(super::invariants::Body, DMatrix<f64>), String> {
    use super::invariants::Body;
    use super::reduce::{DENSE_MAX_DOFS, DENSE_UP_TO};
    let n = fe.dofs.len();
    let interior = tr.len().saturating_sub(6 * interface.len());
    let dense = n <= DENSE_UP_TO || modes + crate::lanczos::BLOCK > interior;
    let (frame, iface) = (interface[0], &interface[1..]);
    if dense && n <= DENSE_MAX_DOFS {
        let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
        let red = reduce(fe, &k, &m, Some(tr), interface, modes).map_err(|e| e.to_string())?;
        let body = Body::new(fe, &m, &red, frame, iface).map_err(|e| e.to_string())?;
        Ok((body, red.basis))
    } else {
        let red = reduce_sparse(fe, tr, interface, modes).map_err(|e| e.to_string())?;
        let body = Body::new(fe, &fe.m, &red, frame, iface).map_err(|e| e.to_string())?;
        Ok((body, red.basis))
    }
}

/// The sparse Craig–Bampton reduction on `TᵀKT`, `TᵀMT`, the basis mapped back by `T`.
pub fn reduce_sparse(
    fe: &FeModel,
    tr: &Transform,
    interface: &[u32],
    modes: usize,
) -> Result<super::reduce::Reduction, super::reduce::ReduceError> {
    let fe_t = FeModel {
        k: tr.congruent_sparse(&fe.k),
        m: tr.congruent_sparse(&fe.m),
        nodes: fe.nodes.clone(),
        dofs: tr.dofs.clone(),
    };
    let mut red = super::sparse::reduce(&fe_t, interface, modes)?;
    red.basis = tr.expand(&red.basis);
    Ok(red)
}

/// `fe` with the interface nodes of `rbes` added to its nodes (coordinates only, no dofs):
/// what the floating frame's invariants read positions from.
pub fn with_nodes(mut fe: FeModel, rbes: &[Rbe]) -> FeModel {
    for r in rbes {
        fe.nodes.insert(r.node, r.at);
    }
    fe
}

/// The deck's `RBE2`/`RBE3` clauses resolved against `fe`: each interface node at `at(fe
/// number)` (its deck node's position), each set checked.
pub fn resolve_all(
    fe: &FeModel,
    specs: &[crate::model::RbeSpec],
    at: impl Fn(u32) -> Vector3<f64>,
) -> Result<Vec<Rbe>, RbeError> {
    specs
        .iter()
        .map(|s| {
            let x = at(s.node);
            Ok(Rbe {
                kind: s.kind,
                node: s.node,
                at: x,
                set: resolve_set(fe, s.kind, s.node, &x, &s.set)?,
                weights: s.weights.clone(),
            })
        })
        .collect()
}
