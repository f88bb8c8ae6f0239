//! RBE2 and RBE3 interfaces against independent solutions: a bundle of beams between two
//! rigid end plates (its condensed stiffness in closed form), the averaging interface's
//! no-stiffness property (free–free spectrum unchanged, six zero eigenvalues), rigid motions
//! and the weighted least-squares fit solved here by an SVD.

use super::fe::FeModel;
use super::frame_model::{A, E, G, IY, IZ, J, frame, l_frame};
use super::invariants::Body;
use super::mtx::SymMatrix;
use super::rbe::{self, Rbe, RbeError, RbeKind, SetSpec, Transform};
use super::reduce::lowest_eigenvalues;
use nalgebra::{DMatrix, Matrix6, Vector3};

/// `beams` FE models side by side in one: node `p` of model `b` becomes `100 (b + 1) + p`.
fn merge(beams: &[FeModel]) -> FeModel {
    let n: usize = beams.iter().map(|b| b.dofs.len()).sum();
    let (mut k, mut m) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
    let (mut nodes, mut dofs) = (indexmap::IndexMap::new(), Vec::new());
    let mut off = 0;
    for (b, fe) in beams.iter().enumerate() {
        let nb = fe.dofs.len();
        k.view_mut((off, off), (nb, nb)).copy_from(&fe.k.to_dense());
        m.view_mut((off, off), (nb, nb)).copy_from(&fe.m.to_dense());
        let shift = 100 * (b as u32 + 1);
        nodes.extend(fe.nodes.iter().map(|(p, x)| (p + shift, *x)));
        dofs.extend(fe.dofs.iter().map(|(p, c)| (p + shift, *c)));
        off += nb;
    }
    FeModel {
        k: SymMatrix::from_dense(&k, 0.0),
        m: SymMatrix::from_dense(&m, 0.0),
        nodes,
        dofs,
    }
}

/// Four beams along x, 1 m, at the corners of a 0.1 × 0.06 m rectangle, `per` elements each.
fn bundle(per: usize) -> (FeModel, Vec<Vector3<f64>>) {
    let offsets: Vec<Vector3<f64>> = [(0.05, 0.03), (-0.05, 0.03), (-0.05, -0.03), (0.05, -0.03)]
        .iter()
        .map(|&(y, z)| Vector3::new(0.0, y, z))
        .collect();
    let beams: Vec<FeModel> = offsets
        .iter()
        .map(|d| frame(&[*d, d + Vector3::x()], per))
        .collect();
    (merge(&beams), offsets)
}

fn rigid(kind: RbeKind, node: u32, at: Vector3<f64>, set: Vec<u32>) -> Rbe {
    Rbe {
        kind,
        node,
        at,
        set,
        weights: Vec::new(),
    }
}

/// The spectral condition number of `a` scaled to a unit diagonal (a bound on the relative
/// round-off of solves with it: `ε κ`).
fn scaled_condition(a: &DMatrix<f64>) -> f64 {
    let d = a.diagonal().map(|x| 1.0 / x.sqrt());
    let s = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * d[i] * d[j]);
    let ev = s.symmetric_eigenvalues();
    ev.max() / ev.min()
}

/// Rigid end plates (RBE2) on a bundle of four cantilevers: with no modes (Guyan), the
/// reduced 6×6 stiffness of the tip plate relative to the clamped root plate is the sum of
/// the beams' closed-form tip stiffnesses carried to the plate's centre, `Σ Tᵢᵀ K_c Tᵢ`,
/// `Tᵢ = [I −d̃ᵢ; 0 I]` — exactly, as cubic Euler–Bernoulli elements condense to the exact
/// static tip flexibility (Przemieniecki §5). Tolerance: round-off of the condensation,
/// `n ε κ` with κ the scaled condition number of the interior stiffness.
#[test]
fn rigid_plates_give_the_bundles_end_stiffness() {
    let per = 4;
    let (fe, offsets) = bundle(per);
    let tip = per as u32 + 1;
    let root_set: Vec<u32> = (1..=4).map(|b| 100 * b + 1).collect();
    let tip_set: Vec<u32> = (1..=4).map(|b| 100 * b + tip).collect();
    let rbes = [
        rigid(RbeKind::Rigid, 1000, Vector3::zeros(), root_set),
        rigid(RbeKind::Rigid, 2000, Vector3::x(), tip_set),
    ];
    let tr = Transform::new(&fe, &rbes, &[1000, 2000]).expect("transform");
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let red = rbe::reduce(&fe, &k, &m, Some(&tr), &[1000, 2000], 0).expect("reduces");
    // The cantilever's tip flexibility (local = global axes for a beam along x).
    let l = 1.0;
    let mut f = Matrix6::zeros();
    f[(0, 0)] = l / (E * A);
    f[(3, 3)] = l / (G * J);
    // Plane xy (Iz): v, θz = v′.
    f[(1, 1)] = l.powi(3) / (3.0 * E * IZ);
    f[(1, 5)] = l.powi(2) / (2.0 * E * IZ);
    f[(5, 1)] = f[(1, 5)];
    f[(5, 5)] = l / (E * IZ);
    // Plane xz (Iy): w, θy = −w′.
    f[(2, 2)] = l.powi(3) / (3.0 * E * IY);
    f[(2, 4)] = -l.powi(2) / (2.0 * E * IY);
    f[(4, 2)] = f[(2, 4)];
    f[(4, 4)] = l / (E * IY);
    let kc = f.try_inverse().expect("flexibility");
    let mut expected = Matrix6::zeros();
    for d in &offsets {
        let mut t = Matrix6::identity();
        // u_tip = u_g + θ_g × d  ⇒  coefficient of θ_g is −d̃.
        let dt = d.cross_matrix();
        t.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-dt));
        expected += t.transpose() * kc * t;
    }
    // Round-off bound from the interior's conditioning.
    let kt = tr.congruent(&k);
    let interior: Vec<usize> = (0..tr.len())
        .filter(|&i| !matches!(tr.dofs[i].0, 1000 | 2000))
        .collect();
    let kii = DMatrix::from_fn(interior.len(), interior.len(), |i, j| {
        kt[(interior[i], interior[j])]
    });
    let tol = interior.len() as f64 * f64::EPSILON * scaled_condition(&kii);
    let mut worst = 0.0f64;
    for i in 0..6 {
        for j in 0..6 {
            let scale = (expected[(i, i)] * expected[(j, j)]).sqrt();
            worst = worst.max((red.k[(i, j)] - expected[(i, j)]).abs() / scale);
        }
    }
    eprintln!("RBE2 bundle: largest scaled difference {worst:.2e} (round-off bound {tol:.1e})");
    assert!(worst <= tol, "{worst} above {tol}");
    // The bundle without plates is four independent beams: the plates made them one body
    // (the axial-bending coupling of the offsets is there).
    assert!(expected[(1, 5)].abs() > 0.0 && expected[(4, 4)] > 4.0 * kc[(4, 4)]);
}

/// An RBE3 over part of an L frame, `weights` given.
fn averaging() -> (FeModel, Rbe) {
    let fe = l_frame(4);
    // Nodes 3..7 turn the corner (node 5): not collinear.
    let r = Rbe {
        kind: RbeKind::Average,
        node: 100,
        at: Vector3::new(0.8, 0.3, 0.05),
        set: vec![3, 4, 5, 6, 7],
        weights: vec![1.0, 2.0, 0.5, 3.0, 1.5],
    };
    (fe, r)
}

/// The RBE3 node reads the weighted least-squares rigid fit of its set's translations,
/// solved here independently (SVD of `√W S` built from the positions), and a rigid motion of
/// the mesh exactly. `ũ = T⁻¹u` by LU; tolerance `n ε κ(T)` of that solve.
#[test]
fn averaging_node_reads_the_least_squares_fit() {
    let (fe, r) = averaging();
    let tr = Transform::new(&fe, std::slice::from_ref(&r), &[1]).expect("transform");
    let t = tr.dense();
    let n = t.nrows();
    let sv = t.clone().svd(false, false).singular_values;
    let tol = n as f64 * f64::EPSILON * sv.max() / sv.min();
    let g0 = tr.dofs.iter().position(|d| d.0 == 100).expect("g dofs");
    let lu = t.clone().lu();
    let mut rng = crate::elements::testing::Lcg(7);
    // A random deformation: the g coordinates against the fit solved here.
    let u = DMatrix::from_fn(n, 1, |_, _| rng.next() - 0.5);
    let ut = lu.solve(&u).expect("T invertible");
    let k = r.set.len();
    let mut sw = DMatrix::zeros(3 * k, 6);
    let mut uw = DMatrix::zeros(3 * k, 1);
    for (a, p) in r.set.iter().enumerate() {
        let rp = fe.nodes[p] - r.at;
        let w = r.weights[a].sqrt();
        for c in 0..3 {
            sw[(3 * a + c, c)] = w;
            // (θ × r)_c = Σ_j θ_j (e_j × r)_c.
            for j in 0..3 {
                sw[(3 * a + c, 3 + j)] = w * Vector3::ith(j, 1.0).cross(&rp)[c];
            }
            uw[(3 * a + c, 0)] = w * u[(fe.dof_of(*p, c as u8).expect("dof"), 0)];
        }
    }
    // The fit's own round-off adds ε κ(√W S) to the bound.
    let ssv = sw.clone().svd(false, false).singular_values;
    let tol = tol + n as f64 * f64::EPSILON * ssv.max() / ssv.min();
    let fit = sw.svd(true, true).solve(&uw, 0.0).expect("fit");
    let mut worst = 0.0f64;
    for j in 0..6 {
        worst = worst.max((ut[(g0 + j, 0)] - fit[(j, 0)]).abs());
    }
    eprintln!("RBE3 fit: largest difference {worst:.2e} (bound {tol:.1e})");
    assert!(worst <= tol, "{worst} above {tol}");
    // A rigid motion of the whole mesh: g moves with it, the null-space coordinates are 0.
    let (a, th) = (Vector3::new(0.3, -0.2, 0.7), Vector3::new(-0.4, 0.25, 0.1));
    let ur = DMatrix::from_fn(n, 1, |i, _| {
        let (p, c) = fe.dofs[i];
        match c {
            0..3 => (a + th.cross(&fe.nodes[&p]))[c as usize],
            _ => th[c as usize - 3],
        }
    });
    let ut = lu.solve(&ur).expect("T invertible");
    let at_g = a + th.cross(&r.at);
    for j in 0..6 {
        let want = if j < 3 { at_g[j] } else { th[j - 3] };
        assert!((ut[(g0 + j, 0)] - want).abs() <= tol, "rigid {j}");
    }
    for (i, d) in tr.dofs.iter().enumerate() {
        if d.0 == 0 {
            assert!(ut[(i, 0)].abs() <= tol, "null-space coordinate {i}");
        }
    }
}

/// An RBE3 adds no stiffness: the free–free spectrum of the transformed model, and of the
/// superelement reduced about the RBE3 node as frame with every mode kept, is the FE
/// model's — six zero eigenvalues and the same elastic ones. Tolerance: the symmetric
/// eigenvalues' perturbation `n ε λ_max` (Weyl), relative to each eigenvalue.
#[test]
fn averaging_interface_adds_no_stiffness() {
    let (fe, r) = averaging();
    let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
    let n = fe.dofs.len();
    let all: Vec<usize> = (0..n).collect();
    let full = lowest_eigenvalues(&k, &m, &all, n).expect("full");
    let bound = |x: f64| 1e2 * n as f64 * f64::EPSILON * full[n - 1] + 1e-12 * x.abs();
    let tr = Transform::new(&fe, std::slice::from_ref(&r), &[100]).expect("transform");
    let (kt, mt) = (tr.congruent(&k), tr.congruent(&m));
    let same = lowest_eigenvalues(&kt, &mt, &all, n).expect("transformed");
    for (a, b) in same.iter().zip(&full) {
        assert!((a - b).abs() <= bound(*b), "{a} against {b}");
    }
    // Through the reduction: frame = the RBE3 node, every interior mode.
    let interior = n - 6;
    let red = rbe::reduce(&fe, &k, &m, Some(&tr), &[100], interior).expect("reduces");
    let fe_g = rbe::with_nodes(fe.clone(), std::slice::from_ref(&r));
    let body = Body::new(&fe_g, &m, &red, 100, &[]).expect("mass");
    let (mm, kk) = body.free_free();
    let cb =
        lowest_eigenvalues(&kk, &mm, &(0..mm.nrows()).collect::<Vec<_>>(), 12).expect("reduced");
    let mut worst = 0.0f64;
    for (a, b) in cb.iter().zip(&full) {
        worst = worst.max((a - b).abs() / bound(*b));
    }
    eprintln!(
        "RBE3 frame, all modes: 6 zeros and 6 elastic ω² within {worst:.2e} of the bound; ω²₇ = {:.4e}",
        cb[6]
    );
    assert!(worst <= 1.0, "{cb:?} against {:?}", &full[..12]);
}

#[test]
fn bad_sets_are_refused() {
    let (fe, r) = averaging();
    // Collinear: nodes 1..4 lie on the first leg.
    let line = Rbe {
        set: vec![1, 2, 3, 4],
        weights: vec![],
        ..r.clone()
    };
    let e = Transform::new(&fe, &[line], &[100]).expect_err("collinear");
    assert!(matches!(e, RbeError::Collinear { count: 4, .. }), "{e}");
    // Two nodes are always collinear.
    let two = Rbe {
        set: vec![3, 7],
        weights: vec![],
        ..r.clone()
    };
    assert!(matches!(
        Transform::new(&fe, &[two], &[100]),
        Err(RbeError::Collinear { .. })
    ));
    // Overlapping sets, a set holding an interface node.
    let other = Rbe {
        node: 200,
        kind: RbeKind::Rigid,
        set: vec![7, 8],
        ..r.clone()
    };
    let e = Transform::new(&fe, &[r.clone(), other], &[100, 200]).expect_err("overlap");
    assert!(matches!(e, RbeError::Overlap { shared: 7, .. }), "{e}");
    let e = Transform::new(&fe, std::slice::from_ref(&r), &[1, 5]).expect_err("interface");
    assert!(matches!(e, RbeError::Overlap { shared: 5, .. }), "{e}");
    // A node the mesh does not have, a number the mesh uses, an empty radius.
    let at = Vector3::new(5.0, 5.0, 5.0);
    let miss = rbe::resolve_set(&fe, RbeKind::Rigid, 100, &at, &SetSpec::Nodes(vec![3, 99]));
    assert!(matches!(miss, Err(RbeError::Missing { missing: 99, .. })));
    let taken = rbe::resolve_set(&fe, RbeKind::Rigid, 3, &at, &SetSpec::Nodes(vec![4]));
    assert!(matches!(taken, Err(RbeError::Taken { node: 3, .. })));
    let empty = rbe::resolve_set(&fe, RbeKind::Average, 100, &at, &SetSpec::Within(0.5));
    assert!(matches!(empty, Err(RbeError::Empty { .. })));
    let near = rbe::resolve_set(
        &fe,
        RbeKind::Average,
        100,
        &Vector3::x(),
        &SetSpec::Within(0.26),
    );
    assert_eq!(near.expect("three nodes"), vec![4, 5, 6]);
}

/// The large models' route: `TᵀAT` assembled sparse is the dense `TᵀAT` (the same sums
/// in another order: to `n ε` of the largest entry), for rigid and averaging sets; and the
/// sparse reduction on it gives the dense reduction's body — the bundle between two rigid
/// plates and the L-frame with its RBE3 frame, free–free `ω²` to the two routes' errors,
/// the Lanczos's `TOL` and round-off (as `sparse_tests`'s bound).
#[test]
fn the_sparse_route_with_interfaces_over_many_nodes_is_the_dense_one() {
    let per = 6;
    let (fe, _) = bundle(per);
    let tip = per as u32 + 1;
    let rigid_sets = vec![
        rigid(
            RbeKind::Rigid,
            1000,
            Vector3::zeros(),
            (1..=4).map(|b| 100 * b + 1).collect(),
        ),
        rigid(
            RbeKind::Rigid,
            2000,
            Vector3::x(),
            (1..=4).map(|b| 100 * b + tip).collect(),
        ),
    ];
    let (afe, avg) = averaging();
    let cases = [
        (fe, rigid_sets, vec![1000u32, 2000], 8usize),
        (afe, vec![avg], vec![100u32], 8usize),
    ];
    for (fe, rbes, iface, modes) in cases {
        let tr = Transform::new(&fe, &rbes, &iface).expect("transform");
        for a in [&fe.k, &fe.m] {
            let dense = tr.congruent(&a.to_dense());
            let sparse = tr.congruent_sparse(a).to_dense();
            let e = (&sparse - &dense).amax() / dense.amax();
            assert!(e <= fe.dofs.len() as f64 * f64::EPSILON, "congruent: {e}");
        }
        let (k, m) = (fe.k.to_dense(), fe.m.to_dense());
        let fe_g = rbe::with_nodes(fe.clone(), &rbes);
        let red_d = rbe::reduce(&fe, &k, &m, Some(&tr), &iface, modes).expect("dense");
        let red_s = rbe::reduce_sparse(&fe, &tr, &iface, modes).expect("sparse");
        let body = |red| Body::new(&fe_g, &m, red, iface[0], &iface[1..]).expect("mass");
        let (bd, bs) = (body(&red_d), body(&red_s));
        let eig = |b: &Body| {
            let (mm, kk) = b.free_free();
            lowest_eigenvalues(&kk, &mm, &(0..mm.nrows()).collect::<Vec<_>>(), 12).expect("eig")
        };
        let (ed, es) = (eig(&bd), eig(&bs));
        // κ of the transformed interior stiffness K̃_II (the interface held).
        let kt = tr.congruent(&k);
        let inner: Vec<usize> = (0..tr.len())
            .filter(|&r| !iface.contains(&tr.dofs[r].0))
            .collect();
        let kii = DMatrix::from_fn(inner.len(), inner.len(), |a, b| kt[(inner[a], inner[b])]);
        let kappa = scaled_condition(&kii);
        let bound = 10.0 * (crate::lanczos::TOL + kappa * f64::EPSILON);
        for (s, d) in es[6..].iter().zip(&ed[6..]) {
            let e = (s - d).abs() / d;
            eprintln!("{iface:?}: free-free ω² {d:.6e}, sparse route {e:.2e} (bound {bound:.2e})");
            assert!(e <= bound, "{e} > {bound}");
        }
    }
}
