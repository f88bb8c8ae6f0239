//! Arithmetic expressions in numeric fields: `$E`, `2*$zeta*sqrt($k*$m)`, `(1 + $a) / 2`.
//!
//! Grammar (recursive descent, precedence from low to high):
//!
//! ```text
//! expr    = term { ("+" | "-") term } ;
//! term    = unary { ("*" | "/") unary } ;
//! unary   = ("-" | "+") unary | power ;
//! power   = atom [ "^" unary ] ;             (* right-associative: 2^3^2 = 2^9; -2^2 = -4 *)
//! atom    = number | "$" name | "pi" | "t" | func "(" expr ")" | "(" expr ")" ;
//! func    = "sqrt" | "sin" | "cos" | "exp" | "log" | "abs" ;    (* log: natural *)
//! name    = letter { letter | digit | "_" } ;    (* letters: A-Z, a-z, _ *)
//! ```
//!
//! Nesting (parentheses, function calls, signs and powers, which nest to the right) is at
//! most [`MAX_DEPTH`] deep: a deeper expression is a located error, not a stack overflow.
//!
//! The time `t` is a variable only in a `FUNCTIONS … EXPR` field ([`parse_time`]), which
//! is kept as a tree ([`crate::model::Expr`]) and evaluated at each time; anywhere else
//! `t` is an unknown name. Every other field is evaluated when the deck is read
//! ([`eval`]).
//!
//! Blanks are allowed anywhere (the lexer keeps the blanks inside parentheses within one
//! field). Function names and `pi` are case-insensitive; parameter names are case-sensitive.
//! Evaluation is in `f64`; a result (or an intermediate value) that is not finite is an
//! error (`sqrt(-1)`, `1/0`). The parser never panics: it walks ASCII bytes and reports the
//! first byte it cannot use, with what it expected there.

/// Why an expression could not be read or evaluated; `at` is the byte offset in the
/// expression's text where the problem starts and `len` its length (≥ 0).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ExprError {
    /// Byte offset within the expression text.
    pub at: usize,
    /// Length in bytes of the offending part.
    pub len: usize,
    /// What is wrong.
    pub kind: ExprErrorKind,
}

/// The kinds of expression errors.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ExprErrorKind {
    /// A syntax error: `expected` is what would have been accepted, `found` what is there.
    Syntax { expected: String, found: String },
    /// `$name` where no parameter `name` is defined (so far).
    UndefinedParameter { name: String },
    /// A function name that is not one of the functions above.
    UnknownFunction { name: String },
    /// The value is not finite (e.g. `sqrt(-1)`, `1/0`, `1e200*1e200`).
    NotFinite { what: String },
    /// Parentheses, calls, signs or powers nested deeper than [`MAX_DEPTH`].
    TooDeep,
}

/// The deepest nesting an expression may have: each `(`, function call, unary sign and
/// `^` opens one level. Far beyond any formula a deck needs, and small enough that the
/// recursive descent stays well inside a thread's stack (a few hundred bytes per level).
pub const MAX_DEPTH: usize = 100;

use crate::model::control::Sensor;
use crate::model::{At, BinOp, Expr, Func};

/// Whether a field's text is meant as an expression (rather than a keyword or a malformed
/// number): it contains `$`, `(`, `)`, `*`, `/` or `^`, is `pi`, or has a `+`/`-` that is
/// not its first character nor an exponent's sign (`1e-3` is a number, `2.1e-` is a
/// malformed number, `1-2` is an expression).
pub(crate) fn looks_like_expression(text: &str) -> bool {
    if text.eq_ignore_ascii_case("pi") {
        return true;
    }
    let b = text.as_bytes();
    b.iter().enumerate().any(|(i, &c)| match c {
        b'$' | b'(' | b')' | b'*' | b'/' | b'^' => true,
        b'+' | b'-' => i > 0 && !matches!(b[i - 1], b'e' | b'E'),
        _ => false,
    })
}

/// Evaluates `text` with parameter values from `lookup` (a parameter name → its value).
pub(crate) fn eval(text: &str, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, ExprError> {
    let node = parse(text, lookup, false)?;
    // Without `t` every node has its value.
    finite(node.v.unwrap_or(f64::NAN), 0, text.len(), "the expression")
}

/// Reads `text` as an expression of the time `t` into its tree, parameters replaced by
/// their values from `lookup`. Parts that do not depend on `t` are evaluated as they are
/// read and must be finite (`1/0` is an error here too).
pub(crate) fn parse_time(
    text: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<Expr, ExprError> {
    parse(text, lookup, true).map(|n| n.e)
}

fn parse(text: &str, lookup: &dyn Fn(&str) -> Option<f64>, time: bool) -> Result<Node, ExprError> {
    parse_with(text, lookup, time, None)
}

/// A sensor an expression reads, where it is in the text (the reference it names is
/// checked by the card's builder).
pub(crate) type SensorRef = (Sensor, At);

/// Reads `text` as a control law (`ELEMENTS … CONTROL … LAW`): an expression of the time
/// `t` and of sensors — `angle(h)`, `rate(h)` of a HINGE `h`, `x(n)`, `y(n)`, `z(n)`,
/// `vx(n)`, `vy(n)`, `vz(n)` of a node `n`, each argument a constant whole number
/// (`$name` allowed). Returns the tree, whose [`Expr::Sensor`] indices number the
/// distinct sensors in order of first appearance, and those sensors.
pub(crate) fn parse_law(
    text: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
) -> Result<(Expr, Vec<SensorRef>), ExprError> {
    let mut sensors = Vec::new();
    let node = parse_with(text, lookup, true, Some(&mut sensors))?;
    Ok((node.e, sensors))
}

fn parse_with(
    text: &str,
    lookup: &dyn Fn(&str) -> Option<f64>,
    time: bool,
    sensors: Option<&mut Vec<SensorRef>>,
) -> Result<Node, ExprError> {
    let mut p = Parser {
        s: text.as_bytes(),
        pos: 0,
        depth: 0,
        lookup,
        time,
        sensors,
    };
    let node = p.expr()?;
    p.blanks();
    if p.pos < p.s.len() {
        return Err(p.syntax("an operator (+ - * / ^) or the end of the expression"));
    }
    Ok(node)
}

/// The sensor a name reads, with the number it takes: `angle`, `rate` (a HINGE's),
/// `x`, `y`, `z`, `vx`, `vy`, `vz` (a node's).
fn sensor_of(name: &str, id: u32) -> Option<Sensor> {
    use crate::model::{ElementId, NodeId};
    Some(match name {
        "angle" => Sensor::HingeAngle(ElementId(id)),
        "rate" => Sensor::HingeRate(ElementId(id)),
        "x" => Sensor::Coordinate(NodeId(id), 0),
        "y" => Sensor::Coordinate(NodeId(id), 1),
        "z" => Sensor::Coordinate(NodeId(id), 2),
        "vx" => Sensor::Velocity(NodeId(id), 0),
        "vy" => Sensor::Velocity(NodeId(id), 1),
        "vz" => Sensor::Velocity(NodeId(id), 2),
        _ => return None,
    })
}

/// The sensors' names, for messages.
pub(crate) const SENSORS: &str = "angle(h), rate(h), x(n), y(n), z(n), vx(n), vy(n), vz(n)";

/// A subexpression read: its tree and, when it does not depend on `t`, its value.
struct Node {
    e: Expr,
    v: Option<f64>,
}

impl Node {
    fn constant(e: Expr, v: f64) -> Self {
        Node { e, v: Some(v) }
    }
}

/// Whether `name` is a valid parameter name: a letter or `_`, then letters, digits, `_`.
pub(crate) fn is_name(name: &str) -> bool {
    let mut b = name.bytes();
    b.next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
        && b.all(|c| c.is_ascii_alphanumeric() || c == b'_')
}

fn finite(v: f64, at: usize, len: usize, what: &str) -> Result<f64, ExprError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ExprError {
            at,
            len,
            kind: ExprErrorKind::NotFinite { what: what.into() },
        })
    }
}

struct Parser<'s, 'f> {
    s: &'s [u8],
    pos: usize,
    /// Levels of [`Parser::unary`] under way: every recursive path goes through it.
    depth: usize,
    lookup: &'f dyn Fn(&str) -> Option<f64>,
    /// Whether `t` is the time variable (an EXPR function) or an unknown name.
    time: bool,
    /// A control law's sensors read so far (`None`: sensors are unknown names).
    sensors: Option<&'f mut Vec<SensorRef>>,
}

impl Parser<'_, '_> {
    /// `name(<whole number>)` of a sensor, after its name (`start`: where it began).
    fn sensor(&mut self, name: &str, start: usize) -> Result<Node, ExprError> {
        if self.peek() != Some(b'(') {
            return Err(self.syntax(&format!("`(` and a number after the sensor {name}")));
        }
        self.pos += 1;
        let arg_start = self.pos;
        let arg = self.expr()?;
        let arg_end = self.pos;
        self.close()?;
        let id = match arg.v {
            Some(v) if v >= 1.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0 => v as u32,
            _ => {
                return Err(ExprError {
                    at: arg_start,
                    len: arg_end - arg_start,
                    kind: ExprErrorKind::Syntax {
                        expected: format!(
                            "a whole number >= 1 (the {} number) as the argument of {name}",
                            if matches!(name, "angle" | "rate") {
                                "HINGE element"
                            } else {
                                "node"
                            }
                        ),
                        found: format!(
                            "`{}`",
                            std::str::from_utf8(&self.s[arg_start..arg_end]).unwrap_or("?")
                        ),
                    },
                });
            }
        };
        let sensor = sensor_of(name, id).expect("a sensor's name");
        let at = At::span(start, self.pos);
        let list = self.sensors.as_mut().expect("sensors are read in a law");
        let k = match list.iter().position(|(s, _)| *s == sensor) {
            Some(k) => k,
            None => {
                list.push((sensor, at));
                list.len() - 1
            }
        };
        Ok(Node {
            e: Expr::Sensor(k, at),
            v: None,
        })
    }

    fn blanks(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.blanks();
        self.s.get(self.pos).copied()
    }

    /// A syntax error at the current position (or at the end).
    fn syntax(&self, expected: &str) -> ExprError {
        let found = match self.s.get(self.pos) {
            None => "the end of the expression".to_string(),
            Some(_) => {
                // The offending character (the text is valid UTF-8 and `pos` is at a char
                // boundary: only ASCII bytes are ever skipped).
                let rest = std::str::from_utf8(&self.s[self.pos..]).unwrap_or("?");
                format!("`{}`", rest.chars().next().unwrap_or('?'))
            }
        };
        let len = std::str::from_utf8(&self.s[self.pos..])
            .ok()
            .and_then(|r| r.chars().next())
            .map_or(0, char::len_utf8);
        ExprError {
            at: self.pos,
            len,
            kind: ExprErrorKind::Syntax {
                expected: expected.into(),
                found,
            },
        }
    }

    /// `a op b`, its value checked when both are known (`start`: where `a` began).
    fn bin(&self, op: BinOp, a: Node, b: Node, start: usize) -> Result<Node, ExprError> {
        let what = match op {
            BinOp::Add | BinOp::Sub => "a sum",
            BinOp::Mul => "a product",
            BinOp::Div => "a quotient (division by zero?)",
            BinOp::Pow => "a power",
        };
        let v = match (a.v, b.v) {
            (Some(x), Some(y)) => Some(finite(op.apply(x, y), start, self.pos - start, what)?),
            _ => None,
        };
        Ok(Node {
            e: Expr::Bin(op, Box::new(a.e), Box::new(b.e), At::span(start, self.pos)),
            v,
        })
    }

    fn expr(&mut self) -> Result<Node, ExprError> {
        let start = self.pos;
        let mut v = self.term()?;
        while let Some(op @ (b'+' | b'-')) = self.peek() {
            self.pos += 1;
            let r = self.term()?;
            let op = if op == b'+' { BinOp::Add } else { BinOp::Sub };
            v = self.bin(op, v, r, start)?;
        }
        Ok(v)
    }

    fn term(&mut self) -> Result<Node, ExprError> {
        let start = self.pos;
        let mut v = self.unary()?;
        while let Some(op @ (b'*' | b'/')) = self.peek() {
            self.pos += 1;
            let r = self.unary()?;
            let op = if op == b'*' { BinOp::Mul } else { BinOp::Div };
            v = self.bin(op, v, r, start)?;
        }
        Ok(v)
    }

    /// Every recursion of the grammar (parentheses and calls via `expr`, signs, powers)
    /// passes here, so the depth is bounded here.
    fn unary(&mut self) -> Result<Node, ExprError> {
        // The expression itself is not a level: MAX_DEPTH parentheses are accepted, as
        // grammar.md says (issue 35 §5: 100 were refused).
        if self.depth > MAX_DEPTH {
            self.blanks();
            return Err(ExprError {
                at: self.pos,
                len: std::str::from_utf8(&self.s[self.pos..])
                    .ok()
                    .and_then(|r| r.chars().next())
                    .map_or(0, char::len_utf8),
                kind: ExprErrorKind::TooDeep,
            });
        }
        self.depth += 1;
        let v = self.unary_inner();
        self.depth -= 1;
        v
    }

    fn unary_inner(&mut self) -> Result<Node, ExprError> {
        match self.peek() {
            Some(b'-') => {
                let start = self.pos;
                self.pos += 1;
                let x = self.unary()?;
                Ok(Node {
                    v: x.v.map(|v| -v),
                    e: Expr::Neg(Box::new(x.e), At::span(start, self.pos)),
                })
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, ExprError> {
        self.blanks();
        let start = self.pos;
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.pos += 1;
            let e = self.unary()?;
            return self.bin(BinOp::Pow, base, e, start);
        }
        Ok(base)
    }

    fn name(&mut self) -> &str {
        let start = self.pos;
        while self.pos < self.s.len()
            && (self.s[self.pos].is_ascii_alphanumeric() || self.s[self.pos] == b'_')
        {
            self.pos += 1;
        }
        std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("")
    }

    fn atom(&mut self) -> Result<Node, ExprError> {
        const ATOM: &str =
            "a number, `$name`, `pi`, a function (sqrt, sin, cos, exp, log, abs) or `(`";
        let Some(c) = self.peek() else {
            return Err(self.syntax(ATOM));
        };
        let start = self.pos;
        match c {
            b'0'..=b'9' | b'.' => self.number().map(|v| Node::constant(Expr::Num(v), v)),
            b'$' => {
                self.pos += 1;
                let name = self.name().to_string();
                if !is_name(&name) {
                    self.pos = start + 1;
                    return Err(self.syntax("a parameter name after `$` (a letter or `_` first)"));
                }
                match (self.lookup)(&name) {
                    Some(value) => Ok(Node::constant(Expr::Param { name, value }, value)),
                    None => Err(ExprError {
                        at: start,
                        len: self.pos - start,
                        kind: ExprErrorKind::UndefinedParameter { name },
                    }),
                }
            }
            b'(' => {
                self.pos += 1;
                let v = self.expr()?;
                self.close()?;
                Ok(v)
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let name = self.name().to_ascii_lowercase();
                if name == "pi" {
                    let pi = std::f64::consts::PI;
                    return Ok(Node::constant(Expr::Num(pi), pi));
                }
                if name == "t" && self.time {
                    return Ok(Node {
                        e: Expr::Time,
                        v: None,
                    });
                }
                if self.sensors.is_some() && sensor_of(&name, 1).is_some() {
                    return self.sensor(&name, start);
                }
                let len = self.pos - start;
                let Some(func) = Func::from_name(&name) else {
                    return Err(ExprError {
                        at: start,
                        len,
                        kind: ExprErrorKind::UnknownFunction { name },
                    });
                };
                if self.peek() != Some(b'(') {
                    return Err(self.syntax(&format!("`(` after the function {name}")));
                }
                self.pos += 1;
                let x = self.expr()?;
                self.close()?;
                let v = match x.v {
                    Some(x) => Some(finite(
                        func.apply(x),
                        start,
                        self.pos - start,
                        &format!("{name}({x})"),
                    )?),
                    None => None,
                };
                Ok(Node {
                    e: Expr::Call(func, Box::new(x.e), At::span(start, self.pos)),
                    v,
                })
            }
            _ => Err(self.syntax(ATOM)),
        }
    }

    fn close(&mut self) -> Result<(), ExprError> {
        if self.peek() == Some(b')') {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.syntax("`)` or an operator (+ - * / ^)"))
        }
    }

    /// `digits ['.' digits] ['e' ['+'|'-'] digits]` or `'.' digits ...` (no sign: signs are
    /// unary operators).
    fn number(&mut self) -> Result<f64, ExprError> {
        let start = self.pos;
        let digits = |p: &mut Self| {
            let s = p.pos;
            while p.pos < p.s.len() && p.s[p.pos].is_ascii_digit() {
                p.pos += 1;
            }
            p.pos - s
        };
        let int = digits(self);
        let mut frac = 0;
        if self.s.get(self.pos) == Some(&b'.') {
            self.pos += 1;
            frac = digits(self);
        }
        if int == 0 && frac == 0 {
            return Err(self.syntax("digits in a number"));
        }
        if matches!(self.s.get(self.pos), Some(b'e' | b'E')) {
            self.pos += 1;
            if matches!(self.s.get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            if digits(self) == 0 {
                return Err(self.syntax("the digits of an exponent"));
            }
        }
        let text = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
        let v: f64 = text.parse().map_err(|_| self.syntax("a number"))?;
        finite(v, start, self.pos - start, "a number")
    }
}

#[cfg(test)]
mod tests;
