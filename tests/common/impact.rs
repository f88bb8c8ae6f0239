//! The 1-D impact of a mass on a compliant wall, `m δ̈ = −max(F(δ, δ̇), 0)` from `δ = 0`,
//! `δ̇ = v₀`, integrated by RK4: the independent route the clearance joint's tests check
//! their impacts against (tests/mechanics/clearance.rs, tests/stability/clearance.rs).

/// RK4 with `n` steps over `t_est` (an estimate of the impact's duration) until the
/// penetration closes again: `(rebound speed / v₀, deepest penetration)`.
pub fn impact_ode(
    m: f64,
    v0: f64,
    force: impl Fn(f64, f64) -> f64,
    t_est: f64,
    n: usize,
) -> (f64, f64) {
    let h = t_est / n as f64;
    let acc = |d: f64, dd: f64| -force(d, dd).max(0.0) / m;
    let (mut d, mut dd, mut deepest) = (0.0f64, v0, 0.0f64);
    for _ in 0..20 * n {
        let (k1d, k1v) = (dd, acc(d, dd));
        let (k2d, k2v) = (
            dd + 0.5 * h * k1v,
            acc(d + 0.5 * h * k1d, dd + 0.5 * h * k1v),
        );
        let (k3d, k3v) = (
            dd + 0.5 * h * k2v,
            acc(d + 0.5 * h * k2d, dd + 0.5 * h * k2v),
        );
        let (k4d, k4v) = (dd + h * k3v, acc(d + h * k3d, dd + h * k3v));
        d += h / 6.0 * (k1d + 2.0 * k2d + 2.0 * k3d + k4d);
        dd += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        deepest = deepest.max(d);
        if d <= 0.0 && dd < 0.0 {
            return (-dd / v0, deepest);
        }
    }
    panic!("the impact ODE did not release");
}

/// The Lankarani–Nikravesh force `K δⁿ (1 + 3(1 − e²)/4 · δ̇/v₀)` (zero apart).
pub fn lankarani_nikravesh(k: f64, n: f64, e: f64, v0: f64) -> impl Fn(f64, f64) -> f64 {
    let d = 0.75 * (1.0 - e * e);
    move |x, xd| {
        if x > 0.0 {
            k * x.powf(n) * (1.0 + d * xd / v0)
        } else {
            0.0
        }
    }
}
