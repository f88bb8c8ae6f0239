//! Bodies: point masses, rigid bodies, superelements.

pub(super) mod mass;
pub(super) mod superelement;
