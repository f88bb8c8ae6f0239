//! Contact: cam–follower (CAME), revolute joint with clearance (CLEARANCE).

pub(super) mod came;
pub(super) mod clearance;
