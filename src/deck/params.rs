//! Deck parameters: the `PARAMETERS` section (`name value`) and the expressions of numeric
//! fields (`E $E`, `C 2*$zeta*sqrt($k*$m)`), resolved between stage 1 (cards) and stage 2
//! (build).
//!
//! Parameters are read in deck order; a parameter's value is a number or an expression of
//! the parameters defined before it. An override (`--set name=value`, or a case of a sweep)
//! replaces the value of a parameter the deck defines — the parameters after it that use
//! it follow — and naming a parameter the deck does not define is an error.
//!
//! Then every field of every other card that looks like an expression
//! ([`expr::looks_like_expression`]) is evaluated with all parameters; its value becomes the
//! token's number, so that stage 2 reads it like any number. An expression that fails keeps
//! its error in the token: it is reported, located to the offending part of the field, when
//! a numeric field reads the token. Titles and the `OUTPUT DIR` path are text, never
//! evaluated.

use super::cards::{Card, Section};
use super::error::{DeckError, DeckErrorKind as K, line_col};
use super::expr::{self, ExprError, ExprErrorKind};
use super::lex::Token;
use crate::model::Span;
use indexmap::IndexMap;

/// The parameters' names as a sentence for error messages.
fn known<'n>(names: impl Iterator<Item = &'n String>) -> String {
    let names: Vec<String> = names.map(|n| format!("`{n}`")).collect();
    if names.is_empty() {
        "no parameter is defined".into()
    } else {
        format!("defined: {}", names.join(", "))
    }
}

/// Turns an expression error in `tok` into a deck error located inside the token.
fn deck_error(tok: &Token<'_>, e: ExprError, params: &IndexMap<String, (f64, Span)>) -> DeckError {
    located(tok, e, || known(params.keys()))
}

/// [`deck_error`] with the parameters' sentence computed by `known` when needed.
fn located(tok: &Token<'_>, e: ExprError, known: impl Fn() -> String) -> DeckError {
    let start = (tok.span.start + e.at).min(tok.span.end);
    let span = Span::new(start, (start + e.len).min(tok.span.end));
    let text = tok.text.to_string();
    let kind = match e.kind {
        ExprErrorKind::Syntax { expected, found } => K::BadExpression {
            text,
            expected,
            found,
        },
        ExprErrorKind::UndefinedParameter { name } => K::UndefinedParameter {
            name,
            known: known(),
        },
        ExprErrorKind::UnknownFunction { name } => K::UnknownFunction { name, text },
        ExprErrorKind::NotFinite { what } => K::ExpressionNotFinite { text, what },
        ExprErrorKind::TooDeep => K::ExpressionTooDeep {
            text,
            limit: expr::MAX_DEPTH,
        },
    };
    DeckError::new(kind, span)
}

/// [`deck_error`] outside a deck (no parameters defined): `--set name=value`.
pub(crate) fn expr_error(tok: &Token<'_>, e: ExprError) -> DeckError {
    deck_error(tok, e, &IndexMap::new())
}

/// The field `tok` read as an expression of the time `t` (`FUNCTIONS … EXPR`), with the
/// parameters' values in force; errors located inside the field.
pub(crate) fn time_expression(
    tok: &Token<'_>,
    params: &IndexMap<String, f64>,
) -> Result<crate::model::Expr, DeckError> {
    expr::parse_time(tok.text, &|n| params.get(n).copied())
        .map_err(|e| located(tok, e, || known(params.keys())))
}

/// The field `tok` read as a control law (`ELEMENTS … CONTROL … LAW`): an expression of
/// `t` and of sensors, with the parameters' values in force; errors located inside the
/// field (a name that is neither a function nor a sensor names both lists).
pub(crate) fn law_expression(
    tok: &Token<'_>,
    params: &IndexMap<String, f64>,
) -> Result<(crate::model::Expr, Vec<expr::SensorRef>), DeckError> {
    expr::parse_law(tok.text, &|n| params.get(n).copied()).map_err(|mut e| {
        if let ExprErrorKind::UnknownFunction { name } = &e.kind {
            e.kind = ExprErrorKind::Syntax {
                expected: format!(
                    "a sensor ({}) or a function (sqrt, sin, cos, exp, log, abs)",
                    expr::SENSORS
                ),
                found: format!("`{name}`"),
            };
        }
        located(tok, e, || known(params.keys()))
    })
}

/// The value of a field: its number, or its expression evaluated with `params`.
fn value(tok: &Token<'_>, params: &IndexMap<String, (f64, Span)>) -> Result<f64, DeckError> {
    if let Some(v) = tok.number {
        if v.is_finite() {
            return Ok(v);
        }
        return Err(DeckError::new(
            K::NonFinite {
                expected: "a parameter value".into(),
                found: tok.text.into(),
            },
            tok.span,
        ));
    }
    expr::eval(tok.text, &|n| params.get(n).map(|p| p.0)).map_err(|e| deck_error(tok, e, params))
}

/// Reads the PARAMETERS cards (applying `overrides`), evaluates the expressions of all other
/// cards in place, and returns the parameters (name → value in force) in deck order. Errors
/// go to `errors`.
pub(crate) fn resolve(
    src: &str,
    cards: &mut [Card<'_>],
    overrides: &[(String, f64)],
    errors: &mut Vec<DeckError>,
) -> IndexMap<String, f64> {
    let mut params: IndexMap<String, (f64, Span)> = IndexMap::new();
    for card in cards.iter().filter(|c| c.section == Section::Parameters) {
        let name_tok = &card.tokens[0];
        let name = name_tok.text;
        if !expr::is_name(name) {
            errors.push(DeckError::new(
                K::BadParameterName { found: name.into() },
                name_tok.span,
            ));
            continue;
        }
        if let Some((_, first)) = params.get(name) {
            errors.push(DeckError::new(
                K::DuplicateParameter {
                    name: name.into(),
                    first_line: line_col(src, first.start).0,
                },
                name_tok.span,
            ));
            continue;
        }
        let Some(value_tok) = card.tokens.get(1) else {
            errors.push(DeckError::new(
                K::MissingField {
                    expected: format!(
                        "the value of parameter `{}` in PARAMETERS card",
                        crate::deck::short(name)
                    ),
                },
                Span::new(name_tok.span.end, name_tok.span.end),
            ));
            continue;
        };
        if let Some(extra) = card.tokens.get(2) {
            errors.push(DeckError::new(
                K::ExtraToken {
                    found: extra.text.into(),
                    context: "PARAMETERS".into(),
                },
                extra.span,
            ));
            continue;
        }
        let default = value(value_tok, &params);
        let v = match overrides.iter().rev().find(|(n, _)| n == name) {
            Some((_, v)) => {
                // The default must still be a valid value: a deck is valid or not
                // whatever the overrides.
                if let Err(e) = default {
                    errors.push(e);
                }
                *v
            }
            None => match default {
                Ok(v) => v,
                Err(e) => {
                    errors.push(e);
                    continue;
                }
            },
        };
        params.insert(name.to_string(), (v, name_tok.span));
    }
    for (i, (name, _)) in overrides.iter().enumerate() {
        let repeated = overrides[..i].iter().any(|(n, _)| n == name);
        if !params.contains_key(name) && !repeated {
            errors.push(DeckError {
                kind: K::UnknownOverride {
                    name: name.clone(),
                    known: known(params.keys()),
                },
                span: None,
            });
        }
    }
    for card in cards.iter_mut() {
        match card.section {
            Section::Parameters | Section::Title => continue,
            _ => {}
        }
        let mut after_dir = false;
        for tok in card.tokens.iter_mut() {
            let is_path = after_dir;
            after_dir = card.section == Section::Output && tok.is_kw("DIR");
            if is_path || tok.number.is_some() || !expr::looks_like_expression(tok.text) {
                continue;
            }
            match value(tok, &params) {
                Ok(v) => tok.number = Some(v),
                Err(e) => tok.bad_expr = Some(Box::new(e)),
            }
        }
    }
    params.into_iter().map(|(n, (v, _))| (n, v)).collect()
}

#[cfg(test)]
mod tests {
    use crate::deck::{DeckErrorKind, parse_deck, parse_deck_with};

    const DECK: &str = "PARAMETERS\n E 2.1e11\n h 1e-4\n k2 (2 * $E)\nMATERIALS\n 1 E $E NU 0.3 RHO 7800\n\
        SECTIONS\n 1 A 1e-4 I2 1e-8 I3 1e-8 J 2e-8\nNODES\n 1 0 0 0 FIX ALL\n 2 1 0 0\n\
        ELEMENTS\n 1 BEAM 1 2 MAT 1 SEC 1\nANALYSIS DYNAMIC STEP $h END 100*$h\nOUTPUT DIR out/$h\n";

    #[test]
    fn parameters_fill_fields_and_overrides_follow() {
        let m = parse_deck(DECK, "p.dat").expect("valid");
        assert_eq!(m.parameters["E"], 2.1e11);
        assert_eq!(m.parameters["k2"], 4.2e11);
        let mat = m.materials.values().next().expect("a material");
        assert_eq!(mat.young, 2.1e11);
        assert_eq!(m.output.dir.as_deref(), Some("out/$h"));
        let m = parse_deck_with(DECK, "p.dat", &[("E".into(), 1e10)]).expect("valid");
        assert_eq!(
            m.parameters["k2"], 2e10,
            "a parameter follows the override of one it uses"
        );
        assert_eq!(m.materials.values().next().map(|x| x.young), Some(1e10));
        match &m.analysis {
            crate::model::Analysis::Dynamic { step, end, .. } => {
                assert_eq!(*step, 1e-4);
                assert_eq!(*end, 100.0 * 1e-4);
            }
            _ => panic!("dynamic expected"),
        }
    }

    #[test]
    fn errors_are_located_and_typed() {
        let bad = DECK.replace("1 E $E NU", "1 E 2*$F NU");
        let e = parse_deck(&bad, "p.dat").expect_err("undefined parameter");
        // (and, as for any bad material card, the BEAM's reference to material 1)
        assert_eq!(e.errors().len(), 2, "{:?}", e.errors());
        assert!(
            matches!(&e.errors()[0].kind, DeckErrorKind::UndefinedParameter { name, .. } if name == "F")
        );
        let at = bad.find("2*$F").expect("there") + 2;
        let span = e.errors()[0].span.expect("located");
        assert_eq!((span.start, span.end), (at, at + 2));
        assert_eq!(e.line_col(0), Some((6, 8)));

        let bad = DECK.replace("END 100*$h", "END 100*");
        let e = parse_deck(&bad, "p.dat").expect_err("syntax");
        assert!(matches!(
            &e.errors()[0].kind,
            DeckErrorKind::BadExpression { .. }
        ));

        let bad = DECK.replace(" h 1e-4\n", " h 1e-4\n h 2\n 3x 1\n");
        let e = parse_deck(&bad, "p.dat").expect_err("duplicate and bad name");
        let kinds: Vec<_> = e.errors().iter().map(|e| e.code()).collect();
        assert_eq!(
            kinds,
            ["mecano::deck::parameter", "mecano::deck::parameter"]
        );

        let e = parse_deck_with(DECK, "p.dat", &[("G".into(), 1.0)]).expect_err("unknown");
        assert!(
            matches!(&e.errors()[0].kind, DeckErrorKind::UnknownOverride { name, .. } if name == "G")
        );

        // A parameter may only use those before it.
        let bad = DECK.replace(" E 2.1e11\n", " a $E\n E 2.1e11\n");
        assert!(parse_deck(&bad, "p.dat").is_err());
        // A value out of range is reported like a number's.
        let e = parse_deck_with(DECK, "p.dat", &[("E".into(), -1.0)]).expect_err("range");
        assert_eq!(e.errors()[0].code(), "mecano::deck::range");
    }
}
