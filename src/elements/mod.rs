//! Element library.
