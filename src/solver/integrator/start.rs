//! The start of a run: reference magnitudes of the iteration matrix and the consistent
//! initial (or restart) accelerations and multipliers.

use super::*;

impl Integrator {
    /// Reference magnitudes of the mass and stiffness diagonals, and the consistent
    /// initial accelerations (and multipliers) from the equations of motion at t = 0:
    /// `[M  sBᵀ; sB  0] [v̇₀; λ̂₀] = [−r(q₀, v₀, 0); 0]` (acceleration-level constraints of
    /// scleronomic joints, exact for a start from rest).
    pub fn initialize(&mut self) -> Result<(), Failure> {
        self.started = true;
        let n = self.sys.n_eq();
        let nn = self.sys.n_node_eq;
        if n > nn {
            self.start_constraints()?;
        }
        // Stiffness part (c_a = 0), then with c_a = 1: the difference is the mass matrix.
        let ctx0 = EvalContext {
            c_v: 0.0,
            c_a: 0.0,
            ..self.context(0.0, 0.0, 1.0)
        };
        let zero = vec![0.0; n];
        self.sys.assemble(&ctx0, &self.nodes, &zero, true);
        let k_vals = self.sys.matrix.values.clone();
        let ctx1 = EvalContext { c_a: 1.0, ..ctx0 };
        self.sys.assemble(&ctx1, &self.nodes, &zero, true);
        let (mut msum, mut ksum, mut kmax, mut cnt) = (0.0, 0.0, 0.0f64, 0usize);
        let (mut jsum, mut jcnt) = (0.0, 0usize);
        for eq in 0..nn {
            if let crate::solver::system::DofOwner::Node { comp, .. } = self.sys.owners[eq]
                && let Some(p) = self.sys.matrix.position(eq, eq)
            {
                if comp < 3 {
                    msum += (self.sys.matrix.values[p] - k_vals[p]).abs();
                    ksum += k_vals[p].abs();
                    kmax = kmax.max(k_vals[p].abs());
                    cnt += 1;
                } else {
                    jsum += (self.sys.matrix.values[p] - k_vals[p]).abs();
                    jcnt += 1;
                }
            }
        }
        self.rot_mass_ref = jsum / jcnt.max(1) as f64;
        let cnt = cnt.max(1) as f64;
        self.mass_ref = msum / cnt;
        self.stiff_ref = ksum / cnt;
        self.residual_floor = 10.0 * f64::EPSILON * kmax * self.sys.ref_length;
        if self.mass_ref == 0.0 && self.stiff_ref == 0.0 {
            self.stiff_ref = 1.0;
        }
        if !self.dynamic {
            self.scale = self.scale_for(0.0);
            return Ok(());
        }
        // A driver prescribes a velocity `B v = a ḟ(0)`, and given velocities may violate
        // the joints (a node off a joint's axis): the initial velocities are made
        // consistent with every constraint before the accelerations are solved for (at
        // rest and without drivers there is nothing to project).
        let drivers = self.sys.elements.iter().any(|e| e.rheonomic());
        let moving = self
            .nodes
            .iter()
            .any(|s| s.v != Vector3::zeros() || s.w != Vector3::zeros());
        // (Without constraints a moving start is still "projected": its fixed components'
        // velocities are zeroed, the solve changes nothing else.)
        self.consistent_start((n > nn && drivers) || moving)
    }

    /// Before the first step of a constrained model: the redundant constraint equations
    /// found and removed ([`crate::solver::redundancy`]), the initial positions moved
    /// onto the constraints ([`crate::solver::assembly`]), and the removed equations
    /// checked to follow from the kept ones there (else the constraints contradict each
    /// other). What was done is added to [`Integrator::notices`].
    pub fn start_constraints(&mut self) -> Result<(), Failure> {
        use crate::solver::notice::Notice;
        use crate::solver::redundancy;
        let t = self.t;
        let mut red = redundancy::detect(&self.sys, &self.nodes, t);
        self.sys.remove_equations(&red.globals());
        let tol = CONSTRAINT_TOL.max(100.0 * f64::EPSILON * self.sys.ref_length);
        match crate::solver::assembly::assemble_positions(&mut self.sys, &mut self.nodes, t, tol) {
            Ok(Some(notice)) => {
                self.notices.push(notice);
                // The rank at the closed position is the one that counts.
                let again = redundancy::detect(&self.sys, &self.nodes, t);
                if again.removed.len() > red.removed.len() {
                    self.sys.remove_equations(&again.globals());
                }
                red = redundancy::detect(&self.sys, &self.nodes, t);
            }
            Ok(None) => {}
            Err(f) => {
                return Err(self.failure(
                    0.0,
                    FailureReason::Constraints(f.to_string().into()),
                    vec![],
                    self.sys.ref_force,
                ));
            }
        }
        if let Some((v, r)) = red.removed_violation(&self.sys, &self.nodes, t)
            && v > removed_tolerance(self.sys.ref_length)
        {
            return Err(self.failure(
                0.0,
                FailureReason::Constraints(format!(
                    "the constraints contradict each other: element {}'s equation {} ({}) depends on the equations before it but is violated by {v:.3e} where they hold; two joints or drivers impose one motion differently",
                    r.id.0,
                    r.equation + 1,
                    r.motion
                ).into()),
                vec![],
                self.sys.ref_force,
            ));
        }
        for (msg, r) in red.describe().into_iter().zip(group_starts(&red)) {
            self.notices.push(Notice::Redundant {
                element: r.0,
                equations: r.1,
                message: msg,
            });
        }
        for &(equations, dofs) in &red.unchecked {
            self.notices.push(Notice::Unchecked { equations, dofs });
        }
        self.redundancy = red;
        Ok(())
    }

    /// Consistent accelerations and multipliers at the current state, from the equations
    /// of motion `[M  sBᵀ; sB  0] [v̇; λ̂] = [−r(q, v, 0); −s Ḃv]`; the pseudo-accelerations
    /// restart from them (`a = v̇`). Used at `t = 0` and after an element switched its force
    /// law ([`crate::elements::Element::restart`]): a restart costs one local error of
    /// `O(h²)` in the velocities, which keeps the scheme second-order, while a step across
    /// the jump would cost `O(h)`.
    pub fn consistent_accelerations(&mut self) -> Result<(), Failure> {
        self.consistent_start(false)
    }

    /// [`Self::consistent_accelerations`], first making the velocities consistent with
    /// the constraints when `project` (the start of a run with drivers).
    fn consistent_start(&mut self, project: bool) -> Result<(), Failure> {
        let given = project
            && self
                .nodes
                .iter()
                .any(|s| s.v != Vector3::zeros() || s.w != Vector3::zeros());
        let n = self.sys.n_eq();
        let nn = self.sys.n_node_eq;
        let ctx0 = EvalContext {
            c_v: 0.0,
            c_a: 0.0,
            ..self.context(self.t, 0.0, 1.0)
        };
        let ctx1 = EvalContext { c_a: 1.0, ..ctx0 };
        // The work vectors are taken out of `self` for the solve (no allocation once sized)
        // and put back at its end; a failed solve drops them (they are sized again next time).
        let mut sc = std::mem::take(&mut self.acc);
        sc.zero.clear();
        sc.zero.resize(n, 0.0);
        let zero = &sc.zero;
        // The residual's inertia terms use the nodes' accelerations: clear them, so that
        // the solution is the acceleration itself, not a correction to it.
        for s in &mut self.nodes {
            s.a = Vector3::zeros();
            s.wd = Vector3::zeros();
        }
        self.scale = self.scale_for(0.0).max(self.mass_ref);
        // Build [M, sBᵀ; sB, 0] from the two assemblies.
        let s = self.scale;
        let ctx_s = EvalContext {
            constraint_scale: s,
            ..ctx0
        };
        self.sys.assemble(&ctx_s, &self.nodes, zero, true);
        sc.kb.clear();
        sc.kb.extend_from_slice(&self.sys.matrix.values);
        let kb = &sc.kb;
        let ctx_m = EvalContext {
            constraint_scale: s,
            ..ctx1
        };
        let info = self.sys.assemble(&ctx_m, &self.nodes, zero, true);
        sc.rhs.clear();
        sc.rhs.extend(self.sys.rhs.iter().map(|r| -r));
        for eq in 0..n {
            let a = self.sys.matrix.position_range(eq);
            for p in a {
                let row = self.sys.matrix.row_of(p);
                if row < nn && eq < nn {
                    self.sys.matrix.values[p] -= kb[p];
                }
            }
        }
        self.lu_step = f64::NAN;
        if let Err(e) = self.sys.matrix.factor() {
            return Err(self.failure(
                0.0,
                FailureReason::Singular(e.to_string()),
                vec![],
                info.force_scale,
            ));
        }
        self.stats.factorizations += 1;
        if project {
            self.project_velocities(&mut sc, s, given);
            // The velocity-dependent forces at the projected velocities.
            self.sys.assemble(&ctx_m, &self.nodes, &sc.zero, false);
            for (r, f) in sc.rhs.iter_mut().zip(&self.sys.rhs[..nn]) {
                *r = -f;
            }
        }
        // Acceleration-level constraints: s(B v̇ + Ḃv) = 0. The velocity term Ḃv is the
        // second derivative of Φ along the geodesic q exp(εv) (constant velocities), taken by
        // a central second difference (truncation O(ε²), ε|v| = 1e-3 L_ref; it is zero for
        // a start from rest and gives e.g. the centripetal tension of a launched pendulum).
        let (vmax, wmax) = self.nodes.iter().fold((0.0f64, 0.0f64), |(a, b), s| {
            (a.max(s.v.norm()), b.max(s.w.norm()))
        });
        sc.bdot_v.clear();
        sc.bdot_v.resize(n - nn, 0.0);
        if n > nn && (vmax > 0.0 || wmax > 0.0) {
            let eps = (1e-3 * self.sys.ref_length / vmax.max(1e-300)).min(1e-3 / wmax.max(1e-300));
            moved_along_velocities(&self.nodes, eps, &mut sc.plus);
            moved_along_velocities(&self.nodes, -eps, &mut sc.minus);
            self.sys.assemble(&ctx_s, &self.nodes, &sc.zero, false);
            sc.r0.clear();
            sc.r0.extend_from_slice(&self.sys.rhs[nn..]);
            self.sys.assemble(&ctx_s, &sc.plus, &sc.zero, false);
            sc.rp.clear();
            sc.rp.extend_from_slice(&self.sys.rhs[nn..]);
            self.sys.assemble(&ctx_s, &sc.minus, &sc.zero, false);
            for (k, b) in sc.bdot_v.iter_mut().enumerate() {
                *b = (sc.rp[k] - 2.0 * sc.r0[k] + self.sys.rhs[nn + k]) / (eps * eps);
            }
        }
        for (r, b) in sc.rhs.iter_mut().skip(nn).zip(&sc.bdot_v) {
            *r = -b;
        }
        // Drivers: s(B v̇ + Ḃv + Φ_tt) = 0.
        self.add_time_derivatives(&mut sc.rhs, 2, s);
        let _ = self.sys.matrix.solve(&mut sc.rhs);
        let rhs = &sc.rhs;
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(self.failure(
                0.0,
                FailureReason::Singular("initial accelerations are not finite (singular mass matrix: a node with rotational or translational freedom but no inertia?)".into()),
                vec![],
                info.force_scale,
            ));
        }
        for (i, d) in self.sys.node_dofs.iter().enumerate() {
            for c in 0..6 {
                if d[c] != crate::solver::system::FIXED {
                    let v = rhs[d[c]];
                    if c < 3 {
                        self.nodes[i].a[c] = v;
                        self.pseudo[i][0][c] = v;
                    } else {
                        self.nodes[i].wd[c - 3] = v;
                        self.pseudo[i][1][c - 3] = v;
                    }
                }
            }
        }
        self.lambda[nn..n].copy_from_slice(&rhs[nn..n]);
        self.acc = sc;
        Ok(())
    }
}

impl Integrator {
    /// Adds `−s ∂^{order}Φ/∂t^{order}` of every driver's constraint rows to `rhs` (order 1:
    /// the velocity level `s(Bv + Φ_t) = 0`, order 2: the acceleration level). The laws
    /// are read just after `t` (by 1e-12 of max(1, |t|) s): at a breakpoint of a law (where
    /// the run restarts the accelerations) the value after its jump is the one that holds.
    fn add_time_derivatives(&self, rhs: &mut [f64], order: usize, s: f64) {
        let t = self.t + 1e-12 * self.t.abs().max(1.0);
        for (e, el) in self.sys.elements.iter().enumerate() {
            if !el.rheonomic() {
                continue;
            }
            let o = self.sys.mult_offset[e];
            for k in 0..el.multipliers() {
                if self.redundancy.removed.iter().any(|r| r.global == o + k) {
                    continue;
                }
                rhs[o + k] -= s * el.constraint_time_derivatives(t, k)[order - 1];
            }
        }
    }

    /// Makes the nodes' velocities consistent with the constraints, drivers included:
    /// `v ← v + Δv` with `[M  sBᵀ; sB  0] [Δv; μ] = [0; −s(Bv + Φ_t)]`, the smallest change
    /// in the kinetic-energy norm that gives `B v = −Φ_t` (`= a ḟ` for a driver). The
    /// matrix is the factored one of the acceleration solve; `B v` is read from its
    /// constraint rows. INITIAL velocities that contradict a driver are thus overridden
    /// (grammar.md, "Drivers").
    fn project_velocities(&mut self, sc: &mut AccelerationScratch, s: f64, given: bool) {
        let n = self.sys.n_eq();
        let nn = self.sys.n_node_eq;
        let fixed = crate::solver::system::FIXED;
        // A fixed component's velocity is zero (an INITIAL velocity along it contradicts
        // the fixity: held, it would move the node in the energies but never in position,
        // and the first step would create its kinetic energy out of nothing —
        // tests/deck/energy/7_2002: a FIX TRANS node given V, 0.178 J at every step size).
        let mut zeroed = vec![(0.0f64, 0.0f64); self.nodes.len()];
        for ((node, d), z) in self
            .nodes
            .iter_mut()
            .zip(&self.sys.node_dofs)
            .zip(&mut zeroed)
        {
            for c in 0..6 {
                if d[c] == fixed {
                    if c < 3 {
                        z.0 = z.0.hypot(node.v[c]);
                        node.v[c] = 0.0;
                    } else {
                        z.1 = z.1.hypot(node.w[c - 3]);
                        node.w[c - 3] = 0.0;
                    }
                }
            }
        }
        // Velocities in equation order, into the first nn entries of `zero` (restored below).
        let v = &mut sc.zero;
        for (i, d) in self.sys.node_dofs.iter().enumerate() {
            for c in 0..6 {
                if d[c] != fixed {
                    v[d[c]] = if c < 3 {
                        self.nodes[i].v[c]
                    } else {
                        self.nodes[i].w[c - 3]
                    };
                }
            }
        }
        let rhs = &mut sc.rp;
        rhs.clear();
        rhs.resize(n, 0.0);
        for col in 0..nn {
            for p in self.sys.matrix.position_range(col) {
                let row = self.sys.matrix.row_of(p);
                if row >= nn {
                    rhs[row] -= self.sys.matrix.values[p] * v[col];
                }
            }
        }
        v.iter_mut().for_each(|x| *x = 0.0);
        self.add_time_derivatives(rhs, 1, s);
        if self.sys.matrix.solve(rhs).is_err() || rhs.iter().any(|x| !x.is_finite()) {
            return;
        }
        for (i, d) in self.sys.node_dofs.iter().enumerate() {
            for c in 0..6 {
                if d[c] != fixed {
                    if c < 3 {
                        self.nodes[i].v[c] += rhs[d[c]];
                    } else {
                        self.nodes[i].w[c - 3] += rhs[d[c]];
                    }
                }
            }
        }
        // Given velocities that the projection changed are said (a driver's start from
        // rest is what grammar.md's "Drivers" describes, and goes without saying).
        if given {
            let (mut dv, mut dw, mut node) = (0.0f64, 0.0f64, 0);
            for (i, d) in self.sys.node_dofs.iter().enumerate() {
                let get = |c: usize| if d[c] == fixed { 0.0 } else { rhs[d[c]] };
                let v = Vector3::new(get(0), get(1), get(2))
                    .norm()
                    .hypot(zeroed[i].0);
                let w = Vector3::new(get(3), get(4), get(5))
                    .norm()
                    .hypot(zeroed[i].1);
                if v + w * self.sys.ref_length > dv + dw * self.sys.ref_length {
                    node = i;
                }
                dv = dv.max(v);
                dw = dw.max(w);
            }
            let scale = self.nodes.iter().fold(0.0f64, |m, s| {
                m.max(s.v.norm()).max(s.w.norm() * self.sys.ref_length)
            });
            if dv + dw * self.sys.ref_length > 1e-9 * scale {
                self.notices
                    .push(crate::solver::notice::Notice::VelocitiesProjected {
                        change: dv,
                        angular_change: dw,
                        node: self.sys.node_ids[node],
                    });
            }
        }
    }
}

/// How far a removed (redundant) equation may drift from zero while the kept ones hold:
/// they imply it exactly where the redundancy is structural, so only the kept equations'
/// Newton tolerance times the loop's conditioning shows; 1e-7 of the model's size is far
/// above that and far below any visible motion.
pub(crate) fn removed_tolerance(ref_length: f64) -> f64 {
    1e-7 * ref_length.max(1.0)
}

/// The removed equations grouped by element: (element, its equations, 1-based).
fn group_starts(
    red: &crate::solver::redundancy::Redundancy,
) -> Vec<(crate::model::ElementId, Vec<usize>)> {
    let mut out: Vec<(crate::model::ElementId, Vec<usize>)> = Vec::new();
    for r in &red.removed {
        match out.last_mut() {
            Some((id, v)) if *id == r.id => v.push(r.equation + 1),
            _ => out.push((r.id, vec![r.equation + 1])),
        }
    }
    out
}
