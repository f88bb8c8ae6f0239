//! Bodies: point masses (rigid bodies and superelements keep their former places until
//! they move here; ARCHITECTURE.md).

pub mod mass;
