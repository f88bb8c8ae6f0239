//! An expression shown finite on a whole domain: its tree evaluated on intervals
//! ([`crate::interval`]) with second-order jets, the domain bisected where an enclosure is
//! not finite, until every piece is shown finite or a piece as narrow as the doubles
//! allow still is not: then the node whose enclosure blew up, where in the domain, and
//! whether the expression's `f64` value there is itself not finite, are reported.
//!
//! An enclosure holds every value the `f64` evaluation of [`Expr::jet`] can take at a
//! point of the piece (each interval operation encloses the `f64` operation, rounding
//! outward, and the jets' rules are the same identities on intervals), so "finite on every
//! piece" means finite at every double of the domain: no pole, overflow or undefined part
//! between the instants a sampling would have looked at. (Tests with the grammar's
//! parser: `deck/expr/tests.rs`.)

use super::{At, BinOp, Expr, Func};
use crate::interval::Interval;

/// `(f, f′, f″)` enclosed over an interval of the variable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IJet {
    /// Value.
    pub v: Interval,
    /// First derivative.
    pub d1: Interval,
    /// Second derivative.
    pub d2: Interval,
}

impl IJet {
    fn constant(v: f64) -> Self {
        let z = Interval::point(0.0);
        IJet {
            v: Interval::point(v),
            d1: z,
            d2: z,
        }
    }

    /// Whether the components up to `order` (0: the value, 1: and the slope, 2: and the
    /// curvature) are finite.
    pub fn finite_to(&self, order: u8) -> bool {
        self.v.is_finite()
            && (order < 1 || self.d1.is_finite())
            && (order < 2 || self.d2.is_finite())
    }

    /// `φ(f)` from enclosures of `φ`, `φ′`, `φ″` at `f`'s values; a term whose derivative
    /// factor is exactly 0 is left out (as [`crate::dual::Jet2`]'s chain rule does).
    fn chain(self, phi: Interval, d_phi: Interval, dd_phi: Interval) -> Self {
        let zero = Interval::point(0.0);
        let first = if self.d1.is_zero() {
            zero
        } else {
            d_phi * self.d1
        };
        let curvature = if self.d1.is_zero() {
            zero
        } else {
            dd_phi * (self.d1 * self.d1)
        };
        let stretch = if self.d2.is_zero() {
            zero
        } else {
            d_phi * self.d2
        };
        IJet {
            v: phi,
            d1: first,
            d2: curvature + stretch,
        }
    }

    fn neg(self) -> Self {
        IJet {
            v: -self.v,
            d1: -self.d1,
            d2: -self.d2,
        }
    }

    fn bin(op: BinOp, a: IJet, b: IJet) -> Self {
        match op {
            BinOp::Add => IJet {
                v: a.v + b.v,
                d1: a.d1 + b.d1,
                d2: a.d2 + b.d2,
            },
            BinOp::Sub => IJet {
                v: a.v - b.v,
                d1: a.d1 - b.d1,
                d2: a.d2 - b.d2,
            },
            BinOp::Mul => IJet {
                v: a.v * b.v,
                d1: a.d1 * b.v + a.v * b.d1,
                d2: a.d2 * b.v + Interval::point(2.0) * (a.d1 * b.d1) + a.v * b.d2,
            },
            BinOp::Div => {
                let v = a.v / b.v;
                let d1 = (a.d1 - v * b.d1) / b.v;
                let d2 = (a.d2 - Interval::point(2.0) * (d1 * b.d1) - v * b.d2) / b.v;
                IJet { v, d1, d2 }
            }
            BinOp::Pow => {
                let constant = b.d1.is_zero() && b.d2.is_zero();
                if constant && b.v.lo == b.v.hi {
                    let c = b.v.lo;
                    let value = a.v.pow(b.v);
                    if c == 0.0 {
                        return IJet {
                            v: value,
                            ..IJet::constant(0.0)
                        };
                    }
                    let cm1 = a.v.pow(Interval::point(c - 1.0));
                    let d_phi = Interval::point(c) * cm1;
                    let dd_phi = if c == 1.0 {
                        Interval::point(0.0)
                    } else {
                        Interval::point(c * (c - 1.0)) * a.v.pow(Interval::point(c - 2.0))
                    };
                    return a.chain(value, d_phi, dd_phi);
                }
                // x^y = exp(y ln x), the value as powf gives it.
                let mut j = IJet::bin(BinOp::Mul, b, a.call(Func::Log)).call(Func::Exp);
                j.v = a.v.pow(b.v);
                j
            }
        }
    }

    fn call(self, f: Func) -> Self {
        let x = self.v;
        match f {
            Func::Sqrt => {
                let s = x.sqrt();
                self.chain(
                    s,
                    Interval::point(0.5) / s,
                    Interval::point(-0.25) / (x * s),
                )
            }
            Func::Sin => {
                let (s, c) = (x.sin(), x.cos());
                self.chain(s, c, -s)
            }
            Func::Cos => {
                let (s, c) = (x.sin(), x.cos());
                self.chain(c, -s, -c)
            }
            Func::Exp => {
                let e = x.exp();
                self.chain(e, e, e)
            }
            Func::Log => self.chain(
                x.ln(),
                Interval::point(1.0) / x,
                Interval::point(-1.0) / (x * x),
            ),
            Func::Abs => {
                // sign(x) (0 at 0): the hull of the signs x takes; no curvature.
                let sign = if x.lo > 0.0 {
                    Interval::point(1.0)
                } else if x.hi < 0.0 {
                    Interval::point(-1.0)
                } else {
                    Interval::new(
                        if x.lo < 0.0 { -1.0 } else { 0.0 },
                        if x.hi > 0.0 { 1.0 } else { 0.0 },
                    )
                };
                self.chain(x.abs(), sign, Interval::point(0.0))
            }
        }
    }
}

/// Where an expression could not be shown finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blowup {
    /// The innermost node whose enclosure was not finite.
    pub at: At,
    /// The piece of the domain, as narrow as the bisection went.
    pub piece: (f64, f64),
    /// The derivative that blew up: 0 the value, 1 the slope, 2 the curvature.
    pub order: u8,
    /// A point of the piece where the `f64` evaluation itself is not finite, if one of
    /// the piece's ends or middle is.
    pub point: Option<f64>,
}

/// The most pieces one proof evaluates (a bound on the work of a hostile expression).
pub const MAX_PIECES: usize = 100_000;

impl Expr {
    /// The expression's jet enclosed over `t ∈ x` (the variable's jet `(x, 1, 0)`), or the
    /// innermost node whose enclosure up to `order` is not finite.
    pub fn interval_jet(&self, x: Interval, order: u8) -> Result<IJet, (At, u8)> {
        let check = |j: IJet, at: At| -> Result<IJet, (At, u8)> {
            if j.finite_to(order) {
                Ok(j)
            } else {
                let bad = if !j.v.is_finite() {
                    0
                } else if !j.d1.is_finite() {
                    1
                } else {
                    2
                };
                Err((at, bad))
            }
        };
        match self {
            Expr::Num(v) | Expr::Param { value: v, .. } => Ok(IJet::constant(*v)),
            Expr::Time => Ok(IJet {
                v: x,
                d1: Interval::point(1.0),
                d2: Interval::point(0.0),
            }),
            // A sensor is a number here only after `Expr::with_sensors`.
            Expr::Sensor(_, at) => Err((*at, 0)),
            Expr::Neg(a, at) => check(a.interval_jet(x, order)?.neg(), *at),
            Expr::Bin(op, a, b, at) => {
                let (a, b) = (a.interval_jet(x, order)?, b.interval_jet(x, order)?);
                check(IJet::bin(*op, a, b), *at)
            }
            Expr::Call(f, a, at) => check(a.interval_jet(x, order)?.call(*f), *at),
        }
    }

    /// Shows the expression and its derivatives up to `order` finite at every `t` of
    /// `[lo, hi]` (module docs): pieces are halved where an enclosure is not finite, down
    /// to a width of `2⁻⁴⁰` of the domain (or of its magnitude, or a few ulps), and at most
    /// [`MAX_PIECES`] pieces are evaluated.
    pub fn prove_finite(&self, lo: f64, hi: f64, order: u8) -> Result<(), Blowup> {
        let scale = (hi - lo)
            .max(lo.abs().max(hi.abs()) * 1e-3)
            .max(f64::MIN_POSITIVE);
        let min_width = (scale * 2f64.powi(-40)).max(8.0 * f64::EPSILON * lo.abs().max(hi.abs()));
        let mut stack = vec![(lo, hi)];
        let mut evaluated = 0usize;
        while let Some((a, b)) = stack.pop() {
            evaluated += 1;
            let Err((at, bad)) = self.interval_jet(Interval::new(a, b), order) else {
                continue;
            };
            let m = 0.5 * a + 0.5 * b;
            if b - a > min_width && evaluated < MAX_PIECES && m > a && m < b {
                // Left piece last: it is proved (or fails) first.
                stack.push((m, b));
                stack.push((a, m));
                continue;
            }
            let point = [a, m, b].into_iter().find(|t| {
                let j = self.jet(*t);
                !(j.v.is_finite()
                    && (order < 1 || j.d1.is_finite())
                    && (order < 2 || j.d2.is_finite()))
            });
            return Err(Blowup {
                at,
                piece: (a, b),
                order: bad,
                point,
            });
        }
        Ok(())
    }
}

/// A jump of a function's first derivative found at an `abs` whose argument crosses 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kink {
    /// The `abs` call.
    pub at: At,
    /// A piece a few ulps wide holding the crossing.
    pub piece: (f64, f64),
    /// The jump of `ḟ` across it, enclosed (it excludes 0: the jump is proven).
    pub jump: Interval,
}

impl Expr {
    /// `jet` on intervals with the signs of some `abs` calls forced (`sign(at)`), and
    /// every `abs` argument's enclosure recorded in `seen`.
    fn forced_jet(
        &self,
        x: Interval,
        sign: &dyn Fn(At) -> Option<f64>,
        seen: &mut Vec<(At, IJet)>,
    ) -> IJet {
        match self {
            Expr::Num(v) | Expr::Param { value: v, .. } => IJet::constant(*v),
            Expr::Time => IJet {
                v: x,
                d1: Interval::point(1.0),
                d2: Interval::point(0.0),
            },
            Expr::Sensor(..) => IJet::constant(f64::NAN),
            Expr::Neg(a, _) => a.forced_jet(x, sign, seen).neg(),
            Expr::Bin(op, a, b, _) => {
                let (a, b) = (a.forced_jet(x, sign, seen), b.forced_jet(x, sign, seen));
                IJet::bin(*op, a, b)
            }
            Expr::Call(Func::Abs, a, at) => {
                let g = a.forced_jet(x, sign, seen);
                seen.push((*at, g));
                match sign(*at) {
                    Some(s) => {
                        let s = Interval::point(s);
                        IJet {
                            v: s * g.v,
                            d1: s * g.d1,
                            d2: s * g.d2,
                        }
                    }
                    None => g.call(Func::Abs),
                }
            }
            Expr::Call(f, a, _) => a.forced_jet(x, sign, seen).call(*f),
        }
    }

    /// The first jump of `ḟ` on `[lo, hi]` that interval arithmetic proves: the pieces
    /// where an `abs` argument may vanish are halved down to a few ulps; on such a piece,
    /// when every argument that may vanish there crosses 0 with a slope of known sign, the
    /// jets with all those `abs` on their left branch (sign `−sign g′`) and on their right
    /// one are enclosed on the piece; both hold their one-sided limits at the crossing, so a
    /// difference of the slopes that excludes 0 is a jump. (Kinks that cancel, as in
    /// `t − (t + T − |t − T|)/2`'s companions, give a difference holding 0: no jump.)
    /// `None` when none is proven within [`MAX_PIECES`] pieces.
    pub fn velocity_jump(&self, lo: f64, hi: f64) -> Option<Kink> {
        let scale = (hi - lo)
            .max(lo.abs().max(hi.abs()) * 1e-3)
            .max(f64::MIN_POSITIVE);
        let min_width = (scale * 2f64.powi(-44)).max(8.0 * f64::EPSILON * lo.abs().max(hi.abs()));
        let mut stack = vec![(lo, hi)];
        let mut evaluated = 0usize;
        let mut seen = Vec::new();
        while let Some((a, b)) = stack.pop() {
            evaluated += 1;
            if evaluated > MAX_PIECES {
                return None;
            }
            let x = Interval::new(a, b);
            seen.clear();
            let _ = self.forced_jet(x, &|_| None, &mut seen);
            let crossing: Vec<(At, IJet)> = seen
                .iter()
                .copied()
                .filter(|(_, g)| g.v.contains(0.0))
                .collect();
            if crossing.is_empty() {
                continue;
            }
            let m = 0.5 * a + 0.5 * b;
            if b - a > min_width && m > a && m < b {
                stack.push((m, b));
                stack.push((a, m));
                continue;
            }
            // Every argument that may vanish here must change sign between the piece's
            // ends (so it does vanish inside) with a slope of known sign.
            let ends = |t: f64| {
                let mut e = Vec::new();
                let _ = self.forced_jet(Interval::point(t), &|_| None, &mut e);
                e
            };
            let (at_a, at_b) = (ends(a), ends(b));
            let slopes: Option<Vec<(At, f64)>> = seen
                .iter()
                .enumerate()
                .filter(|(_, (_, g))| g.v.contains(0.0))
                .map(|(i, (at, g))| {
                    let (ga, gb) = (at_a.get(i)?.1.v, at_b.get(i)?.1.v);
                    let changes = (ga.hi < 0.0 && gb.lo > 0.0) || (ga.lo > 0.0 && gb.hi < 0.0);
                    if !changes {
                        None
                    } else if g.d1.lo > 0.0 {
                        Some((*at, 1.0))
                    } else if g.d1.hi < 0.0 {
                        Some((*at, -1.0))
                    } else {
                        None
                    }
                })
                .collect();
            let Some(slopes) = slopes else { continue };
            let side = |s: f64| {
                let slopes = &slopes;
                move |at: At| slopes.iter().find(|(a, _)| *a == at).map(|(_, d)| s * d)
            };
            let (left, right) = (side(-1.0), side(1.0));
            let mut scratch = Vec::new();
            let fl = self.forced_jet(x, &left, &mut scratch);
            let fr = self.forced_jet(x, &right, &mut scratch);
            let jump = fr.d1 - fl.d1;
            if jump.is_finite() && !jump.contains(0.0) {
                return Some(Kink {
                    at: crossing[0].0,
                    piece: (a, b),
                    jump,
                });
            }
        }
        None
    }
}
