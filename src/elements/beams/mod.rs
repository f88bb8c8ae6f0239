//! Beams: the geometrically exact beam of any order, straight or curved, and its rigid
//! limit (grammar.md, "Elements").

pub mod beam;
