//! Second-order jets in one variable: `(f, f′, f″)` carried through arithmetic, for the
//! exact first and second time derivatives of a deck's expression of `t`
//! (`model::TimeExpr`).
//!
//! A jet is the truncated Taylor series `f + f′ ε + f″ ε²/2` with `ε³ = 0`. The rules are
//! the chain rule to second order (Faà di Bruno): for `g = φ(f)`,
//! `g′ = φ′(f) f′`, `g″ = φ″(f) f′² + φ′(f) f″`; for a product `(ab)″ = a″b + 2a′b′ + ab″`.
//! Every value component is computed with exactly the `f64` operations of a plain
//! evaluation, so a jet's value equals the `f64` result bit for bit.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `(f, f′, f″)` at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet2 {
    /// Value f.
    pub v: f64,
    /// First derivative f′.
    pub d1: f64,
    /// Second derivative f″.
    pub d2: f64,
}

impl Jet2 {
    /// A constant: zero derivatives.
    pub fn constant(v: f64) -> Self {
        Jet2 {
            v,
            d1: 0.0,
            d2: 0.0,
        }
    }

    /// The independent variable at `v`: `(v, 1, 0)`.
    pub fn variable(v: f64) -> Self {
        Jet2 {
            v,
            d1: 1.0,
            d2: 0.0,
        }
    }

    /// Whether both derivatives are zero (a constant).
    pub fn is_constant(&self) -> bool {
        self.d1 == 0.0 && self.d2 == 0.0
    }

    /// Whether the value and both derivatives are finite.
    pub fn is_finite(&self) -> bool {
        self.v.is_finite() && self.d1.is_finite() && self.d2.is_finite()
    }

    /// `φ(f)` given `φ(f)`, `φ′(f)`, `φ″(f)`: `(φ, φ′ f′, φ″ f′² + φ′ f″)`. A term whose
    /// derivative factor is exactly zero is left out, so that an infinite `φ′` or `φ″`
    /// (√ at 0) times a zero derivative (a constant argument) stays finite.
    fn chain(self, phi: f64, d_phi: f64, dd_phi: f64) -> Self {
        let first = if self.d1 == 0.0 { 0.0 } else { d_phi * self.d1 };
        let curvature = if self.d1 == 0.0 {
            0.0
        } else {
            dd_phi * self.d1 * self.d1
        };
        let stretch = if self.d2 == 0.0 { 0.0 } else { d_phi * self.d2 };
        Jet2 {
            v: phi,
            d1: first,
            d2: curvature + stretch,
        }
    }

    /// Square root: `φ′ = 1/(2√x)`, `φ″ = −1/(4 x√x)`.
    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (self.v * s))
    }

    /// Sine: `φ′ = cos x`, `φ″ = −sin x`.
    pub fn sin(self) -> Self {
        let (s, c) = (self.v.sin(), self.v.cos());
        self.chain(s, c, -s)
    }

    /// Cosine: `φ′ = −sin x`, `φ″ = −cos x`.
    pub fn cos(self) -> Self {
        let (s, c) = (self.v.sin(), self.v.cos());
        self.chain(c, -s, -c)
    }

    /// Exponential: `φ′ = φ″ = eˣ`.
    pub fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e, e)
    }

    /// Natural logarithm: `φ′ = 1/x`, `φ″ = −1/x²`.
    pub fn ln(self) -> Self {
        self.chain(self.v.ln(), 1.0 / self.v, -1.0 / (self.v * self.v))
    }

    /// Absolute value: `φ′ = sign x` (taken as 0 at x = 0, where |x| has no derivative),
    /// `φ″ = 0` (the impulse at x = 0 is not represented).
    pub fn abs(self) -> Self {
        let sign = if self.v > 0.0 {
            1.0
        } else if self.v < 0.0 {
            -1.0
        } else {
            0.0
        };
        self.chain(self.v.abs(), sign, 0.0)
    }

    /// `self^e`. A constant exponent `c` takes the power rule
    /// `φ′ = c x^(c−1)`, `φ″ = c(c−1) x^(c−2)` (exact at x = 0 for `c` = 1, 2, …: a zero
    /// factor leaves its term out); a varying one `x^y = exp(y ln x)` (x > 0). The value is
    /// `powf` in both cases.
    pub fn powf(self, e: Self) -> Self {
        let value = self.v.powf(e.v);
        if e.is_constant() {
            let c = e.v;
            if c == 0.0 {
                return Jet2::constant(value);
            }
            let d_phi = c * self.v.powf(c - 1.0);
            let dd_phi = if c == 1.0 {
                0.0
            } else {
                c * (c - 1.0) * self.v.powf(c - 2.0)
            };
            return self.chain(value, d_phi, dd_phi);
        }
        let mut j = (e * self.ln()).exp();
        j.v = value;
        j
    }
}

impl Add for Jet2 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Jet2 {
            v: self.v + o.v,
            d1: self.d1 + o.d1,
            d2: self.d2 + o.d2,
        }
    }
}

impl Sub for Jet2 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Jet2 {
            v: self.v - o.v,
            d1: self.d1 - o.d1,
            d2: self.d2 - o.d2,
        }
    }
}

impl Neg for Jet2 {
    type Output = Self;
    fn neg(self) -> Self {
        Jet2 {
            v: -self.v,
            d1: -self.d1,
            d2: -self.d2,
        }
    }
}

impl Mul for Jet2 {
    type Output = Self;
    /// `(ab)′ = a′b + ab′`, `(ab)″ = a″b + 2a′b′ + ab″`.
    fn mul(self, o: Self) -> Self {
        Jet2 {
            v: self.v * o.v,
            d1: self.d1 * o.v + self.v * o.d1,
            d2: self.d2 * o.v + 2.0 * self.d1 * o.d1 + self.v * o.d2,
        }
    }
}

impl Div for Jet2 {
    type Output = Self;
    /// `q = a/b`: `q′ = (a′ − q b′)/b`, `q″ = (a″ − 2q′b′ − q b″)/b` (from `a = qb`
    /// differentiated twice).
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        let q1 = (self.d1 - q * o.d1) / o.v;
        let q2 = (self.d2 - 2.0 * q1 * o.d1 - q * o.d2) / o.v;
        Jet2 {
            v: q,
            d1: q1,
            d2: q2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Jet2;

    /// Each rule against the closed-form derivatives of one composite function of x,
    /// at points away from singularities. Closed forms are evaluated in f64 with a few
    /// operations each: agreement to 1e-13 relative (some 50 ulp).
    #[test]
    fn rules_match_closed_forms() {
        for x in [0.3, 1.1, 2.7] {
            let t = Jet2::variable(x);
            let close = |j: Jet2, f: [f64; 3], what: &str| {
                for (k, (a, b)) in [j.v, j.d1, j.d2].iter().zip(f).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-13 * (1.0 + b.abs()),
                        "{what} d{k} at {x}: {a} vs {b}"
                    );
                }
            };
            // t² sin t
            let (s, c) = (x.sin(), x.cos());
            close(
                t * t * t.sin(),
                [
                    x * x * s,
                    2.0 * x * s + x * x * c,
                    2.0 * s + 4.0 * x * c - x * x * s,
                ],
                "t^2 sin t",
            );
            // exp(−t) / (1 + t)
            let e = (-x).exp();
            let u = 1.0 + x;
            close(
                (-t).exp() / (Jet2::constant(1.0) + t),
                [
                    e / u,
                    -e / u - e / (u * u),
                    e / u + 2.0 * e / (u * u) + 2.0 * e / (u * u * u),
                ],
                "exp(-t)/(1+t)",
            );
            // sqrt(t) cos(t)
            let r = x.sqrt();
            close(
                t.sqrt() * t.cos(),
                [
                    r * c,
                    0.5 / r * c - r * s,
                    -0.25 / (x * r) * c - s / r - r * c,
                ],
                "sqrt(t) cos t",
            );
            // ln t, t^2.5, t^t, |−t|
            close(t.ln(), [x.ln(), 1.0 / x, -1.0 / (x * x)], "ln t");
            close(
                t.powf(Jet2::constant(2.5)),
                [x.powf(2.5), 2.5 * x.powf(1.5), 3.75 * x.sqrt()],
                "t^2.5",
            );
            let tt = x.powf(x);
            let l = x.ln() + 1.0;
            close(t.powf(t), [tt, tt * l, tt * (l * l + 1.0 / x)], "t^t");
            close((-t).abs(), [x, 1.0, 0.0], "|-t|");
        }
    }

    /// Powers at zero: `t²` and `t¹` have finite derivatives there; a constant base stays
    /// a constant even where `x^(c−1)` is infinite.
    #[test]
    fn powers_at_zero_stay_finite() {
        let t = Jet2::variable(0.0);
        assert_eq!(
            t.powf(Jet2::constant(2.0)),
            Jet2 {
                v: 0.0,
                d1: 0.0,
                d2: 2.0
            }
        );
        assert_eq!(
            t.powf(Jet2::constant(1.0)),
            Jet2 {
                v: 0.0,
                d1: 1.0,
                d2: 0.0
            }
        );
        assert_eq!(
            Jet2::constant(0.0).powf(Jet2::constant(0.5)),
            Jet2::constant(0.0)
        );
        assert!(!t.sqrt().is_finite(), "√t has an infinite slope at 0");
    }
}
