//! Forward-mode automatic differentiation for element tangents.
//!
//! [`Real`] is the small set of operations the element kernels use, implemented for `f64`
//! (residuals), for [`Dual`] (a fixed-size dual number: value plus `N` directional
//! derivatives in a plain array, `Copy`, no heap and no branches — the fast path for
//! tangents) and, through a blanket implementation, for every `nalgebra::RealField` scalar such as
//! `num_dual::DualSVec64<N>`.
//! A kernel written once over `S: Real` gives the residual with `f64` and the exact
//! tangent with `Dual<N>` (seed direction `k` with [`Dual::var`]).
//! [`Jet2`] carries a value with its first and second derivatives in one variable (the
//! exact `ḟ`, `f̈` of a deck's expression of time).

mod jet;
pub use jet::Jet2;

use nalgebra::Scalar;
use num_traits::{One, Zero};
use std::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// The scalar operations element kernels need.
pub trait Real:
    Scalar
    + Copy
    + PartialOrd
    + Zero
    + One
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
{
    /// A constant.
    fn cst(x: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Four-quadrant arctangent of `self / x`.
    fn atan2(self, x: Self) -> Self;
}

/// Every nalgebra real scalar (`f64`, num-dual's dual numbers…) is a [`Real`].
impl<T: nalgebra::RealField + Copy> Real for T {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        nalgebra::convert(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        nalgebra::ComplexField::sqrt(self)
    }
    #[inline(always)]
    fn sin(self) -> Self {
        nalgebra::ComplexField::sin(self)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        nalgebra::ComplexField::cos(self)
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        nalgebra::RealField::atan2(self, x)
    }
}

/// A dual number with `N` derivative directions: `re + Σ eps[k] ε_k`, `ε_j ε_k = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const N: usize> {
    /// Value.
    pub re: f64,
    /// Derivatives along the `N` seeded directions.
    pub eps: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// A constant (zero derivatives).
    #[inline(always)]
    pub fn constant(re: f64) -> Self {
        Dual { re, eps: [0.0; N] }
    }
    /// The independent variable number `k` with value `re`.
    #[inline(always)]
    pub fn var(re: f64, k: usize) -> Self {
        let mut eps = [0.0; N];
        eps[k] = 1.0;
        Dual { re, eps }
    }
    #[inline(always)]
    fn chain(self, f: f64, df: f64) -> Self {
        let mut eps = self.eps;
        for e in &mut eps {
            *e *= df;
        }
        Dual { re: f, eps }
    }
}

impl<const N: usize> PartialOrd for Dual<N> {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        self.re.partial_cmp(&o.re)
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn add(mut self, o: Self) -> Self {
        self.re += o.re;
        for k in 0..N {
            self.eps[k] += o.eps[k];
        }
        self
    }
}
impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(mut self, o: Self) -> Self {
        self.re -= o.re;
        for k in 0..N {
            self.eps[k] -= o.eps[k];
        }
        self
    }
}
impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        let mut eps = [0.0; N];
        for ((e, a), b) in eps.iter_mut().zip(&self.eps).zip(&o.eps) {
            *e = a * o.re + self.re * b;
        }
        Dual {
            re: self.re * o.re,
            eps,
        }
    }
}
impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let inv = 1.0 / o.re;
        let q = self.re * inv;
        let mut eps = [0.0; N];
        for ((e, a), b) in eps.iter_mut().zip(&self.eps).zip(&o.eps) {
            *e = (a - q * b) * inv;
        }
        Dual { re: q, eps }
    }
}
impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(mut self) -> Self {
        self.re = -self.re;
        for e in &mut self.eps {
            *e = -*e;
        }
        self
    }
}
impl<const N: usize> AddAssign for Dual<N> {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}
impl<const N: usize> SubAssign for Dual<N> {
    #[inline(always)]
    fn sub_assign(&mut self, o: Self) {
        *self = *self - o;
    }
}
impl<const N: usize> MulAssign for Dual<N> {
    #[inline(always)]
    fn mul_assign(&mut self, o: Self) {
        *self = *self * o;
    }
}
impl<const N: usize> DivAssign for Dual<N> {
    #[inline(always)]
    fn div_assign(&mut self, o: Self) {
        *self = *self / o;
    }
}
impl<const N: usize> Zero for Dual<N> {
    fn zero() -> Self {
        Self::constant(0.0)
    }
    fn is_zero(&self) -> bool {
        self.re == 0.0 && self.eps.iter().all(|e| *e == 0.0)
    }
}
impl<const N: usize> One for Dual<N> {
    fn one() -> Self {
        Self::constant(1.0)
    }
}

impl<const N: usize> Real for Dual<N> {
    #[inline(always)]
    fn cst(x: f64) -> Self {
        Self::constant(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.re.sqrt();
        self.chain(s, 0.5 / s)
    }
    #[inline(always)]
    fn sin(self) -> Self {
        self.chain(self.re.sin(), self.re.cos())
    }
    #[inline(always)]
    fn cos(self) -> Self {
        self.chain(self.re.cos(), -self.re.sin())
    }
    #[inline(always)]
    fn atan2(self, x: Self) -> Self {
        // d atan2(y, x) = (x dy − y dx) / (x² + y²)
        let r2 = x.re * x.re + self.re * self.re;
        let mut eps = [0.0; N];
        for ((e, dy), dx) in eps.iter_mut().zip(&self.eps).zip(&x.eps) {
            *e = (x.re * dy - self.re * dx) / r2;
        }
        Dual {
            re: self.re.atan2(x.re),
            eps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_of_elementary_functions() {
        let x = Dual::<2>::var(0.7, 0);
        let y = Dual::<2>::var(-0.3, 1);
        let f = (x * y).sin() / (x + y * y).sqrt() + y.atan2(x) - x.cos();
        // Central differences of the same expression.
        let g = |a: f64, b: f64| (a * b).sin() / (a + b * b).sqrt() + b.atan2(a) - a.cos();
        let h = 1e-6;
        let dx = (g(0.7 + h, -0.3) - g(0.7 - h, -0.3)) / (2.0 * h);
        let dy = (g(0.7, -0.3 + h) - g(0.7, -0.3 - h)) / (2.0 * h);
        assert!((f.re - g(0.7, -0.3)).abs() < 1e-15);
        assert!((f.eps[0] - dx).abs() < 1e-8 && (f.eps[1] - dy).abs() < 1e-8);
    }
}
