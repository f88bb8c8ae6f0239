//! Forces: the spring family of issue 25 §3 — `SPRING`, `BUSHING`, `RSPRING`
//! (`spring::from_model` builds all three).

pub mod bushing;
pub mod control;
pub mod rspring;
pub mod spring;
