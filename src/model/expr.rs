//! An expression of the time `t` (`FUNCTIONS … EXPR`), kept as a tree and evaluated with
//! second-order jets, so that `f`, `ḟ`, `f̈` are exact (to round-off) at every `t`.
//!
//! The tree is what the deck's expression grammar (`deck/expr.rs`) reads, with the time
//! `t` as a variable and each `$name` a constant of the value it had when the deck was
//! read. It lives in `model` so that the deck builds it and the solver evaluates it
//! without either importing the other.

use crate::dual::Jet2;

mod proof;
pub use proof::{Blowup, IJet, Kink};

/// A function the expression grammar can call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `sqrt`.
    Sqrt,
    /// `sin`.
    Sin,
    /// `cos`.
    Cos,
    /// `exp`.
    Exp,
    /// `log`, natural.
    Log,
    /// `abs`.
    Abs,
}

impl Func {
    /// Every function, in the order the grammar lists them.
    pub const ALL: [Func; 6] = [
        Func::Sqrt,
        Func::Sin,
        Func::Cos,
        Func::Exp,
        Func::Log,
        Func::Abs,
    ];

    /// The name in an expression (lower case; the grammar is case-insensitive).
    pub fn name(self) -> &'static str {
        match self {
            Func::Sqrt => "sqrt",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Exp => "exp",
            Func::Log => "log",
            Func::Abs => "abs",
        }
    }

    /// The function of a (lower-case) name.
    pub fn from_name(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Its value at `x`.
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Exp => x.exp(),
            Func::Log => x.ln(),
            Func::Abs => x.abs(),
        }
    }

    /// Its jet at `x` (value equal to [`Func::apply`]'s).
    pub fn apply_jet(self, x: Jet2) -> Jet2 {
        match self {
            Func::Sqrt => x.sqrt(),
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Exp => x.exp(),
            Func::Log => x.ln(),
            Func::Abs => x.abs(),
        }
    }
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
    /// `^`.
    Pow,
}

impl BinOp {
    /// `a op b` in `f64`.
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            BinOp::Add => a + b,
            BinOp::Sub => a - b,
            BinOp::Mul => a * b,
            BinOp::Div => a / b,
            BinOp::Pow => a.powf(b),
        }
    }

    /// `a op b` on jets (value equal to [`BinOp::apply`]'s).
    pub fn apply_jet(self, a: Jet2, b: Jet2) -> Jet2 {
        match self {
            BinOp::Add => a + b,
            BinOp::Sub => a - b,
            BinOp::Mul => a * b,
            BinOp::Div => a / b,
            BinOp::Pow => a.powf(b),
        }
    }
}

/// Where a node of an expression is in the expression's text: byte offset and length
/// (what a located error points at).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct At {
    /// Byte offset in the text.
    pub start: u32,
    /// Length in bytes.
    pub len: u32,
}

impl At {
    /// The bytes `start..end` of the text.
    pub fn span(start: usize, end: usize) -> Self {
        At {
            start: u32::try_from(start).unwrap_or(u32::MAX),
            len: u32::try_from(end.saturating_sub(start)).unwrap_or(u32::MAX),
        }
    }
}

/// A node of an expression tree. The operations carry where they are in the text ([`At`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number (also `pi`).
    Num(f64),
    /// `$name`: a deck parameter, a constant of its value.
    Param {
        /// The parameter's name.
        name: String,
        /// Its value.
        value: f64,
    },
    /// The time `t`.
    Time,
    /// The value of the law's sensor number `k` (a `CONTROL` card's `angle(3)`, `vx(5)`:
    /// [`crate::model::control::ControlData::sensors`]); only in a control law.
    Sensor(usize, At),
    /// `-x`.
    Neg(Box<Expr>, At),
    /// `a op b`.
    Bin(BinOp, Box<Expr>, Box<Expr>, At),
    /// `f(x)`.
    Call(Func, Box<Expr>, At),
}

impl Expr {
    /// Value and exact first and second derivatives with respect to `t`, at `t`.
    pub fn jet(&self, t: f64) -> Jet2 {
        self.jet_at(t, &[], None)
    }

    /// Value and exact derivatives at `t` and sensor values `s`, with respect to `t`
    /// (`wrt = None`) or to the sensor `s[k]` (`wrt = Some(k)`). A sensor beyond `s` is
    /// NaN (a time function has none).
    pub fn jet_at(&self, t: f64, s: &[f64], wrt: Option<usize>) -> Jet2 {
        match self {
            Expr::Num(v) | Expr::Param { value: v, .. } => Jet2::constant(*v),
            Expr::Time if wrt.is_none() => Jet2::variable(t),
            Expr::Time => Jet2::constant(t),
            Expr::Sensor(k, _) => {
                let v = s.get(*k).copied().unwrap_or(f64::NAN);
                if wrt == Some(*k) {
                    Jet2::variable(v)
                } else {
                    Jet2::constant(v)
                }
            }
            Expr::Neg(x, _) => -x.jet_at(t, s, wrt),
            Expr::Bin(op, a, b, _) => op.apply_jet(a.jet_at(t, s, wrt), b.jet_at(t, s, wrt)),
            Expr::Call(f, x, _) => f.apply_jet(x.jet_at(t, s, wrt)),
        }
    }

    /// A control law's value `u(t, s)` and, into `grad`, its exact derivatives `∂u/∂sₖ`
    /// (forward mode, one pass per sensor: `Jet2`'s first component).
    pub fn law(&self, t: f64, s: &[f64], grad: Option<&mut [f64]>) -> f64 {
        if let Some(g) = grad {
            for (k, gk) in g.iter_mut().enumerate() {
                *gk = self.jet_at(t, s, Some(k)).d1;
            }
        }
        self.jet_at(t, s, Some(usize::MAX)).v
    }

    /// The expression with every sensor replaced by the number `s[k]` (an expression of
    /// `t` alone, which [`Expr::prove_finite`] can check).
    pub fn with_sensors(&self, s: &[f64]) -> Expr {
        let b = |e: &Expr| Box::new(e.with_sensors(s));
        match self {
            Expr::Sensor(k, _) => Expr::Num(s.get(*k).copied().unwrap_or(f64::NAN)),
            Expr::Neg(x, at) => Expr::Neg(b(x), *at),
            Expr::Bin(op, x, y, at) => Expr::Bin(*op, b(x), b(y), *at),
            Expr::Call(f, x, at) => Expr::Call(*f, b(x), *at),
            other => other.clone(),
        }
    }

    /// Whether `t` appears in the expression.
    pub fn depends_on_time(&self) -> bool {
        match self {
            Expr::Num(_) | Expr::Param { .. } | Expr::Sensor(..) => false,
            Expr::Time => true,
            Expr::Neg(x, _) | Expr::Call(_, x, _) => x.depends_on_time(),
            Expr::Bin(_, a, b, _) => a.depends_on_time() || b.depends_on_time(),
        }
    }
}

/// An expression of `t` as the deck wrote it (`text`, which the canonical writer prints
/// back) and as a tree (`expr`, which is evaluated).
#[derive(Debug, Clone, PartialEq)]
pub struct TimeExpr {
    /// The expression's text as written in the deck (one field).
    pub text: String,
    /// Its tree.
    pub expr: Expr,
    /// Where the field is in the deck (errors inside the expression point into it).
    pub field: super::Span,
}

impl TimeExpr {
    /// `[f, ḟ, f̈]` at `t`.
    pub fn derivatives(&self, t: f64) -> [f64; 3] {
        let j = self.expr.jet(t);
        [j.v, j.d1, j.d2]
    }

    /// `f(t)`.
    pub fn eval(&self, t: f64) -> f64 {
        self.expr.jet(t).v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(e: Expr) -> Box<Expr> {
        Box::new(e)
    }

    /// `t² sin t` built by hand against its closed-form derivatives (1e-13 relative:
    /// a few roundings in each).
    #[test]
    fn tree_jets_match_closed_forms() {
        let at = At::default();
        let e = Expr::Bin(
            BinOp::Mul,
            b(Expr::Bin(BinOp::Pow, b(Expr::Time), b(Expr::Num(2.0)), at)),
            b(Expr::Call(Func::Sin, b(Expr::Time), at)),
            at,
        );
        assert!(e.depends_on_time());
        for x in [-1.3, 0.0, 0.4, 5.0] {
            let j = e.jet(x);
            let (s, c) = (f64::sin(x), f64::cos(x));
            let want = [
                x * x * s,
                2.0 * x * s + x * x * c,
                2.0 * s + 4.0 * x * c - x * x * s,
            ];
            for (k, (a, w)) in [j.v, j.d1, j.d2].iter().zip(want).enumerate() {
                assert!((a - w).abs() <= 1e-13 * (1.0 + w.abs()), "d{k} at {x}");
            }
        }
        let k = Expr::Neg(
            b(Expr::Param {
                name: "w".into(),
                value: 4.0,
            }),
            at,
        );
        assert!(!k.depends_on_time());
        assert_eq!(k.jet(3.0), Jet2::constant(-4.0));
        for f in Func::ALL {
            assert_eq!(Func::from_name(f.name()), Some(f));
        }
    }
}
