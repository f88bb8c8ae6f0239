//! Time functions `f(t)`: what scales a load and what a driver prescribes.
//!
//! Every kind gives its value and, where it has them, its exact first and second time
//! derivatives ([`Function::derivatives`]): a driver (a prescribed motion) needs
//! `f, ḟ, f̈` for positions, velocities and accelerations consistent with the time
//! integrator; a load needs only `f`.

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
}

impl Function {
    /// Value at time `t`.
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            Function::Constant(c) => *c,
            Function::Haversine { start, duration } => {
                let s = (t - start) / duration;
                if (0.0..=1.0).contains(&s) {
                    (std::f64::consts::PI * s).sin().powi(2)
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

    /// Times where the function has kinks (table breakpoints), which a time integrator
    /// should step on rather than across.
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Function::Constant(_) => Vec::new(),
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
                    let pi = std::f64::consts::PI;
                    let w = 2.0 * pi * s;
                    Some([
                        (pi * s).sin().powi(2),
                        pi / duration * w.sin(),
                        2.0 * pi * pi / (duration * duration) * w.cos(),
                    ])
                } else {
                    Some([0.0, 0.0, 0.0])
                }
            }
            Function::Table(_) => None,
        }
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
