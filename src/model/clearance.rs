//! Data of a revolute joint with radial clearance (`CLEARANCE`): a journal in a bearing
//! (Flores & Ambrósio 2004, Computers & Structures 82: 1359–1369; Lankarani & Nikravesh
//! 1990, J. Mech. Des. 112: 369–376). The element is `crate::elements::clearance`.

use nalgebra::Vector3;

/// The normal force law of a clearance joint, a function of the penetration
/// `δ = |e| − c ≥ 0` and its rate `δ̇`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactLaw {
    /// The seed's Kelvin–Voigt law (Sampaio & Barrientos, eq. [17], as CAME):
    /// `F = k δ + c δ̇`, clipped at zero (never adhesive).
    KelvinVoigt {
        /// Stiffness `k`, N/m (> 0).
        k: f64,
        /// Damping `c`, N·s/m (≥ 0).
        c: f64,
    },
    /// Lankarani & Nikravesh (1990) hysteresis damping on a Hertz law:
    /// `F = K δⁿ (1 + 3(1 − e²)/4 · δ̇/δ̇⁻)`, `δ̇⁻` the approach speed at the impact,
    /// clipped at zero.
    LankaraniNikravesh {
        /// Generalised stiffness `K`, N/mⁿ (> 0).
        k: f64,
        /// Hertz exponent `n` (> 0; 1.5 for Hertz).
        exponent: f64,
        /// Coefficient of restitution `e` in (0, 1].
        restitution: f64,
    },
}

/// Data of a `CLEARANCE` element (first node: bearing, second: journal).
#[derive(Debug, Clone, PartialEq)]
pub struct ClearanceData {
    /// Bearing axis (unit), global at t = 0, fixed to the bearing node.
    pub axis: Vector3<f64>,
    /// Bearing radius `R_b`, m (> clearance).
    pub radius: f64,
    /// Radial clearance `c = R_b − R_j`, m (> 0).
    pub clearance: f64,
    /// The normal force law.
    pub law: ContactLaw,
    /// Coulomb friction coefficient μ (≥ 0).
    pub friction: f64,
    /// Regularisation speed of friction, m/s (> 0).
    pub friction_speed: f64,
    /// Floor of the approach speed `δ̇⁻` of the Lankarani–Nikravesh law, m/s (> 0).
    pub min_approach: f64,
    /// Minimum number of time steps that must resolve each impact.
    pub impact_steps: u32,
}
