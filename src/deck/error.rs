//! Deck errors: one [`DeckError`] per mistake, all of a deck gathered in [`DeckErrors`],
//! rendered like a compiler diagnostic by miette.

use crate::model::Span;
use miette::{Diagnostic, LabeledSpan};
use std::fmt;

/// What is wrong. Each message names the offending text and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DeckErrorKind {
    /// The deck file could not be read.
    #[error("cannot read deck file `{path}`: {reason}")]
    Io {
        /// The path as given.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
    /// The deck file is not UTF-8 text.
    #[error(
        "deck file `{path}` is not UTF-8 text (invalid byte at offset {offset}): the whole file must be UTF-8, also after END"
    )]
    NotUtf8 {
        /// The path as given.
        path: String,
        /// Byte offset of the first invalid byte.
        offset: usize,
    },
    /// Nothing but blanks and comments.
    #[error("empty deck: no cards found (a deck needs at least an ANALYSIS card)")]
    EmptyDeck,
    /// No ANALYSIS card.
    #[error(
        "no ANALYSIS card: expected `ANALYSIS DYNAMIC ...`, `ANALYSIS STATIC ...` or `ANALYSIS MODES n`"
    )]
    MissingAnalysis,
    /// A card that may appear once appears again.
    #[error("second {keyword} card: only one is allowed (the first is on line {first_line})")]
    RepeatedCard {
        /// The card keyword (ANALYSIS, OUTPUT, TITLE, GRAVITY).
        keyword: String,
        /// Line of the first one.
        first_line: usize,
    },
    /// A line starts with a word that is neither a section keyword nor a card keyword.
    #[error("unknown keyword `{found}` at the start of a line: expected {expected}")]
    UnknownSection {
        /// The word.
        found: String,
        /// What is allowed there.
        expected: String,
    },
    /// A data card before the first section keyword (or after a one-line section).
    #[error("card `{found}` is outside a section: expected a section keyword first ({expected})")]
    CardOutsideSection {
        /// The first token of the card.
        found: String,
        /// What is allowed there.
        expected: String,
    },
    /// A keyword not allowed at this place of a card.
    #[error("unexpected `{found}` in {context}: expected {expected}")]
    UnknownKeyword {
        /// The token.
        found: String,
        /// The card.
        context: String,
        /// What is allowed there.
        expected: String,
    },
    /// An unknown element type.
    #[error("unknown element type `{found}`: expected one of {expected}")]
    UnknownElementType {
        /// The word.
        found: String,
        /// The element types the deck reads (the registry's, `crate::kinds`), by commas.
        expected: String,
    },
    /// A token where a number is due is not a number.
    #[error("expected {expected}, found `{found}` (not a number)")]
    ExpectedNumber {
        /// The field.
        expected: String,
        /// The token.
        found: String,
    },
    /// A token where a whole number is due is not one.
    #[error("expected {expected} (a whole number from 0 to 4294967295), found `{found}`")]
    ExpectedInteger {
        /// The field.
        expected: String,
        /// The token.
        found: String,
    },
    /// A number too large to represent.
    #[error("number `{found}` for {expected} is out of range (not a finite value)")]
    NonFinite {
        /// The field.
        expected: String,
        /// The token.
        found: String,
    },
    /// The card ends before a required field.
    #[error("missing {expected}: the card ends too early")]
    MissingField {
        /// The field.
        expected: String,
    },
    /// Tokens left over at the end of a card.
    #[error("unexpected `{found}` at the end of the {context} card: too many fields")]
    ExtraToken {
        /// The first extra token.
        found: String,
        /// The card.
        context: String,
    },
    /// A required keyword is absent.
    #[error("{context} needs {expected}")]
    MissingKeyword {
        /// The card.
        context: String,
        /// The missing keyword and its value.
        expected: String,
    },
    /// A keyword given twice in one card.
    #[error("`{keyword}` given twice in {context}")]
    RepeatedKeyword {
        /// The keyword.
        keyword: String,
        /// The card.
        context: String,
    },
    /// Two keywords that exclude each other.
    #[error("{first} and {second} cannot both be given in {context}: give one of them")]
    Conflict {
        /// The first keyword.
        first: String,
        /// The second keyword.
        second: String,
        /// The card.
        context: String,
    },
    /// An entity number defined twice.
    #[error("duplicate {what} number {id}: already defined on line {first_line}")]
    Duplicate {
        /// node, element, material, section or function.
        what: &'static str,
        /// The number.
        id: u32,
        /// Line of the first definition.
        first_line: usize,
    },
    /// A reference to an entity never defined.
    #[error("undefined {what} {id}: no {what} with this number is defined")]
    Undefined {
        /// node, element, material, section or function.
        what: &'static str,
        /// The number.
        id: u32,
    },
    /// A generation `a TO b` with `b <= a` (or overflowing numbers).
    #[error("bad generation `{first} TO {last}`: {reason}")]
    BadGeneration {
        /// First number.
        first: u32,
        /// Last number.
        last: u32,
        /// What is wrong.
        reason: String,
    },
    /// A BEAM whose two nodes are the same.
    #[error("BEAM element {element} joins node {node} to itself: the two nodes must differ")]
    BeamSameNode {
        /// Element number.
        element: u32,
        /// Node number.
        node: u32,
    },
    /// A BEAM of zero length.
    #[error(
        "BEAM element {element} has zero length: nodes {first} and {second} are at the same position"
    )]
    BeamZeroLength {
        /// Element number.
        element: u32,
        /// First node.
        first: u32,
        /// Second node.
        second: u32,
    },
    /// A BEAM's ARC that does not make a circular arc with its end nodes.
    #[error("ARC of BEAM element {element}: {reason}")]
    BadArc {
        /// Element number.
        element: u32,
        /// What is wrong with the three points.
        reason: String,
    },
    /// A BEAM that names a material for a section given by its properties per unit length.
    #[error(
        "BEAM element {element} names material {material}, but section {section} gives its stiffness and inertia per unit length (PROPERTIES): remove MAT (a damping coefficient goes on the section card: DAMPING)"
    )]
    MaterialNotUsed {
        /// Element number.
        element: u32,
        /// The material named.
        material: u32,
        /// The section of properties.
        section: u32,
    },
    /// A zero or non-finite direction vector.
    #[error("{what} must be a non-zero finite vector, found ({x}, {y}, {z})")]
    BadAxis {
        /// Which vector.
        what: String,
        /// Components as written.
        x: String,
        /// Components as written.
        y: String,
        /// Components as written.
        z: String,
    },
    /// BEAM AXIS2 along the beam.
    #[error(
        "AXIS2 of BEAM element {element} is parallel to the beam: it must point across the beam"
    )]
    Axis2Parallel {
        /// Element number.
        element: u32,
    },
    /// PLANE vectors parallel.
    #[error("PLANE vectors of a CAME profile are parallel: e1 and e2 must span a plane")]
    PlaneParallel,
    /// UJOINT axes not perpendicular.
    #[error(
        "UJOINT element {element}: AXIS1 and AXIS2 must be perpendicular (|a1·a2| = {dot:e} > 1e-6 |a1||a2|)"
    )]
    UJointNotPerpendicular {
        /// Element number.
        element: u32,
        /// `|a1·a2| / (|a1||a2|)`.
        dot: f64,
    },
    /// A value outside its admissible range.
    #[error("{field} = {found} is out of range: expected {range}")]
    OutOfRange {
        /// The field.
        field: String,
        /// The value as written.
        found: String,
        /// The admissible range.
        range: String,
    },
    /// A TABLE with an odd number of values.
    #[error("TABLE values come in pairs `t f`: found {count} values (an odd number or none)")]
    OddTable {
        /// Number of values.
        count: usize,
    },
    /// A TABLE with decreasing times.
    #[error("TABLE times must be non-decreasing: t = {found} comes after t = {previous}")]
    DecreasingTime {
        /// The offending time as written.
        found: String,
        /// The previous time as written.
        previous: String,
    },
    /// A SPLINE with an odd number of values.
    #[error("SPLINE values come in pairs `t f`: found {count} values (an odd number)")]
    OddSpline {
        /// Number of values.
        count: usize,
    },
    /// Points that do not make a spline (too few, times not increasing).
    #[error("SPLINE: {reason}")]
    BadSpline {
        /// Why.
        reason: crate::model::SplineError,
    },
    /// An EXPR function not shown finite, with the derivatives its use needs, on the
    /// domain of that use (interval arithmetic: `deck/build/functions.rs`). (Boxed: the
    /// error travels in every `Result` of the parser.)
    #[error("{0}")]
    FunctionNotFinite(Box<FunctionNotFinite>),
    /// An expression that does not parse.
    #[error("bad expression `{text}`: expected {expected}, found {found}")]
    BadExpression {
        /// The whole field.
        text: String,
        /// What would have been accepted there.
        expected: String,
        /// What is there.
        found: String,
    },
    /// `$name` without a parameter `name` (defined before, in a PARAMETERS section).
    #[error(
        "undefined parameter `{name}`: {known} (a parameter may only use the parameters defined before it)"
    )]
    UndefinedParameter {
        /// The name after `$`.
        name: String,
        /// The parameters defined, as a sentence.
        known: String,
    },
    /// A function that expressions do not have.
    #[error(
        "unknown function `{name}` in `{text}`: expected one of sqrt, sin, cos, exp, log, abs (or pi; t, the time, only in a FUNCTIONS EXPR)"
    )]
    UnknownFunction {
        /// The name.
        name: String,
        /// The whole field.
        text: String,
    },
    /// An expression whose value (or part) is not a finite number.
    #[error("expression `{text}`: {what} is not a finite number")]
    ExpressionNotFinite {
        /// The whole field.
        text: String,
        /// The part that overflowed or is undefined.
        what: String,
    },
    /// An expression nested deeper than the parser allows (issue 28: a stack overflow
    /// before).
    #[error(
        "expression `{text}` is nested too deeply: at most {limit} levels of parentheses, calls, signs and powers"
    )]
    ExpressionTooDeep {
        /// The whole field.
        text: String,
        /// The deepest nesting allowed.
        limit: usize,
    },
    /// A deck beyond what the reader accepts (grammar.md, "Limits"): refused before it
    /// can exhaust time or memory.
    #[error("{what} exceeds the limit of {limit} {unit} (see grammar.md, Limits)")]
    TooLarge {
        /// What is too large (the deck, a line, a field, a card).
        what: &'static str,
        /// The limit.
        limit: usize,
        /// Its unit (bytes, fields).
        unit: &'static str,
    },
    /// A model that would not fit in the memory the process may take (model::budget),
    /// refused before its nodes and elements are generated.
    #[error("{request}: {reason}")]
    ModelTooLarge {
        /// What asked for it (`DIVIDE 1000000`).
        request: String,
        /// The estimate and the limit.
        reason: String,
    },
    /// A joint or CAME whose nodes repeat one node.
    #[error("{keyword} element {element} joins node {node} to itself: its nodes must differ")]
    NodeToItself {
        /// HINGE, RIGID, SPHERICAL, CAME, ...
        keyword: &'static str,
        /// Element number.
        element: u32,
        /// The repeated node.
        node: u32,
    },
    /// A CAME whose two profiles cannot touch or are not supported together.
    #[error("CAME element {element}: {reason}")]
    CameProfiles {
        /// Element number.
        element: u32,
        /// Why (and what to give instead).
        reason: &'static str,
    },
    /// SPLINE points that do not make a curve (two consecutive ones coincide).
    #[error("SPLINE point {index} coincides with point {previous}: consecutive points must differ")]
    SplinePointsCoincide {
        /// 1-based number of the point.
        index: usize,
        /// 1-based number of the point it repeats.
        previous: usize,
    },
    /// A PARAMETERS card whose first field is not a valid name.
    #[error(
        "bad parameter name `{found}`: expected a letter or `_` followed by letters, digits or `_`"
    )]
    BadParameterName {
        /// The field.
        found: String,
    },
    /// A parameter defined twice.
    #[error("parameter `{name}` defined again: already defined on line {first_line}")]
    DuplicateParameter {
        /// The name.
        name: String,
        /// Line of the first definition.
        first_line: usize,
    },
    /// A SPRING whose nodes coincide at t = 0.
    #[error("SPRING element {element} joins nodes {first} and {second} at zero distance: {reason}")]
    SpringZeroLength {
        /// The spring.
        element: u32,
        /// Its first node.
        first: u32,
        /// Its second node.
        second: u32,
        /// Why that is refused.
        reason: &'static str,
    },
    /// An RSPRING, PID or CONTROL (its actuator or a sensor) naming an element that is
    /// not a HINGE.
    #[error("{by} element {element} names element {target}, a {found}: {what} a HINGE")]
    NotAHinge {
        /// The referring element's type keyword (`RSPRING`, `PID`, `CONTROL`).
        by: &'static str,
        /// What it needs the hinge for.
        what: &'static str,
        /// The referring element.
        element: u32,
        /// The element it names.
        target: u32,
        /// That element's type keyword.
        found: &'static str,
    },
    /// A driver (a `DRIVE` on a joint, a `PRESCRIBED` element) that cannot be built.
    #[error("{context}: {reason}")]
    BadDrive {
        /// The card (`element 3 (UJOINT)`).
        context: String,
        /// What is wrong and what is accepted.
        reason: String,
    },
    /// `--set name=value` (or a sweep plan) for a parameter the deck does not define.
    #[error("cannot set parameter `{name}`: the deck does not define it ({known})")]
    UnknownOverride {
        /// The name given.
        name: String,
        /// The parameters defined, as a sentence.
        known: String,
    },
}

/// One mistake in a deck: what, and where (byte span in the source; `None` for file errors).
#[derive(Debug, Clone, PartialEq)]
pub struct DeckError {
    /// What is wrong.
    pub kind: DeckErrorKind,
    /// Where, in bytes of the source text.
    pub span: Option<Span>,
}

impl DeckError {
    /// An error at `span`.
    pub fn new(kind: DeckErrorKind, span: Span) -> Self {
        DeckError {
            kind,
            span: Some(span),
        }
    }

    /// A diagnostic code per kind of mistake, e.g. `mecano::deck::undefined`.
    pub fn code(&self) -> &'static str {
        use DeckErrorKind as K;
        match &self.kind {
            K::Io { .. } => "mecano::deck::io",
            K::NotUtf8 { .. } => "mecano::deck::not_utf8",
            K::EmptyDeck => "mecano::deck::empty",
            K::MissingAnalysis => "mecano::deck::no_analysis",
            K::RepeatedCard { .. } => "mecano::deck::repeated_card",
            K::UnknownSection { .. } | K::CardOutsideSection { .. } => {
                "mecano::deck::unknown_section"
            }
            K::UnknownKeyword { .. } => "mecano::deck::unknown_keyword",
            K::UnknownElementType { .. } => "mecano::deck::unknown_element",
            K::ExpectedNumber { .. } | K::ExpectedInteger { .. } | K::NonFinite { .. } => {
                "mecano::deck::bad_number"
            }
            K::MissingField { .. } | K::MissingKeyword { .. } => "mecano::deck::missing",
            K::ExtraToken { .. } => "mecano::deck::extra",
            K::RepeatedKeyword { .. } | K::Conflict { .. } => "mecano::deck::conflict",
            K::Duplicate { .. } => "mecano::deck::duplicate",
            K::Undefined { .. } => "mecano::deck::undefined",
            K::BadGeneration { .. } => "mecano::deck::generation",
            K::BeamSameNode { .. }
            | K::BeamZeroLength { .. }
            | K::BadArc { .. }
            | K::MaterialNotUsed { .. } => "mecano::deck::beam",
            K::BadAxis { .. }
            | K::Axis2Parallel { .. }
            | K::PlaneParallel
            | K::UJointNotPerpendicular { .. } => "mecano::deck::axis",
            K::OutOfRange { .. } => "mecano::deck::range",
            K::OddTable { .. }
            | K::DecreasingTime { .. }
            | K::OddSpline { .. }
            | K::BadSpline { .. } => "mecano::deck::table",
            K::BadExpression { .. } | K::UnknownFunction { .. } | K::ExpressionTooDeep { .. } => {
                "mecano::deck::expression"
            }
            K::ExpressionNotFinite { .. } | K::FunctionNotFinite { .. } => {
                "mecano::deck::expression_value"
            }
            K::UndefinedParameter { .. } | K::UnknownOverride { .. } => {
                "mecano::deck::undefined_parameter"
            }
            K::BadParameterName { .. } | K::DuplicateParameter { .. } => "mecano::deck::parameter",
            K::TooLarge { .. } | K::ModelTooLarge { .. } => "mecano::deck::too_large",
            K::NodeToItself { .. } | K::CameProfiles { .. } | K::SplinePointsCoincide { .. } => {
                "mecano::deck::element"
            }
            K::SpringZeroLength { .. } | K::NotAHinge { .. } => "mecano::deck::spring",
            K::BadDrive { .. } => "mecano::deck::drive",
        }
    }

    /// The short text under the underlined span.
    fn label(&self) -> &'static str {
        use DeckErrorKind as K;
        match &self.kind {
            K::ExpectedNumber { .. } => "not a number",
            K::ExpectedInteger { .. } => "not a whole number",
            K::NonFinite { .. } => "too large",
            K::MissingField { .. } | K::MissingKeyword { .. } => "card ends here",
            K::ExtraToken { .. } => "extra field",
            K::Duplicate { .. } | K::RepeatedCard { .. } | K::RepeatedKeyword { .. } => {
                "defined again here"
            }
            K::Undefined { .. } | K::UndefinedParameter { .. } => "undefined",
            K::BadExpression { .. } | K::UnknownFunction { .. } => "unexpected here",
            K::ExpressionNotFinite { .. } => "not finite",
            K::DuplicateParameter { .. } => "defined again here",
            K::UnknownSection { .. }
            | K::UnknownKeyword { .. }
            | K::UnknownElementType { .. }
            | K::CardOutsideSection { .. } => "unknown here",
            K::OutOfRange { .. } | K::DecreasingTime { .. } => "out of range",
            _ => "here",
        }
    }

    fn labeled_span(&self) -> Option<LabeledSpan> {
        self.span.map(|s| {
            LabeledSpan::new(
                Some(self.label().to_string()),
                s.start,
                s.end.saturating_sub(s.start),
            )
        })
    }
}

impl fmt::Display for DeckError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.kind.fmt(f)
    }
}

impl std::error::Error for DeckError {}

impl Diagnostic for DeckError {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        Some(Box::new(DeckError::code(self)))
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        self.labeled_span()
            .map(|l| Box::new(std::iter::once(l)) as Box<dyn Iterator<Item = LabeledSpan>>)
    }
}

mod echo;
mod function;
mod list;
pub use echo::{ECHO_CHARS, short};
pub use function::FunctionNotFinite;
pub use list::DeckErrors;
pub(crate) use list::line_col;
