//! The [`Element`] interface of a joint: residual and iteration matrix of the augmented
//! Lagrangian, commits of the angle history, checkpoints and output rows.

use super::*;

impl Element for Joint {
    fn id(&self) -> ElementId {
        self.id
    }

    fn drive_law_mut(&mut self) -> Option<&mut crate::elements::drive::TimeLaw> {
        self.drive.as_mut()
    }

    fn nodes(&self) -> &[usize] {
        &self.nodes
    }

    fn multipliers(&self) -> usize {
        self.m_pair() * self.pairs.len()
    }

    fn evaluate(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        out: &mut Local,
    ) {
        let s = ctx.constraint_scale;
        let m = self.m_pair();
        let nn = 6 * self.nodes.len();
        for (k, pair) in self.pairs.iter().enumerate() {
            let (s1, s2) = (&nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
            let lam = &lambda[k * m..(k + 1) * m];
            let lrow = nn + k * m;
            if !tangent {
                let (phi, g) = self.forces_f64(pair, s1, s2, ctx, lam);
                for (j, gj) in g.iter().enumerate() {
                    out.res[Self::local(pair, j)] += gj;
                }
                for (i, v) in phi.iter().take(m).enumerate() {
                    out.res[lrow + i] += s * v;
                }
                continue;
            }
            let (phi, g) = self.forces_dual(pair, s1, s2, ctx, lam);
            for (row, gr) in g.iter().enumerate() {
                let lr = Self::local(pair, row);
                out.res[lr] += gr.re;
                for (col, e) in gr.eps.iter().enumerate() {
                    out.add_tan(lr, Self::local(pair, col), *e);
                }
            }
            for (i, v) in phi.iter().take(m).enumerate() {
                out.res[lrow + i] += s * v.re;
                for (col, e) in v.eps.iter().enumerate() {
                    let lc = Self::local(pair, col);
                    out.add_tan(lc, lrow + i, s * e);
                    out.add_tan(lrow + i, lc, s * e);
                }
            }
        }
    }

    fn save_state(&self) -> ElementState {
        ElementState::Joint(JointState(self.hist.clone()))
    }

    fn restore_state(&mut self, state: &ElementState) -> Result<(), StateMismatch> {
        let ElementState::Joint(JointState(h)) = state else {
            return Err(StateMismatch { element: self.id });
        };
        self.hist = h.clone();
        Ok(())
    }

    fn commit(&mut self, ctx: &EvalContext, nodes: &[NodeState], _lambda: &[f64]) {
        let a = self.angles_at(ctx.t, nodes);
        self.hist.angles = [a[0], a[1]];
        if matches!(self.kind, JointType::UJoint { .. }) {
            let cb = a[2].abs();
            self.hist.min_abs_cos_bend = Some(self.hist.min_abs_cos_bend.map_or(cb, |m| m.min(cb)));
            let singular = cb < UJOINT_SINGULAR_COS;
            if singular && !self.hist.in_singular {
                self.hist.singular_passages += 1;
                if self.hist.first_singular_time.is_none() {
                    self.hist.first_singular_time = Some(ctx.t);
                    if let Some(msg) = self.singularity(nodes) {
                        eprintln!("warning: t = {:.6e} s: {msg}", ctx.t);
                    }
                }
            }
            self.hist.in_singular = singular;
        }
    }

    fn output_header(&self) -> Vec<String> {
        let mut h: Vec<&str> = match &self.kind {
            JointType::Hinge { .. } => vec!["angle"],
            JointType::UJoint { .. } => vec!["angle1", "angle2", "bend"],
            JointType::Prismatic { .. } => vec!["slide"],
            _ => vec![],
        };
        if self.drive.is_some() {
            h.push("prescribed");
            h.push(if matches!(self.kind, JointType::Hinge { .. }) {
                "torque"
            } else {
                "force"
            });
        }
        let r = ["fx", "fy", "fz", "mx", "my", "mz"];
        if self.pairs.len() == 1 {
            h.extend(r);
            h.iter().map(|s| s.to_string()).collect()
        } else {
            let mut out: Vec<String> = h.iter().map(|s| s.to_string()).collect();
            for pair in &self.pairs {
                out.extend(r.iter().map(|c| format!("{c}_{}", pair.b + 1)));
            }
            out
        }
    }

    fn write_output_row(
        &self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        row: &mut Vec<f64>,
    ) {
        let a = self.angles_at(ctx.t, nodes);
        match &self.kind {
            JointType::Hinge { .. } => row.push(a[0]),
            JointType::UJoint { .. } => {
                row.extend_from_slice(&[a[0], a[1], a[2].clamp(-1.0, 1.0).acos()]);
            }
            JointType::Prismatic { a: ax, .. } => {
                let (s1, s2) = (&nodes[self.nodes[0]], &nodes[self.nodes[1]]);
                let d = s2.x + s2.r * self.pairs[0].c2 - s1.x;
                row.push(d.dot(&(s1.r * ax)));
            }
            _ => {}
        }
        if let Some([law, _, _]) = self.drive_law(ctx.t) {
            row.extend_from_slice(&[law, -self.drive_mu(ctx, nodes, lambda)]);
        }
        for k in 0..self.pairs.len() {
            let (f, m) = self.reaction(k, ctx, nodes, lambda);
            row.extend_from_slice(f.as_slice());
            row.extend_from_slice(m.as_slice());
        }
    }

    fn constraint_violation(&self, nodes: &[NodeState]) -> f64 {
        let m = self.m_pair();
        self.pairs
            .iter()
            .map(|pair| {
                let phi =
                    self.phi_f64(pair, &nodes[self.nodes[pair.a]], &nodes[self.nodes[pair.b]]);
                phi[..m].iter().fold(0.0f64, |x, v| x.max(v.abs()))
            })
            .fold(0.0, f64::max)
    }

    fn rheonomic(&self) -> bool {
        self.drive.is_some()
    }

    /// `B v` by one dual direction: `Φ` (joints/constraints.rs, generic) at
    /// `x + εv`, `R(I + εΩ̃)` (exact to first order in `ε`, all a dual number carries).
    fn constraint_rates(&self, nodes: &[NodeState], out: &mut [f64]) -> bool {
        let m = self.m_pair();
        let moved = |s: &NodeState| {
            let rw = s.r * skew(&s.w);
            (
                Vector3::from_fn(|i, _| Dual::<1> {
                    re: s.x[i],
                    eps: [s.v[i]],
                }),
                Matrix3::from_fn(|i, j| Dual::<1> {
                    re: s.r[(i, j)],
                    eps: [rw[(i, j)]],
                }),
            )
        };
        for (k, pair) in self.pairs.iter().enumerate() {
            let (x1, r1) = moved(&nodes[self.nodes[pair.a]]);
            let (x2, r2) = moved(&nodes[self.nodes[pair.b]]);
            // The driver's target is a constant along the motion: its value is not needed.
            let phi = self.phi(pair, &x1, &r1, &x2, &r2, 0.0);
            for (o, p) in out[k * m..(k + 1) * m].iter_mut().zip(&phi) {
                *o = p.eps[0];
            }
        }
        true
    }

    fn constraint_time_derivatives(&self, t: f64, k: usize) -> [f64; 2] {
        match self.drive_law(t) {
            Some([_, fd, fdd]) if k == 5 => [-fd, -fdd],
            _ => [0.0; 2],
        }
    }

    fn input_power(&self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) -> f64 {
        match self.drive_law(ctx.t) {
            Some([_, fd, _]) => -self.drive_mu(ctx, nodes, lambda) * fd,
            None => 0.0,
        }
    }

    fn diagnose(&self, nodes: &[NodeState]) -> Option<String> {
        self.singularity(nodes)
    }

    fn summary(&self) -> Option<serde_json::Value> {
        if !matches!(self.kind, JointType::UJoint { .. }) {
            return None;
        }
        Some(serde_json::json!({
            "type": "UJOINT",
            "singular_passages": self.hist.singular_passages,
            "first_singular_time": self.hist.first_singular_time,
            "min_abs_cos_bend": self.hist.min_abs_cos_bend,
        }))
    }
}
