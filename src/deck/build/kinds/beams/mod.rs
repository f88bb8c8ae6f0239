//! Beams: the geometrically exact beam of any order, straight or on an arc, rigid or
//! elastic by its section (grammar.md, "Elements").

pub(super) mod beam;
