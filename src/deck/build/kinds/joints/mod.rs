//! Joints: revolute and prismatic (driven or not), universal, spherical, clamp, rigid
//! body (grammar.md, "Elements"); every one built as a `crate::elements::joints::Joint`.

pub(super) mod hinge;
pub(super) mod prescribed;
pub(super) mod rigid;
pub(super) mod spherical;
pub(super) mod ujoint;
