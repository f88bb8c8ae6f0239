//! Bodies: point masses and superelements (rigid bodies keep their former place until they
//! move here; ARCHITECTURE.md).

pub mod mass;
pub mod superelement;
