//! Finite rotations.
