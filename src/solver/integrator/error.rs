//! The step controller's measure: the Zienkiewicz–Xie local error of a trial step.

use super::*;

impl Integrator {
    /// Zienkiewicz–Xie local error estimate of the trial step, relative to the tolerances:
    /// `e = h² |β − 1/6| |ẍ_{n+1} − ẍ_n|` per node for positions (and the same with `Ω̇`
    /// for rotations), `max(|e_x|/tol_pos, |e_r|/tol_rot)` over the nodes
    /// (Zienkiewicz & Xie, Earthquake Eng. Struct. Dyn. 20, 1991, eq. 9; the leading term
    /// of the local truncation error of Newmark-type schemes). ≤ 1 means acceptable.
    /// The ESDIRK schemes use their embedded pair instead ([`Self::embedded_error`]).
    pub fn local_error(&mut self, h: f64, a: &crate::model::Adaptive, ctx: &EvalContext) -> f64 {
        if self.is_esdirk() {
            return self.embedded_error(h, a, ctx);
        }
        let c = h * h * (self.params.beta - 1.0 / 6.0).abs();
        let mut err: f64 = 0.0;
        for (old, new) in self.nodes.iter().zip(&self.trial) {
            err = err
                .max(c * (new.a - old.a).norm() / a.tol_position)
                .max(c * (new.wd - old.wd).norm() / a.tol_rotation);
        }
        err
    }
}
