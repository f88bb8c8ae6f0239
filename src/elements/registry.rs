//! The element halves of the registered kinds (`crate::kinds`): one `KIND` per kind,
//! beside its element in `<family>/<kind>`; [`build`](super::build) goes through [`KINDS`].

use super::{BuildError, Element};
use crate::model::{self, Model, NodeId};

/// The build of a kind: the model's element → the runtime element.
pub type BuildFn = fn(&Model, &model::Element) -> Result<Box<dyn Element>, BuildError>;

/// The element half of an element kind.
pub struct Kind {
    /// The element types it builds (the model's `ElementKind::keyword`).
    pub types: &'static [&'static str],
    /// The model's element → the runtime element. The model is valid (every reference
    /// resolves); data the element cannot use is a [`BuildError::Invalid`], never a panic.
    pub build: BuildFn,
}

macro_rules! kinds {
    ($($family:ident :: $kind:ident),* $(,)?) => {
        /// The element halves of the registered kinds, in the registry's order.
        pub static KINDS: &[&Kind] = &[$(&super::$family::$kind::KIND),*];
    };
}
crate::kinds::element_kinds!(kinds);

/// The kind that builds elements of type `keyword`.
pub fn kind(keyword: &str) -> Option<&'static Kind> {
    KINDS.iter().copied().find(|k| k.types.contains(&keyword))
}

/// The index of node `id` in the model's node map (the solver's node numbering).
pub fn node_index(model: &Model, id: &NodeId) -> usize {
    model
        .nodes
        .get_index_of(id)
        .expect("validated model: nodes exist")
}

/// The error of a kind given an element of another kind: the registry is wrong.
pub fn not_mine(el: &model::Element, kind: &str) -> BuildError {
    BuildError::Invalid {
        element: el.id,
        message: format!("{} given to the builder of {kind}", el.kind.keyword()),
    }
}
