//! Stage 1 (syntax): logical lines → cards grouped by section.
//!
//! A line whose first token is a section keyword opens that section. `MATERIALS`,
//! `SECTIONS`, `NODES`, `ELEMENTS`, `FUNCTIONS`, `LOADS`, `INITIAL` and `PARAMETERS` are block sections: their
//! header stands alone and the following lines are their cards. `TITLE`, `ANALYSIS` and
//! `OUTPUT` are one-line sections: the line is the card. `END` stops reading.

use super::error::{DeckError, DeckErrorKind};
use super::lex::{Line, Token};
use crate::model::Span;

/// The sections of a deck.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Section {
    Title,
    Materials,
    Sections,
    Nodes,
    Elements,
    Functions,
    Loads,
    Initial,
    Analysis,
    Output,
    Parameters,
}

impl Section {
    /// Section keywords (the `END` terminator is handled apart).
    const ALL: [(&'static str, Section); 11] = [
        ("TITLE", Section::Title),
        ("MATERIALS", Section::Materials),
        ("SECTIONS", Section::Sections),
        ("NODES", Section::Nodes),
        ("ELEMENTS", Section::Elements),
        ("FUNCTIONS", Section::Functions),
        ("LOADS", Section::Loads),
        ("INITIAL", Section::Initial),
        ("ANALYSIS", Section::Analysis),
        ("OUTPUT", Section::Output),
        ("PARAMETERS", Section::Parameters),
    ];

    fn one_line(self) -> bool {
        matches!(self, Section::Title | Section::Analysis | Section::Output)
    }

    /// Keywords that may start a card of this section.
    fn card_keywords(self) -> &'static [&'static str] {
        match self {
            Section::Nodes => &["FIX"],
            Section::Loads => &["GRAVITY", "FORCE", "MOMENT"],
            _ => &[],
        }
    }
}

const SECTION_LIST: &str = "TITLE, PARAMETERS, MATERIALS, SECTIONS, NODES, ELEMENTS, FUNCTIONS, LOADS, INITIAL, ANALYSIS, OUTPUT or END";

/// One card: the tokens of a logical line, in the section it belongs to. For one-line
/// sections the first token is the section keyword itself.
#[derive(Debug, Clone)]
pub(crate) struct Card<'a> {
    /// The section.
    pub section: Section,
    /// Tokens (never empty).
    pub tokens: Vec<Token<'a>>,
}

impl Card<'_> {
    /// From the first token's start to the last token's end.
    pub fn span(&self) -> Span {
        match (self.tokens.first(), self.tokens.last()) {
            (Some(a), Some(b)) => Span::new(a.span.start, b.span.end),
            _ => Span::default(),
        }
    }
}

/// Groups logical lines into cards; errors for unknown keywords and stray cards.
pub(crate) fn cards<'a>(lines: Vec<Line<'a>>, errors: &mut Vec<DeckError>) -> Vec<Card<'a>> {
    let mut out = Vec::new();
    let mut current: Option<Section> = None;
    for line in lines {
        let Some(first) = line.tokens.first() else {
            continue;
        };
        if first.is_kw("END") {
            if let Some(extra) = line.tokens.get(1) {
                errors.push(DeckError::new(
                    DeckErrorKind::ExtraToken {
                        found: extra.text.to_string(),
                        context: "END".into(),
                    },
                    extra.span,
                ));
            }
            break;
        }
        let header = Section::ALL
            .iter()
            .find(|(kw, _)| first.is_kw(kw))
            .map(|(_, s)| *s);
        if let Some(section) = header {
            if section.one_line() {
                current = None;
                out.push(Card {
                    section,
                    tokens: line.tokens,
                });
            } else {
                current = Some(section);
                if let Some(extra) = line.tokens.get(1) {
                    errors.push(DeckError::new(
                        DeckErrorKind::ExtraToken {
                            found: extra.text.to_string(),
                            context: format!("{} header", first.text.to_uppercase()),
                        },
                        extra.span,
                    ));
                }
            }
            continue;
        }
        let is_word = first.number.is_none();
        match current {
            // A PARAMETERS card starts with the parameter's name.
            Some(section)
                if !is_word
                    || section == Section::Parameters
                    || section.card_keywords().iter().any(|k| first.is_kw(k)) =>
            {
                out.push(Card {
                    section,
                    tokens: line.tokens,
                });
            }
            Some(section) => {
                let mut expected = String::from("a section keyword (");
                expected.push_str(SECTION_LIST);
                expected.push(')');
                let kws = section.card_keywords();
                if kws.is_empty() {
                    expected.push_str(" or a card starting with a number");
                } else {
                    expected.push_str(", a card keyword (");
                    expected.push_str(&kws.join(", "));
                    expected.push_str(") or a card starting with a number");
                }
                errors.push(DeckError::new(
                    DeckErrorKind::UnknownSection {
                        found: first.text.to_string(),
                        expected,
                    },
                    first.span,
                ));
            }
            None if is_word => errors.push(DeckError::new(
                DeckErrorKind::UnknownSection {
                    found: first.text.to_string(),
                    expected: format!("a section keyword ({SECTION_LIST})"),
                },
                first.span,
            )),
            None => errors.push(DeckError::new(
                DeckErrorKind::CardOutsideSection {
                    found: first.text.to_string(),
                    expected: SECTION_LIST.to_string(),
                },
                first.span,
            )),
        }
    }
    out
}
