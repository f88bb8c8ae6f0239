//! Material `DAMPING η` (stiffness-proportional, Kelvin–Voigt: `σ = C (ε + η ε̇)`) against
//! the closed form of a cantilever's first mode, `ζ₁ = η ω₁ / 2`, and the energy balance.

use mecano::deck::parse_deck;
use mecano::model::Model;
use mecano::output::History;
use mecano::solver;
use std::f64::consts::PI;

/// The seed's steel cantilever (L = 1 m, `n` elements of order `p`), released from rest under
/// a gravity step: its tip oscillates about the static deflection, mostly in the first mode.
fn cantilever(eta: f64, elements: usize, order: usize, h: f64, end: f64) -> Model {
    let text = format!(
        "TITLE damped cantilever
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800 DAMPING {eta:e}
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 8.3e-8 J 4.15e-8 K 0.8333333333333334
NODES
  1 0 0 0 FIX ALL
  2 TO {last} LINE {dx} 0 0  1 0 0
ELEMENTS
  1 TO {elements} BEAM 1 2 MAT 1 SEC 1{ord}
LOADS
  GRAVITY 0 -9.81 0
ANALYSIS DYNAMIC ALPHA 0 STEP {h:e} END {end}
OUTPUT NODES {last} ELEMENTS NONE
END
",
        last = elements + 1,
        dx = 1.0 / elements as f64,
        ord = if order > 1 {
            format!(" ORDER {order}")
        } else {
            String::new()
        },
    );
    parse_deck(&text, "damped cantilever").expect("the deck parses")
}

/// First bending circular frequency of the Euler–Bernoulli cantilever, rad/s:
/// `ω₁ = (1.8751)² √(EI/ρA) / L²`.
fn omega1() -> f64 {
    let (e, i, rho, a): (f64, f64, f64, f64) = (2.1e11, 8.3e-8, 7800.0, 9e-4);
    1.875104068711961f64.powi(2) * (e * i / (rho * a)).sqrt()
}

/// Runs the cantilever; returns the history and the tip's dense index.
fn run(model: &Model) -> (History, usize) {
    let mut h = History::new(1);
    let report = solver::run(model, &mut h).expect("run starts");
    assert!(report.failure.is_none(), "{:?}", report.failure);
    // The tip: the last node of the deck's LINE (generated nodes come after it).
    let last = model
        .nodes
        .keys()
        .filter(|id| id.0 <= model.elements.len() as u32 + 1)
        .max()
        .copied()
        .expect("nodes");
    let tip = model.nodes.get_index_of(&last).expect("tip");
    (h, tip)
}

/// Extremes of a sampled signal (times and values), each refined by the parabola through
/// the sample and its neighbours (error O(h³) in the value for a smooth signal).
fn extremes(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for k in 1..y.len() - 1 {
        let (a, b, c) = (y[k - 1], y[k], y[k + 1]);
        if (b > a && b >= c) || (b < a && b <= c) {
            let den = a - 2.0 * b + c;
            let s = if den != 0.0 { 0.5 * (a - c) / den } else { 0.0 };
            out.push((t[k] + s * (t[k + 1] - t[k]), b - 0.25 * (a - c) * s));
        }
    }
    out
}

/// Measured damping ratio and damped circular frequency of the tip's free vibration, from
/// the peak-to-peak amplitudes `Aₖ = |yₖ − yₖ₊₁|` of consecutive extremes: for
/// `y = y_s + A e^{−ζωt} cos(ω_d t + φ)` they fall by `e^{−ζω T_d}` per damped period `T_d`
/// (the logarithmic decrement `δ`), and `ζ = δ / √(4π² + δ²)`. Extremes from `skip` on.
fn decay(h: &History, tip: usize, skip: usize) -> (f64, f64) {
    let y: Vec<f64> = h.nodes.iter().map(|n| n[tip].x.y).collect();
    let ex = extremes(&h.t, &y);
    let ex = &ex[skip..];
    assert!(ex.len() >= 8, "only {} extremes", ex.len());
    let amp: Vec<f64> = ex.windows(2).map(|w| (w[0].1 - w[1].1).abs()).collect();
    // Half-periods between the first and the last amplitude: 2 per period.
    let halves = (amp.len() - 1) as f64;
    let periods = halves / 2.0;
    let delta = (amp[0] / amp[amp.len() - 1]).ln() / periods;
    let td = (ex[ex.len() - 1].0 - ex[0].0) / ((ex.len() - 1) as f64 / 2.0);
    (
        delta / (4.0 * PI * PI + delta * delta).sqrt(),
        2.0 * PI / td,
    )
}

/// A cantilever of 20 two-node beams with η = 2ζ/ω₁ for ζ = 1 %: the tip's logarithmic
/// decrement gives ζ₁ = η ω₁ / 2.
///
/// Tolerance (errors measured or bounded, each relative to ζ): the discrete ω₁ differs from
/// the Euler–Bernoulli closed form by ~0.1 % (measured 175.08 vs 175.20 rad/s: mesh, shear
/// and rotary inertia), and ζ = ηω/2 inherits it;
/// the trapezoidal rule (HHT α = 0, no numerical damping) at ωh = 0.035 errs by
/// O((ωh)²/12) = 1e-4 on the decay per period; the refined extremes err by O((ωh)³);
/// the second mode (ζ₂ = η ω₂ / 2 ≈ 6 %) has decayed by e⁻⁷ when the count starts
/// (3 periods = 19 periods of mode 2). The sum is below 0.2 %; the check allows 0.5 %,
/// while a damping law off by a factor (η C vs η C/2, or the rates of the wrong strains)
/// misses by 50 % or more. Measured: ζ = 0.009992 against ηω₁/2 = 0.01 (−7.8e-4) and
/// against ηω/2 with the measured ω (−1.0e-4); energy balance residue 5.6e-4 of W_d.
#[test]
fn cantilever_first_mode_decays_with_zeta_eta_omega_over_two() {
    let zeta = 0.01;
    let w1 = omega1();
    let eta = 2.0 * zeta / w1;
    let t1 = 2.0 * PI / w1;
    let model = cantilever(eta, 20, 1, 2e-4, 10.0 * t1);
    let (h, tip) = run(&model);
    let (z, wd) = decay(&h, tip, 6);
    let w = wd / (1.0 - z * z).sqrt();
    println!(
        "damped cantilever: zeta measured {z:.6}, eta*omega1/2 = {:.6} (closed-form omega1 {w1:.3} rad/s), \
         eta*omega/2 = {:.6} (measured omega {w:.3} rad/s); relative {:+.2e}, {:+.2e}",
        eta * w1 / 2.0,
        eta * w / 2.0,
        z / (eta * w1 / 2.0) - 1.0,
        z / (eta * w / 2.0) - 1.0
    );
    assert!(
        (z / (eta * w1 / 2.0) - 1.0).abs() < 5e-3,
        "zeta {z} vs {}",
        eta * w1 / 2.0
    );
    // Energy balance: E(t) − E(0) = −W_d + (numerical), with the numerical part of the
    // trapezoidal rule O((ωh)²) of the dissipated work (the power is integrated by the
    // trapezoid, the equations by the midpoint of the velocities: they differ by
    // h η (Δv)²/4 per step): bounded by 1e-3 of W_d.
    let k = h.t.len() - 1;
    let wd_total = h.damping_work[k];
    let numerical = -wd_total - (h.energy[k] - h.energy[0]);
    println!(
        "damped cantilever: dissipated {wd_total:.4e} J, energy change {:.4e} J, balance residue {numerical:.2e} J ({:.1e} of W_d)",
        h.energy[k] - h.energy[0],
        numerical / wd_total
    );
    assert!(wd_total > 0.0);
    assert!(
        numerical.abs() < 1e-3 * wd_total,
        "balance residue {numerical:e} J"
    );
}

/// The same with two elements of order 6 (the order-p beam): the same ζ, same tolerance
/// (measured −1.1e-3: the Timoshenko ω₁ is ~0.1 % below the Euler–Bernoulli one).
#[test]
fn order_p_cantilever_decays_with_zeta_eta_omega_over_two() {
    let zeta = 0.01;
    let w1 = omega1();
    let eta = 2.0 * zeta / w1;
    let t1 = 2.0 * PI / w1;
    let model = cantilever(eta, 2, 6, 2e-4, 10.0 * t1);
    let (h, tip) = run(&model);
    let (z, _) = decay(&h, tip, 6);
    println!(
        "damped order-6 cantilever: zeta measured {z:.6}, eta*omega1/2 = {:.6} ({:+.2e})",
        eta * w1 / 2.0,
        z / (eta * w1 / 2.0) - 1.0
    );
    assert!((z / (eta * w1 / 2.0) - 1.0).abs() < 5e-3, "zeta {z}");
}
