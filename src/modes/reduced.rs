//! The dense solve of the reduced linearised problem (the constraints' null space, then
//! [`super::dense`]) and the classification of its modes: rigid (a zero within round-off),
//! unstable, elastic.

use super::{
    ASYMMETRY_TOL, DAMPED_TOL, Method, ModalAnalysis, ModesError, dense, group_index, linearise,
    make_mode_s, max_abs, model_scale,
};
use crate::elements::NodeState;
use crate::solver::system::System;
use nalgebra::DMatrix;
use std::f64::consts::PI;

#[allow(clippy::too_many_arguments)]
pub(super) fn analyse_dense(
    sys: &System,
    nodes: &[NodeState],
    lambda: &[f64],
    scale: f64,
    t: f64,
    groups: &[&str],
    count: usize,
    shapes: bool,
) -> Result<ModalAnalysis, ModesError> {
    let lin = linearise::linearise(sys, nodes, lambda, scale, t);
    solve_dense(lin, sys.n_node_eq, groups, count, shapes)
}

/// The dense solve of the linearised model; `shapes = false`: the frequencies alone
/// ([`Solver::DenseFrequencies`]).
pub(super) fn solve_dense(
    lin: linearise::Linearised,
    nn: usize,
    groups: &[&str],
    count: usize,
    shapes: bool,
) -> Result<ModalAnalysis, ModesError> {
    let basis = linearise::null_space(&lin.b, nn);
    let free = basis.ncols();
    if free == 0 {
        return Err(ModesError::NothingToVibrate(
            "every degree of freedom is fixed or constrained".into(),
        ));
    }
    // Without constraints the basis is the identity: the products would copy (exactly).
    let unconstrained = linearise::unconstrained(&lin.b);
    let reduce = |a: &DMatrix<f64>| {
        if unconstrained {
            a.clone()
        } else {
            basis.transpose() * a * &basis
        }
    };
    let (kr, cr, mr) = (reduce(&lin.k), reduce(&lin.c), reduce(&lin.m));
    // The mass before the count: a massless model has nothing to vibrate, whatever the count.
    if max_abs(&mr) == 0.0 {
        return Err(ModesError::NothingToVibrate(
            "no mass on any free degree of freedom".into(),
        ));
    }
    if count > free {
        return Err(ModesError::TooMany {
            count,
            free,
            finite: free,
        });
    }
    let kn = max_abs(&kr);
    let asymmetry = if kn > 0.0 {
        max_abs(&(&kr - kr.transpose())) / kn
    } else {
        0.0
    };
    let damped = max_abs(&cr) > DAMPED_TOL * (kn.max(f64::MIN_POSITIVE) * max_abs(&mr)).sqrt();
    let regular_mass = mr.clone().cholesky().is_some();
    let state_space = (damped || asymmetry > ASYMMETRY_TOL) && regular_mass;
    let (method, raw) = if state_space {
        let raw = if shapes {
            dense::state_space(&kr, &cr, &mr)?
        } else {
            // Without shapes a mode is told rigid by the model's zero alone (below); one
            // whose own round-off could call it rigid (between that zero and the largest
            // the per-mode test can give) needs its shape: then all are computed.
            let (raw, light) = dense::state_space_values(&kr, &cr, &mr)?;
            let (zero, own_max) = zero_bounds(&lin, &raw, &kr, light);
            if raw
                .iter()
                .any(|r| r.omega2.abs() > zero && r.omega2.abs() <= own_max)
            {
                dense::state_space(&kr, &cr, &mr)?
            } else {
                raw
            }
        };
        (Method::StateSpace, raw)
    } else {
        let ks = (&kr + kr.transpose()) * 0.5;
        let ms = (&mr + mr.transpose()) * 0.5;
        (Method::Symmetric, dense::conservative(&ks, &ms)?)
    };
    let finite = raw.len();
    if finite == 0 {
        return Err(ModesError::NothingToVibrate(
            "no finite mode: the free directions carry no mass".into(),
        ));
    }
    if count > finite {
        return Err(ModesError::TooMany {
            count,
            free,
            finite,
        });
    }
    // The zero threshold against the model's stiffness scale `‖K‖/‖M‖` (max-abs norms of
    // the assembled, unreduced matrices, 1/s²), not against ω²_max alone: when every mode
    // is a zero (a single pendulum at rest with its link horizontal), ω²_max is round-off
    // itself and a relative threshold calls it a frequency. The entries of K carry
    // ε‖K‖, so a computed ω² carries ε‖K‖/‖M‖ (ZERO_FACTOR of it: [`dense::ZERO_FACTOR`]);
    // the shift of [`dense::conservative`] adds ε σ, σ = 1e-8 ω²_max (or 1e-8 1/s² on a
    // model without stiffness): the floor `1e-8` ([`scales`]).
    let (w2max, stiffness_scale) = scales(&lin, &raw);
    let zero = dense::ZERO_FACTOR * f64::EPSILON * stiffness_scale;
    // Per mode, the same round-off seen through the mode's own mass: a perturbation δK of
    // the reduced stiffness moves ω² by the Rayleigh quotient `φᵀδKφ / φᵀMφ`, at most
    // `ε‖K‖ · |φ|²/φᵀMφ`, and `|φ|²/φᵀMφ` is 1/(the smallest mass) for a mode that moves
    // only a light direction: a spherical pendulum's spin about its link carries the point
    // mass's rotary inertia (1e-3 kg·m²) alone, and its ω² = 1.9e-13 1/s² of round-off, above
    // ε‖K‖/‖M‖ (‖M‖ the 1 kg mass), was called a frequency — or, negative, an instability
    // (issue 34 §8). ‖K‖ the max-abs norm of the reduced stiffness.
    let k_norm = max_abs(&kr);
    let mode_zero = |r: &dense::RawMode| {
        if r.shape.is_empty() {
            // Frequencies alone: `zero_bounds` found no mode its own round-off could call
            // rigid.
            return zero;
        }
        let mass = r.shape.dot(&(&mr * &r.shape));
        let norm2 = r.shape.norm_squared();
        let own = if mass > 0.0 && norm2 > 0.0 {
            dense::ZERO_FACTOR * f64::EPSILON * k_norm * norm2 / mass
        } else {
            0.0
        };
        zero.max(own)
    };
    // Each mode's test once (an `O(n²)` product: the sort below would repeat it).
    let zeros: Vec<bool> = raw.iter().map(|r| r.omega2.abs() <= mode_zero(r)).collect();
    let rigid_modes = zeros.iter().filter(|z| **z).count();
    let w2max_finite = raw
        .iter()
        .zip(&zeros)
        .filter(|(_, z)| !**z)
        .fold(0.0f64, |m, (r, _)| m.max(r.omega2.abs()));
    let highest_hz = w2max_finite.sqrt() / (2.0 * PI);
    // Round-off of Re s in the first-order form `A = [0 I; −M⁻¹K −M⁻¹C]`: the dense
    // eigen-solver is backward stable, `δA ~ ε‖A‖`, `‖A‖ ≈ max(1, ‖K‖/‖M‖, ‖C‖/‖M‖, ω²_max)`
    // (SI units of the assembly), and moves an eigenvalue by its condition number times
    // that. (The solve balances `A`'s blocks, `dense::block_balance`: `‖A‖ ≈ ω_max` and
    // the pair's condition `(σ² + |s|²)/(2σ|s|)`, whose product with it is at most the
    // bound below, which stays an upper bound.) For the undamped pair `s = ±iω` the right
    // and left eigenvectors are `(φ, sφ)` and `(sφ, φ)`-like, condition `(1 + ω²)/(2ω)`; so `|δRe s| ≲ ε‖A‖(1 + |s|²)/(2|s|)`,
    // ZERO_FACTOR of it as for ω². Below it the sign of Re s is round-off: the mode is
    // neither damped nor unstable (the heavy top's ζ = −1.9e-15 at |s| = 4.75 1/s; the
    // pendulum at 0.05 s: ζ = −2.6e-6 at |s| = 5.7 1/s with ω²_max = 9.4e10 1/s²).
    let re_tol = if method == Method::StateSpace {
        let a_norm = 1f64.max(stiffness_scale).max(model_scale(&lin.c, &lin.m));
        dense::ZERO_FACTOR * f64::EPSILON * a_norm
    } else {
        0.0
    };
    // Rigid first, unstable next, then by ω².
    let mut order: Vec<usize> = (0..raw.len()).collect();
    order.sort_by_key(|&i| u8::from(!zeros[i]));
    // Undamped gyroscopic (`C` skew, `K` symmetric — a rotating frame's Coriolis matrix):
    // the eigenvalues of a stable model are imaginary, and a real part is the first-order
    // form's round-off, `ε ‖A‖ κ ≈ ε ω²_max (1 + |s|²)/(2|s|)` (‖A‖ ≈ ω²_max in
    // mass-orthonormal coordinates, κ the condition of the pair `(φ, sφ)`), ×ZERO_FACTOR:
    // below it it is reported as zero, neither damping nor instability.
    let skew_c = state_space
        && asymmetry <= ASYMMETRY_TOL
        && max_abs(&(&cr + cr.transpose()))
            <= DAMPED_TOL * (kn.max(f64::MIN_POSITIVE) * max_abs(&mr)).sqrt();
    let clean = |s: (f64, f64)| {
        let a = s.0.hypot(s.1);
        let noise = dense::ZERO_FACTOR * f64::EPSILON * w2max * (1.0 + a * a) / (2.0 * a);
        if skew_c && a > 0.0 && s.0.abs() <= noise {
            (0.0, s.1)
        } else {
            s
        }
    };
    let (group_names, group_of) = group_index(groups);
    let modes = order
        .into_iter()
        .take(count)
        .map(|i| {
            let r = &raw[i];
            // Frequencies alone: no shape (`make_mode_s` then gives no energy shares).
            let phi: Vec<f64> = if r.shape.is_empty() {
                Vec::new()
            } else {
                if unconstrained {
                    r.shape.iter().copied().collect()
                } else {
                    (&basis * &r.shape).iter().copied().collect()
                }
            };
            let (re, im) = r.s;
            let w = re.hypot(im);
            let tol = if w > 0.0 {
                re_tol * (1.0 + w * w) / (2.0 * w)
            } else {
                0.0
            };
            let s = if re.abs() <= tol { (0.0, im) } else { r.s };
            make_mode_s(
                phi,
                clean(s),
                zeros[i],
                &lin.locals,
                &group_of,
                group_names.len(),
            )
        })
        .collect();
    Ok(ModalAnalysis {
        modes,
        free_unknowns: free,
        constraints: (lin.b.nrows(), nn - free),
        rigid_modes,
        finite_modes: finite,
        highest_hz,
        method,
        asymmetry,
        groups: group_names,
    })
}

/// `ω²_max` of the computed modes and the model's stiffness scale
/// `max(‖K‖/‖M‖, ω²_max, 1e-8)`, 1/s² ([`solve_dense`]'s zero is `ZERO_FACTOR ε` times it).
fn scales(lin: &linearise::Linearised, raw: &[dense::RawMode]) -> (f64, f64) {
    let w2max = raw.iter().fold(0.0f64, |m, r| m.max(r.omega2.abs()));
    (w2max, model_scale(&lin.k, &lin.m).max(w2max).max(1e-8))
}

/// The model's zero of `ω²` and the largest a mode's own zero can be: `ZERO_FACTOR ε ‖K‖
/// |φ|²/φᵀMφ` ([`solve_dense`]) is at most `ZERO_FACTOR ε ‖K‖ / λ_min(M)`, and
/// `1/λ_min(M) = ‖L⁻¹‖₂² ≤ light`, `light = ‖L⁻¹‖_F²` of `M = LLᵀ`.
fn zero_bounds(
    lin: &linearise::Linearised,
    raw: &[dense::RawMode],
    kr: &DMatrix<f64>,
    light: f64,
) -> (f64, f64) {
    let zero = dense::ZERO_FACTOR * f64::EPSILON * scales(lin, raw).1;
    (
        zero,
        zero.max(dense::ZERO_FACTOR * f64::EPSILON * max_abs(kr) * light),
    )
}
