//! Contact: cam–follower (`came`, on the profiles of `profile`) and the revolute joint
//! with radial clearance (`clearance`, reusing CAME's event rules).

pub mod came;
pub mod clearance;
pub mod profile;
