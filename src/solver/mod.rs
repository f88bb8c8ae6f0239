//! Time integration.
