//! `CARRY MODES`: how far an adaptive ESDIRK step's velocity error can move the positions
//! by the run's end `T`, told apart by the linearised model's modes (issue 37 §1) — a drift
//! (a rigid motion, or a mode slow against the run, `ωT ≪ 1`) by `T |e_v|`, a vibration of
//! frequency `ω` by its amplitude `|e_v|/ω` only. (`CARRY RUN`, the default, takes `T |e_v|`
//! for both: an oscillation's velocity error is then weighed `ωT` times its effect.)
//!
//! The filter `z = A⁻¹ (M/T²) e_v`, `A = K + C/T + M/T²` — the iteration matrix
//! `K + C/(γh) + M/(γh)²` at `γh = T` — has, per mode of frequency `ωᵢ` and damping ratio
//! `ζᵢ`, the gain `gᵢ = 1/(1 + 2ζᵢωᵢT + (ωᵢT)²)`: 1 for a drift (`ω = 0`), about `1/(ωT)²`
//! for a vibration. Per node, the measure `T √(|e_v| |z|)` (with `|z|` capped at `|e_v|`) is
//! then `T |e_v|` for a drift and `|e_v|/ω` for an undamped vibration, the amplitude a
//! velocity error `e_v` leaves an oscillator `ẍ + ω²x = 0` with; it is never more than
//! `CARRY RUN`'s `T |e_v|`. The product `(M/T²) e_v = A e_v − K′ e_v` needs no mass matrix of
//! its own: `K′ = K + C/T` is assembled on `A`'s pattern beside it.
//!
//! The elements whose forces come and go with events (contacts,
//! [`crate::elements::Element::intermittent`]) are left out of `K`: the linearised model
//! about one state says nothing of the run after the next touch or release, and without
//! them a velocity error at a contact counts as the free structure's (a drift, for a body
//! that bounces). `A` is assembled at a step's start and factored, and kept until the
//! step's start is [`REFRESH`] of the run further on: it is the operator of an estimate,
//! not of Newton's iterations, and `K` changes on the time scale of the motion.
//!
//! A linear measure: on a nonlinear oscillator (a pendulum's swing, whose period depends on
//! its energy) a velocity error also shifts the phase for the rest of the run, which no
//! modal weight sees — measured, the error then reaches several times TOLPOS
//! (docs/accuracy.md, "CARRY MODES").

use super::*;
use crate::solver::linear::{LinearError, LuState, SparseSystem};
use crate::solver::system::FIXED;

/// The filter's matrix is rebuilt when the step's start has moved by this fraction of the
/// run's length since it was built (200 builds at most per run; on the seed's scene, a
/// build every 7.5 ms, 24 of its fixed deck's steps).
pub const REFRESH: f64 = 1.0 / 200.0;

/// The filter's operator (module docs) and its buffers.
pub struct DriftFilter {
    /// `A = K + C/T + M/T²` at `built_at`, factored.
    a: SparseSystem,
    /// `K′ = K + C/T`'s values on `A`'s pattern.
    k: Vec<f64>,
    /// The time of the step's start it was built at.
    built_at: f64,
    x: Vec<f64>,
    y: Vec<f64>,
    /// The last filtered velocity error per node.
    z: Vec<[Vector3<f64>; 2]>,
    /// The elements left out of `K` ([`crate::elements::Element::intermittent`]).
    left_out: Vec<bool>,
    /// The residual the filter's assemblies write, swapped with the system's (kept).
    rhs: Vec<f64>,
}

/// What a checkpoint keeps of the [`DriftFilter`], so that a resumed run estimates as the
/// run never stopped would have.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DriftState {
    built_at: f64,
    k: Vec<f64>,
    lu: LuState,
}

impl DriftFilter {
    /// Its buffers for `sys`, allocated once: a rebuild allocates nothing.
    fn sized(sys: &System) -> Option<Box<Self>> {
        let a = SparseSystem::new(&sys.matrix.columns()).ok()?;
        let n = a.dim();
        Some(Box::new(DriftFilter {
            k: Vec::with_capacity(a.nnz()),
            a,
            built_at: f64::NAN,
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: Vec::with_capacity(sys.node_dofs.len()),
            left_out: sys.elements.iter().map(|e| e.intermittent()).collect(),
            rhs: vec![0.0; sys.rhs.len()],
        }))
    }
}

impl Integrator {
    /// The filtered velocity error `z` per node (`[translation, rotation]`, module docs)
    /// of the embedded velocity error `ev` of the step under way; `None` when the filter's
    /// matrix is singular (the caller then keeps `T |e_v|`).
    pub(super) fn drift_filtered(
        &mut self,
        ev: &[[Vector3<f64>; 2]],
        ctx: &EvalContext,
    ) -> Option<&[[Vector3<f64>; 2]]> {
        let n = self.sys.n_eq();
        let t_run = self.error_horizon;
        let fresh = self
            .drift
            .as_deref()
            .is_some_and(|f| f.a.dim() == n && (self.t - f.built_at).abs() < REFRESH * t_run);
        if !fresh {
            self.build_drift(ctx)?;
        }
        let f = self.drift.as_deref_mut()?;
        f.x.fill(0.0);
        for (dofs, e) in self.sys.node_dofs.iter().zip(ev) {
            for (c, &d) in dofs.iter().enumerate() {
                if d != FIXED {
                    f.x[d] = e[c / 3][c % 3];
                }
            }
        }
        f.a.mul(&f.x, &mut f.y);
        f.a.mul_add(&f.k, -1.0, &f.x, &mut f.y);
        f.a.solve(&mut f.y).ok()?;
        f.z.clear();
        for dofs in &self.sys.node_dofs {
            let mut p = [Vector3::zeros(); 2];
            for (c, &d) in dofs.iter().enumerate() {
                if d != FIXED {
                    p[c / 3][c % 3] = f.y[d];
                }
            }
            f.z.push(p);
        }
        Some(&f.z)
    }

    /// Assembles `K′` and `A` at the step's start (the accepted state) and factors `A`,
    /// in the system's matrix swapped out for the filter's; the system's residual is kept.
    fn build_drift(&mut self, ctx: &EvalContext) -> Option<()> {
        let n = self.sys.n_eq();
        let mut f = match self.drift.take() {
            Some(f) if f.a.dim() == n => f,
            _ => DriftFilter::sized(&self.sys)?,
        };
        let t_run = self.error_horizon;
        std::mem::swap(&mut self.sys.rhs, &mut f.rhs);
        std::mem::swap(&mut self.sys.matrix, &mut f.a);
        let stiff = EvalContext {
            c_a: 0.0,
            c_v: 1.0 / t_run,
            ..*ctx
        };
        let (nodes, lambda) = (&self.nodes, &self.lambda);
        self.sys
            .assemble_except(&stiff, nodes, lambda, true, None, &f.left_out);
        f.k.clone_from(&self.sys.matrix.values);
        let slow = EvalContext {
            c_a: 1.0 / (t_run * t_run),
            c_v: 1.0 / t_run,
            ..*ctx
        };
        self.sys
            .assemble_except(&slow, nodes, lambda, true, None, &f.left_out);
        let factored = self.sys.matrix.factor().is_ok();
        std::mem::swap(&mut self.sys.matrix, &mut f.a);
        std::mem::swap(&mut self.sys.rhs, &mut f.rhs);
        f.built_at = self.t;
        self.drift = Some(f).filter(|_| factored);
        self.drift.as_ref().map(|_| ())
    }

    /// The drift filter as a checkpoint keeps it ([`DriftState`]).
    pub(crate) fn drift_state(&self) -> Option<DriftState> {
        self.drift.as_deref().map(|f| DriftState {
            built_at: f.built_at,
            k: f.k.clone(),
            lu: f.a.save_state(),
        })
    }

    /// Restores [`Self::drift_state`].
    pub(crate) fn restore_drift(&mut self, s: Option<DriftState>) -> Result<(), LinearError> {
        self.drift = None;
        let Some(s) = s else {
            return Ok(());
        };
        let mut f = DriftFilter::sized(&self.sys).ok_or_else(|| {
            LinearError::State("the drift filter's matrix cannot be built".into())
        })?;
        if s.k.len() != f.a.nnz() {
            return Err(LinearError::State(
                "the saved state's drift filter does not fit the model".into(),
            ));
        }
        f.a.restore_state(s.lu)?;
        f.k = s.k;
        f.built_at = s.built_at;
        self.drift = Some(f);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mass on a spring–damper along x (free across it) and a free mass.
    const DECK: &str = "TITLE drift filter
NODES
  1 0 0 0 FIX ALL
  2 1 0 0 FIX ROT
  3 0 2 0 FIX ROT
ELEMENTS
  1 SPRING 1 2 K 800 C 4
  2 MASS 2 M 2
  3 MASS 3 M 5
ANALYSIS DYNAMIC ESDIRK5 STEP 1e-3 END 3 ADAPTIVE TOLPOS 1e-6 TOLROT 1e-6 CARRY MODES
END
";

    /// The deck's integrator, started, its run 3 s long, and the context of a step.
    fn started() -> (Integrator, EvalContext) {
        let model = crate::deck::parse_deck(DECK, "t").expect("parses");
        let mut integ = crate::solver::prepare(&model).expect("builds");
        integ.initialize().expect("starts");
        integ.error_horizon = 3.0;
        let ctx = integ.context(0.0, 1e-3, integ.scale);
        (integ, ctx)
    }

    /// The filter's gain against its closed form: along the spring
    /// `g = (m/T²)/(k + c/T + m/T²)` (a vibration, `ωT = 60`), 1 across it and on the free
    /// mass (drifts). The few operations of a 6-unknown solve: 1e-12 relative.
    #[test]
    fn the_filter_passes_a_drift_and_weighs_a_vibration_by_its_closed_form_gain() {
        let (mut integ, ctx) = started();
        let mut ev = vec![[Vector3::zeros(); 2]; 3];
        ev[1][0] = Vector3::new(0.7, -0.4, 0.2);
        ev[2][0] = Vector3::new(0.3, 0.1, -0.9);
        let z = integ.drift_filtered(&ev, &ctx).expect("filters").to_vec();
        let (k, c, m, t) = (800.0, 4.0, 2.0, 3.0);
        let g = (m / (t * t)) / (k + c / t + m / (t * t));
        let want = [
            Vector3::new(0.7 * g, -0.4, 0.2),
            Vector3::new(0.3, 0.1, -0.9),
        ];
        for (got, want) in [z[1][0], z[2][0]].iter().zip(&want) {
            assert!((got - want).amax() <= 1e-12, "{got} against {want}");
        }
        assert!(z[0][0].amax() == 0.0 && z.iter().all(|p| p[1].amax() == 0.0));
        // The measure's two ends: T √(|e| |z|) along the spring is |e|/ω to within the
        // damping's and M/T²'s share (ζ = 0.05, (ωT)⁻² = 2.8e-4): 1.6 % here.
        let omega = (k / m).sqrt();
        let along = t * (0.7 * z[1][0].x.abs()).sqrt();
        assert!((along / (0.7 / omega) - 1.0).abs() < 0.1, "{along}");
    }

    /// A checkpoint keeps the filter: restored, it filters as the original does, bit for
    /// bit, where one built afresh would not.
    #[test]
    fn a_saved_filter_filters_as_the_original() {
        let (mut integ, ctx) = started();
        let mut ev = vec![[Vector3::zeros(); 2]; 3];
        ev[1][0] = Vector3::new(0.7, -0.4, 0.2);
        let z = integ.drift_filtered(&ev, &ctx).expect("filters").to_vec();
        let saved = integ.drift_state();
        assert!(saved.is_some());
        let (mut other, _) = started();
        other.restore_drift(saved).expect("restores");
        // Moved: a filter built here would turn the spring's stiffness with its line (the
        // mass off the x axis); the restored one is the saved state's.
        other.nodes[1].x += Vector3::new(0.0, 0.5, 0.0);
        let z2 = other.drift_filtered(&ev, &ctx).expect("filters");
        assert_eq!(z, z2);
    }
}
