//! The data of the spring elements of a model (issue 25 §3): the two-node `SPRING`, the
//! six-component `BUSHING` and the rotational spring–damper–friction `RSPRING` on a
//! `HINGE`. What each computes is in `elements/forces/spring.rs`, `elements/forces/bushing.rs` and
//! `elements/forces/rspring.rs`; the deck syntax in grammar.md.

use super::{ElementId, FunctionId};
use nalgebra::{Matrix3, Vector3};

/// Data of a `SPRING`: a spring–damper along the line of its two nodes.
///
/// Tension `F = P + k δ + F_c(δ) + c ℓ̇`, with `ℓ = |x₂ − x₁|`, the deflection (elongation)
/// `δ = ℓ − L_ref` and `F_c` the optional force–deflection curve (a FUNCTION read as
/// `F(δ)`, its abscissa a deflection in m, not a time).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringData {
    /// Stiffness k, N/m (≥ 0).
    pub stiffness: f64,
    /// Damping c on the elongation rate, N·s/m (≥ 0).
    pub damping: f64,
    /// How the reference length `L_ref` (where `δ = 0`) and the preload are given.
    pub length: SpringLength,
    /// The force–deflection curve `F_c(δ)`, N, added to `k δ`; `None` = linear.
    pub curve: Option<FunctionId>,
}

/// The reference length of a [`SpringData`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpringLength {
    /// The initial distance of the nodes is the free length (the default: no force at t = 0
    /// but the damper's and the curve's `F_c(0)`).
    Initial,
    /// The free length `L0`, m (≥ 0): `δ = ℓ − L0`.
    Free(f64),
    /// A preload `P`, N (tension > 0): `δ` counts from the initial distance and the tension
    /// is `P + k δ + …` (a spring built in stretched or compressed).
    Preload(f64),
}

/// Data of a `BUSHING`: six uncoupled linear springs and dampers in a frame fixed to node 1.
#[derive(Debug, Clone, PartialEq)]
pub struct BushingData {
    /// Stiffnesses `[kx, ky, kz]` N/m, `[krx, kry, krz]` N·m/rad along the bushing axes
    /// (all ≥ 0).
    pub stiffness: [f64; 6],
    /// Dampings, same layout, N·s/m and N·m·s/rad (≥ 0).
    pub damping: [f64; 6],
    /// The bushing axes (columns, orthonormal, right-handed), global frame at t = 0 (=
    /// node 1's material frame). Identity by default.
    pub axes: Matrix3<f64>,
}

/// Data of an `RSPRING`: a rotational spring, damper and regularised Coulomb friction about
/// the axis of a `HINGE`, between the hinge's two nodes.
///
/// Torque `T = k (θ − θ₀) + c θ̇ + T_f tanh(θ̇/ω_reg)`.
#[derive(Debug, Clone, PartialEq)]
pub struct RSpringData {
    /// The HINGE whose nodes and axis the element takes.
    pub hinge: ElementId,
    /// The hinge's axis (unit), global at t = 0 (filled in from the hinge).
    pub axis: Vector3<f64>,
    /// Torsional stiffness k, N·m/rad (≥ 0).
    pub stiffness: f64,
    /// Torsional damping c, N·m·s/rad (≥ 0).
    pub damping: f64,
    /// Unloaded angle θ₀, rad.
    pub angle0: f64,
    /// Friction torque `T_f`, N·m (≥ 0; 0 = none).
    pub friction: f64,
    /// Regularisation speed `ω_reg` of the friction, rad/s (> 0).
    pub friction_speed: f64,
}
