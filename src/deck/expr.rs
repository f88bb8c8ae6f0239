//! Arithmetic expressions in numeric fields: `$E`, `2*$zeta*sqrt($k*$m)`, `(1 + $a) / 2`.
//!
//! Grammar (recursive descent, precedence from low to high):
//!
//! ```text
//! expr    = term { ("+" | "-") term } ;
//! term    = unary { ("*" | "/") unary } ;
//! unary   = ("-" | "+") unary | power ;
//! power   = atom [ "^" unary ] ;             (* right-associative: 2^3^2 = 2^9; -2^2 = -4 *)
//! atom    = number | "$" name | "pi" | func "(" expr ")" | "(" expr ")" ;
//! func    = "sqrt" | "sin" | "cos" | "exp" | "log" | "abs" ;    (* log: natural *)
//! name    = letter { letter | digit | "_" } ;    (* letters: A-Z, a-z, _ *)
//! ```
//!
//! Nesting (parentheses, function calls, signs and powers, which nest to the right) is at
//! most [`MAX_DEPTH`] deep: a deeper expression is a located error, not a stack overflow.
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

/// The functions an expression may call.
pub(crate) const FUNCTIONS: [&str; 6] = ["sqrt", "sin", "cos", "exp", "log", "abs"];

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
    let mut p = Parser {
        s: text.as_bytes(),
        pos: 0,
        depth: 0,
        lookup,
    };
    let v = p.expr()?;
    p.blanks();
    if p.pos < p.s.len() {
        return Err(p.syntax("an operator (+ - * / ^) or the end of the expression"));
    }
    finite(v, 0, text.len(), "the expression")
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
}

impl Parser<'_, '_> {
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

    fn expr(&mut self) -> Result<f64, ExprError> {
        let start = self.pos;
        let mut v = self.term()?;
        while let Some(op @ (b'+' | b'-')) = self.peek() {
            self.pos += 1;
            let r = self.term()?;
            v = if op == b'+' { v + r } else { v - r };
            v = finite(v, start, self.pos - start, "a sum")?;
        }
        Ok(v)
    }

    fn term(&mut self) -> Result<f64, ExprError> {
        let start = self.pos;
        let mut v = self.unary()?;
        while let Some(op @ (b'*' | b'/')) = self.peek() {
            self.pos += 1;
            let r = self.unary()?;
            v = if op == b'*' { v * r } else { v / r };
            let what = if op == b'*' {
                "a product"
            } else {
                "a quotient (division by zero?)"
            };
            v = finite(v, start, self.pos - start, what)?;
        }
        Ok(v)
    }

    /// Every recursion of the grammar (parentheses and calls via `expr`, signs, powers)
    /// passes here, so the depth is bounded here.
    fn unary(&mut self) -> Result<f64, ExprError> {
        if self.depth >= MAX_DEPTH {
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

    fn unary_inner(&mut self) -> Result<f64, ExprError> {
        match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Ok(-self.unary()?)
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<f64, ExprError> {
        self.blanks();
        let start = self.pos;
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.pos += 1;
            let e = self.unary()?;
            return finite(base.powf(e), start, self.pos - start, "a power");
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

    fn atom(&mut self) -> Result<f64, ExprError> {
        const ATOM: &str =
            "a number, `$name`, `pi`, a function (sqrt, sin, cos, exp, log, abs) or `(`";
        let Some(c) = self.peek() else {
            return Err(self.syntax(ATOM));
        };
        let start = self.pos;
        match c {
            b'0'..=b'9' | b'.' => self.number(),
            b'$' => {
                self.pos += 1;
                let name = self.name().to_string();
                if !is_name(&name) {
                    self.pos = start + 1;
                    return Err(self.syntax("a parameter name after `$` (a letter or `_` first)"));
                }
                (self.lookup)(&name).ok_or(ExprError {
                    at: start,
                    len: self.pos - start,
                    kind: ExprErrorKind::UndefinedParameter { name },
                })
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
                    return Ok(std::f64::consts::PI);
                }
                let len = self.pos - start;
                if !FUNCTIONS.contains(&name.as_str()) {
                    return Err(ExprError {
                        at: start,
                        len,
                        kind: ExprErrorKind::UnknownFunction { name },
                    });
                }
                if self.peek() != Some(b'(') {
                    return Err(self.syntax(&format!("`(` after the function {name}")));
                }
                self.pos += 1;
                let x = self.expr()?;
                self.close()?;
                let v = match name.as_str() {
                    "sqrt" => x.sqrt(),
                    "sin" => x.sin(),
                    "cos" => x.cos(),
                    "exp" => x.exp(),
                    "log" => x.ln(),
                    _ => x.abs(),
                };
                finite(v, start, self.pos - start, &format!("{name}({x})"))
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
mod tests {
    use super::*;

    fn params(name: &str) -> Option<f64> {
        match name {
            "E" => Some(2.1e11),
            "k" => Some(4.0),
            "m" => Some(9.0),
            "zeta" => Some(0.05),
            "a_1" => Some(-2.0),
            _ => None,
        }
    }

    fn ev(t: &str) -> Result<f64, ExprError> {
        eval(t, &params)
    }

    #[test]
    fn values_and_precedence() {
        assert_eq!(ev("$E"), Ok(2.1e11));
        assert_eq!(ev("2*$zeta*sqrt($k*$m)"), Ok(2.0 * 0.05 * 6.0));
        assert_eq!(ev("1+2*3"), Ok(7.0));
        assert_eq!(ev("(1+2)*3"), Ok(9.0));
        assert_eq!(ev("2^3^2"), Ok(512.0));
        assert_eq!(ev("-2^2"), Ok(-4.0));
        assert_eq!(ev("2^-1"), Ok(0.5));
        assert_eq!(ev("8/4/2"), Ok(1.0));
        assert_eq!(ev("1-2-3"), Ok(-4.0));
        assert_eq!(ev("--3"), Ok(3.0));
        assert_eq!(ev("1e-3*$a_1"), Ok(-2e-3));
        assert_eq!(ev(".5E+1"), Ok(5.0));
        assert_eq!(ev(" ( 1 + 2 ) * 3 "), Ok(9.0));
        assert_eq!(ev("PI"), Ok(std::f64::consts::PI));
        assert_eq!(ev("cos(pi)"), Ok(-1.0));
        assert_eq!(ev("SIN(0)"), Ok(0.0));
        assert_eq!(ev("exp(log(3))"), Ok(3.0f64.ln().exp()));
        assert_eq!(ev("abs(-$k)"), Ok(4.0));
    }

    #[test]
    fn errors_are_located() {
        let e = ev("2*$F").unwrap_err();
        assert_eq!((e.at, e.len), (2, 2));
        assert_eq!(
            e.kind,
            ExprErrorKind::UndefinedParameter { name: "F".into() }
        );
        let e = ev("2*").unwrap_err();
        assert_eq!(e.at, 2);
        assert!(
            matches!(e.kind, ExprErrorKind::Syntax { ref found, .. } if found == "the end of the expression")
        );
        let e = ev("(1+2").unwrap_err();
        assert_eq!(e.at, 4);
        let e = ev("1+2)").unwrap_err();
        assert_eq!(e.at, 3);
        let e = ev("tan(1)").unwrap_err();
        assert_eq!((e.at, e.len), (0, 3));
        assert!(matches!(e.kind, ExprErrorKind::UnknownFunction { .. }));
        let e = ev("sqrt(-1)").unwrap_err();
        assert!(matches!(e.kind, ExprErrorKind::NotFinite { .. }));
        assert!(matches!(
            ev("1/(1-1)").unwrap_err().kind,
            ExprErrorKind::NotFinite { .. }
        ));
        let e = ev("2.1e").unwrap_err();
        assert_eq!(e.at, 4);
        let e = ev("$ 1").unwrap_err();
        assert_eq!(e.at, 1);
        let e = ev("1 é").unwrap_err();
        assert_eq!((e.at, e.len), (2, 2));
        assert!(ev("").is_err());
        assert!(ev("sqrt 2").is_err());
    }

    /// Issue 28 §2: 100,000 nested parentheses, calls, signs or powers are a located
    /// error at the first level past [`MAX_DEPTH`], not a stack overflow.
    #[test]
    fn deep_nesting_is_a_located_error() {
        let n = 100_000;
        let cases = [
            format!("{}1{}", "(".repeat(n), ")".repeat(n)),
            format!("{}1{}", "sqrt(".repeat(n), ")".repeat(n)),
            format!("{}1", "-".repeat(n)),
            vec!["1"; n].join("^"),
            format!("{}1", "+ -".repeat(n)),
        ];
        for text in &cases {
            let e = ev(text).unwrap_err();
            assert_eq!(e.kind, ExprErrorKind::TooDeep, "{}", &text[..20]);
            assert!(e.at > 0 && e.at < 1000, "{}", e.at);
        }
        // At the limit it still evaluates: MAX_DEPTH - 1 parentheses (the outermost
        // level is the expression itself).
        let ok = format!(
            "{}2{}",
            "(".repeat(MAX_DEPTH - 1),
            ")".repeat(MAX_DEPTH - 1)
        );
        assert_eq!(ev(&ok), Ok(2.0));
        let ok = vec!["1"; MAX_DEPTH].join("^");
        assert_eq!(ev(&ok), Ok(1.0));
    }

    #[test]
    fn what_looks_like_an_expression() {
        for t in ["$E", "2*3", "(1)", "pi", "1-2", "a/b", "2^2", "-$x"] {
            assert!(looks_like_expression(t), "{t}");
        }
        for t in ["E", "2.1e", "2.1e-", "-", "+", "IMPACT_STEPS", "abc", "1e5"] {
            assert!(!looks_like_expression(t), "{t}");
        }
    }

    proptest::proptest! {
        /// Any text: a value or a located error, never a panic, and an error's span lies
        /// within the text on character boundaries.
        #[test]
        fn never_panics(s in "[-+*/^()$a-zE_0-9. é,]{0,24}") {
            match ev(&s) {
                Ok(v) => proptest::prop_assert!(v.is_finite()),
                Err(e) => {
                    proptest::prop_assert!(e.at + e.len <= s.len());
                    proptest::prop_assert!(s.is_char_boundary(e.at) && s.is_char_boundary(e.at + e.len));
                }
            }
        }
    }

    #[test]
    fn names() {
        assert!(is_name("E") && is_name("_x1") && is_name("k_cont"));
        assert!(!is_name("") && !is_name("1a") && !is_name("a-b") && !is_name("é"));
    }
}
