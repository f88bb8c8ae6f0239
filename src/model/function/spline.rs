//! The C² cubic spline through points (`FUNCTIONS … SPLINE`).
//!
//! On each interval `[tᵢ, tᵢ₊₁]` of length `hᵢ`, with `a = (tᵢ₊₁ − t)/hᵢ`, `b = 1 − a` and
//! the knots' second derivatives (moments) `Mᵢ`:
//! `S = a fᵢ + b fᵢ₊₁ + ((a³ − a) Mᵢ + (b³ − b) Mᵢ₊₁) hᵢ²/6`,
//! `S′ = (fᵢ₊₁ − fᵢ)/hᵢ − (3a² − 1) hᵢ Mᵢ/6 + (3b² − 1) hᵢ Mᵢ₊₁/6`, `S″ = a Mᵢ + b Mᵢ₊₁`
//! (Press et al., *Numerical Recipes*, 3rd ed., §3.3, eqs. 3.3.3–3.3.5). Continuity of
//! `S′` at the interior knots gives the tridiagonal system (eq. 3.3.7)
//! `hᵢ₋₁ Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ) Mᵢ + hᵢ Mᵢ₊₁ = 6((fᵢ₊₁ − fᵢ)/hᵢ − (fᵢ − fᵢ₋₁)/hᵢ₋₁)`,
//! closed by the end conditions:
//! * natural (no slopes given): `M₀ = Mₙ = 0`;
//! * clamped (end slopes `s₀`, `sₙ` given): `2h₀M₀ + h₀M₁ = 6((f₁ − f₀)/h₀ − s₀)` and
//!   `hₙ₋₁Mₙ₋₁ + 2hₙ₋₁Mₙ = 6(sₙ − (fₙ − fₙ₋₁)/hₙ₋₁)`.
//!
//! The system is strictly diagonally dominant, so the Thomas algorithm (no pivoting) is
//! stable. Beyond its ends the spline continues along the straight line of its end value
//! and end slope (`S″ = 0`): C² everywhere for natural ends, a jump of `S″` at the first
//! and last knots for clamped ones (there `S″` is `M₀`, `Mₙ`); `SLOPES 0 0` holds the end
//! values (a move from one position to another that stays there).

/// Why points do not make a spline.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SplineError {
    /// Fewer than two points.
    #[error("a spline needs at least two points, found {count}")]
    TooFewPoints {
        /// Points given.
        count: usize,
    },
    /// `t` of point `index` (from 0) is not greater than the previous one.
    #[error("spline times must increase: point {index} does not come after point {}", index - 1)]
    NotIncreasing {
        /// The offending point, from 0.
        index: usize,
    },
    /// A value that is not finite.
    #[error("a spline's times, values and slopes must be finite")]
    NotFinite,
}

/// A C² cubic spline through `(tᵢ, fᵢ)`, natural or with clamped end slopes.
#[derive(Debug, Clone, PartialEq)]
pub struct CubicSpline {
    points: Vec<(f64, f64)>,
    slopes: Option<(f64, f64)>,
    /// Second derivatives at the knots.
    moments: Vec<f64>,
}

impl CubicSpline {
    /// The spline through `points` (times strictly increasing, at least two), natural
    /// when `slopes` is `None`, else with the end slopes `(s₀, sₙ)`.
    pub fn new(points: Vec<(f64, f64)>, slopes: Option<(f64, f64)>) -> Result<Self, SplineError> {
        let n = points.len();
        if n < 2 {
            return Err(SplineError::TooFewPoints { count: n });
        }
        let finite = |x: f64| x.is_finite();
        if !points.iter().all(|p| finite(p.0) && finite(p.1))
            || !slopes.is_none_or(|s| finite(s.0) && finite(s.1))
        {
            return Err(SplineError::NotFinite);
        }
        if let Some(i) = (1..n).find(|&i| points[i].0 <= points[i - 1].0) {
            return Err(SplineError::NotIncreasing { index: i });
        }
        let h: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
        let slope: Vec<f64> = points
            .windows(2)
            .zip(&h)
            .map(|(w, h)| (w[1].1 - w[0].1) / h)
            .collect();
        // Tridiagonal rows: sub[i] M[i-1] + diag[i] M[i] + sup[i] M[i+1] = rhs[i].
        let (mut sub, mut diag, mut sup, mut rhs) =
            (vec![0.0; n], vec![1.0; n], vec![0.0; n], vec![0.0; n]);
        for i in 1..n - 1 {
            sub[i] = h[i - 1];
            diag[i] = 2.0 * (h[i - 1] + h[i]);
            sup[i] = h[i];
            rhs[i] = 6.0 * (slope[i] - slope[i - 1]);
        }
        if let Some((s0, sn)) = slopes {
            diag[0] = 2.0 * h[0];
            sup[0] = h[0];
            rhs[0] = 6.0 * (slope[0] - s0);
            sub[n - 1] = h[n - 2];
            diag[n - 1] = 2.0 * h[n - 2];
            rhs[n - 1] = 6.0 * (sn - slope[n - 2]);
        }
        // Thomas algorithm: forward elimination, back substitution.
        for i in 1..n {
            let w = sub[i] / diag[i - 1];
            diag[i] -= w * sup[i - 1];
            rhs[i] -= w * rhs[i - 1];
        }
        let mut moments = vec![0.0; n];
        moments[n - 1] = rhs[n - 1] / diag[n - 1];
        for i in (0..n - 1).rev() {
            moments[i] = (rhs[i] - sup[i] * moments[i + 1]) / diag[i];
        }
        Ok(CubicSpline {
            points,
            slopes,
            moments,
        })
    }

    /// The points `(tᵢ, fᵢ)`.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The clamped end slopes, `None` for natural ends.
    pub fn slopes(&self) -> Option<(f64, f64)> {
        self.slopes
    }

    /// The second derivatives at the knots.
    pub fn moments(&self) -> &[f64] {
        &self.moments
    }

    /// `[S, S′, S″]` inside interval `i` (module doc).
    fn on_interval(&self, i: usize, t: f64) -> [f64; 3] {
        let ((t0, f0), (t1, f1)) = (self.points[i], self.points[i + 1]);
        let (m0, m1) = (self.moments[i], self.moments[i + 1]);
        let h = t1 - t0;
        let a = (t1 - t) / h;
        let b = (t - t0) / h;
        [
            a * f0 + b * f1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0,
            (f1 - f0) / h - (3.0 * a * a - 1.0) * h * m0 / 6.0 + (3.0 * b * b - 1.0) * h * m1 / 6.0,
            a * m0 + b * m1,
        ]
    }

    /// `[S, S′, S″]` at `t`; beyond the ends, the straight line of the end value and slope.
    pub fn derivatives(&self, t: f64) -> [f64; 3] {
        let n = self.points.len();
        let (first, last) = (self.points[0].0, self.points[n - 1].0);
        if t < first {
            let [f, d, _] = self.on_interval(0, first);
            return [f + d * (t - first), d, 0.0];
        }
        if t > last {
            let [f, d, _] = self.on_interval(n - 2, last);
            return [f + d * (t - last), d, 0.0];
        }
        // The interval [tᵢ, tᵢ₊₁] holding t: i = (number of knots ≤ t) − 1, at most n − 2.
        let i = (self.points.partition_point(|p| p.0 <= t) - 1).min(n - 2);
        self.on_interval(i, t)
    }
}
