//! The independent route of the spatial four-bar (decks/benchmarks/four_bar_bauchau.dat):
//! its response to first order in the crank angle θ, from linear beam theory. Nothing here
//! uses mecano.
//!
//! **Why the bars deform.** The rigid parallelogram turns the crank and the rocker by θ
//! about Z and translates the coupler, so at C the rocker turns by θ about Z relative to
//! the coupler; the hinge at C lets it turn only about n = (sin β, 0, cos β). To first
//! order the rocker's rotation relative to the coupler is φ n with φ cos β = θ (the Z
//! part, the in-plane structure being a mechanism), which leaves θ tan β about X that the
//! loop must take up elastically: torsion of the coupler, out-of-plane bending of the
//! crank and the rocker, and (through the hinge's moment, perpendicular to n) a little
//! in-plane bending.
//!
//! **The linear frame.** Nine nodes (each bar's two ends and its middle; a hinge joins two
//! nodes at one point), six unknowns each (u, φ: displacement and small rotation, global),
//! and six linear Timoshenko beams (two per bar) with the deck's EA, kGA, GJ, EI. For a
//! uniform beam loaded only at its ends this element is exact (cubic deflection, quadratic
//! rotation: J. S. Przemieniecki, *Theory of Matrix Structural Analysis*, 1968, §5.6), so
//! the route has no mesh error: gravity and inertia are left out (the test compares it with
//! static runs without gravity). The joints are the linearised hinges: equal
//! displacements, and the relative rotation without components perpendicular to the axis
//! (at A and D one side is the ground); the driver sets the crank's rotation about Z at
//! A to θ. The 21 equations join the 54 unknowns by Lagrange multipliers; the KKT system is
//! solved by LU.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// A bar's section: the deck's PROPERTIES.
#[derive(Debug, Clone, Copy)]
pub struct Section {
    /// Axial stiffness EA, N.
    pub ea: f64,
    /// Shear stiffness kGA (both directions), N.
    pub kga: f64,
    /// Torsional stiffness GJ, N m².
    pub gj: f64,
    /// Bending stiffness EI (both directions), N m².
    pub ei: f64,
}

/// The mechanism's data.
#[derive(Debug, Clone, Copy)]
pub struct FourBar {
    /// Crank and rocker length, m (the coupler and the ground are twice it).
    pub l: f64,
    /// Tilt of the hinge at C about Y, rad.
    pub beta: f64,
    /// Crank and coupler section.
    pub thick: Section,
    /// Rocker section.
    pub thin: Section,
}

/// The route's nodes, in order: crank A, mid, B; coupler B, mid, C; rocker C, mid, D.
pub const NODES: usize = 9;

impl FourBar {
    /// Positions of the route's nodes (the deck's geometry).
    pub fn positions(&self) -> [Vector3<f64>; NODES] {
        let l = self.l;
        let p = |x: f64, y: f64| Vector3::new(x, y, 0.0);
        [
            p(0.0, 0.0),
            p(0.0, l / 2.0),
            p(0.0, l),
            p(0.0, l),
            p(l, l),
            p(2.0 * l, l),
            p(2.0 * l, l),
            p(2.0 * l, l / 2.0),
            p(2.0 * l, 0.0),
        ]
    }

    /// The displacements and rotations (u, φ) of the nodes per radian of crank angle: the
    /// derivative of the response at θ = 0.
    pub fn per_radian(&self) -> [(Vector3<f64>, Vector3<f64>); NODES] {
        let x = self.positions();
        let n = 6 * NODES;
        let mut k = DMatrix::<f64>::zeros(n, n);
        let beams = [
            (0, 1, self.thick),
            (1, 2, self.thick),
            (3, 4, self.thick),
            (4, 5, self.thick),
            (6, 7, self.thin),
            (7, 8, self.thin),
        ];
        for (a, b, s) in beams {
            let ke = beam_stiffness(x[a], x[b], s);
            let dofs: Vec<usize> = (0..6)
                .map(|i| 6 * a + i)
                .chain((0..6).map(|i| 6 * b + i))
                .collect();
            for (i, &gi) in dofs.iter().enumerate() {
                for (j, &gj) in dofs.iter().enumerate() {
                    k[(gi, gj)] += ke[(i, j)];
                }
            }
        }
        // The joints' equations: rows of C q = d.
        let (ex, ey) = (Vector3::<f64>::x(), Vector3::<f64>::y());
        let axis_c = Vector3::new(self.beta.sin(), 0.0, self.beta.cos());
        let p_c = axis_c.cross(&ey).normalize();
        let q_c = axis_c.cross(&p_c);
        let mut rows: Vec<(Vec<(usize, f64)>, f64)> = Vec::new();
        let u = |node: usize, i: usize| 6 * node + i;
        let f = |node: usize, i: usize| 6 * node + 3 + i;
        // A: the crank's end on the ground, its rotation θ = 1 about Z.
        for i in 0..3 {
            rows.push((vec![(u(0, i), 1.0)], 0.0));
            rows.push((vec![(f(0, i), 1.0)], if i == 2 { 1.0 } else { 0.0 }));
        }
        // A hinge between nodes a and b (b = None: the ground) about `axis`'s normals.
        let mut hinge = |a: usize, b: Option<usize>, normals: [Vector3<f64>; 2]| {
            for i in 0..3 {
                let mut r = vec![(u(a, i), 1.0)];
                if let Some(b) = b {
                    r.push((u(b, i), -1.0));
                }
                rows.push((r, 0.0));
            }
            for m in normals {
                let mut r: Vec<(usize, f64)> = (0..3).map(|i| (f(a, i), m[i])).collect();
                if let Some(b) = b {
                    r.extend((0..3).map(|i| (f(b, i), -m[i])));
                }
                rows.push((r, 0.0));
            }
        };
        hinge(2, Some(3), [ex, ey]);
        hinge(5, Some(6), [p_c, q_c]);
        hinge(8, None, [ex, ey]);
        let m = rows.len();
        let mut kkt = DMatrix::<f64>::zeros(n + m, n + m);
        let mut rhs = DVector::<f64>::zeros(n + m);
        kkt.view_mut((0, 0), (n, n)).copy_from(&k);
        // Scale the constraint rows to the stiffness (conditioning only).
        let scale = k.diagonal().max();
        for (r, (entries, d)) in rows.iter().enumerate() {
            for &(c, v) in entries {
                kkt[(n + r, c)] += scale * v;
                kkt[(c, n + r)] += scale * v;
            }
            rhs[n + r] = scale * d;
        }
        let q = kkt
            .lu()
            .solve(&rhs)
            .expect("the linear frame is determinate");
        std::array::from_fn(|i| {
            (
                Vector3::new(q[6 * i], q[6 * i + 1], q[6 * i + 2]),
                Vector3::new(q[6 * i + 3], q[6 * i + 4], q[6 * i + 5]),
            )
        })
    }
}

/// The 12×12 stiffness (global) of a linear Timoshenko beam from `a` to `b` in the XY plane
/// (unknowns u₁ φ₁ u₂ φ₂): axial EA/L, torsion GJ/L, and in each bending plane
/// `EI/((1 + Φ) L³)` times the matrix of Przemieniecki (1968, eq. 5.116), Φ = 12 EI/(kGA L²).
fn beam_stiffness(a: Vector3<f64>, b: Vector3<f64>, s: Section) -> DMatrix<f64> {
    let d = b - a;
    let l = d.norm();
    let e1 = d / l;
    let e3 = Vector3::z();
    let e2 = e3.cross(&e1);
    let mut kl = DMatrix::<f64>::zeros(12, 12);
    let ka = s.ea / l;
    let kt = s.gj / l;
    for (i, j, v) in [
        (0, 0, ka),
        (0, 6, -ka),
        (6, 6, ka),
        (3, 3, kt),
        (3, 9, -kt),
        (9, 9, kt),
    ] {
        kl[(i, j)] += v;
        if i != j {
            kl[(j, i)] += v;
        }
    }
    let phi = 12.0 * s.ei / (s.kga * l * l);
    let c = s.ei / ((1.0 + phi) * l.powi(3));
    // Bending (v, θz): deflection along e2, rotation about e3; (w, θy): along e3, about e2
    // (θy = −w', hence the signs).
    for (tr, rot, sg) in [(1usize, 5usize, 1.0), (2, 4, -1.0)] {
        let dofs = [tr, rot, tr + 6, rot + 6];
        let m = [
            [12.0, sg * 6.0 * l, -12.0, sg * 6.0 * l],
            [
                sg * 6.0 * l,
                (4.0 + phi) * l * l,
                -sg * 6.0 * l,
                (2.0 - phi) * l * l,
            ],
            [-12.0, -sg * 6.0 * l, 12.0, -sg * 6.0 * l],
            [
                sg * 6.0 * l,
                (2.0 - phi) * l * l,
                -sg * 6.0 * l,
                (4.0 + phi) * l * l,
            ],
        ];
        for i in 0..4 {
            for j in 0..4 {
                kl[(dofs[i], dofs[j])] += c * m[i][j];
            }
        }
    }
    // Local components = R · global, R's rows the local axes.
    let r = Matrix3::from_rows(&[e1.transpose(), e2.transpose(), e3.transpose()]);
    let mut t = DMatrix::<f64>::zeros(12, 12);
    for blk in 0..4 {
        t.view_mut((3 * blk, 3 * blk), (3, 3)).copy_from(&r);
    }
    t.transpose() * kl * t
}
