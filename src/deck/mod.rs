//! The deck: text → raw cards (syntax) → [`crate::model::Model`] (meaning).
//! (Being written; see `grammar.md`.)
