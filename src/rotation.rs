//! Finite rotations: exponential map, logarithm, tangent operator and its inverse.
//!
//! Conventions (physics.md §1, Géradin & Cardona 2001 ch. 4):
//! - skew matrix `Φ̃ v = Φ × v`;
//! - `R = exp(Φ̃) = I + (sin φ/φ) Φ̃ + ((1 − cos φ)/φ²) Φ̃²` (Rodrigues; paper eq. [2]);
//! - material (right-trivialised) tangent operator `T(Φ)`: `δR = R (T(Φ) δΦ)~`,
//!   `T(Φ) = I − ((1 − cos φ)/φ²) Φ̃ + ((φ − sin φ)/φ³) Φ̃²` (paper eq. [3], rewritten);
//! - `T⁻¹(Φ) = I + ½ Φ̃ + (1/φ²)(1 − (φ/2) cot(φ/2)) Φ̃²`.
//!
//! Every coefficient is a smooth function of `φ² = Φ·Φ`; below `φ < 0.1` it is evaluated by
//! its Taylor series in `φ²` (truncation < 3e-15 relative), so the maps are accurate at 0 and
//! differentiable there — which matters because the functions are generic over the scalar
//! and are differentiated by dual numbers ([`num_dual`]) to build element tangents.
//!
//! Nodal orientations are stored as rotation matrices updated by incremental rotation
//! vectors (`R ← R exp(ΔΘ̃)`), so there is no singularity at `φ = 2π`: a node may turn any
//! number of times. [`log`] is accurate up to and at `φ = π` (quaternion form).

use crate::dual::Real;
use nalgebra::{Matrix3, Vector3};

/// Converts an `f64` constant into the generic scalar.
#[inline(always)]
pub fn c<S: Real>(x: f64) -> S {
    S::cst(x)
}

/// Below this `φ²` the coefficients use their Taylor series.
const SERIES_PHI2: f64 = 1e-2;

/// The skew-symmetric matrix `ṽ` with `ṽ w = v × w`.
#[inline]
pub fn skew<S: Real>(v: &Vector3<S>) -> Matrix3<S> {
    let z = S::zero();
    Matrix3::new(z, -v.z, v.y, v.z, z, -v.x, -v.y, v.x, z)
}

/// `a b` for 3×3 matrices, unrolled (nalgebra's generic product is slow for dual scalars).
#[inline(always)]
pub fn mm<S: Real>(a: &Matrix3<S>, b: &Matrix3<S>) -> Matrix3<S> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
}

/// `aᵀ b` for 3×3 matrices, unrolled.
#[inline(always)]
pub fn mtm<S: Real>(a: &Matrix3<S>, b: &Matrix3<S>) -> Matrix3<S> {
    Matrix3::from_fn(|i, j| a[(0, i)] * b[(0, j)] + a[(1, i)] * b[(1, j)] + a[(2, i)] * b[(2, j)])
}

/// `a v`, unrolled.
#[inline(always)]
pub fn mv<S: Real>(a: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
    Vector3::new(
        a[(0, 0)] * v.x + a[(0, 1)] * v.y + a[(0, 2)] * v.z,
        a[(1, 0)] * v.x + a[(1, 1)] * v.y + a[(1, 2)] * v.z,
        a[(2, 0)] * v.x + a[(2, 1)] * v.y + a[(2, 2)] * v.z,
    )
}

/// `aᵀ v`, unrolled.
#[inline(always)]
pub fn mtv<S: Real>(a: &Matrix3<S>, v: &Vector3<S>) -> Vector3<S> {
    Vector3::new(
        a[(0, 0)] * v.x + a[(1, 0)] * v.y + a[(2, 0)] * v.z,
        a[(0, 1)] * v.x + a[(1, 1)] * v.y + a[(2, 1)] * v.z,
        a[(0, 2)] * v.x + a[(1, 2)] * v.y + a[(2, 2)] * v.z,
    )
}

/// `Matrix3::identity() + a k + b k²` for a skew `k = Φ̃`, using `Φ̃² = ΦΦᵀ − |Φ|² I`.
#[inline(always)]
fn rodrigues_like<S: Real>(phi: &Vector3<S>, a: S, b: S) -> Matrix3<S> {
    let p2 = phi.x * phi.x + phi.y * phi.y + phi.z * phi.z;
    let one = S::one();
    Matrix3::from_fn(|i, j| {
        let k = match (i, j) {
            (0, 1) => -phi.z,
            (0, 2) => phi.y,
            (1, 0) => phi.z,
            (1, 2) => -phi.x,
            (2, 0) => -phi.y,
            (2, 1) => phi.x,
            _ => S::zero(),
        };
        let k2 = phi[i] * phi[j] - if i == j { p2 } else { S::zero() };
        (if i == j { one } else { S::zero() }) + a * k + b * k2
    })
}

/// The axial vector of the skew part of `m`: `axial(ṽ) = v`.
#[inline]
pub fn axial<S: Real>(m: &Matrix3<S>) -> Vector3<S> {
    let h = c::<S>(0.5);
    Vector3::new(
        (m[(2, 1)] - m[(1, 2)]) * h,
        (m[(0, 2)] - m[(2, 0)]) * h,
        (m[(1, 0)] - m[(0, 1)]) * h,
    )
}

/// `(sin φ/φ, (1 − cos φ)/φ², (φ − sin φ)/φ³)` as functions of `φ²`.
#[inline]
fn coefficients<S: Real>(phi2: S) -> (S, S, S) {
    if phi2 < c(SERIES_PHI2) {
        let p = phi2;
        let a = S::one() - p / c(6.0) + p * p / c(120.0) - p * p * p / c(5040.0);
        let b = c::<S>(0.5) - p / c(24.0) + p * p / c(720.0) - p * p * p / c(40320.0);
        let d = c::<S>(1.0 / 6.0) - p / c(120.0) + p * p / c(5040.0) - p * p * p / c(362880.0);
        (a, b, d)
    } else {
        let phi = phi2.sqrt();
        let (s, co) = (phi.sin(), phi.cos());
        (s / phi, (S::one() - co) / phi2, (phi - s) / (phi2 * phi))
    }
}

/// Exponential map `exp(Φ̃)` (Rodrigues' formula, paper eq. [2]).
pub fn exp<S: Real>(phi: &Vector3<S>) -> Matrix3<S> {
    let (a, b, _) = coefficients(phi.x * phi.x + phi.y * phi.y + phi.z * phi.z);
    rodrigues_like(phi, a, b)
}

/// Material tangent operator `T(Φ)`: `δR = R (T(Φ) δΦ)~`, `Ω = T(Φ) Φ̇` (paper eq. [3]).
pub fn tangent<S: Real>(phi: &Vector3<S>) -> Matrix3<S> {
    let (_, b, d) = coefficients(phi.x * phi.x + phi.y * phi.y + phi.z * phi.z);
    rodrigues_like(phi, -b, d)
}

/// Inverse tangent operator `T⁻¹(Φ) = I + ½Φ̃ + (1/φ²)(1 − (φ/2)cot(φ/2)) Φ̃²`.
///
/// Singular at `φ = 2π` only; the code keeps `φ ≤ π` by construction (logs of relative or
/// incremental rotations).
pub fn tangent_inv<S: Real>(phi: &Vector3<S>) -> Matrix3<S> {
    let p = phi.x * phi.x + phi.y * phi.y + phi.z * phi.z;
    let e = if p < c(SERIES_PHI2) {
        c::<S>(1.0 / 12.0) + p / c(720.0) + p * p / c(30240.0) + p * p * p / c(1209600.0)
    } else {
        let phi = p.sqrt();
        let h = phi * c(0.5);
        (S::one() - h * h.cos() / h.sin()) / p
    };
    rodrigues_like(phi, c(0.5), e)
}

/// Unit quaternion `(w, v)` of a rotation matrix, `w ≥ 0` (Shepperd's method, stable for
/// every rotation).
pub fn quaternion<S: Real>(r: &Matrix3<S>) -> (S, Vector3<S>) {
    let tr = r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    let quarter = c::<S>(0.25);
    let (w, v) = if tr >= r[(0, 0)] && tr >= r[(1, 1)] && tr >= r[(2, 2)] {
        let s = (S::one() + tr).sqrt() * c(2.0); // 4w
        (
            s * quarter,
            Vector3::new(
                (r[(2, 1)] - r[(1, 2)]) / s,
                (r[(0, 2)] - r[(2, 0)]) / s,
                (r[(1, 0)] - r[(0, 1)]) / s,
            ),
        )
    } else if r[(0, 0)] >= r[(1, 1)] && r[(0, 0)] >= r[(2, 2)] {
        let s = (S::one() + r[(0, 0)] * c(2.0) - tr).sqrt() * c(2.0); // 4x
        (
            (r[(2, 1)] - r[(1, 2)]) / s,
            Vector3::new(
                s * quarter,
                (r[(0, 1)] + r[(1, 0)]) / s,
                (r[(0, 2)] + r[(2, 0)]) / s,
            ),
        )
    } else if r[(1, 1)] >= r[(2, 2)] {
        let s = (S::one() + r[(1, 1)] * c(2.0) - tr).sqrt() * c(2.0); // 4y
        (
            (r[(0, 2)] - r[(2, 0)]) / s,
            Vector3::new(
                (r[(0, 1)] + r[(1, 0)]) / s,
                s * quarter,
                (r[(1, 2)] + r[(2, 1)]) / s,
            ),
        )
    } else {
        let s = (S::one() + r[(2, 2)] * c(2.0) - tr).sqrt() * c(2.0); // 4z
        (
            (r[(1, 0)] - r[(0, 1)]) / s,
            Vector3::new(
                (r[(0, 2)] + r[(2, 0)]) / s,
                (r[(1, 2)] + r[(2, 1)]) / s,
                s * quarter,
            ),
        )
    };
    if w < S::zero() { (-w, -v) } else { (w, v) }
}

/// Logarithm of a rotation matrix: the rotation vector `Φ` with `‖Φ‖ ≤ π` and
/// `exp(Φ̃) = R`. Accurate near 0 (series in `‖v‖²`) and at π (quaternion form).
pub fn log<S: Real>(r: &Matrix3<S>) -> Vector3<S> {
    let (w, v) = quaternion(r);
    log_of_quaternion(w, &v)
}

/// [`log`] and `cot(φ/2)` (`φ = ‖Φ‖`) from the same unit quaternion, `cos(φ/2)/sin(φ/2) =
/// w/‖v‖` (infinite at `φ = 0`): the coefficient of `T⁻¹(Φ)` without a `tan`.
pub fn log_and_cot_half(r: &Matrix3<f64>) -> (Vector3<f64>, f64) {
    let (w, v) = quaternion(r);
    let s = v.norm();
    (log_of_quaternion(w, &v), w / s)
}

/// `Φ = 2 atan2(|v|, w) v/|v|` of the unit quaternion `(w, v)`, `w ≥ 0`.
fn log_of_quaternion<S: Real>(w: S, v: &Vector3<S>) -> Vector3<S> {
    let s2 = v.dot(v);
    // The factor is smooth in |v|² near 0.
    let k = if s2 < c::<S>(1e-4) * w * w {
        let x2 = s2 / (w * w);
        (S::one() - x2 / c(3.0) + x2 * x2 / c(5.0) - x2 * x2 * x2 / c(7.0)) * c(2.0) / w
    } else {
        let s = s2.sqrt();
        s.atan2(w) * c(2.0) / s
    };
    *v * k
}

/// Re-orthonormalises a rotation matrix (polar projection by one Newton step, enough for
/// drift of round-off size). Used after many incremental updates.
pub fn orthonormalize(r: &Matrix3<f64>) -> Matrix3<f64> {
    // R ← R (3I − RᵀR)/2 converges quadratically to the orthogonal polar factor.
    let rtr = r.transpose() * r;
    r * (Matrix3::identity() * 3.0 - rtr) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Matrix3<f64>, b: &Matrix3<f64>, tol: f64) -> bool {
        (a - b).abs().max() < tol
    }

    #[test]
    fn exp_of_axis_rotation_matches_closed_form() {
        let t = 0.7_f64;
        let r = exp(&Vector3::new(0.0, 0.0, t));
        let expected = Matrix3::new(t.cos(), -t.sin(), 0.0, t.sin(), t.cos(), 0.0, 0.0, 0.0, 1.0);
        assert!(close(&r, &expected, 1e-15));
    }

    #[test]
    fn log_at_pi_and_near_zero() {
        let phi = Vector3::new(0.0, std::f64::consts::PI, 0.0);
        let l = log(&exp(&phi));
        assert!((l.norm() - std::f64::consts::PI).abs() < 1e-12);
        let tiny = Vector3::new(1e-9, -2e-9, 3e-9);
        assert!((log(&exp(&tiny)) - tiny).norm() < 1e-22);
    }

    /// `cot(φ/2)` from the quaternion equals `1/tan(φ/2)` (to a few ulps of its size, up to
    /// `φ = π` where it is 0), and the rotation vector is [`log`]'s.
    #[test]
    fn cot_half_from_the_quaternion_is_the_cotangent() {
        for phi in [
            Vector3::new(0.01, 0.02, -0.03),
            Vector3::new(0.3, -1.2, 0.5),
            Vector3::new(2.0, 1.0, -1.5),
            Vector3::new(0.0, 0.0, std::f64::consts::PI - 1e-9),
        ] {
            let r = exp(&phi);
            let (l, cot) = log_and_cot_half(&r);
            assert!((l - log(&r)).norm() == 0.0);
            let want = 1.0 / (0.5 * phi.norm()).tan();
            assert!(
                (cot - want).abs() <= 1e-14 * (1.0 + want.abs()) / phi.norm().min(1.0),
                "{phi:?}: {cot} vs {want}"
            );
        }
    }

    #[test]
    fn tangent_inverse_is_inverse() {
        for phi in [
            Vector3::new(0.01, 0.02, -0.03),
            Vector3::new(0.3, -1.2, 0.5),
            Vector3::new(2.0, 1.0, -1.5),
        ] {
            let p = tangent(&phi) * tangent_inv(&phi);
            assert!(close(&p, &Matrix3::identity(), 1e-13), "{phi:?}");
        }
    }
}
