//! Typed identifiers: the user's own numbers, never dense indices.
//!
//! A deck numbers its nodes, elements, materials, sections and functions freely
//! (numbers need not be contiguous). The model keeps those numbers as keys of
//! [`indexmap::IndexMap`]s; the solver maps them to dense indices once, with
//! `IndexMap::get_index_of`.

use std::fmt;

macro_rules! typed_id {
    ($(#[$doc:meta])* $name:ident, $label:literal) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
        pub struct $name(pub u32);

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, "{} {}", $label, self.0)
            }
        }
    };
}

typed_id!(
    /// A node number as written in the deck.
    NodeId,
    "node"
);
typed_id!(
    /// An element number as written in the deck.
    ElementId,
    "element"
);
typed_id!(
    /// A material number as written in the deck.
    MaterialId,
    "material"
);
typed_id!(
    /// A section number as written in the deck.
    SectionId,
    "section"
);
typed_id!(
    /// A time-function number as written in the deck.
    FunctionId,
    "function"
);
