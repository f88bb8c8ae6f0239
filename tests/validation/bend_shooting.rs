//! The 45° bend (Bathe & Bolourchi 1979) solved without finite elements: the static
//! equilibrium of the Reissner–Simo rod as a boundary-value problem, integrated along the
//! arc (RK4) and shot from the clamp. An independent route to the converged answer that the
//! beam elements are checked against (`tests/validation/high_order.rs`, `beam_p_cases.rs`).
//!
//! Equations (Simo 1985, eqs. 2.10–2.14; Simo & Vu-Quoc 1986 §2, statics): with the triad
//! `Λ(s)`, the material strains `Γ = Λᵀx′ − e₁`, `K = axial(ΛᵀΛ′) − K⁰` and the spatial
//! resultants `n = Λ C_N Γ`, `m = Λ C_M K` (`C_N = diag(EA, κGA, κGA)`,
//! `C_M = diag(GJ, EI₂, EI₃)`), the rod loaded by the force `F` at its tip only has
//! `n(s) = F` and `m′ = −x′ × F`, `m(L) = 0`. So
//! `x′ = Λ(e₁ + C_N⁻¹ΛᵀF)`, `Λ′ = Λ (C_M⁻¹Λᵀm + K⁰)~`, `m′ = −x′ × F`,
//! with `x(0) = 0`, `Λ(0) = Λ⁰(0)` and the unknown `m(0)` chosen (Newton, finite-difference
//! Jacobian, load in ten increments) so that `m(L) = 0`.

use mecano::deck::load_deck;
use mecano::model::NodeId;
use mecano::output::History;
use mecano::solver;
use nalgebra::{Matrix3, Vector3};
use std::path::Path;

/// The bend's data: radius 100, 45°, unit square section, E = 1e7, G = 5e6, κ = 5/6,
/// J = I₂ + I₃ (the benchmark's convention), tip force 600 normal to the plane.
struct Bend {
    radius: f64,
    length: f64,
    cn: Vector3<f64>,
    cm: Vector3<f64>,
    k0: Vector3<f64>,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

impl Bend {
    fn new() -> Self {
        let (e, g, a, i) = (1e7, 5e6, 1.0, 1.0 / 12.0);
        let radius = 100.0;
        Bend {
            radius,
            length: radius * std::f64::consts::FRAC_PI_4,
            cn: Vector3::new(e * a, 5.0 / 6.0 * g * a, 5.0 / 6.0 * g * a),
            cm: Vector3::new(g * 2.0 * i, e * i, e * i),
            // Arc in the XY plane from the origin, tangent +X, centre (0, R, 0); triad
            // t₁ = tangent, t₂ = Z, t₃ = t₁ × t₂: t₁′ = −t₃/R, i.e. K⁰ = (0, 1/R, 0).
            k0: Vector3::new(0.0, 1.0 / radius, 0.0),
        }
    }

    /// Right-hand side of the rod's equations at the state `(x, Λ, m)`.
    fn rhs(
        &self,
        f: &Vector3<f64>,
        lam: &Matrix3<f64>,
        m: &Vector3<f64>,
    ) -> (Vector3<f64>, Matrix3<f64>, Vector3<f64>) {
        let gamma = lam.transpose() * f;
        let gamma = Vector3::new(
            gamma.x / self.cn.x,
            gamma.y / self.cn.y,
            gamma.z / self.cn.z,
        );
        let dx = lam * (Vector3::x() + gamma);
        let mm = lam.transpose() * m;
        let k = Vector3::new(mm.x / self.cm.x, mm.y / self.cm.y, mm.z / self.cm.z) + self.k0;
        (dx, lam * skew(&k), -dx.cross(f))
    }

    /// Integrate from the clamp with `m(0) = m0` over `steps` RK4 steps: tip position and
    /// tip moment.
    fn shoot(
        &self,
        f: &Vector3<f64>,
        m0: &Vector3<f64>,
        steps: usize,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let h = self.length / steps as f64;
        let mut x = Vector3::zeros();
        let mut lam = Matrix3::identity(); // Λ⁰(0): t₁ = X, t₂ = Z, t₃ = −Y
        lam.set_column(1, &Vector3::z());
        lam.set_column(2, &(-Vector3::y()));
        let mut m = *m0;
        for _ in 0..steps {
            let (x1, l1, m1) = self.rhs(f, &lam, &m);
            let (x2, l2, m2) = self.rhs(f, &(lam + l1 * (h / 2.0)), &(m + m1 * (h / 2.0)));
            let (x3, l3, m3) = self.rhs(f, &(lam + l2 * (h / 2.0)), &(m + m2 * (h / 2.0)));
            let (x4, l4, m4) = self.rhs(f, &(lam + l3 * h), &(m + m3 * h));
            x += (x1 + x2 * 2.0 + x3 * 2.0 + x4) * (h / 6.0);
            lam += (l1 + l2 * 2.0 + l3 * 2.0 + l4) * (h / 6.0);
            m += (m1 + m2 * 2.0 + m3 * 2.0 + m4) * (h / 6.0);
        }
        (x, m)
    }

    /// The tip position under the tip force `p` along Z, `steps` RK4 steps.
    fn solve(&self, p: f64, steps: usize) -> Vector3<f64> {
        let mut m0 = Vector3::zeros();
        for inc in 1..=10 {
            let f = Vector3::new(0.0, 0.0, p * inc as f64 / 10.0);
            for it in 0.. {
                let (_, r) = self.shoot(&f, &m0, steps);
                if r.norm() < 1e-9 * p * self.radius {
                    break;
                }
                assert!(it < 30, "shooting does not converge at increment {inc}");
                let mut jac = Matrix3::zeros();
                for k in 0..3 {
                    let d = 1e-6 * p * self.radius;
                    let mut mp = m0;
                    mp[k] += d;
                    let mut mm = m0;
                    mm[k] -= d;
                    let (_, rp) = self.shoot(&f, &mp, steps);
                    let (_, rm) = self.shoot(&f, &mm, steps);
                    jac.set_column(k, &((rp - rm) / (2.0 * d)));
                }
                m0 -= jac.lu().solve(&r).expect("regular Jacobian");
            }
        }
        self.shoot(&Vector3::new(0.0, 0.0, p), &m0, steps).0
    }
}

fn fe_tip(deck: &str) -> Vector3<f64> {
    fe_tip_of(deck, 2)
}

/// The last position of node `node` of `decks/<deck>`.
fn fe_tip_of(deck: &str, node: u32) -> Vector3<f64> {
    let m = load_deck(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("decks")
            .join(deck),
    )
    .unwrap_or_else(|e| panic!("{deck}: {e:?}"));
    let mut h = History::new(1);
    let report = solver::run(&m, &mut h).expect("run starts");
    assert!(report.failure.is_none(), "{deck} failed");
    let i = m.nodes.get_index_of(&NodeId(node)).expect("node");
    h.nodes.last().expect("states")[i].x
}

/// The shooting solution is converged in its own step (RK4: halving the step changes the tip
/// by (1/2)⁴ of the error; 1,000 → 2,000 steps agree to round-off), and the two curved
/// elements of order 6 of `decks/bend45_p6.dat` agree with it to 1e-6: the element's own
/// p-convergence (order 4 → 6 changes the tip by 1.6e-5, the exponential rate of the roll-up
/// gives well under 1e-6 at order 6) bounds the difference, the ODE route shares no code with
/// the element.
#[test]
fn the_bend_by_shooting_agrees_with_two_curved_elements_of_order_6() {
    let b = Bend::new();
    let coarse = b.solve(600.0, 1000);
    let fine = b.solve(600.0, 2000);
    assert!((coarse - fine).norm() < 1e-9, "{coarse} vs {fine}");
    let fe = fe_tip("bend45_p6.dat");
    assert!((fe - fine).norm() < 1e-6, "FE {fe} vs shooting {fine}");
}

/// The point the issue names, (47.07, 15.57, 53.58) (Kynema's single Legendre spectral element
/// with 9–12 nodes, its documentation's "curved beam" case, with the same stiffnesses), is
/// not the equilibrium of this rod: the shooting solution, which involves no element at all, is
/// 0.08–0.12 away from it in each coordinate. Our elements are held to the rod's solution
/// (test above); this test records the disagreement so that it cannot go unnoticed if either
/// moves.
#[test]
fn the_issue_s_reference_point_is_not_the_rod_s_equilibrium() {
    let x = Bend::new().solve(600.0, 1000);
    let issue = Vector3::new(47.07, 15.57, 53.58);
    let d = (x - issue).abs();
    assert!(d.min() > 0.05 && d.max() < 0.15, "|x − issue| = {d}");
}

/// The tip of the 45° bend meshed with `n` two-node beams whose nodes lie on the arc
/// (`decks/bend45_p6.dat`'s card with `DIVIDE n` and order 1).
fn two_node_tip(n: u32) -> Vector3<f64> {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("decks/bend45_p6.dat"))
            .expect("deck");
    assert!(text.contains("DIVIDE 2 ORDER 6"));
    let text = text.replace("DIVIDE 2 ORDER 6", &format!("DIVIDE {n}"));
    let m = mecano::deck::parse_deck(&text, "bend45_two_node.dat").expect("parses");
    let mut h = History::new(1);
    let report = solver::run(&m, &mut h).expect("run starts");
    assert!(report.failure.is_none(), "{n} elements failed");
    let i = m.nodes.get_index_of(&NodeId(2)).expect("node 2");
    h.nodes.last().expect("states")[i].x
}

/// The literature's mesh of the 45° bend, `decks/bend45.dat` (16 two-node elements, Bathe &
/// Bolourchi 1979, Simo & Vu-Quoc 1986), held to the rod's own solution by shooting (above),
/// not to a published point: the issue's (47.07, 15.57, 53.58) is 0.08–0.12 off the rod's
/// equilibrium (test above), and a ±0.3 band around it could not catch an error of that size.
/// The two-node element converges at second order in the element length, so its error at
/// 16 elements is (4/3)|x₁₆ − x₃₂| by Richardson, to the accuracy of the ratio
/// e₁₆/e₃₂ = 4 (checked: within 10 %, the band also allowed on the estimate).
#[test]
fn the_literature_s_mesh_converges_to_the_shooting_solution() {
    let exact = Bend::new().solve(600.0, 1000);
    let deck = fe_tip_of("bend45.dat", 17);
    let (x16, x32) = (two_node_tip(16), two_node_tip(32));
    assert!(
        (deck - x16).norm() < 1e-9,
        "bend45.dat {deck} vs the arc's 16 elements {x16}"
    );
    let (e16, e32) = ((x16 - exact).norm(), (x32 - exact).norm());
    let estimate = 4.0 / 3.0 * (x16 - x32).norm();
    eprintln!(
        "45° bend, two-node beams: tip {:?} (16), {:?} (32), shooting {:?}; errors {e16:.3e}, {e32:.3e}, ratio {:.3}, Richardson estimate {estimate:.3e}",
        x16.as_slice(),
        x32.as_slice(),
        exact.as_slice(),
        e16 / e32
    );
    assert!((3.6..=4.4).contains(&(e16 / e32)), "ratio {}", e16 / e32);
    assert!(
        e16 <= 1.1 * estimate,
        "error {e16} above the estimate {estimate}"
    );
}
