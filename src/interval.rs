//! Interval arithmetic: closed intervals `[lo, hi]` of `f64` that enclose every value an
//! operation takes over its operands' intervals, rounding outward.
//!
//! **Rounding.** `+ − × ÷ √` are correctly rounded in IEEE 754 (error ≤ ½ ulp), so each
//! bound is moved one ulp outward (`f64::next_down` / `next_up`) after the operation.
//! `exp`, `ln`, `sin`, `cos` and `powf` come from the platform's libm, which is not
//! correctly rounded: glibc documents at most 1–2 ulp for them on x86-64 (the GNU C Library
//! manual, "Known Maximum Errors in Math Functions"); their bounds are moved [`LIBM_ULPS`]
//! ulps outward. Results are then clamped to the function's range where it has one
//! (`[−1, 1]` for sine and cosine, `≥ 0` for `√`, `exp`, `|x|`).
//!
//! **Undefined and unbounded results.** Where an operation may be undefined or infinite
//! on part of its operands (a division by an interval holding 0, `√` or `ln` of one
//! reaching below 0, a non-integer power of a negative base) the result is [`Interval::ENTIRE`];
//! an overflow gives an infinite bound. [`Interval::is_finite`] is then false: nothing is
//! shown about that part of the domain (the caller subdivides, `model::expr::prove`).
//!
//! Why not a crate: `inari` (IEEE 1788) needs a nightly toolchain or a Haswell target
//! configuration and GMP/MPFR for its transcendental functions; `honestintervals` binds
//! MPFR; the few operations an expression of the deck uses are short enough to test here.

use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Ulps by which the bounds of a libm function are moved outward (glibc: ≤ 2 ulp for
/// `exp`, `log`, `sin`, `cos`, `pow` on x86-64; twice that as a margin).
pub const LIBM_ULPS: u32 = 4;

/// A closed interval `[lo, hi]` (`lo ≤ hi`; bounds may be infinite).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

fn down(x: f64, ulps: u32) -> f64 {
    (0..ulps).fold(x, |y, _| y.next_down())
}

fn up(x: f64, ulps: u32) -> f64 {
    (0..ulps).fold(x, |y, _| y.next_up())
}

impl Interval {
    /// The whole real line: nothing is known (a possibly undefined or infinite result).
    pub const ENTIRE: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[lo, hi]` (the bounds ordered; a NaN bound gives [`Interval::ENTIRE`]).
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo.is_nan() || hi.is_nan() {
            return Interval::ENTIRE;
        }
        Interval {
            lo: lo.min(hi),
            hi: lo.max(hi),
        }
    }

    /// The point `[x, x]`.
    pub fn point(x: f64) -> Self {
        Interval::new(x, x)
    }

    /// Rounded outward by `ulps` on both sides.
    fn widened(lo: f64, hi: f64, ulps: u32) -> Self {
        Interval::new(down(lo, ulps), up(hi, ulps))
    }

    /// Whether both bounds are finite.
    pub fn is_finite(&self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }

    /// Whether `x` lies in the interval.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Whether the interval is the single point 0 (an exactly zero derivative).
    pub fn is_zero(&self) -> bool {
        self.lo == 0.0 && self.hi == 0.0
    }

    /// `hi − lo`.
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// The midpoint.
    pub fn mid(&self) -> f64 {
        0.5 * self.lo + 0.5 * self.hi
    }

    /// `max |x|` over the interval (its magnitude).
    pub fn mag(&self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The smallest interval holding both.
    pub fn hull(&self, o: &Interval) -> Interval {
        Interval::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }

    /// `√x`: defined for `lo ≥ 0`.
    pub fn sqrt(self) -> Self {
        if self.lo < 0.0 {
            return Interval::ENTIRE;
        }
        let r = Interval::widened(self.lo.sqrt(), self.hi.sqrt(), 1);
        Interval::new(r.lo.max(0.0), r.hi)
    }

    /// `eˣ`.
    pub fn exp(self) -> Self {
        let r = Interval::widened(self.lo.exp(), self.hi.exp(), LIBM_ULPS);
        Interval::new(r.lo.max(0.0), r.hi)
    }

    /// `ln x`: defined for `lo > 0`.
    pub fn ln(self) -> Self {
        if self.lo <= 0.0 {
            return Interval::ENTIRE;
        }
        Interval::widened(self.lo.ln(), self.hi.ln(), LIBM_ULPS)
    }

    /// `|x|`.
    pub fn abs(self) -> Self {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            -self
        } else {
            Interval::new(0.0, self.mag())
        }
    }

    /// `sin x`: the end values and every extremum `±1` at `π/2 + kπ` inside (looked for in
    /// the interval widened by a few ulps of its bounds: `π` is not a double).
    pub fn sin(self) -> Self {
        periodic(self, 0.0, f64::sin)
    }

    /// `cos x`: as [`Interval::sin`], extrema at `kπ`.
    pub fn cos(self) -> Self {
        periodic(self, FRAC_PI_2, f64::cos)
    }

    /// `xⁿ` for an integer `n` (`powf`'s value for integral exponents: defined for every
    /// base, `0⁰ = 1`): monotone pieces; a negative `n` needs `0 ∉ x`.
    pub fn powi(self, n: i32) -> Self {
        if n == 0 {
            return Interval::point(1.0);
        }
        if n < 0 {
            return Interval::point(1.0) / self.powi(-n);
        }
        let f = |x: f64| x.powf(f64::from(n));
        let r = if n % 2 == 1 || self.lo >= 0.0 {
            Interval::widened(f(self.lo), f(self.hi), LIBM_ULPS)
        } else if self.hi <= 0.0 {
            Interval::widened(f(self.hi), f(self.lo), LIBM_ULPS)
        } else {
            Interval::new(0.0, up(f(self.mag()), LIBM_ULPS))
        };
        if n % 2 == 0 {
            Interval::new(r.lo.max(0.0), r.hi)
        } else {
            r
        }
    }

    /// `x^y` as `powf` computes it: an integral point exponent by [`Interval::powi`]; any
    /// other needs `x ≥ 0` (and `x > 0` if `y` may be ≤ 0). `x^y = exp(y ln x)` is
    /// monotone in each of `y` and `ln x` (bilinear in the exponent): its extremes are
    /// at the corners of the box.
    pub fn pow(self, y: Interval) -> Self {
        if y.lo == y.hi && y.lo.fract() == 0.0 && y.lo.abs() <= f64::from(i32::MAX) {
            return self.powi(y.lo as i32);
        }
        if self.lo < 0.0 || (self.lo == 0.0 && y.lo <= 0.0) {
            return Interval::ENTIRE;
        }
        let c = [
            self.lo.powf(y.lo),
            self.lo.powf(y.hi),
            self.hi.powf(y.lo),
            self.hi.powf(y.hi),
        ];
        if c.iter().any(|v| v.is_nan()) {
            return Interval::ENTIRE;
        }
        let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let r = Interval::widened(lo, hi, LIBM_ULPS);
        Interval::new(r.lo.max(0.0), r.hi)
    }
}

/// `sin` (`shift = 0`) or `cos` (`shift = π/2`) over `x`: extrema at `π/2 + kπ − shift`.
fn periodic(x: Interval, shift: f64, f: fn(f64) -> f64) -> Interval {
    let full = Interval::new(-1.0, 1.0);
    if !x.is_finite() || x.width() >= 2.0 * PI || x.mag() > 1e15 {
        return full;
    }
    let ends = Interval::widened(f(x.lo).min(f(x.hi)), f(x.lo).max(f(x.hi)), LIBM_ULPS);
    let (mut lo, mut hi) = (ends.lo, ends.hi);
    // Critical points c_k = π/2 − shift + kπ, with value ±1 (sin: (−1)^k; cos: (−1)^k).
    let slack = 8.0 * f64::EPSILON * x.mag().max(1.0);
    let k0 = ((x.lo - slack - (FRAC_PI_2 - shift)) / PI).ceil() as i64;
    let k1 = ((x.hi + slack - (FRAC_PI_2 - shift)) / PI).floor() as i64;
    for k in k0..=k1 {
        // sin(π/2 + kπ) = (−1)^k; cos(kπ) = (−1)^k.
        if k.rem_euclid(2) == 0 {
            hi = 1.0;
        } else {
            lo = -1.0;
        }
    }
    Interval::new(lo.max(-1.0), hi.min(1.0))
}

impl Neg for Interval {
    type Output = Interval;
    fn neg(self) -> Interval {
        Interval::new(-self.hi, -self.lo)
    }
}

impl Add for Interval {
    type Output = Interval;
    fn add(self, o: Interval) -> Interval {
        Interval::widened(self.lo + o.lo, self.hi + o.hi, 1)
    }
}

impl Sub for Interval {
    type Output = Interval;
    fn sub(self, o: Interval) -> Interval {
        Interval::widened(self.lo - o.hi, self.hi - o.lo, 1)
    }
}

impl Mul for Interval {
    type Output = Interval;
    fn mul(self, o: Interval) -> Interval {
        // 0 × ∞ is NaN: an unbounded operand makes the product unknown unless the other
        // is exactly 0.
        if self.is_zero() || o.is_zero() {
            return Interval::point(0.0);
        }
        let c = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        if c.iter().any(|v| v.is_nan()) {
            return Interval::ENTIRE;
        }
        let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Interval::widened(lo, hi, 1)
    }
}

impl Div for Interval {
    type Output = Interval;
    fn div(self, o: Interval) -> Interval {
        if o.contains(0.0) {
            return Interval::ENTIRE;
        }
        let c = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        if c.iter().any(|v| v.is_nan()) {
            return Interval::ENTIRE;
        }
        let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Interval::widened(lo, hi, 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible stream of doubles in `[-r, r]` (xorshift: no dependency).
    fn stream(seed: u64, r: f64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            r * (2.0 * ((s >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
        }
    }

    /// Every operation encloses its f64 values at points sampled in its operands (the
    /// fundamental property), on random intervals, including ones holding 0 and wide ones.
    #[test]
    fn operations_enclose_sampled_values() {
        let mut g = stream(0x9e37_79b9_7f4a_7c15, 10.0);
        for _ in 0..20_000 {
            let (a, b) = (Interval::new(g(), g()), Interval::new(g(), g()));
            let ta = |u: f64| a.lo + (a.hi - a.lo) * (0.5 + 0.5 * u / 10.0);
            let tb = |u: f64| b.lo + (b.hi - b.lo) * (0.5 + 0.5 * u / 10.0);
            for _ in 0..4 {
                let (x, y) = (ta(g()), tb(g()));
                let check = |name: &str, r: Interval, v: f64| {
                    assert!(
                        !v.is_finite() && !r.is_finite() || r.contains(v) || v.is_nan(),
                        "{name}: {v} not in {r:?} (a = {a:?}, b = {b:?}, x = {x}, y = {y})"
                    );
                };
                check("+", a + b, x + y);
                check("-", a - b, x - y);
                check("*", a * b, x * y);
                if !b.contains(0.0) {
                    check("/", a / b, x / y);
                }
                check("sin", a.sin(), x.sin());
                check("cos", a.cos(), x.cos());
                check("exp", a.exp(), x.exp());
                check("abs", a.abs(), x.abs());
                if a.lo > 0.0 {
                    check("ln", a.ln(), x.ln());
                    check("pow", a.pow(b), x.powf(y));
                }
                if a.lo >= 0.0 {
                    check("sqrt", a.sqrt(), x.sqrt());
                }
                for n in [-3, -2, 2, 3, 5] {
                    if n > 0 || !a.contains(0.0) {
                        check("powi", a.powi(n), x.powf(f64::from(n)));
                    }
                }
            }
        }
    }

    /// The enclosures are tight where they should be (a point stays within a few ulps),
    /// sine and cosine reach ±1 exactly where they have an extremum inside, and what may be
    /// undefined is unbounded.
    #[test]
    fn extremes_and_undefined_parts() {
        let p = Interval::point(0.1) + Interval::point(0.2);
        assert!(p.contains(0.1 + 0.2) && p.width() < 4.0 * f64::EPSILON);
        assert_eq!(Interval::new(1.0, 2.0).sin().hi, 1.0);
        assert!(Interval::new(1.0, 1.5).sin().hi < 1.0);
        assert_eq!(Interval::new(3.0, 3.3).cos().lo, -1.0);
        assert_eq!(Interval::new(-0.1, 0.1).cos().hi, 1.0);
        assert_eq!(Interval::new(0.0, 100.0).sin(), Interval::new(-1.0, 1.0));
        assert!(!(Interval::point(1.0) / Interval::new(-1e-9, 1e-9)).is_finite());
        assert!(!Interval::new(-1e-300, 4.0).sqrt().is_finite());
        assert_eq!(Interval::new(0.0, 4.0).sqrt().lo, 0.0);
        assert!(!Interval::new(0.0, 1.0).ln().is_finite());
        assert!(
            !Interval::new(-2.0, -1.0)
                .pow(Interval::point(0.5))
                .is_finite()
        );
        assert!(
            Interval::new(-2.0, 1.0)
                .pow(Interval::point(2.0))
                .contains(4.0)
        );
        assert_eq!(Interval::new(-2.0, 1.0).powi(2).lo, 0.0);
        assert!(!Interval::new(700.0, 710.0).exp().is_finite());
        assert!(!(Interval::new(1e200, 1e200) * Interval::point(1e200)).is_finite());
        assert_eq!(
            Interval::ENTIRE * Interval::point(0.0),
            Interval::point(0.0)
        );
    }
}
