//! Property tests of the rotation maps (issue: the dynamics core, item 1).

use mecano::rotation::{self, exp, log, orthonormalize, skew, tangent, tangent_inv};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

fn vec3(max: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-max..max, -max..max, -max..max).prop_map(|(a, b, c)| Vector3::new(a, b, c))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// exp(log(R)) = R for any rotation, including rotation vectors far past 2π (their log
    /// is brought back into the ball |Φ| ≤ π) and near π.
    #[test]
    fn exp_of_log_is_identity(phi in vec3(12.0)) {
        let r = exp(&phi);
        let back = exp(&log(&r));
        prop_assert!((back - r).abs().max() < 1e-13, "{}", (back - r).abs().max());
        prop_assert!(log(&r).norm() <= PI + 1e-12);
    }

    /// Near π: log(exp(Φ)) = ±Φ with |Φ| = π − δ, accurate to round-off (quaternion form).
    #[test]
    fn log_is_accurate_near_pi(axis in vec3(1.0), delta in 1e-9f64..1e-3) {
        prop_assume!(axis.norm() > 1e-3);
        let phi = axis.normalize() * (PI - delta);
        let l = log(&exp(&phi));
        let err = (l - phi).norm().min((l + phi).norm());
        prop_assert!(err < 1e-9, "{err:e}");
    }

    /// Small vectors: the series branches agree with the closed forms to round-off.
    #[test]
    fn log_of_exp_for_small_rotations(phi in vec3(0.2)) {
        let l = log(&exp(&phi));
        // R's entries are O(1) and known to ε = 2.2e-16; log takes twice its skew part:
        // an absolute error of a few ε, independent of |Φ| (relative accuracy is lost
        // only as ε/|Φ|, the conditioning of the problem itself).
        let err = (l - phi).norm();
        prop_assert!(err < 16.0 * f64::EPSILON, "{err:e}");
    }

    /// The material tangent operator: exp(Φ + εδ) = exp(Φ) exp(ε T(Φ) δ) + O(ε²), checked by
    /// a central difference (error O(ε²) ≈ 1e-10 relative with ε = 1e-5).
    #[test]
    fn tangent_matches_a_finite_difference_of_exp(phi in vec3(3.0), d in vec3(1.0)) {
        let eps = 1e-5;
        let r = exp(&phi);
        let dr = (exp(&(phi + d * eps)) - exp(&(phi - d * eps))) / (2.0 * eps);
        // dR = R (T δ)~
        let expected = r * skew(&(tangent(&phi) * d));
        prop_assert!((dr - expected).abs().max() < 1e-8, "{}", (dr - expected).abs().max());
        let ti = tangent_inv(&phi) * tangent(&phi);
        prop_assert!((ti - Matrix3::identity()).abs().max() < 1e-10);
    }
}

/// Orthogonality kept over 10⁶ incremental updates `R ← R exp(ΔΘ)` with the
/// re-orthonormalisation the integrator applies after every step; the accumulated rotation
/// is also checked against the closed form of a steady spin (ΔΘ constant about one axis).
#[test]
fn orthogonality_kept_over_a_million_updates() {
    let n = 1_000_000;
    let dtheta = Vector3::new(0.3, -0.2, 0.5).normalize() * 1e-3;
    let mut r = Matrix3::identity();
    for _ in 0..n {
        r = orthonormalize(&(r * exp(&dtheta)));
    }
    let orth = (r.transpose() * r - Matrix3::identity()).abs().max();
    assert!(orth < 1e-14, "RᵀR − I = {orth:e}");
    // 1000 rad of spin: each step adds a round-off of ~1e-16 rad; 1e6 steps ≤ ~1e-10.
    let exact = exp(&(dtheta * n as f64));
    assert!(
        (r - exact).abs().max() < 1e-9,
        "{:e}",
        (r - exact).abs().max()
    );
    let _ = rotation::c::<f64>;
}
