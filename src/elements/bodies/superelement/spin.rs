//! How fast a superelement may turn: a floating frame carries a *linear* elastic body, so
//! it has the centrifugal softening of its rotation (the `Ωᵀ H(q) Ω` terms of the kinetic
//! energy, `kernel`) but not the stiffening of the stresses the rotation causes (the
//! geometric stiffness a beam or a nonlinear solid has: Southwell's `ω² = ω₀² + k Ω²`).
//! Its deflections then err by `O((Ω/ω₁)²)`, `ω₁` the body's lowest elastic frequency
//! with its frame held (Kane, Ryan & Banerjee, J. Guidance 10(2), 1987; Simo & Vu-Quoc,
//! J. Appl. Mech. 53, 1986), and above `ω₁` a mode whose softening exceeds its stiffness
//! grows without bound, with the energy conserved (the 1 m steel bar of
//! `decks/superelement/beam/` spun in its plane about its middle at 298 rad/s, `ω₁` =
//! 175 rad/s: 27 J of strain after 0.05 s from round-off, 454 J in the release build whose
//! round-off seeds it differently; at 150 rad/s, 3e-27 J: `tests/superelement.rs`). The
//! energy guard cannot see that, so the element says it: the first time `(|Ω|/ω₁)²`
//! passes [`SPIN_SHARE`], a warning names the element, the time and the ratio.

use super::invariants::Body;
use nalgebra::Vector3;

/// The share `(|Ω|/ω₁)²` above which a turning superelement is said to be modelled
/// coarsely: a tenth of its deflection (the order of the missing stiffening).
pub const SPIN_SHARE: f64 = 0.1;

/// `ω₁²`, the lowest eigenvalue of `K_r x = λ M_qq x` (the reduced stiffness and the elastic
/// coordinates' block of `𝕄₀`: the body with its frame held, every other interface free),
/// rad²/s²; `∞` without elastic coordinates or for a mass block that is not positive
/// definite (the build refuses those).
pub fn lowest_omega2(body: &Body) -> f64 {
    let n = body.n;
    if n == 0 {
        return f64::INFINITY;
    }
    let mqq = body.m0.view((6, 6), (n, n)).into_owned();
    let keep: Vec<usize> = (0..n).collect();
    super::reduce::lowest_eigenvalues(&body.k, &mqq, &keep, 1)
        .and_then(|e| e.first().copied())
        .unwrap_or(f64::INFINITY)
}

/// Watches the frame's angular velocity against `ω₁` (module docs).
#[derive(Debug, Clone, Copy)]
pub struct SpinWatch {
    /// `ω₁²`, rad²/s².
    pub omega1_2: f64,
    /// Whether the warning was given.
    warned: bool,
}

impl SpinWatch {
    /// The watch of `body`.
    pub fn new(body: &Body) -> Self {
        SpinWatch {
            omega1_2: lowest_omega2(body),
            warned: false,
        }
    }

    /// The warning to give at an accepted state whose frame turns at `w` (rad/s), once;
    /// `what` names the element (called only then: nothing is formatted at the other
    /// steps).
    pub fn check(
        &mut self,
        what: impl FnOnce() -> String,
        t: f64,
        w: &Vector3<f64>,
    ) -> Option<String> {
        let share = w.norm_squared() / self.omega1_2;
        // (A NaN rate is not a reason to warn: the guard stops such a run.)
        if self.warned || share.is_nan() || share <= SPIN_SHARE {
            return None;
        }
        self.warned = true;
        Some(format!(
            "t = {t:.6e} s: {} turns at |Ω| = {:.4e} rad/s, (Ω/ω₁)² = {share:.3} of its lowest elastic frequency with its frame held, ω₁ = {:.4e} rad/s: a floating frame's linear body has no centrifugal stiffening, so its deflections err by about that share, and above ω₁ its modes grow without bound (docs/superelements.md, \"What it leaves out\")",
            what(),
            w.norm(),
            self.omega1_2.sqrt()
        ))
    }
}
