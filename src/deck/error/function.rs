//! The details of an EXPR function that interval arithmetic could not show finite
//! (`deck/build/functions.rs`), boxed in [`super::DeckErrorKind::FunctionNotFinite`].

use std::fmt;

/// Where an EXPR function could not be shown finite ([`super::DeckErrorKind::FunctionNotFinite`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FunctionNotFinite {
    /// What it is: `function`, or `CONTROL element` (a law, its sensors at the drawing).
    pub owner: &'static str,
    /// The function's (element's) number.
    pub id: u32,
    /// The expression.
    pub text: String,
    /// The innermost part whose enclosure blew up.
    pub part: String,
    /// `value`, `first derivative` or `second derivative`.
    pub what: &'static str,
    /// The variable (`t`, `the deflection`).
    pub var: &'static str,
    /// Where, rounded to 9 digits.
    pub at: f64,
    /// The variable's unit.
    pub unit: &'static str,
    /// Whether the `f64` evaluation itself is not finite there.
    pub sure: bool,
    /// The domain checked.
    pub domain: (f64, f64),
}

impl fmt::Display for FunctionNotFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let FunctionNotFinite {
            owner,
            id,
            text,
            part,
            what,
            var,
            at,
            unit,
            sure,
            domain,
        } = self;
        let how = if *sure {
            "is not finite"
        } else {
            "could not be shown finite (its enclosure stays unbounded)"
        };
        write!(
            f,
            "{owner} {id}: `{part}` in `{text}`: its {what} {how} at {var} = {at} {unit} ({var} in [{}, {}] {unit} is the domain the run can reach; shown by interval arithmetic, which bounds the expression at every double of it)",
            domain.0, domain.1
        )
    }
}
