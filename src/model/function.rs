//! Time functions `f(t)`: what scales a load and what a driver prescribes.
//!
//! Every kind gives its value and, where it has them, its exact first and second time
//! derivatives ([`Function::derivatives`]): a driver (a prescribed motion) needs
//! `f, ḟ, f̈` for positions, velocities and accelerations consistent with the time
//! integrator; a load needs only `f`.
//!
//! The smooth kinds, with exact derivatives: `CONSTANT`, `HAVERSINE`, the C² cubic
//! [`CubicSpline`], the harmonic `SINE`/`COSINE`, the quintic `RAMP` and an expression of
//! `t` ([`TimeExpr`], evaluated with second-order jets).

#[cfg(test)]
mod smooth_tests;
mod spline;

pub use spline::{CubicSpline, SplineError};

use super::expr::TimeExpr;
use std::f64::consts::PI;

/// A time function `f(t)` that scales a load.
#[derive(Debug, Clone, PartialEq)]
pub enum Function {
    /// Piecewise-linear table of `(t, f)` with non-decreasing `t`; constant beyond its ends.
    Table(Vec<(f64, f64)>),
    /// A constant value.
    Constant(f64),
    /// The haversine pulse `f(t) = sin²(π (t − t₀)/T)` for `t₀ ≤ t ≤ t₀ + T`, 0 elsewhere:
    /// peak 1 at the middle, impulse `T/2` (the triangle 0 → 1 → 0 over `T` has the same),
    /// continuous with its first derivative (a jump of `2π²/T²` in `f''` at both ends),
    /// where a triangle has jumps in `f'`.
    Haversine {
        /// Start time t₀, s.
        start: f64,
        /// Duration T, s (> 0).
        duration: f64,
    },
    /// The C² cubic spline through points, natural or with clamped end slopes; a straight
    /// line beyond its ends ([`CubicSpline`]).
    Spline(CubicSpline),
    /// `f(t) = A sin(ω(t − t₀) + φ)` (`cosine`: `A cos(…)`) for `t ≥ t₀`, and 0 before
    /// the start `t₀` when one is given (then `f` jumps by `A sin φ` and `ḟ` by `A ω cos φ`
    /// there — for the cosine `A cos φ` and `−A ω sin φ`); without a start, `t₀ = 0` and
    /// the wave holds for every `t`. `ḟ = A ω cos(…)`, `f̈ = −A ω² sin(…)`.
    Harmonic {
        /// Cosine rather than sine.
        cosine: bool,
        /// Amplitude A.
        amplitude: f64,
        /// Circular frequency ω, rad/s (2π times the frequency in Hz).
        omega: f64,
        /// Phase φ, rad.
        phase: f64,
        /// Start time t₀, s, if any.
        start: Option<f64>,
    },
    /// A quintic smooth step from `f₀` at `t₀` to `f₁` at `t₁`, constant outside:
    /// `f = f₀ + (f₁ − f₀) p(s)`, `s = (t − t₀)/(t₁ − t₀)`, `p = 10s³ − 15s⁴ + 6s⁵`
    /// (the lowest-degree polynomial with `p(0) = 0`, `p(1) = 1` and `p′`, `p″` zero at
    /// both ends), so `f`, `ḟ`, `f̈` are continuous (C²; `f⃛` jumps by `60Δ/T³` at both
    /// ends). `ḟ = Δ·30s²(1 − s)²/T`, peak `1.875 Δ/T` at mid-ramp;
    /// `f̈ = Δ·60s(1 − s)(1 − 2s)/T²`, peak `(10/√3) Δ/T²` at `s = (3 ∓ √3)/6`.
    Ramp {
        /// Start time t₀, s.
        t0: f64,
        /// Value before and at t₀.
        f0: f64,
        /// End time t₁ > t₀, s.
        t1: f64,
        /// Value at and after t₁.
        f1: f64,
    },
    /// An expression of `t` with the deck's expression syntax and parameters, evaluated
    /// with second-order jets (exact `ḟ`, `f̈`).
    Expr(TimeExpr),
}

impl Function {
    /// Value at time `t`.
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            Function::Expr(e) => e.eval(t),
            Function::Spline(_) | Function::Harmonic { .. } | Function::Ramp { .. } => {
                self.derivatives(t).map_or(0.0, |d| d[0])
            }
            Function::Constant(c) => *c,
            Function::Haversine { start, duration } => {
                let s = (t - start) / duration;
                if (0.0..=1.0).contains(&s) {
                    (PI * s).sin().powi(2)
                } else {
                    0.0
                }
            }
            Function::Table(pts) => {
                let Some(first) = pts.first() else { return 0.0 };
                if t <= first.0 {
                    return first.1;
                }
                for w in pts.windows(2) {
                    let (t0, f0) = w[0];
                    let (t1, f1) = w[1];
                    if t <= t1 {
                        if t1 > t0 {
                            return f0 + (f1 - f0) * (t - t0) / (t1 - t0);
                        }
                        return f1;
                    }
                }
                pts[pts.len() - 1].1
            }
        }
    }

    /// Times where the function or one of its first three derivatives jumps (table
    /// points, a pulse's or a ramp's ends, a harmonic's start, a clamped spline's end
    /// knots), which a time integrator should step on rather than across. A spline's
    /// interior knots are not listed: `f`, `ḟ`, `f̈` are continuous there (only `f⃛`
    /// jumps), nor are a natural spline's ends (its `f̈` is 0 on both sides).
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Function::Constant(_) | Function::Expr(_) => Vec::new(),
            Function::Spline(s) => match s.slopes() {
                Some(_) => vec![s.points()[0].0, s.points()[s.points().len() - 1].0],
                None => Vec::new(),
            },
            Function::Harmonic { start, .. } => start.iter().copied().collect(),
            Function::Ramp { t0, t1, .. } => vec![*t0, *t1],
            Function::Haversine { start, duration } => vec![*start, start + duration],
            Function::Table(p) => p.iter().map(|x| x.0).collect(),
        }
    }
}

impl Function {
    /// Value and exact first and second time derivatives `[f, ḟ, f̈]` at `t`, for the
    /// kinds that have them ([`Function::has_derivatives`]); `None` for a piecewise-linear
    /// `TABLE`, whose velocity jumps and whose acceleration is impulsive at its points.
    ///
    /// Haversine `f = sin²(π s)`, `s = (t − t₀)/T`: `ḟ = (π/T) sin(2π s)`,
    /// `f̈ = (2π²/T²) cos(2π s)` inside the pulse, 0 outside (`f̈` jumps at both ends).
    pub fn derivatives(&self, t: f64) -> Option<[f64; 3]> {
        match self {
            Function::Constant(c) => Some([*c, 0.0, 0.0]),
            Function::Haversine { start, duration } => {
                let s = (t - start) / duration;
                if (0.0..=1.0).contains(&s) {
                    let w = 2.0 * PI * s;
                    Some([
                        (PI * s).sin().powi(2),
                        PI / duration * w.sin(),
                        2.0 * PI * PI / (duration * duration) * w.cos(),
                    ])
                } else {
                    Some([0.0, 0.0, 0.0])
                }
            }
            Function::Spline(s) => Some(s.derivatives(t)),
            Function::Harmonic {
                cosine,
                amplitude: a,
                omega: w,
                phase,
                start,
            } => {
                let t0 = start.unwrap_or(0.0);
                if start.is_some() && t < t0 {
                    return Some([0.0, 0.0, 0.0]);
                }
                let x = w * (t - t0) + phase;
                let (s, c) = (x.sin(), x.cos());
                Some(if *cosine {
                    [a * c, -a * w * s, -a * w * w * c]
                } else {
                    [a * s, a * w * c, -a * w * w * s]
                })
            }
            Function::Ramp { t0, f0, t1, f1 } => {
                let span = t1 - t0;
                let s = ((t - t0) / span).clamp(0.0, 1.0);
                let d = f1 - f0;
                let p = s * s * s * (10.0 + s * (-15.0 + 6.0 * s));
                let p1 = 30.0 * s * s * (1.0 - s) * (1.0 - s);
                let p2 = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s);
                Some([f0 + d * p, d * p1 / span, d * p2 / (span * span)])
            }
            Function::Expr(e) => Some(e.derivatives(t)),
            Function::Table(_) => None,
        }
    }

    /// The largest `|f|` over `[t0, t1]` (a reference magnitude for convergence tests):
    /// exact for the tables, constants, pulses, waves and ramps; for a spline and an
    /// expression, the largest over the knots in the window and 1025 evenly spaced
    /// instants (a spline overshoots its knots by a fraction of their spread).
    pub fn max_abs(&self, t0: f64, t1: f64) -> f64 {
        let sampled = |extra: &mut dyn Iterator<Item = f64>| {
            let n = 1024;
            (0..=n)
                .map(|k| t0 + (t1 - t0) * k as f64 / n as f64)
                .chain(extra)
                .filter(|t| *t >= t0 && *t <= t1)
                .map(|t| self.eval(t).abs())
                .filter(|v| v.is_finite())
                .fold(0.0f64, f64::max)
        };
        match self {
            Function::Constant(c) => c.abs(),
            Function::Haversine { .. } => 1.0,
            Function::Table(p) => p.iter().fold(0.0f64, |m, q| m.max(q.1.abs())),
            Function::Harmonic { amplitude, .. } => amplitude.abs(),
            Function::Ramp { f0, f1, .. } => f0.abs().max(f1.abs()),
            Function::Spline(s) => sampled(&mut s.points().iter().map(|p| p.0)),
            Function::Expr(_) => sampled(&mut std::iter::empty()),
        }
    }

    /// The first of 1001 evenly spaced instants of `[t0, t1]` (ends included) where an
    /// expression's value or derivatives are not finite (`log(t)` and `sqrt(t)` at 0,
    /// `1/(t − 1)` at 1), or `None`. The other kinds are finite by construction.
    pub fn first_non_finite(&self, t0: f64, t1: f64) -> Option<f64> {
        let Function::Expr(e) = self else {
            return None;
        };
        let n = 1000;
        (0..=n)
            .map(|k| t0 + (t1 - t0) * k as f64 / n as f64)
            .find(|t| !e.expr.jet(*t).is_finite())
    }

    /// Whether [`Function::derivatives`] gives exact derivatives (a driver may use it).
    pub fn has_derivatives(&self) -> bool {
        !matches!(self, Function::Table(_))
    }
}

#[cfg(test)]
mod tests {
    use super::Function;

    /// The haversine pulse: values at the quarter points, zero outside, impulse T/2
    /// (Simpson's rule on 2000 intervals: exact to ~1e-13 for this smooth integrand), and
    /// a slope that vanishes at both ends (continuous with the zero outside).
    #[test]
    fn haversine_pulse_values_impulse_and_slope() {
        let f = Function::Haversine {
            start: 0.1,
            duration: 0.02,
        };
        for (t, v) in [
            (0.1, 0.0),
            (0.105, 0.5),
            (0.11, 1.0),
            (0.115, 0.5),
            (0.12, 0.0),
        ] {
            assert!((f.eval(t) - v).abs() < 1e-12, "f({t}) = {}", f.eval(t));
        }
        assert_eq!(f.eval(0.0999), 0.0);
        assert_eq!(f.eval(0.1201), 0.0);
        let n = 2000;
        let dt = 0.02 / n as f64;
        let simpson: f64 = (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * f.eval(0.1 + i as f64 * dt)
            })
            .sum::<f64>()
            * dt
            / 3.0;
        assert!((simpson - 0.01).abs() < 1e-12, "impulse {simpson}");
        let d = 1e-7;
        for t in [0.1, 0.12] {
            let slope = (f.eval(t + d) - f.eval(t - d)) / (2.0 * d);
            // f ≈ (π s)² near the ends: slope over ±d at most π² d / T² ≈ 2.5e-3.
            assert!(slope.abs() < 3e-3, "slope {slope} at {t}");
        }
        let b = f.breakpoints();
        assert!(b.len() == 2 && b[0] == 0.1 && (b[1] - 0.12).abs() < 1e-15);
    }

    /// The haversine's derivatives against central differences of its values (step 1e-6
    /// of T: truncation ~1e-12 relative, round-off ~1e-10 / 1e-4 for f', f'').
    #[test]
    fn haversine_derivatives_match_differences() {
        let f = Function::Haversine {
            start: 0.1,
            duration: 0.02,
        };
        let d = 2e-8;
        for t in [0.101, 0.1037, 0.11, 0.1172, 0.119] {
            let [v, v1, v2] = f.derivatives(t).unwrap();
            assert!((v - f.eval(t)).abs() < 1e-15);
            let fd1 = (f.eval(t + d) - f.eval(t - d)) / (2.0 * d);
            let g = |t| f.derivatives(t).unwrap()[1];
            let fd2 = (g(t + d) - g(t - d)) / (2.0 * d);
            assert!(
                (v1 - fd1).abs() < 1e-6 * (1.0 + v1.abs()),
                "f' {v1} vs {fd1}"
            );
            assert!(
                (v2 - fd2).abs() < 1e-5 * (1.0 + v2.abs()),
                "f'' {v2} vs {fd2}"
            );
        }
        assert_eq!(f.derivatives(0.05), Some([0.0, 0.0, 0.0]));
        assert!(
            Function::Table(vec![(0.0, 0.0), (1.0, 1.0)])
                .derivatives(0.5)
                .is_none()
        );
    }
}
