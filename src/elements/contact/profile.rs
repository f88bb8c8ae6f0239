//! Planar profile curves of the CAME element and their closest-point projection.
//!
//! A curve lives in the plane of its profile frame (local axes 1–2); the contact surface is
//! the curve extruded along axis 3. Each curve has a *free side*, given by its unit normal
//! `ν(η)` (the follower must stay on that side; the gap is positive there):
//! - `LINE`: the local axis 1 through the origin, `η` = abscissa, `ν = e₂` (the left of the
//!   direction of travel, so a floor drawn along +X has its free side towards +Y);
//! - `CIRCLE r`: centred at the origin, `η = r θ` (θ from axis 1), `ν` outward;
//! - `SPLINE`: a cubic spline through the points with chord-length parameter `η`
//!   (≈ arc length): *natural* (zero curvature at the ends, continued by its end tangents
//!   beyond them) when open, periodic when closed. Open: `ν` is the left normal, as for
//!   `LINE` (the open spline bounds a half-plane). Closed: `ν` is outward, whichever way
//!   the points turn.
//!
//! The projection of a point `ℓ` on the curve is exact in closed form for the line and the
//! circle; for splines a coarse search over samples of every segment picks the global
//! candidate and Newton's method on `γ'(η)·(ℓ − γ(η)) = 0` refines it. The refined value
//! is then passed through one more Newton step written in the generic scalar `S`, so with
//! dual numbers `η` carries its exact first derivative with respect to `ℓ` (implicit
//! function theorem) and the curve's curvature enters the contact tangent automatically.

use crate::model::Profile;
use nalgebra::{RealField, Vector2};

/// A contact curve ("surface" role): a line, a circle or a spline.
#[derive(Debug, Clone)]
pub enum Curve {
    /// The local axis 1.
    Line,
    /// A circle of this radius about the origin.
    Circle(f64),
    /// A cubic spline.
    Spline(Spline),
}

/// The result of a projection, in the generic scalar.
#[derive(Debug, Clone, Copy)]
pub struct Projection<S> {
    /// Closest point on the curve (profile plane coordinates).
    pub point: Vector2<S>,
    /// Unit normal towards the free side.
    pub normal: Vector2<S>,
    /// Curvilinear coordinate of the point.
    pub eta: S,
}

impl Curve {
    /// The curve of a profile that can play the "surface" role (`None` for a point).
    pub fn from_profile(p: &Profile) -> Result<Option<Curve>, String> {
        Ok(match p {
            Profile::Point => None,
            Profile::Line => Some(Curve::Line),
            Profile::Circle { radius } => Some(Curve::Circle(*radius)),
            Profile::Spline { points, closed } => {
                Some(Curve::Spline(Spline::new(points, *closed)?))
            }
        })
    }

    /// A lower bound of the signed distance from `l` to the curve when it is cheap and
    /// certain (`None` when only a projection can tell): the far-apart test.
    pub fn quick_distance(&self, l: &Vector2<f64>) -> Option<f64> {
        match self {
            Curve::Line => Some(l.y),
            Curve::Circle(r) => Some(l.norm() - r),
            Curve::Spline(s) if s.closed => {
                let d = (l - s.center).norm() - s.radius;
                (d > 0.0).then_some(d)
            }
            Curve::Spline(_) => None,
        }
    }

    /// The parameter of the closest point (f64), for the generic refinement.
    pub fn closest_parameter(&self, l: &Vector2<f64>) -> f64 {
        match self {
            Curve::Line => l.x,
            Curve::Circle(r) => r * l.y.atan2(l.x),
            Curve::Spline(s) => s.closest(l),
        }
    }

    /// Projection of `l` with the parameter `eta0` from [`Curve::closest_parameter`].
    pub fn project<S: RealField + Copy>(&self, l: &Vector2<S>, eta0: f64) -> Projection<S> {
        match self {
            Curve::Line => Projection {
                point: Vector2::new(l.x, S::zero()),
                normal: Vector2::new(S::zero(), S::one()),
                eta: l.x,
            },
            Curve::Circle(r) => {
                let nrm = l.dot(l).sqrt();
                let nu = if nrm > c(0.0) {
                    *l / nrm
                } else {
                    Vector2::new(S::one(), S::zero())
                };
                Projection {
                    point: nu * c::<S>(*r),
                    normal: nu,
                    eta: c::<S>(eta0),
                }
            }
            Curve::Spline(s) => s.project(l, eta0),
        }
    }
}

/// A cubic spline through points, chord-length parametrised.
#[derive(Debug, Clone)]
pub struct Spline {
    /// Knots `s_0 = 0 < s_1 < … < s_m` (m segments).
    knots: Vec<f64>,
    /// Per segment: `[a, b, c, d]` with `γ(s_i + t) = a + b t + c t² + d t³`.
    coef: Vec<[Vector2<f64>; 4]>,
    closed: bool,
    /// Free side: +1 = left normal, −1 = right normal.
    side: f64,
    /// Bounding circle of the points (and of the curve, with a margin).
    center: Vector2<f64>,
    radius: f64,
}

impl Spline {
    /// Builds the spline (natural when open, periodic when closed).
    pub fn new(points: &[[f64; 2]], closed: bool) -> Result<Self, String> {
        let mut p: Vec<Vector2<f64>> = points.iter().map(|q| Vector2::new(q[0], q[1])).collect();
        if closed && p.len() > 1 && (p[0] - p[p.len() - 1]).norm() == 0.0 {
            p.pop();
        }
        let n = p.len();
        if n < 2 || (closed && n < 3) {
            return Err("a SPLINE needs at least 2 distinct points (3 when CLOSED)".into());
        }
        let m = if closed { n } else { n - 1 };
        let pt = |i: usize| p[i % n];
        let h: Vec<f64> = (0..m).map(|i| (pt(i + 1) - pt(i)).norm()).collect();
        if h.iter().any(|h| *h <= 0.0) {
            return Err("two consecutive SPLINE points coincide".into());
        }
        // Second derivatives M_i at the points: a dense solve (profiles have few points).
        let nm = n;
        let mut a = vec![vec![0.0; nm]; nm];
        let mut rhs = vec![Vector2::zeros(); nm];
        for (i, row) in a.iter_mut().enumerate() {
            let interior = closed || (i > 0 && i < n - 1);
            if !interior {
                row[i] = 1.0;
                continue;
            }
            let (im, hp) = ((i + n - 1) % n, h[i % m]);
            let hm = h[(i + m - 1) % m];
            row[im] += hm;
            row[i] += 2.0 * (hm + hp);
            row[(i + 1) % n] += hp;
            rhs[i] = ((pt(i + 1) - pt(i)) / hp - (pt(i) - pt(im)) / hm) * 6.0;
        }
        let mm = solve_dense(a, rhs);
        let mut knots = vec![0.0];
        let mut coef = Vec::with_capacity(m);
        for i in 0..m {
            let (p0, p1, m0, m1, hi) = (pt(i), pt(i + 1), mm[i % n], mm[(i + 1) % n], h[i]);
            knots.push(knots[i] + hi);
            coef.push([
                p0,
                (p1 - p0) / hi - (m0 * 2.0 + m1) * (hi / 6.0),
                m0 * 0.5,
                (m1 - m0) / (6.0 * hi),
            ]);
        }
        let center = p.iter().fold(Vector2::zeros(), |s, q| s + q) / n as f64;
        let radius = p.iter().map(|q| (q - center).norm()).fold(0.0, f64::max);
        // Bulge of a cubic segment beyond its chord: bounded by max |M| h² / 8.
        let bulge = (0..m)
            .map(|i| mm[i % n].norm().max(mm[(i + 1) % n].norm()) * h[i] * h[i] / 8.0)
            .fold(0.0, f64::max);
        let mut s = Spline {
            knots,
            coef,
            closed,
            side: 1.0,
            center,
            radius: radius + bulge + 1e-9 * (1.0 + radius),
        };
        if closed {
            // Signed area (shoelace over a fine sampling): counter-clockwise ⇒ outward is right.
            let len = s.length();
            let k = 64 * m;
            let mut area = 0.0;
            for j in 0..k {
                let (q0, q1) = (
                    s.eval(len * j as f64 / k as f64).0,
                    s.eval(len * (j + 1) as f64 / k as f64).0,
                );
                area += q0.x * q1.y - q1.x * q0.y;
            }
            s.side = if area > 0.0 { -1.0 } else { 1.0 };
        }
        Ok(s)
    }

    fn length(&self) -> f64 {
        self.knots[self.knots.len() - 1]
    }

    /// Segment and local parameter of `eta` (wrapped when closed; beyond the ends of an
    /// open spline, the end segment with `t` out of range, handled by [`Spline::eval_g`]).
    fn locate(&self, eta: f64) -> (usize, f64) {
        let len = self.length();
        let e = if self.closed {
            eta.rem_euclid(len)
        } else {
            eta
        };
        let m = self.coef.len();
        let i = match self.knots[1..m].binary_search_by(|k| k.total_cmp(&e)) {
            Ok(i) => i + 1,
            Err(i) => i,
        }
        .min(m - 1);
        (
            i,
            eta - self.knots[i] - (if self.closed { eta - e } else { 0.0 }),
        )
    }

    /// `γ, γ', γ''` at `eta`, generic in the scalar (the segment is chosen by the value).
    fn eval_g<S: RealField + Copy>(
        &self,
        eta: S,
        eta_val: f64,
    ) -> (Vector2<S>, Vector2<S>, Vector2<S>) {
        let (i, t0) = self.locate(eta_val);
        let [a, b, cc, d] = self.coef[i].map(|v| v.map(c::<S>));
        let t = eta - c::<S>(eta_val - t0);
        let len = self.length();
        if !self.closed && (eta_val < 0.0 || eta_val > len) {
            // Linear continuation (natural spline: zero curvature at the ends).
            let h = c::<S>(if eta_val < 0.0 {
                0.0
            } else {
                self.knots[i + 1] - self.knots[i]
            });
            let g = a + b * h + cc * (h * h) + d * (h * h * h);
            let g1 = b + cc * (h * c::<S>(2.0)) + d * (h * h * c::<S>(3.0));
            return (g + g1 * (t - h), g1, Vector2::zeros());
        }
        let g = a + (b + (cc + d * t) * t) * t;
        let g1 = b + (cc * c::<S>(2.0) + d * (t * c::<S>(3.0))) * t;
        let g2 = cc * c::<S>(2.0) + d * (t * c::<S>(6.0));
        (g, g1, g2)
    }

    fn eval(&self, eta: f64) -> (Vector2<f64>, Vector2<f64>, Vector2<f64>) {
        self.eval_g(eta, eta)
    }

    /// Parameter of the closest point to `l` (global search, then Newton).
    pub fn closest(&self, l: &Vector2<f64>) -> f64 {
        const SAMPLES: usize = 16;
        let (mut best, mut bd) = (0.0, f64::INFINITY);
        let m = self.coef.len();
        for i in 0..m {
            let (s0, s1) = (self.knots[i], self.knots[i + 1]);
            for j in 0..=SAMPLES {
                let s = s0 + (s1 - s0) * j as f64 / SAMPLES as f64;
                let d = (self.eval(s).0 - l).norm_squared();
                if d < bd {
                    bd = d;
                    best = s;
                }
            }
        }
        if !self.closed {
            // The straight continuations beyond the ends.
            let len = self.length();
            for (s_end, dir) in [(0.0, -1.0), (len, 1.0)] {
                let (g, g1, _) = self.eval(s_end);
                let u = (l - g).dot(&g1) / g1.norm_squared();
                if u * dir > 0.0 {
                    let d = (g + g1 * u - l).norm_squared();
                    if d < bd {
                        bd = d;
                        best = s_end + u;
                    }
                }
            }
        }
        let hmin = self
            .knots
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let mut eta = best;
        for _ in 0..30 {
            let (g, g1, g2) = self.eval(eta);
            let r = l - g;
            let f = g1.dot(&r);
            let df = g2.dot(&r) - g1.norm_squared();
            if df >= 0.0 {
                break; // not a minimum locally: keep the sample
            }
            let step = (-f / df).clamp(-0.5 * hmin, 0.5 * hmin);
            eta += step;
            if step.abs() <= 1e-15 * (1.0 + self.length()) {
                break;
            }
        }
        eta
    }

    /// Generic projection from the converged `eta0`: one Newton step in `S` carries the
    /// exact first derivative of the closest point.
    pub fn project<S: RealField + Copy>(&self, l: &Vector2<S>, eta0: f64) -> Projection<S> {
        let (g, g1, g2) = self.eval(eta0);
        let lv: Vector2<f64> = l.map(|v| v.to_subset().unwrap_or(f64::NAN));
        let gs: Vector2<S> = g.map(c);
        let g1s: Vector2<S> = g1.map(c);
        let f = g1s.dot(&(*l - gs));
        let df = g2.dot(&(lv - g)) - g1.norm_squared();
        let eta = c::<S>(eta0) - f / c::<S>(df);
        let (p, t, _) = self.eval_g(eta, eta0);
        let t = t / t.dot(&t).sqrt();
        let side = c::<S>(self.side);
        Projection {
            point: p,
            normal: Vector2::new(-t.y, t.x) * side,
            eta,
        }
    }
}

/// Converts an `f64` constant into the generic scalar.
#[inline(always)]
pub(crate) fn c<S: RealField + Copy>(x: f64) -> S {
    nalgebra::convert(x)
}

/// Solves the dense system `A x = b` (partial pivoting) for vector right-hand sides.
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<Vector2<f64>>) -> Vec<Vector2<f64>> {
    let n = b.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|i, j| a[*i][k].abs().total_cmp(&a[*j][k].abs()))
            .unwrap_or(k);
        a.swap(k, p);
        b.swap(k, p);
        let piv = a[k][k];
        for i in k + 1..n {
            let f = a[i][k] / piv;
            if f != 0.0 {
                let (top, bottom) = a.split_at_mut(i);
                for (x, y) in bottom[0][k..].iter_mut().zip(&top[k][k..]) {
                    *x -= f * y;
                }
                let bk = b[k];
                b[i] -= bk * f;
            }
        }
    }
    let mut x = vec![Vector2::zeros(); n];
    for k in (0..n).rev() {
        let mut s = b[k];
        for j in k + 1..n {
            s -= x[j] * a[k][j];
        }
        x[k] = s / a[k][k];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_spline_through_circle_points_is_close_to_the_circle() {
        let pts: Vec<[f64; 2]> = (0..24)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 24.0;
                [0.5 * a.cos(), 0.5 * a.sin()]
            })
            .collect();
        let s = Spline::new(&pts, true).unwrap();
        for l in [
            Vector2::new(1.0, 0.3),
            Vector2::new(-0.2, 0.9),
            Vector2::new(0.1, -0.45),
        ] {
            let e = s.closest(&l);
            let pr: Projection<f64> = s.project(&l, e);
            let gap = pr.normal.dot(&(l - pr.point));
            assert!((gap - (l.norm() - 0.5)).abs() < 1e-4, "gap {gap}");
            assert!((pr.normal - l / l.norm()).norm() < 1e-3);
        }
    }

    #[test]
    fn open_spline_on_a_straight_line_is_the_line() {
        let s = Spline::new(&[[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]], false).unwrap();
        for l in [
            Vector2::new(0.5, 0.2),
            Vector2::new(-2.0, -0.1),
            Vector2::new(5.0, 0.3),
        ] {
            let pr: Projection<f64> = s.project(&l, s.closest(&l));
            assert!((pr.normal.dot(&(l - pr.point)) - l.y).abs() < 1e-12);
            assert!((pr.eta - l.x).abs() < 1e-12);
        }
    }
}
