//! Forces: springs, dampers, bushings, rotational springs (issue 25 §3; grammar.md,
//! "Springs, bushings and rotational springs").

pub(super) mod bushing;
pub(super) mod control;
pub(super) mod rspring;
pub(super) mod spring;
