//! The geometrically exact beam of order `p` (Legendre spectral element, `p + 1` nodes).
//!
//! # Kinematics (objective; Crisfield & Jelenić 1999, eqs. 9–12; Jelenić & Crisfield 1999)
//! Node `i` at parametric position `ξᵢ ∈ [−1, 1]` (the Gauss–Lobatto–Legendre points for a
//! deck's `ORDER p`, [`crate::lagrange::gll`]) carries its position `xᵢ` and the triad
//! `Λᵢ = Rᵢ Λ⁰ᵢ` (`Λ⁰ᵢ`: the reference triad at the node, axis 1 along the reference axis).
//! With the **reference node** `r = ⌊p/2⌋` (for `p = 1` the first node) the element works in
//! local variables that a rigid motion leaves unchanged:
//! `yᵢ = Λᵣᵀ (xᵢ − xᵣ)`, `ψᵢ = log(Λᵣᵀ Λᵢ)` (the *relative* rotations).
//! Both are Lagrange-interpolated, `y(ξ) = Σ Nᵢ(ξ) yᵢ`, `ψ(ξ) = Σ Nᵢ(ξ) ψᵢ`, and the triad
//! field is `Λ(ξ) = Λᵣ exp(ψ̃(ξ))`. The strains (physics.md §2, paper eqs. [5]–[9]) per unit
//! reference arc length `s` (`ds = J dξ`, `J = |X'(ξ)|`) are
//! `Γ = exp(ψ̃)ᵀ y_s − Γ⁰`, `K = T(ψ) ψ_s − K⁰`,
//! (`K̃ = Λᵀ Λ_s` with the material tangent operator `T` of [`crate::rotation::tangent`]),
//! `Γ⁰`, `K⁰` being the same expressions in the reference configuration — zero strain there
//! for a straight or a curved reference axis alike (Jelenić & Crisfield 1999, §4).
//! For `p = 1` this is exactly the two-node element of [`super::two_node`].
//!
//! A node may be more than π away from the reference node (a cantilever rolled into a full
//! circle by one element puts its ends ±π from the middle): `ψᵢ` is the branch
//! `φ̂ (|φ| + 2πk)` of the logarithm `φ` nearest to its neighbour's `ψ`, walking out from
//! the reference node, so the interpolated field is continuous at any rotation.
//!
//! # Quadrature
//! Strain energy `U = ∫ ½ (Γ·C_N Γ + K·C_M K) ds` by **reduced Gauss quadrature with `p`
//! points**. Why: `p` points integrate degree `2p − 1` exactly, which is the degree of the
//! strain energy of the linearised element with its derivative fields `u_s`, `θ_s`, `θ` of
//! degree `p − 1, p − 1, p`, except the `θ × E₁` part of the shear strain, whose exact
//! integration is what locks (Prathap & Bhashyam 1982; Reissner/Simo beams, Crisfield 1991
//! §7.4). No spurious zero-energy mode: zero strains at `p` distinct points make the
//! degree-`(p − 1)` polynomials `θ_s` and `u_s − θ × E₁` vanish identically, i.e. a rigid
//! motion — so the stiffness keeps its full rank `6(p + 1) − 6`.
//! Inertia uses `p + 1` points (exact for the consistent mass of a straight element).
//!
//! # Internal forces and exact tangent
//! `U` is a sum over Gauss points of the energy density of nine local numbers
//! `(ψ, ψ_s, y_s)` at the point, which depend linearly on the nodal `zᵢ = (yᵢ, ψᵢ)`; each
//! `zᵢ` depends on node `i` and the reference node only. So, in exponential coordinates
//! `Rᵢ exp(θ̃ᵢ)` of every node, `U(q) = Ũ(z(q))` and
//! - forces `f = Zᵀ ∇Ũ` (`Z = ∂z/∂q`),
//! - Hessian `∇²U = Zᵀ ∇²Ũ Z + Σₐ (∇Ũ)ₐ ∇²zₐ`,
//!
//! with the gradient of each point's energy density (9 variables) and the Jacobian `Z` in
//! closed form ([`BeamP::density_grad`], `internal_forces`), and the second derivatives as
//! forward-mode derivatives of those gradients by the fixed-size [`Dual`] numbers (9 directions
//! per point, 6 per node for `ψᵢ(θᵢ, θᵣ)`; `yᵢ` is linear in the positions and its Hessian
//! is written out): exact to round-off, at `O(n²)` per element. The iteration matrix is the derivative of the forces along `Rᵢ exp(ε eₖ)`:
//! `∂f/∂q = ∇²U + diag(½ f̃_Θᵢ)` on the rotation blocks (the Baker–Campbell–Hausdorff term
//! `exp(e) exp(θ) = exp(e + θ + ½ e × θ + …)`). Checked against central differences.
//!
//! # Inertia (paper eqs. [10]–[11])
//! Consistent translational mass `Mᵢⱼ = ∫ ρA Nᵢ Nⱼ ds`; rotary inertia at the nodes
//! `Jᵢ = (∫ Nᵢ ds) Λ⁰ᵢ ρ diag(I₂+I₃, I₂, I₃) Λ⁰ᵢᵀ` in the node's material frame — on GLL nodes
//! this is the GLL quadrature of the rotary kinetic energy (spectral-element mass lumping,
//! exact to degree `2p − 1`) — with its gyroscopic force `J Ω̇ + Ω × J Ω`, as the
//! two-node beam. Gravity: `∫ ρA Nᵢ ds g` on node `i`.

use super::two_node::BeamProperties;
use crate::dual::Real;
use crate::elements::{Local, NodeState};
use crate::lagrange;
use crate::model::ElementId;
use crate::rotation::{self, c};
use nalgebra::{Matrix3, SMatrix, Vector3};
use std::cell::RefCell;
use std::f64::consts::PI;

/// The largest order the element accepts (13 nodes beyond which nothing is gained in double
/// precision for smooth fields; the spectral rules stay accurate well beyond).
pub const MAX_ORDER: usize = 16;

/// Shape functions of one quadrature point.
#[derive(Debug, Clone)]
struct Point {
    /// `Nᵢ(ξ)`.
    n: Vec<f64>,
    /// `dNᵢ/ds = N'ᵢ(ξ)/J`.
    ds: Vec<f64>,
    /// Weight times Jacobian, m.
    wj: f64,
    /// Reference strains `Γ⁰`, `K⁰`.
    gamma0: Vector3<f64>,
    kappa0: Vector3<f64>,
}

/// A geometrically exact beam of order `p` with `p + 1` nodes.
#[derive(Debug, Clone)]
pub struct BeamP {
    id: ElementId,
    /// Dense node indices along the axis (first end, interior, last end).
    nodes: Vec<usize>,
    /// Reference node `⌊p/2⌋`.
    refn: usize,
    /// Reference triads at the nodes.
    lambda0: Vec<Matrix3<f64>>,
    props: BeamProperties,
    /// Stiffness points (`p`, reduced Gauss).
    stiff: Vec<Point>,
    /// The element's midpoint `ξ = 0`, for the output of strains.
    mid: Point,
    /// Consistent translational mass, `n × n`, row-major, kg.
    mass: Vec<f64>,
    /// `∫ ρA Nᵢ ds`, kg.
    lumped: Vec<f64>,
    /// Rotary inertia at each node, node material frame.
    j_node: Vec<Matrix3<f64>>,
    length: f64,
    /// Stiffness-proportional damping coefficient η, s (0: none; [`damping`]).
    eta: f64,
}

/// Scratch buffers of the evaluation, one per thread (grown once: no allocation per step).
#[derive(Default)]
struct Scratch {
    shift: Vec<f64>,
    /// `Λᵣᵀ Λᵢ = exp(ψ̃ᵢ)` of every node.
    rel: Vec<Matrix3<f64>>,
    /// `cot(|ψᵢ|/2)` of every node (the residual path's `T⁻¹`).
    cot: Vec<f64>,
    z: Vec<[f64; 6]>,
    gz: Vec<[f64; 6]>,
    jac: Vec<SMatrix<f64, 6, 12>>,
    ht: Vec<SMatrix<f64, 6, 6>>,
    hp: Vec<SMatrix<f64, 9, 6>>,
    force: Vec<[f64; 6]>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

impl Scratch {
    fn size(&mut self, n: usize) {
        if self.z.len() < n {
            self.shift.resize(n, 0.0);
            self.rel.resize(n, Matrix3::identity());
            self.cot.resize(n, 0.0);
            self.z.resize(n, [0.0; 6]);
            self.gz.resize(n, [0.0; 6]);
            self.jac.resize(n, SMatrix::zeros());
            self.ht.resize(n * n, SMatrix::zeros());
            self.hp.resize(n, SMatrix::zeros());
            self.force.resize(n, [0.0; 6]);
        }
    }
}

/// Strains `(Λᵀ x_s, T(ψ) ψ_s)` (before subtracting the reference) from the local numbers
/// of a point: `ψ`, `ψ_s`, `y_s`.
fn point_strains<S: Real>(
    psi: &Vector3<S>,
    dpsi: &Vector3<S>,
    dy: &Vector3<S>,
) -> (Vector3<S>, Vector3<S>) {
    let e = rotation::exp(psi);
    (
        rotation::mtv(&e, dy),
        rotation::mv(&rotation::tangent(psi), dpsi),
    )
}

/// `(b, d, b′, d′)` with `b = (1 − cos φ)/φ²`, `d = (φ − sin φ)/φ³` (so that
/// `T(ψ) = I − b ψ̃ + d ψ̃²`) and their derivatives with respect to `x = φ²`:
/// `b′ = (φ sin φ − 2(1 − cos φ))/(2φ⁴)`, `d′ = ((1 − cos φ)φ − 3(φ − sin φ))/(2φ⁵)`;
/// Taylor series in `x` below `x = 0.01` (four terms: truncation < 1e-12 relative).
fn t_coefficients<S: Real>(x: S) -> (S, S, S, S) {
    if x < c(1e-2) {
        let b = c::<S>(0.5) - x / c(24.0) + x * x / c(720.0) - x * x * x / c(40320.0);
        let d = c::<S>(1.0 / 6.0) - x / c(120.0) + x * x / c(5040.0) - x * x * x / c(362880.0);
        let db = c::<S>(-1.0 / 24.0) + x / c(360.0) - x * x / c(13440.0) + x * x * x / c(907200.0);
        let dd =
            c::<S>(-1.0 / 120.0) + x / c(2520.0) - x * x / c(120960.0) + x * x * x / c(9979200.0);
        (b, d, db, dd)
    } else {
        let f = x.sqrt();
        let (sn, cs) = (f.sin(), f.cos());
        let x2 = x * x;
        (
            (S::one() - cs) / x,
            (f - sn) / (x * f),
            (f * sn - (S::one() - cs) * c(2.0)) / (x2 * c(2.0)),
            ((S::one() - cs) * f - (f - sn) * c(3.0)) / (x2 * f * c(2.0)),
        )
    }
}

/// The log branch shift `2πk` of `φ` nearest to `prev`.
fn branch(phi: &Vector3<f64>, prev: &Vector3<f64>) -> f64 {
    let n = phi.norm();
    if n < 1e-8 {
        return 0.0; // the branches are 2π apart: no choice near the identity
    }
    // The branches φ̂(|φ| + 2πk) lie on a line 2π apart: |φₖ − prev| ≥ 2π|k| − |φ − prev|,
    // so within π of `prev` the principal branch is the nearest (the usual case).
    if (phi - prev).norm_squared() < PI * PI {
        return 0.0;
    }
    let mut best = (f64::INFINITY, 0.0);
    for k in -3..=3 {
        let s = 2.0 * PI * k as f64;
        let d = (phi * (1.0 + s / n) - prev).norm();
        if d < best.0 {
            best = (d, s);
        }
    }
    best.1
}

impl BeamP {
    /// A beam through the nodes `nodes` (dense indices, along the axis) at parametric
    /// positions `xi` (increasing from −1 to 1), reference positions `x0` and reference triads
    /// `triads` (axis 1 along the reference axis).
    pub fn new(
        id: ElementId,
        nodes: Vec<usize>,
        xi: &[f64],
        x0: &[Vector3<f64>],
        triads: &[Matrix3<f64>],
        props: BeamProperties,
    ) -> Self {
        let n = nodes.len();
        assert!((2..=MAX_ORDER + 1).contains(&n) && xi.len() == n && x0.len() == n);
        let p = n - 1;
        let point = |x: f64, w: f64| {
            let (nv, dv) = lagrange::lagrange(xi, x);
            let dx: Vector3<f64> = dv.iter().zip(x0).map(|(d, x)| x * *d).sum();
            let jac = dx.norm();
            Point {
                n: nv,
                ds: dv.iter().map(|d| d / jac).collect(),
                wj: w * jac,
                gamma0: Vector3::zeros(),
                kappa0: Vector3::zeros(),
            }
        };
        let (gs, gw) = lagrange::gauss(p);
        let stiff: Vec<Point> = gs.iter().zip(&gw).map(|(x, w)| point(*x, *w)).collect();
        let (ms, mw) = lagrange::gauss(p + 1);
        let mpts: Vec<Point> = ms.iter().zip(&mw).map(|(x, w)| point(*x, *w)).collect();
        let mut mass = vec![0.0; n * n];
        let mut lumped = vec![0.0; n];
        let mut shares = vec![0.0; n];
        let mut length = 0.0;
        for q in &mpts {
            length += q.wj;
            for i in 0..n {
                lumped[i] += q.wj * props.mass * q.n[i];
                shares[i] += q.wj * q.n[i];
                for j in 0..n {
                    mass[i * n + j] += q.wj * props.mass * q.n[i] * q.n[j];
                }
            }
        }
        // ∫ Nᵢ ds by the mass rule (exact for a straight element: degree p); through the
        // lumped mass when there is one (its round-off kept), else directly.
        let j_node = (0..n)
            .map(|i| {
                let m = props.mass;
                let w = if m > 0.0 { lumped[i] / m } else { shares[i] };
                triads[i] * Matrix3::from_diagonal(&(props.inertia * w)) * triads[i].transpose()
            })
            .collect();
        let mut beam = BeamP {
            id,
            nodes,
            refn: p / 2,
            lambda0: triads.to_vec(),
            props,
            stiff,
            mid: point(0.0, 0.0),
            mass,
            lumped,
            j_node,
            length,
            eta: 0.0,
        };
        // Reference strains: the same expressions at the reference state.
        let rest: Vec<NodeState> = x0.iter().map(|x| NodeState::at_rest(*x)).collect();
        let mut z = vec![[0.0; 6]; n];
        let mut shift = vec![0.0; n];
        let mut rel = vec![Matrix3::identity(); n];
        let mut cot = vec![0.0; n];
        let idx: Vec<usize> = (0..n).collect();
        beam.locals(&rest, &idx, &mut z, &mut shift, &mut rel, &mut cot);
        let mut pts = std::mem::take(&mut beam.stiff);
        pts.push(beam.mid.clone());
        for q in &mut pts {
            let (g, k) = Self::strains_at(q, &z);
            q.gamma0 = g;
            q.kappa0 = k;
        }
        beam.mid = pts.pop().expect("mid point");
        beam.stiff = pts;
        beam
    }

    /// The order `p`.
    pub fn order(&self) -> usize {
        self.nodes.len() - 1
    }

    /// Reference length (arc length of the reference axis), m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Local numbers `zᵢ`, branch shifts, relative rotations `Λᵣᵀ Λᵢ` and `cot(|ψᵢ|/2)` of
    /// every node (f64); `idx[k]` is node `k`'s index into `nodes`.
    fn locals(
        &self,
        nodes: &[NodeState],
        idx: &[usize],
        z: &mut [[f64; 6]],
        shift: &mut [f64],
        rel: &mut [Matrix3<f64>],
        cot: &mut [f64],
    ) {
        let n = idx.len();
        let m = self.refn;
        let sr = &nodes[idx[m]];
        let lr = sr.r * self.lambda0[m];
        z[m] = [0.0; 6];
        shift[m] = 0.0;
        rel[m] = Matrix3::identity();
        cot[m] = f64::INFINITY;
        let mut set = |k: usize, prev: Vector3<f64>| {
            rel[k] = lr.transpose() * nodes[idx[k]].r * self.lambda0[k];
            let (f, ch) = rotation::log_and_cot_half(&rel[k]);
            let s = branch(&f, &prev);
            shift[k] = s;
            // |ψ|/2 = |φ/2 + πk|, and cot has the period π: cot(|ψ|/2) = ± cot(φ/2).
            let (psi, ch) = if s != 0.0 {
                let t = 1.0 + s / f.norm();
                (f * t, if t < 0.0 { -ch } else { ch })
            } else {
                (f, ch)
            };
            cot[k] = ch;
            let y = lr.transpose() * (nodes[idx[k]].x - sr.x);
            z[k] = [y.x, y.y, y.z, psi.x, psi.y, psi.z];
            psi
        };
        let mut prev = Vector3::zeros();
        for k in m + 1..n {
            prev = set(k, prev);
        }
        prev = Vector3::zeros();
        for k in (0..m).rev() {
            prev = set(k, prev);
        }
    }

    /// Runs `f` on this thread's scratch buffers, sized for the element's `n` nodes and
    /// holding the local numbers, branch shifts and relative rotations of `nodes`
    /// ([`Self::locals`]).
    fn with_locals<R>(&self, nodes: &[NodeState], f: impl FnOnce(&mut Scratch, usize) -> R) -> R {
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            let n = self.nodes.len();
            s.size(n);
            let sc = &mut *s;
            self.locals(
                nodes,
                &self.nodes,
                &mut sc.z[..n],
                &mut sc.shift[..n],
                &mut sc.rel[..n],
                &mut sc.cot[..n],
            );
            f(sc, n)
        })
    }

    /// The nine local numbers `(ψ, ψ_s, y_s)` of a point.
    fn point_vars(q: &Point, z: &[[f64; 6]]) -> [f64; 9] {
        let mut v = [0.0; 9];
        for ((zi, &ni), &di) in z.iter().zip(&q.n).zip(&q.ds) {
            for a in 0..3 {
                v[a] += ni * zi[3 + a];
                v[3 + a] += di * zi[3 + a];
                v[6 + a] += di * zi[a];
            }
        }
        v
    }

    /// Total strains `(Λᵀx_s, K)` at a point (reference not subtracted).
    fn strains_at(q: &Point, z: &[[f64; 6]]) -> (Vector3<f64>, Vector3<f64>) {
        let v = Self::point_vars(q, z);
        let at = |k: usize| Vector3::new(v[k], v[k + 1], v[k + 2]);
        point_strains(&at(0), &at(3), &at(6))
    }

    /// Energy density `½ Γ·C_N Γ + ½ K·C_M K` at a point from its nine local numbers
    /// (generic; the runs use [`Self::density_f64`], tested equal to it).
    #[cfg(test)]
    fn density<S: Real>(&self, q: &Point, v: &[S; 9]) -> S {
        let at = |k: usize| Vector3::new(v[k], v[k + 1], v[k + 2]);
        let (g, k) = point_strains(&at(0), &at(3), &at(6));
        let g = g - q.gamma0.map(c::<S>);
        let k = k - q.kappa0.map(c::<S>);
        let cn: Vector3<S> = self.props.cn.map(c);
        let cm: Vector3<S> = self.props.cm.map(c);
        (g.component_mul(&cn).dot(&g) + k.component_mul(&cm).dot(&k)) * c::<S>(0.5)
    }

    /// Gradient of the energy density in its nine local numbers `(ψ, ψ_s, y_s)`, in closed
    /// form (generic: differentiated once more by dual numbers for the tangent). With
    /// `a = exp(ψ̃)ᵀ y_s`, `v = ψ_s`, `N = C_N(a − Γ⁰)`, `M = C_M(T(ψ) v − K⁰)`:
    /// `∂e/∂y_s = exp(ψ̃) N`, `∂e/∂ψ_s = T(ψ)ᵀ M`,
    /// `∂e/∂ψ = T(ψ)ᵀ (N × a) + (∂(T(ψ)v)/∂ψ)ᵀ M` (`δ exp(ψ̃)ᵀ = −(T δψ)~ exp(ψ̃)ᵀ`), and with
    /// `T v = v − b ψ × v + d ψ × (ψ × v)` ([`t_coefficients`]):
    /// `(∂(T v)/∂ψ)ᵀ M = −2b′ ((ψ×v)·M) ψ + b M × v + 2d′ ((ψ×(ψ×v))·M) ψ
    ///  − d (M × (ψ × v) + (M × ψ) × v)`.
    fn density_grad<S: Real>(&self, q: &Point, v: &[S; 9]) -> [S; 9] {
        let at = |k: usize| Vector3::new(v[k], v[k + 1], v[k + 2]);
        let (psi, dpsi, dy) = (at(0), at(3), at(6));
        let e = rotation::exp(&psi);
        let t = rotation::tangent(&psi);
        let a = rotation::mtv(&e, &dy);
        let cn: Vector3<S> = self.props.cn.map(c);
        let cm: Vector3<S> = self.props.cm.map(c);
        let nn = (a - q.gamma0.map(c::<S>)).component_mul(&cn);
        let mm = (rotation::mv(&t, &dpsi) - q.kappa0.map(c::<S>)).component_mul(&cm);
        Self::stress_grad(&psi, &dpsi, &e, &t, &a, &nn, &mm)
    }

    /// The virtual work of the stresses `N`, `M` per unit length, `δΓ·N + δK·M`, as a
    /// gradient in the nine local numbers `(ψ, ψ_s, y_s)` of a point (the formulas of
    /// [`Self::density_grad`] for any `N`, `M`: elastic or damping stresses), given
    /// `e = exp(ψ̃)`, `t = T(ψ)` and `a = exp(ψ̃)ᵀ y_s`.
    fn stress_grad<S: Real>(
        psi: &Vector3<S>,
        dpsi: &Vector3<S>,
        e: &Matrix3<S>,
        t: &Matrix3<S>,
        a: &Vector3<S>,
        nn: &Vector3<S>,
        mm: &Vector3<S>,
    ) -> [S; 9] {
        let g_dy = rotation::mv(e, nn);
        let g_dpsi = rotation::mtv(t, mm);
        let (b, d, db, dd) = t_coefficients(psi.dot(psi));
        let pv = psi.cross(dpsi);
        let ppv = psi.cross(&pv);
        let two = c::<S>(2.0);
        let g_psi = rotation::mtv(t, &nn.cross(a)) - *psi * (db * two * pv.dot(mm))
            + mm.cross(dpsi) * b
            + *psi * (dd * two * ppv.dot(mm))
            - (mm.cross(&pv) + mm.cross(psi).cross(dpsi)) * d;
        [
            g_psi.x, g_psi.y, g_psi.z, g_dpsi.x, g_dpsi.y, g_dpsi.z, g_dy.x, g_dy.y, g_dy.z,
        ]
    }

    /// Internal forces (node-by-node `[f_x, f_Θ]`, `Θ` material) into `out.res`, and with
    /// `tangent` their exact derivative into `out.tan` (module doc): the residual path
    /// ([`residual`]) or the tangent path ([`tangent`]).
    fn internal(&self, nodes: &[NodeState], tangent: bool, out: &mut Local) {
        if tangent {
            self.internal_tangent(nodes, out)
        } else {
            self.internal_forces(nodes, out)
        }
    }

    /// Strains `Γ`, `K` at the element's midpoint `ξ = 0`.
    pub fn strains(&self, nodes: &[NodeState]) -> (Vector3<f64>, Vector3<f64>) {
        self.with_locals(nodes, |sc, n| {
            let (g, k) = Self::strains_at(&self.mid, &sc.z[..n]);
            (g - self.mid.gamma0, k - self.mid.kappa0)
        })
    }
}

mod build;
mod damping;
mod element;
mod residual;
mod tangent;

pub use build::{from_model, with_properties};

#[cfg(test)]
mod tests;

#[cfg(test)]
mod cases;
