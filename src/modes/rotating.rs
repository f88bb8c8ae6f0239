//! Modes of a steadily rotating mechanism, seen in the rotating frame
//! (`mecano-rs modes DECK --rotating`, `ANALYSIS MODES n ROTATING`).
//!
//! A hub driven at constant speed (`HINGE … DRIVE f` with `a ḟ = Ω`, `a f̈ = 0`, its first
//! node the fixed ground) carries the frame `R(t) = exp(Ω t ã)` about the hinge's axis `a`
//! through the hinge point `p`. The motion is parametrised relative to it,
//! `xᵢ(t) = p + R(t)(xᵢ⁰ − p + δxᵢ(t))`, `Λᵢ(t) = R(t) Λᵢ⁰ exp(δθ̃ᵢ(t))`. At `t = 0`
//! (`R = I`) the inertial quantities the element residuals take are, with `A = Ω̃`
//! (`Ω = Ω a`) and `Wᵢ⁰ = Λᵢ⁰ᵀΩ` (material angular velocity of the rigid rotation):
//!
//! - translations: `v = A(x − p) + δẋ`, `ẍ = A²(x − p) + 2A δẋ + δẍ`;
//! - rotations (material, `Ẇ` from `d/dt[exp(−δθ̃) W⁰] + T(δθ)δθ̇`):
//!   `W = exp(−δθ̃)W⁰ + T(δθ)δθ̇ ≈ W⁰ + W̃⁰δθ + δθ̇`, `Ẇ ≈ W̃⁰δθ̇ + δθ̈`.
//!
//! The residual's translational rows turn with the frame and its material rows do not
//! (objectivity), so in the rotating frame the equations are autonomous: a steady state is a
//! **relative equilibrium** `r(q; v(q), a(q)) = 0` with the constraints (the driver's row
//! keeps the hinge's relative angle fixed, `θ − a f(t) = θ⁰ − a f(0)` since `a f(t) − Ωt` is
//! constant). [`relative_equilibrium`] solves it by Newton: it carries the centrifugal
//! tension whose geometric stiffness is the stiffening (without it the beam is unstressed
//! and nothing stiffens). Differentiating the same map about it gives, with `K`, `C`, `M`
//! the inertial linearisation at the state ([`super::linearise`]), `G = diag(A, W̃ᵢ⁰)` (the
//! dependence of the velocities on `δq`), `H_q = diag(A², 0)` and `H_v = diag(2A, W̃ᵢ⁰)`
//! (of the accelerations on `δq` and `δq̇`):
//!
//! `K_rel = K + C G + M H_q`, `C_rel = C + M H_v`, `M_rel = M`
//!
//! ([`to_rotating`]). `M A²` is the centrifugal softening `−mΩ²(I − aaᵀ)`, `2MA` the Coriolis
//! (gyroscopic, skew) matrix. The eigenvalues of `M_rel ÿ + C_rel ẏ + K_rel y = 0` (on the
//! constraints' null space) are the frequencies an observer on the hub sees (Géradin &
//! Cardona, *Flexible Multibody Dynamics*, 2001, ch. 12; the rotating-beam equations of
//! e.g. Wright et al., J. Sound Vib. 1982). The fixed ground does not turn: it takes no
//! rate, and only the driven hinge may touch it (its alignment rows are invariant under a
//! relative rotation about the axis).

use super::linearise::{Linearised, base_context, linearise};
use crate::elements::NodeState;
use crate::elements::drive::TimeLaw;
use crate::model::{ElementId, ElementKind, Model, Span};
use crate::rotation::{exp, skew};
use crate::solver::system::{FIXED, System};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// The rotating frame of a steadily driven hinge.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The driven hinge.
    pub element: ElementId,
    /// Unit axis `a` (global).
    pub axis: Vector3<f64>,
    /// A point `p` of the axis (the hinge's ground node), m.
    pub point: Vector3<f64>,
    /// Speed `Ω = a ḟ`, rad/s (positive about `axis`).
    pub speed: f64,
    /// Index of the ground node (not turning).
    pub ground: usize,
}

/// Why a deck has no steady rotating frame (bad input: the command exits 2).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// No driven hinge.
    #[error("no driven HINGE (`HINGE n1 n2 AXIS … DRIVE f`): --rotating takes its frame from one")]
    NoDrivenHinge,
    /// A second driver (or a PRESCRIBED motion, or a driven PRISMATIC).
    #[error(
        "{element}: a second driver (or a PRESCRIBED / driven PRISMATIC motion): the rotating frame follows exactly one driven HINGE"
    )]
    OtherDriver {
        /// The element.
        element: ElementId,
        /// Where it is.
        span: Span,
    },
    /// The hinge's first node is not fully fixed: its axis would not be inertial.
    #[error(
        "{element}: the driven hinge's first node must be the fixed ground (FIX ALL) for its axis to be inertial"
    )]
    NotGrounded {
        /// The hinge.
        element: ElementId,
        /// Where it is.
        span: Span,
    },
    /// The speed is not constant at the linearisation time.
    #[error(
        "{element}: the driven speed is not constant at t = {t} s (a ḟ = {speed:e} rad/s, a f̈ = {accel:e} rad/s²): no steady rotation"
    )]
    NotConstant {
        /// The hinge.
        element: ElementId,
        /// The `DRIVE` keyword.
        span: Span,
        /// Time.
        t: f64,
        /// `a ḟ`.
        speed: f64,
        /// `a f̈`.
        accel: f64,
    },
    /// Something fixed in the inertial frame other than the ground, or a load that does
    /// not turn with the frame.
    #[error("{0}: not steady in the rotating frame")]
    NotSteady(String),
}

/// `a f̈` counts as zero below this fraction of `Ω²` (+ 1e-300 rad/s² at rest): an exact
/// law (`OMEGA*t`) gives 0; round-off of an expression's derivatives is ~1e-15 Ω².
pub const CONSTANT_SPEED_TOL: f64 = 1e-10;

impl Frame {
    /// The frame of `model`'s one driven hinge at time `t` (errors: [`FrameError`]).
    pub fn from_model(model: &Model, t: f64) -> Result<Frame, FrameError> {
        let mut found: Option<Frame> = None;
        for (id, el) in &model.elements {
            if let ElementKind::Prescribed { .. } = el.kind {
                return Err(FrameError::OtherDriver {
                    element: *id,
                    span: el.span,
                });
            }
            let Some(drive) = model.drives.get(id) else {
                continue;
            };
            let ElementKind::Hinge { axis } = el.kind else {
                return Err(FrameError::OtherDriver {
                    element: *id,
                    span: el.span,
                });
            };
            if found.is_some() {
                return Err(FrameError::OtherDriver {
                    element: *id,
                    span: el.span,
                });
            }
            let ground = model.nodes.get_index_of(&el.nodes[0]);
            let node = &model.nodes[&el.nodes[0]];
            if node.fixed.iter().any(|f| !f) {
                return Err(FrameError::NotGrounded {
                    element: *id,
                    span: el.span,
                });
            }
            let [_, speed, accel] = TimeLaw::from_model(model, drive).at(t);
            if accel.abs() > CONSTANT_SPEED_TOL * speed * speed + 1e-300 {
                return Err(FrameError::NotConstant {
                    element: *id,
                    span: drive.span,
                    t,
                    speed,
                    accel,
                });
            }
            found = Some(Frame {
                element: *id,
                axis: axis.normalize(),
                point: node.position,
                speed,
                ground: ground.unwrap_or(0),
            });
        }
        let frame = found.ok_or(FrameError::NoDrivenHinge)?;
        let ground_id = model.nodes.get_index(frame.ground).map(|(k, _)| *k);
        for (id, n) in &model.nodes {
            if Some(*id) != ground_id && n.fixed.iter().any(|f| *f) {
                return Err(FrameError::NotSteady(format!(
                    "{id} has fixed degrees of freedom (held in the inertial frame)"
                )));
            }
        }
        for (id, el) in &model.elements {
            if *id != frame.element && ground_id.is_some_and(|g| el.nodes.contains(&g)) {
                return Err(FrameError::NotSteady(format!(
                    "{id} is attached to the ground node, which does not turn"
                )));
            }
        }
        if !model.loads.is_empty() {
            return Err(FrameError::NotSteady(
                "nodal loads (fixed in the inertial frame)".into(),
            ));
        }
        if let Some(g) = model.gravity
            && g.cross(&frame.axis).norm() > 1e-12 * g.norm()
        {
            return Err(FrameError::NotSteady(
                "gravity not along the hub's axis".into(),
            ));
        }
        Ok(frame)
    }

    /// The angular velocity vector `Ω a`, rad/s (global).
    pub fn omega(&self) -> Vector3<f64> {
        self.axis * self.speed
    }

    /// Sets every node's rates to the rigid rotation (the ground at rest): `v = A(x − p)`,
    /// `ẍ = A²(x − p)`, `W = ΛᵀΩ`, `Ẇ = 0`.
    pub fn set_rates(&self, nodes: &mut [NodeState]) {
        let w = self.omega();
        for (i, n) in nodes.iter_mut().enumerate() {
            if i == self.ground {
                n.v = Vector3::zeros();
                n.a = Vector3::zeros();
                n.w = Vector3::zeros();
                n.wd = Vector3::zeros();
                continue;
            }
            let r = n.x - self.point;
            n.v = w.cross(&r);
            n.a = w.cross(&n.v);
            n.w = n.r.transpose() * w;
            n.wd = Vector3::zeros();
        }
    }
}

/// The 3×3 blocks of `G`, `H_q` and `H_v` of each node (translation, rotation).
struct Blocks {
    g: [Matrix3<f64>; 2],
    hq: [Matrix3<f64>; 2],
    hv: [Matrix3<f64>; 2],
}

fn node_blocks(frame: &Frame, node: &NodeState) -> Blocks {
    let a = skew(&frame.omega());
    let w0 = skew(&node.w);
    let z = Matrix3::zeros();
    Blocks {
        g: [a, w0],
        hq: [a * a, z],
        hv: [a * 2.0, w0],
    }
}

/// `X · D` for a block-diagonal `D` on the nodal equations (`pick` chooses the blocks).
fn times_blocks(
    sys: &System,
    frame: &Frame,
    nodes: &[NodeState],
    x: &DMatrix<f64>,
    pick: impl Fn(&Blocks) -> [Matrix3<f64>; 2],
) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(x.nrows(), x.ncols());
    for (i, n) in nodes.iter().enumerate() {
        if i == frame.ground {
            continue;
        }
        let d = &sys.node_dofs[i];
        let b = pick(&node_blocks(frame, n));
        for part in 0..2 {
            for c in 0..3 {
                let col = d[3 * part + c];
                if col == FIXED {
                    continue;
                }
                for k in 0..3 {
                    let j = d[3 * part + k];
                    if j == FIXED || b[part][(k, c)] == 0.0 {
                        continue;
                    }
                    // (X D)[:, col] += X[:, j] D[j, col]
                    let f = b[part][(k, c)];
                    for r in 0..x.nrows() {
                        out[(r, col)] += x[(r, j)] * f;
                    }
                }
            }
        }
    }
    out
}

/// The rotating-frame linearisation `K_rel = K + C G + M H_q`, `C_rel = C + M H_v`,
/// `M_rel = M` of an inertial one `lin` taken at the relative equilibrium `nodes` (module
/// documentation).
pub fn to_rotating(
    sys: &System,
    frame: &Frame,
    nodes: &[NodeState],
    lin: &Linearised,
) -> Linearised {
    let mut out = lin.clone();
    out.k += times_blocks(sys, frame, nodes, &lin.c, |b| b.g)
        + times_blocks(sys, frame, nodes, &lin.m, |b| b.hq);
    out.c += times_blocks(sys, frame, nodes, &lin.m, |b| b.hv);
    out
}

/// Why the relative equilibrium was not found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EquilibriumError {
    /// The Jacobian is singular (a motion free in the rotating frame).
    #[error(
        "the relative equilibrium's Jacobian is singular: a motion is free in the rotating frame"
    )]
    Singular,
    /// Newton did not converge.
    #[error(
        "the relative equilibrium did not converge in {0} Newton iterations (last increment {1:e})"
    )]
    NoConvergence(usize, f64),
}

/// Newton iterations of [`relative_equilibrium`].
pub const EQUILIBRIUM_MAXIT: usize = 30;
/// Convergence: the increment of positions below this fraction of the model's reference
/// length and of rotations below this many radians. Newton converges quadratically on the
/// exact Jacobian: the state left is then at ~1e-24 of it, round-off of the residual
/// (ε·cond) being what limits.
pub const EQUILIBRIUM_TOL: f64 = 1e-12;

/// Solves the relative equilibrium `r(q; v(q), a(q)) = 0` with the constraints at `t`, by
/// Newton on the exact Jacobian `[K_rel, ∂r/∂λ; s B, 0]` (dense), from `nodes` and the
/// scaled multipliers `lambda` (overwritten). Returns the iterations.
pub fn relative_equilibrium(
    sys: &mut System,
    frame: &Frame,
    nodes: &mut [NodeState],
    lambda: &mut [f64],
    scale: f64,
    t: f64,
) -> Result<usize, EquilibriumError> {
    let nn = sys.n_node_eq;
    let n = sys.n_eq();
    let ctx = base_context(sys, scale, t);
    let mut last = f64::INFINITY;
    for it in 1..=EQUILIBRIUM_MAXIT {
        frame.set_rates(nodes);
        sys.assemble(&ctx, nodes, lambda, false);
        let r = DVector::from_column_slice(&sys.rhs);
        let lin = linearise(sys, nodes, lambda, scale, t);
        let rel = to_rotating(sys, frame, nodes, &lin);
        let mut j = DMatrix::<f64>::zeros(n, n);
        j.view_mut((0, 0), (nn, nn)).copy_from(&rel.k);
        j.view_mut((0, nn), (nn, n - nn)).copy_from(&lin.kl);
        j.view_mut((nn, 0), (n - nn, nn))
            .copy_from(&(&lin.b * scale));
        let dx = j.lu().solve(&(-r)).ok_or(EquilibriumError::Singular)?;
        if dx.iter().any(|v| !v.is_finite()) {
            return Err(EquilibriumError::Singular);
        }
        let mut inc: f64 = 0.0;
        for (i, node) in nodes.iter_mut().enumerate() {
            let d = &sys.node_dofs[i];
            let mut th = Vector3::zeros();
            for c in 0..3 {
                if d[c] != FIXED {
                    node.x[c] += dx[d[c]];
                    inc = inc.max(dx[d[c]].abs() / sys.ref_length);
                }
                if d[3 + c] != FIXED {
                    th[c] = dx[d[3 + c]];
                    inc = inc.max(th[c].abs());
                }
            }
            node.r *= exp(&th);
        }
        for (l, d) in lambda[nn..].iter_mut().zip(dx.iter().skip(nn)) {
            *l += d;
        }
        last = inc;
        if inc <= EQUILIBRIUM_TOL {
            frame.set_rates(nodes);
            return Ok(it);
        }
    }
    Err(EquilibriumError::NoConvergence(EQUILIBRIUM_MAXIT, last))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{axial, tangent};

    /// The material angular velocity and acceleration of `Λ(t) = R(t) Λ⁰ exp(δθ̃(t))`,
    /// `R(t) = exp(Ωt ã)`, at `t = 0` by differences, against the linearised
    /// `W⁰ + W̃⁰δθ + δθ̇` and `W̃⁰δθ̇ + δθ̈` (module documentation). Tolerance 1e-7: what is
    /// neglected is second order in the perturbation (`ε = 1e-4`: ~|W⁰|ε² ≈ 3e-8); `W` by
    /// central differences of `Λ` with `h = 1e-5` errs by h²|Λ⁽³⁾|/6 ≈ 2e-10 (round-off
    /// ε/h ≈ 2e-11); `Ẇ` by the fourth-order stencil on `W` with `H = 1e-3` errs by
    /// H⁴|W⁽⁵⁾|/30 ≈ 1e-12, plus round-off 2e-11/H ≈ 2e-8. The linear terms themselves are
    /// ~|W⁰|ε ≈ 2e-4: the check resolves them to 5e-4.
    #[test]
    fn material_rates_of_the_rotating_parametrisation() {
        let omega = Vector3::new(0.3, -0.2, 1.1) * 2.0;
        let l0 = exp(&Vector3::new(0.4, 0.7, -0.2));
        let eps = 1e-4;
        let (th0, thd, thdd) = (
            Vector3::new(0.3, -0.5, 0.8) * eps,
            Vector3::new(-0.7, 0.2, 0.4) * eps,
            Vector3::new(0.1, 0.9, -0.6) * eps,
        );
        let lam = |t: f64| {
            let th = th0 + thd * t + thdd * (t * t / 2.0);
            exp(&(omega * t)) * l0 * exp(&th)
        };
        // W(t) = (Λᵀ Λ̇)ᵛ by central differences of Λ.
        let h = 1e-5;
        let w_at = |t: f64| {
            let d = (lam(t + h) - lam(t - h)) / (2.0 * h);
            axial(&(lam(t).transpose() * d))
        };
        let w = w_at(0.0);
        let hh = 1e-3;
        let wd = (w_at(-2.0 * hh) - w_at(2.0 * hh) + (w_at(hh) - w_at(-hh)) * 8.0) / (12.0 * hh);
        let w0 = l0.transpose() * omega;
        let w_lin = w0 + skew(&w0) * th0 + thd;
        let wd_lin = skew(&w0) * thd + thdd;
        // Check against the exact form too: W = exp(−δθ̃)W⁰ + T(δθ)δθ̇.
        let w_exact = exp(&(-th0)) * w0 + tangent(&th0) * thd;
        assert!((w - w_exact).norm() < 1e-7, "{w} {w_exact}");
        assert!((w - w_lin).norm() < 1e-7, "{w} {w_lin}");
        assert!((wd - wd_lin).norm() < 1e-7, "{wd} {wd_lin}");
        // The linear terms are resolved: they are ~eps, the check is 1e-3 of them.
        assert!((skew(&w0) * th0).norm() > 1e-4 && (skew(&w0) * thd).norm() > 1e-4);
    }

    /// `K_rel` and `C_rel` ([`to_rotating`]) against central differences of the map
    /// `q ↦ r(q; v(q), a(q))` (positions and material spins moved, the rigid rotation's
    /// rates set from them: [`Frame::set_rates`]) and of `r` in the relative rates
    /// (`δv`, `δẍ = 2Aδv`; `δW`, `δẆ = W̃⁰δW`), at the relative equilibrium of a stubby
    /// rotating beam with a large rotary inertia (so that the `W̃⁰` terms count).
    /// Tolerance: central differences with h = 1e-5 err by h²|r'''|/6 ~ 1e-10 |K| and
    /// round-off ε|r|/h ~ 1e-10 |K|; 1e-6 of the rotating part `max|K_rel − K|` (itself
    /// asserted above 1e-3 of |K|, so the check resolves it) leaves room for both.
    #[test]
    fn rotating_frame_matrices_are_the_derivatives_of_the_rotating_residual() {
        let text = "TITLE fd\nSECTIONS\n  1 PROPERTIES EA 100 GA2 80 GA3 60 GJ 2 EI2 1 EI3 1.5 &\n    RHOA 1 RHOJ 0.1 RHOI2 0.05 RHOI3 0.07\nNODES\n  1 0 0 0 FIX ALL\n  2 0 0 0\n  3 1 0.2 0.1\nFUNCTIONS\n  1 EXPR 3*t\nELEMENTS\n  1 HINGE 1 2 AXIS 0 0 1 DRIVE 1\n  2 BEAM 2 3 SEC 1 AXIS2 0 1 0 ORDER 2\nANALYSIS MODES 4 ROTATING\n";
        let model = crate::deck::parse_deck(text, "fd.dat").expect("deck");
        let frame = Frame::from_model(&model, 0.0).expect("frame");
        let mut integ = crate::solver::prepare(&model).expect("model");
        let (t, s) = (integ.t, integ.scale);
        relative_equilibrium(
            &mut integ.sys,
            &frame,
            &mut integ.nodes,
            &mut integ.lambda,
            s,
            t,
        )
        .expect("relative equilibrium");
        let lambda = integ.lambda.clone();
        let nodes0 = integ.nodes.clone();
        let sys = &mut integ.sys;
        let lin = linearise(sys, &nodes0, &lambda, s, t);
        let rel = to_rotating(sys, &frame, &nodes0, &lin);
        let nn = sys.n_node_eq;
        let ctx = base_context(sys, s, t);
        let resid = |sys: &mut System, nodes: &[NodeState]| {
            sys.assemble(&ctx, nodes, &lambda, false);
            DVector::from_column_slice(&sys.rhs[..nn])
        };
        let a = skew(&frame.omega());
        let h = 1e-5;
        let (mut err_k, mut err_c): (f64, f64) = (0.0, 0.0);
        for i in 0..nodes0.len() {
            for part in 0..2 {
                for c in 0..3 {
                    let j = sys.node_dofs[i][3 * part + c];
                    if j == FIXED {
                        continue;
                    }
                    let mut e = Vector3::zeros();
                    e[c] = 1.0;
                    let (mut dk, mut dc) = (DVector::zeros(nn), DVector::zeros(nn));
                    for sign in [1.0, -1.0] {
                        let mut nd = nodes0.clone();
                        if part == 0 {
                            nd[i].x += e * (sign * h);
                        } else {
                            nd[i].r *= exp(&(e * (sign * h)));
                        }
                        frame.set_rates(&mut nd);
                        dk += resid(sys, &nd) * (sign / (2.0 * h));
                        let mut nd = nodes0.clone();
                        if part == 0 {
                            nd[i].v += e * (sign * h);
                            nd[i].a += a * e * (2.0 * sign * h);
                        } else {
                            nd[i].w += e * (sign * h);
                            nd[i].wd += skew(&nodes0[i].w) * e * (sign * h);
                        }
                        dc += resid(sys, &nd) * (sign / (2.0 * h));
                    }
                    err_k = err_k.max((dk - rel.k.column(j)).amax());
                    err_c = err_c.max((dc - rel.c.column(j)).amax());
                }
            }
        }
        let rot_k = (&rel.k - &lin.k).amax();
        let rot_c = (&rel.c - &lin.c).amax();
        eprintln!(
            "K_rel: {err_k:.2e} of {rot_k:.2e} (|K| {:.2e}); C_rel: {err_c:.2e} of {rot_c:.2e}",
            lin.k.amax()
        );
        assert!(rot_k > 1e-3 * lin.k.amax(), "{rot_k} {}", lin.k.amax());
        assert!(err_k <= 1e-6 * rot_k, "K_rel: {err_k:e} against {rot_k:e}");
        assert!(err_c <= 1e-6 * rot_c, "C_rel: {err_c:e} against {rot_c:e}");
    }
}
