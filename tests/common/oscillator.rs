//! What a run of a linear oscillator measures of its integrator: the spectral radius and
//! the relative period error, against their closed forms (tests/stability/damping.rs for HHT,
//! tests/genalpha.rs for generalized-α).

/// From the sampled displacement `x` and velocity `v` of an oscillator of circular
/// frequency `w` (times `t`, step `h`): the period from the first and last upward zero
/// crossings (linearly interpolated), its relative error against `2π/w`, and the spectral
/// radius per step from the energy `½(v² + w²x²)` at those crossings, `ρ = (E₁/E₀)^(1/2n)`.
/// Returns `(ρ, period error)`.
pub fn radius_and_period_error(t: &[f64], x: &[f64], v: &[f64], h: f64, w: f64) -> (f64, f64) {
    use std::f64::consts::PI;
    let ups: Vec<(usize, f64)> = (1..x.len())
        .filter(|&i| x[i - 1] < 0.0 && x[i] >= 0.0)
        .map(|i| (i, t[i - 1] + h * x[i - 1] / (x[i - 1] - x[i])))
        .collect();
    let (i0, t0) = ups[0];
    let (i1, t1) = *ups.last().expect("zero crossings");
    let period = (t1 - t0) / (ups.len() - 1) as f64;
    let en = |i: usize| 0.5 * (v[i] * v[i] + w * w * x[i] * x[i]);
    let rho = (en(i1) / en(i0)).powf(1.0 / (2.0 * (i1 - i0) as f64));
    (rho, period / (2.0 * PI / w) - 1.0)
}
