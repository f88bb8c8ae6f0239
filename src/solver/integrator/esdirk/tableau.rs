//! The Butcher tableaux of the ESDIRK schemes (Kennedy & Carpenter 2016, NASA/TM-2016-219173):
//! the first stage explicit, every other stage with the same diagonal `γ`, stage order 2
//! (`a_21 = γ`), stiffly accurate (`b` = the last row of `A`), L-stable.
//!
//! The coefficients of the fifth-order tableau are the paper's rationals (its § 7.2.2
//! `ESDIRK5(4)7L[2]SA2`, as SUNDIALS' ARKODE lists them), with `a_i1 = c_i − Σ_{j>1} a_ij` and `b_1 = 1 − Σ_{j>1} b_j` evaluated in exact
//! rational arithmetic and rounded once to `f64`. The unit tests check every order condition
//! up to the claimed order (and that the next order fails), the stage order and `R(∞)`.

/// Largest number of stages of a tableau here.
pub const MAX_STAGES: usize = 7;

/// An ESDIRK tableau: `stages` rows of `a` are used (row `i` = stage `i`, `c_i = Σ_j a_ij`;
/// the last row is `b`).
#[derive(Debug, PartialEq)]
pub struct Tableau {
    /// Name on the ANALYSIS card and the command line.
    pub name: &'static str,
    /// Classical order of the step.
    pub order: u32,
    /// Number of stages, the first explicit.
    pub stages: usize,
    /// The common diagonal `γ`.
    pub gamma: f64,
    /// The Butcher matrix, zero-padded to [`MAX_STAGES`].
    pub a: [[f64; MAX_STAGES]; MAX_STAGES],
    /// The weights `b̂` of the embedded scheme (Kennedy & Carpenter 2016, § 2.3): with `b`
    /// the last row of `a`, `h Σ_j (b_j − b̂_j) k_j` estimates the local error of the
    /// embedded solution, `O(h^{q̂+1})` — the step controller's measure (issue 37).
    pub embedded: [f64; MAX_STAGES],
    /// Order `q̂` of the embedded scheme.
    pub embedded_order: u32,
}

/// `γ` of ESDIRK3: the root of `x³ − 3x² + 3x/2 − 1/6 = 0` in (1/3, 1/2) (Kennedy &
/// Carpenter 2016, eq. 207: the L-stable third-order SDIRK's diagonal).
const G3: f64 = 0.435_866_521_508_459;

/// `ESDIRK3(2)4L[2]SA` (Kennedy & Carpenter 2016, § 5.2.1): four stages, `c = (0, 2γ, 3/5, 1)`.
pub const ESDIRK3: Tableau = Tableau {
    name: "esdirk3",
    order: 3,
    stages: 4,
    gamma: G3,
    // The paper's § 5.2.1 `b̂` (as SUNDIALS' ARKODE lists them for ARK3(2)4L[2]SA, whose
    // implicit tableau this is).
    embedded: [
        0.214_740_286_223_389_14,
        -0.485_162_263_884_939_1,
        0.868_725_002_520_387_6,
        0.401_696_975_141_162_4,
        0.0,
        0.0,
        0.0,
    ],
    embedded_order: 2,
    a: [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [G3, G3, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            0.257_648_246_066_427_2,
            -0.093_514_767_574_886_2,
            G3,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            0.187_641_024_346_723_8,
            -0.595_297_473_576_955,
            0.971_789_927_721_772_1,
            G3,
            0.0,
            0.0,
            0.0,
        ],
        [0.0; MAX_STAGES],
        [0.0; MAX_STAGES],
        [0.0; MAX_STAGES],
    ],
};

/// `ESDIRK5(4)7L[2]SA2` (Kennedy & Carpenter 2016, § 7.2.2): seven stages, `γ = 23/125`,
/// `c = (0, 46/125, 7121331996143/11335814405378, 49/353, 3706679970760/5295570149437,
/// 347/382, 1)`.
pub const ESDIRK5: Tableau = Tableau {
    name: "esdirk5",
    order: 5,
    stages: 7,
    gamma: 0.184,
    // The paper's § 7.2.2 `b̂`, its rationals with `b̂_1 = 1 − Σ_{j>1} b̂_j` evaluated exactly
    // and rounded once.
    embedded: [
        -0.080_689_466_566_647_44,
        -0.080_689_466_566_647_44,
        0.182_899_684_613_435_53,
        0.517_013_873_766_231,
        0.426_599_731_302_454_3,
        -0.104_326_857_967_134_98,
        0.139_192_501_418_308_97,
    ],
    embedded_order: 4,
    a: [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.184, 0.184, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            0.222_107_647_738_324_75,
            0.222_107_647_738_324_75,
            0.184,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.014_049_475_381_926_283,
            -0.014_049_475_381_926_283,
            -0.017_090_850_935_864_15,
            0.184,
            0.0,
            0.0,
            0.0,
        ],
        [
            -0.408_388_592_549_314_64,
            -0.408_388_592_549_314_64,
            0.166_463_998_213_629_64,
            1.166_271_806_289_574_5,
            0.184,
            0.0,
            0.0,
        ],
        [
            -0.539_290_723_558_811_4,
            -0.539_290_723_558_811_4,
            -0.242_234_428_845_425,
            1.488_880_611_122_514_6,
            0.556_312_228_191_318_4,
            0.184,
            0.0,
        ],
        [
            -0.039_466_069_109_740_26,
            -0.039_466_069_109_740_26,
            0.272_636_490_250_242_67,
            0.432_165_172_520_288_2,
            0.352_416_086_232_889_1,
            -0.162_285_610_783_939_52,
            0.184,
        ],
    ],
};

impl Tableau {
    /// `c_i = Σ_j a_ij`, the stage's time in the step as a fraction of `h`.
    pub fn c(&self, i: usize) -> f64 {
        self.a[i].iter().sum()
    }

    /// The stability function `R(z) = 1 + z bᵀ(I − zA)⁻¹1` (the step's amplification of
    /// `y' = λy`, `z = λh`), stage by stage since `A` is lower triangular:
    /// `Y_i = (1 + z Σ_{j<i} a_ij Y_j)/(1 − z a_ii)`, `R = Y_s` (stiffly accurate).
    pub fn stability(&self, z: nalgebra::Complex<f64>) -> nalgebra::Complex<f64> {
        let one = nalgebra::Complex::new(1.0, 0.0);
        let mut y = [one; MAX_STAGES];
        for i in 0..self.stages {
            let mut s = one;
            for j in 0..i {
                s += z * self.a[i][j] * y[j];
            }
            y[i] = s / (one - z * self.a[i][i]);
        }
        y[self.stages - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The residuals of the order conditions of each order up to 5 (Butcher's rooted
    /// trees: 1, 1, 2, 4 and 9 of them), `max |Φ(t) − 1/γ(t)|` per order.
    fn order_residuals(t: &Tableau) -> [f64; 5] {
        weights_residuals(t, &t.a[t.stages - 1])
    }

    /// [`order_residuals`] of the weights `b` on `t`'s stages.
    fn weights_residuals(t: &Tableau, b: &[f64; MAX_STAGES]) -> [f64; 5] {
        let s = t.stages;
        let b = &b[..s];
        let c: Vec<f64> = (0..s).map(|i| t.c(i)).collect();
        let a = |v: &[f64]| -> Vec<f64> {
            (0..s)
                .map(|i| (0..s).map(|j| t.a[i][j] * v[j]).sum())
                .collect()
        };
        let pow = |k: i32| -> Vec<f64> { c.iter().map(|x| x.powi(k)).collect() };
        let mul =
            |u: &[f64], v: &[f64]| -> Vec<f64> { u.iter().zip(v).map(|(x, y)| x * y).collect() };
        let dot = |v: &[f64]| -> f64 { b.iter().zip(v).map(|(x, y)| x * y).sum() };
        let ac = a(&c);
        let ac2 = a(&pow(2));
        let aac = a(&ac);
        let conds: [Vec<(f64, f64)>; 5] = [
            vec![(dot(&pow(0)), 1.0)],
            vec![(dot(&c), 0.5)],
            vec![(dot(&pow(2)), 1.0 / 3.0), (dot(&ac), 1.0 / 6.0)],
            vec![
                (dot(&pow(3)), 0.25),
                (dot(&mul(&c, &ac)), 1.0 / 8.0),
                (dot(&ac2), 1.0 / 12.0),
                (dot(&aac), 1.0 / 24.0),
            ],
            vec![
                (dot(&pow(4)), 0.2),
                (dot(&mul(&pow(2), &ac)), 0.1),
                (dot(&mul(&c, &ac2)), 1.0 / 15.0),
                (dot(&mul(&c, &aac)), 1.0 / 30.0),
                (dot(&mul(&ac, &ac)), 1.0 / 20.0),
                (dot(&a(&pow(3))), 1.0 / 20.0),
                (dot(&a(&mul(&c, &ac))), 1.0 / 40.0),
                (dot(&a(&ac2)), 1.0 / 60.0),
                (dot(&a(&aac)), 1.0 / 120.0),
            ],
        ];
        conds.map(|v| v.iter().fold(0.0f64, |m, (x, y)| m.max((x - y).abs())))
    }

    #[test]
    fn each_tableau_has_its_order_and_not_the_next() {
        for t in [&ESDIRK3, &ESDIRK5] {
            let r = order_residuals(t);
            let p = t.order as usize;
            for (k, e) in r.iter().enumerate().take(p) {
                // Rounding the coefficients once to f64 (|a_ij| < 2, ≤ 7 stages, products of
                // ≤ 5 factors): a few hundred ulps at most.
                assert!(*e < 1e-14, "{}: order {} residual {e:e}", t.name, k + 1);
            }
            if p < 5 {
                assert!(
                    r[p] > 1e-6,
                    "{}: order {} also holds ({:e})",
                    t.name,
                    p + 1,
                    r[p]
                );
            }
        }
        // The check has teeth: one weight of ESDIRK5 off by 1e-12 breaks the order
        // conditions by ~1e-12, 100 times their tolerance.
        let mut t = Tableau { ..ESDIRK5 };
        t.a[6][3] += 1e-12;
        let r = order_residuals(&t);
        assert!(r.iter().all(|e| *e > 1e-13), "perturbed: {r:?}");
    }

    /// The embedded weights transcribed: their order conditions hold up to `q̂` (to the
    /// rounding of the coefficients) and fail at `q̂ + 1`, so `b − b̂` measures an error of
    /// order `h^{q̂+1}`.
    #[test]
    fn each_embedded_scheme_has_its_order_and_not_the_next() {
        for t in [&ESDIRK3, &ESDIRK5] {
            let r = weights_residuals(t, &t.embedded);
            let q = t.embedded_order as usize;
            for (k, e) in r.iter().enumerate().take(q) {
                assert!(
                    *e < 1e-14,
                    "{}: embedded order {} residual {e:e}",
                    t.name,
                    k + 1
                );
            }
            assert!(
                r[q] > 1e-6,
                "{}: embedded order {} also holds",
                t.name,
                q + 1
            );
            assert!(t.embedded[t.stages..].iter().all(|w| *w == 0.0));
        }
    }

    #[test]
    fn each_tableau_is_esdirk_stage_order_2_and_l_stable() {
        for t in [&ESDIRK3, &ESDIRK5] {
            let s = t.stages;
            assert_eq!(
                t.a[0], [0.0; MAX_STAGES],
                "{}: first stage explicit",
                t.name
            );
            for i in 1..s {
                assert_eq!(t.a[i][i], t.gamma, "{}: diagonal", t.name);
                // Stage order 2: Σ_j a_ij c_j = c_i²/2.
                let acj: f64 = (0..s).map(|j| t.a[i][j] * t.c(j)).sum();
                assert!(
                    (acj - 0.5 * t.c(i).powi(2)).abs() < 1e-14,
                    "{}: stage order",
                    t.name
                );
                assert!(
                    (0.0..=1.0).contains(&t.c(i)),
                    "{}: c_{i} outside the step",
                    t.name
                );
            }
            assert!(
                (t.c(s - 1) - 1.0).abs() < 1e-15,
                "{}: stiffly accurate",
                t.name
            );
            let far = t.stability(nalgebra::Complex::new(0.0, 1e8)).norm();
            assert!(far < 1e-6, "{}: |R(i·1e8)| = {far:e}", t.name);
            // A-stable along the imaginary axis (undamped modes never grow), ωh = 1e-3 … 1e8.
            for k in -300..=800 {
                let y = 10f64.powf(f64::from(k) / 100.0);
                let r = t.stability(nalgebra::Complex::new(0.0, y)).norm();
                assert!(r <= 1.0 + 1e-14, "{}: |R({y:e}i)| = {r}", t.name);
            }
            // Order p: R(z) − e^z = O(z^{p+1}), at z = 0.01i below 1e-2^{p+1} times a constant
            // of at most 1 (the error constants are 0.02–0.05 for these tableaux).
            let z = nalgebra::Complex::new(0.0, 0.01);
            let d = (t.stability(z) - z.exp()).norm();
            assert!(
                d < 0.01f64.powi(t.order as i32 + 1),
                "{}: R − e^z = {d:e}",
                t.name
            );
        }
        // ESDIRK3's γ is the root of x³ − 3x² + 3x/2 − 1/6 (L-stability of the SDIRK3 family).
        let g = ESDIRK3.gamma;
        assert!((g.powi(3) - 3.0 * g * g + 1.5 * g - 1.0 / 6.0).abs() < 1e-15);
    }
}
