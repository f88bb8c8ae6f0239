//! [`System`]'s assembly: the element contributions (residual, iteration matrix) into the
//! global residual and matrix, the constraint rows alone, and the powers of the loads and
//! the drivers.

use super::{AssemblyInfo, FIXED, NONE, System, safe_norm};
use crate::elements::{EvalContext, Local, NodeState};
use crate::rotation::skew;
use nalgebra::Matrix3;

impl System {
    /// Assembles the global residual into [`System::rhs`] and, when `tangent`, the
    /// iteration matrix into [`System::matrix`]. `lambda` is indexed by global equation.
    pub fn assemble(
        &mut self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
    ) -> AssemblyInfo {
        self.assemble_with(ctx, nodes, lambda, tangent, None)
    }

    /// As [`System::assemble`], with the tangent operators `T(uᵢ)` of the nodes' rotation
    /// increments: the stiffness part of each element's rotational columns is multiplied by
    /// `T(uᵢ)` (since `δΘ = T(u) δu`), so the iteration matrix is the exact derivative with
    /// respect to the step increment `u` (Brüls, Cardona & Arnold 2012, eq. for `S_t`).
    pub fn assemble_with(
        &mut self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        tmap: Option<&[Matrix3<f64>]>,
    ) -> AssemblyInfo {
        self.assemble_except(ctx, nodes, lambda, tangent, tmap, &[])
    }

    /// As [`System::assemble_with`], leaving out the elements `e` with `left_out[e]` (an
    /// empty slice leaves out none).
    pub fn assemble_except(
        &mut self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
        tangent: bool,
        tmap: Option<&[Matrix3<f64>]>,
        left_out: &[bool],
    ) -> AssemblyInfo {
        self.rhs.iter_mut().for_each(|v| *v = 0.0);
        if tangent {
            self.matrix.clear();
        }
        let mut info = AssemblyInfo::default();
        for (e, el) in self.elements.iter().enumerate() {
            if left_out.get(e).is_some_and(|&l| l) {
                continue;
            }
            let local = &mut self.locals[self.local_of[e] as usize];
            // Residual-only assemblies leave `tan` as it was: it is read only after a
            // tangent assembly, which clears it.
            if tangent {
                local.clear();
            } else {
                local.res.fill(0.0);
            }
            let k = el.multipliers();
            let o = self.mult_offset[e];
            el.evaluate(ctx, nodes, &lambda[o..o + k], tangent, local);
            if ctx.dynamic {
                info.force_scale = info.force_scale.max(el.force_scale(nodes, &ctx.gravity));
            }
            let rows = &self.rows[e];
            let nn = 6 * el.nodes().len();
            for (i, &g) in rows.iter().enumerate() {
                if i < nn {
                    info.force_scale = info.force_scale.max(local.res[i].abs());
                }
                if g != NONE {
                    self.rhs[g as usize] += local.res[i];
                }
            }
            if tangent {
                if let Some(tm) = tmap {
                    apply_rotation_tangent(local, el.nodes(), tm);
                }
                for (p, &pos) in self.maps[e].iter().enumerate() {
                    if pos != NONE {
                        self.matrix.values[pos as usize] += local.tan[p];
                    }
                }
            }
        }
        // Removed equations: `s λ_k = 0`, so Newton sets their multipliers to zero.
        for &(g, pos) in &self.removed {
            self.rhs[g] = ctx.constraint_scale * lambda[g];
            if tangent {
                self.matrix.values[pos as usize] += ctx.constraint_scale;
            }
        }
        for l in &self.loads {
            let f = l.at(ctx.t);
            let arm = if l.moment { self.ref_length } else { 1.0 };
            info.load_scale = info.load_scale.max(safe_norm(&f) / arm);
            let d = &self.node_dofs[l.node];
            if l.moment {
                // Global moment m enters the material equations as −Rᵀm; its derivative
                // with respect to δΘ is −(Rᵀm)~.
                let mm = nodes[l.node].r.transpose() * f;
                for c in 0..3 {
                    if d[3 + c] != FIXED {
                        self.rhs[d[3 + c]] -= mm[c];
                    }
                }
                if tangent {
                    let k = -skew(&mm);
                    for c in 0..3 {
                        for r in 0..3 {
                            let pos = self.moment_blocks[l.node][3 * c + r];
                            if pos != NONE {
                                self.matrix.values[pos as usize] += k[(r, c)];
                            }
                        }
                    }
                }
            } else {
                for c in 0..3 {
                    if d[c] != FIXED {
                        self.rhs[d[c]] -= f[c];
                    }
                }
            }
        }
        info
    }

    /// The constraint rows `s Φ(q)` alone (the multipliers' equations, `rhs[n_node_eq..]`),
    /// from the elements that carry multipliers: what [`System::assemble`] puts there, bit for
    /// bit (each multiplier row belongs to one element, so it receives one addition either
    /// way), without evaluating the others (beams, contacts), whose rows these are not. The
    /// nodal part of `rhs` is left as it was. For the ESDIRK stages' velocity-level rows,
    /// which need `Φ` at two moved states per Newton iteration.
    pub fn assemble_constraint_rows(
        &mut self,
        ctx: &EvalContext,
        nodes: &[NodeState],
        lambda: &[f64],
    ) {
        let nn = self.n_node_eq;
        self.rhs[nn..].iter_mut().for_each(|v| *v = 0.0);
        for (e, el) in self.elements.iter().enumerate() {
            let k = el.multipliers();
            if k == 0 {
                continue;
            }
            let local = &mut self.locals[self.local_of[e] as usize];
            local.res.fill(0.0);
            let o = self.mult_offset[e];
            el.evaluate(ctx, nodes, &lambda[o..o + k], false, local);
            let first = 6 * el.nodes().len();
            for (i, &g) in self.rows[e].iter().enumerate().skip(first) {
                if g != NONE {
                    self.rhs[g as usize] += local.res[i];
                }
            }
        }
    }

    /// Power of the applied loads at `t`, W (forces on velocities, moments on global
    /// angular velocities).
    pub fn external_power(&self, t: f64, nodes: &[NodeState]) -> f64 {
        self.loads
            .iter()
            .map(|l| {
                let s = &nodes[l.node];
                let f = l.at(t);
                if l.moment {
                    f.dot(&(s.r * s.w))
                } else {
                    f.dot(&s.v)
                }
            })
            .sum()
    }

    /// Power the drivers deliver at the state, W ([`Element::input_power`]); `lambda`
    /// holds the multipliers scaled by `ctx.constraint_scale`.
    pub fn input_power(&self, ctx: &EvalContext, nodes: &[NodeState], lambda: &[f64]) -> f64 {
        self.elements
            .iter()
            .enumerate()
            .filter(|(_, el)| el.does_work())
            .map(|(e, el)| {
                let o = self.mult_offset[e];
                el.input_power(ctx, nodes, &lambda[o..o + el.multipliers()])
            })
            .sum()
    }
}

/// Replaces the rotational columns `K` of a local tangent by `(K − R) T + R`, with `R` the
/// velocity/acceleration part the element recorded in [`Local::rate`].
fn apply_rotation_tangent(local: &mut Local, nodes: &[usize], tm: &[Matrix3<f64>]) {
    let n = local.n;
    for (k, &node) in nodes.iter().enumerate() {
        let t = &tm[node];
        let c0 = 6 * k + 3;
        for i in 0..n {
            let mut kk = [0.0; 3];
            let mut rr = [0.0; 3];
            for m in 0..3 {
                let p = (c0 + m) * n + i;
                rr[m] = if local.has_rate { local.rate[p] } else { 0.0 };
                kk[m] = local.tan[p] - rr[m];
            }
            for j in 0..3 {
                local.tan[(c0 + j) * n + i] =
                    kk[0] * t[(0, j)] + kk[1] * t[(1, j)] + kk[2] * t[(2, j)] + rr[j];
            }
        }
    }
}
