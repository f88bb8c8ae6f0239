//! The kept iteration matrix in the nodes' co-rotated frames.
//!
//! Modified Newton keeps a factored matrix `S_f` built at an earlier iterate, also from one
//! step to the next. The unknowns of a node are its translation `u_x` (global frame) and its
//! rotation `u_r` (material frame: `R = R₀ exp(ũ_r)`). Under a rigid rotation `Q` of the
//! model every force row in the global frame turns with it and every material row stays:
//! `f_x(Qx, QR) = Q f_x(x, R)`, `m(Qx, QR) = m(x, R)`, so the exact matrix at the turned
//! configuration is `S = D S_f Dᵀ`, `D` = `Q` on each node's translation rows and the
//! identity elsewhere. A kept `S_f` applied as it is carries an error of `|Q − I|·‖K_x‖` in
//! the translation rows: for a beam whose axial stiffness `EA/l` dwarfs its inertia
//! (`c_a m`) the kept matrix stops contracting once the beam has turned a few hundredths of a
//! radian since the factorisation (docs/performance.md, "The kept matrix of the α family").
//!
//! Here each node gets its own `Q_i = R_i R_{f,i}ᵀ`, its turn since the factorisation, and the
//! solve is `Δ = D S_f⁻¹ Dᵀ r`: exact for a model turning rigidly, and for a deforming one the
//! error is the nodes' *relative* turn, which is what the stiff terms see. Rows without such a
//! frame (a node with a fixed translation component, the constraint equations) are left as
//! they are; a kept matrix that no longer contracts is rebuilt as before (`newton.rs`), so
//! this changes how long a matrix is kept, never what a converged iterate must satisfy.
//!
//! (Co-rotational beam elements rotate each element's matrix from a frame that follows the
//! element in the same way: Crisfield, *Non-linear Finite Element Analysis of Solids and
//! Structures*, vol. 2, Wiley 1997, on the co-rotational formulation. Here the identity
//! `S = D S_f Dᵀ` above is used on the factored global matrix, through its right-hand side and
//! solution, which costs a 3 × 3 product per node and solve.)

use super::Integrator;
use crate::solver::system::{FIXED, System};
use nalgebra::Vector3;

/// Which nodes turn their kept matrix: those of an element whose forces turn with its
/// nodes ([`crate::elements::Element::turns_with_its_nodes`]). A rigid body's or a joint's
/// translation rows are exact in the global frame and would be made stale by the turn (the
/// clearance slider-crank: 8 % more CPU with every node turned).
pub(super) fn turning_nodes(sys: &System) -> Vec<bool> {
    let mut turning = vec![false; sys.x0.len()];
    for e in sys.elements.iter().filter(|e| e.turns_with_its_nodes()) {
        for &i in e.nodes() {
            turning[i] = true;
        }
    }
    turning
}

impl Integrator {
    /// Records the nodes' orientations at the iterate whose matrix is being factored.
    pub(super) fn keep_frames(&mut self) {
        for (f, t) in self.lu_frames.iter_mut().zip(&self.trial) {
            *f = t.r;
        }
    }

    /// Turns the translation rows of `delta` by `Q_iᵀ` (`back = false`: the residual into the
    /// factorisation's frames) or by `Q_i` (`back = true`: the solution out of them), `Q_i =
    /// R_i R_{f,i}ᵀ` with `R_i` the node's orientation at the current iterate.
    pub(super) fn turn_translation_rows(&mut self, back: bool) {
        for (((d, t), f), &turning) in self
            .sys
            .node_dofs
            .iter()
            .zip(&self.trial)
            .zip(&self.lu_frames)
            .zip(&self.turning)
        {
            if !turning || d[..3].contains(&FIXED) {
                continue;
            }
            let q = t.r * f.transpose();
            let v = Vector3::new(self.delta[d[0]], self.delta[d[1]], self.delta[d[2]]);
            let w = if back { q * v } else { q.tr_mul(&v) };
            for c in 0..3 {
                self.delta[d[c]] = w[c];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::elements::testing;
    use crate::rotation;
    use nalgebra::{DMatrix, DVector, Vector3};

    /// Free beams of both kinds (two-node, order 3), one of a damped material, hinged to
    /// nothing: every row of the matrix is a beam's.
    const DECK: &str = "TITLE free beams
MATERIALS
  1 E 2.1e11 NU 0.3 RHO 7800
  2 E 2.1e11 NU 0.3 RHO 7800 DAMPING 1e-4
SECTIONS
  1 A 9e-4 I2 8.3e-8 I3 6.1e-8 J 4.15e-8
NODES
  1 0 0 0
  2 0.5 0 0
  3 1.0 0.2 0
  4 1.5 0.2 0.1
ELEMENTS
  1 BEAM 1 2 MAT 1 SEC 1
  2 BEAM 2 3 MAT 1 SEC 1 ORDER 3
  3 BEAM 3 4 MAT 2 SEC 1
ANALYSIS DYNAMIC ALPHA -0.1 STEP 1e-3 END 1e-2
END
";

    fn dense(m: &crate::solver::linear::SparseSystem) -> DMatrix<f64> {
        let n = m.dim();
        let mut d = DMatrix::zeros(n, n);
        for c in 0..n {
            for p in m.position_range(c) {
                d[(m.row_of(p), c)] = m.values[p];
            }
        }
        d
    }

    /// The identity this module rests on, checked on the assembled beams: at a rigidly
    /// turned state (positions, velocities and accelerations turned by `Q`, orientations
    /// `Q R`, material angular rates kept) the iteration matrix is `D S Dᵀ`, `D` = `Q` on
    /// every node's translation rows; so the matrix factored before the turn, applied in the
    /// co-rotated frames, solves the turned system as a fresh factorisation does — and applied
    /// as it is, it does not.
    #[test]
    fn a_rigid_turn_turns_the_iteration_matrix_and_the_kept_solve_follows_it() {
        let model = crate::deck::parse_deck(DECK, "t").expect("parses");
        let mut integ = crate::solver::prepare(&model).expect("builds");
        integ.initialize().expect("starts");
        assert!(integ.turning.iter().all(|&t| t));
        // A deformed, moving state A (strains ~1e-3, rotations up to ~1.5 rad), and B, A
        // turned rigidly by 2.6 rad.
        let a = testing::random_states(&integ.sys.x0, 1e-3, 1.5, 987);
        let q = rotation::exp(&Vector3::new(0.4, -1.3, 2.2));
        let b = testing::rigidly_moved(&a, &q, &Vector3::zeros());
        let ctx = integ.context(0.0, 1e-3, integ.scale);
        let lambda = vec![0.0; integ.sys.n_eq()];
        integ.sys.assemble_with(&ctx, &a, &lambda, true, None);
        let sa = dense(&integ.sys.matrix);
        integ.sys.matrix.factor().expect("factors");
        integ.trial.clone_from(&a);
        integ.keep_frames();
        // The residual at B, then the kept matrix's solves (the matrix is not reassembled).
        integ.sys.assemble_with(&ctx, &b, &lambda, false, None);
        let r = integ.sys.rhs.clone();
        integ.trial.clone_from(&b);
        integ.delta.copy_from_slice(&r);
        integ.turn_translation_rows(false);
        integ.sys.matrix.solve(&mut integ.delta).expect("solves");
        integ.turn_translation_rows(true);
        let turned = DVector::from_column_slice(&integ.delta);
        let mut plain = r.clone();
        integ.sys.matrix.solve(&mut plain).expect("solves");
        let plain = DVector::from_column_slice(&plain);
        integ.sys.assemble_with(&ctx, &b, &lambda, true, None);
        let sb = dense(&integ.sys.matrix);

        let n = sa.nrows();
        let mut d = DMatrix::<f64>::identity(n, n);
        for dofs in &integ.sys.node_dofs {
            for (i, j) in (0..3).flat_map(|i| (0..3).map(move |j| (i, j))) {
                d[(dofs[i], dofs[j])] = q[(i, j)];
            }
        }
        // Each entry is a sum of a few tens of products of entries of at most `max|S|`
        // (Gauss points, inertia, damping and the turn's 3 × 3 products), each exact to a
        // few ε: 1000 ε max|S| bounds their round-off.
        let amax = sa.amax();
        let off = (&sb - &d * &sa * d.transpose()).amax();
        assert!(off <= 1e3 * f64::EPSILON * amax, "{off:e} of {amax:e}");
        // The solves: the kept matrix in the turned frames against a fresh dense LU at B,
        // to the round-off of a solve, κ ε (κ from the singular values); as it is, the kept
        // matrix is off by the order of the turn.
        let fresh = sb
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&r))
            .unwrap();
        let sv = sb.singular_values();
        let kappa = sv.max() / sv.min();
        let err = (&turned - &fresh).amax() / fresh.amax();
        assert!(err <= 10.0 * kappa * f64::EPSILON, "{err:e}, κ = {kappa:e}");
        let stale = (&plain - &fresh).amax() / fresh.amax();
        assert!(stale > 1e-2, "{stale:e}");
    }
}
