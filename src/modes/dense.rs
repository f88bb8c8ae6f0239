//! Dense eigen-solvers of the reduced linearised problem `M ÿ + C ẏ + K y = 0`.
//!
//! **Conservative** (`C = 0`, `K` and `M` symmetric): the generalised problem
//! `K φ = ω² M φ` by shift and invert, `K + σM = LLᵀ` (Cholesky),
//! `L⁻¹ M L⁻ᵀ z = μ z`, `ω² = 1/μ − σ`, `φ = L⁻ᵀ z`. The shift makes a singular `K`
//! (free rigid motions) regular and serves the low modes (their `μ` are the largest and
//! the most accurate); `μ ≈ 0` are massless directions (infinite frequencies), dropped.
//! **Damped or gyroscopic**: the first-order form `ż = A z`,
//! `A = [0 I; −K̂ −Ĉ]` in mass-orthonormal coordinates (`K̂ = L⁻¹KL⁻ᵀ`, `Ĉ = L⁻¹CL⁻ᵀ`,
//! `M = LLᵀ`), eigenvalues `s = −ζω ± iω√(1−ζ²)` (faer's dense
//! eigen-decomposition), one mode per conjugate pair.
//!
//! Large models: shift-invert Lanczos ([`super::sparse`]) and, damped or gyroscopic,
//! shift-invert Arnoldi on the first-order form ([`super::sparse_damped`]) on the
//! project's sparse LU, with this path's conventions (docs/modes.md).

use faer::Mat;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A computed mode in reduced coordinates.
#[derive(Debug, Clone)]
pub struct RawMode {
    /// Eigenvalue `s` (real part, imaginary part ≥ 0), 1/s. Conservative: `s = iω`, or
    /// `s = +√(−ω²)` for a divergent (unstable) direction.
    pub s: (f64, f64),
    /// `ω²` of the conservative problem (`|s|²` with the sign of stability otherwise).
    pub omega2: f64,
    /// Shape in reduced coordinates (real; for a damped mode the real part of the complex
    /// shape after turning its largest component real).
    pub shape: DVector<f64>,
}

/// Why the dense solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DenseError {
    /// `K + σM` stayed indefinite for every shift tried.
    #[error(
        "the stiffness has negative eigenvalues below −{0:.3e} 1/s²: no shift made K + σM positive"
    )]
    Indefinite(f64),
    /// A damped or gyroscopic model with massless directions (the first-order form needs M⁻¹).
    #[error(
        "a damped or gyroscopic model with massless degrees of freedom: the first-order form needs a regular mass matrix"
    )]
    MasslessDamped,
    /// ω²_max, the largest ratio of a stiffness to its mass, is not a finite number.
    #[error(
        "the ratio of stiffness to mass overflows (ω²_max is not a finite number): no eigen-solve is possible"
    )]
    NotFinite,
    /// The eigen-decomposition did not converge.
    #[error("the dense eigen-decomposition did not converge")]
    NoConvergence,
}

/// A computed zero eigenvalue of the conservative problem lies within round-off of the
/// assembled stiffness, whose entries carry `ε ‖K‖ ≈ ε ω_max² ‖M‖`: `|ω²| ≤ ZERO_FACTOR ·
/// ε · ω²_max` is reported as an exact zero (a rigid motion). 10 covers the sums of a few
/// element contributions per entry; the measured free-free beam's zeros sit at ≈ 0.1–1 ε ω²_max
/// and the stiffest deck's pendulum mode (decks/pendulum_rigid_hanging.dat) at 1e2 above it.
pub const ZERO_FACTOR: f64 = 10.0;

/// The reduced symmetric problem's modes, sorted by `ω²` (negative = unstable first).
pub fn conservative(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Result<Vec<RawMode>, DenseError> {
    let n = k.nrows();
    // ω²_max estimate: the largest diagonal ratio (Rayleigh quotients of unit vectors).
    let mut wmax: f64 = 0.0;
    for i in 0..n {
        if m[(i, i)] > 0.0 {
            wmax = wmax.max(k[(i, i)].abs() / m[(i, i)]);
        }
    }
    // A ratio that overflows (a stiffness of 1e308 over a mass of 1) has no shift: no
    // σ ≥ 1e-8 ω²_max is a number. (Also a non-finite entry of K or M.)
    if !wmax.is_finite() || !k.iter().chain(m.iter()).all(|v| v.is_finite()) {
        return Err(DenseError::NotFinite);
    }
    let wmax = if wmax > 0.0 { wmax } else { 1.0 };
    // σ = 1e-8 ω²_max: far above the round-off zeros of K (ε ω²_max), so K + σM is
    // positive definite, and small enough to cost ω² only ε σ = 1e-8 ε ω²_max. Then
    // ×100 up to 1e4 ω²_max: at most SHIFTS tries, whatever the numbers (issue 35: the
    // loop's exit test `σ > 1e2 ω²_max` never held once 1e2 ω²_max overflowed).
    const SHIFTS: i32 = 7;
    let mut chol = None;
    let mut sigma = 1e-8 * wmax;
    for _ in 0..SHIFTS {
        // A shift that overflowed would put NaN (0·∞) in K + σM, which a Cholesky
        // factorisation does not refuse.
        if !sigma.is_finite() {
            break;
        }
        if let Some(c) = (k + m * sigma).cholesky() {
            chol = Some(c);
            break;
        }
        sigma *= 100.0;
    }
    let Some(chol) = chol else {
        return Err(DenseError::Indefinite(sigma / 100.0));
    };
    let l = chol.l();
    let linv = l
        .clone()
        .solve_lower_triangular(&DMatrix::identity(n, n))
        .ok_or(DenseError::NoConvergence)?;
    let linvt = linv.transpose();
    let a = &linv * m * &linvt;
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::try_new(a, f64::EPSILON, 0).ok_or(DenseError::NoConvergence)?;
    let mu_max = eig.eigenvalues.iter().fold(0.0f64, |x, v| x.max(*v));
    let mut out = Vec::new();
    for i in 0..n {
        let mu = eig.eigenvalues[i];
        // Massless directions: μ at round-off of the largest.
        if mu <= (n as f64) * f64::EPSILON * mu_max {
            continue;
        }
        let z = eig.eigenvectors.column(i);
        // φ = L⁻ᵀ z, normalised to φᵀMφ = 1.
        let phi = &linvt * z;
        let phi = &phi / phi.dot(&(m * &phi)).sqrt();
        // ω² = 1/μ − σ carries ε(ω² + σ)²/σ from μ's absolute error ε/σ: exact enough
        // below σ; above it the Rayleigh quotient φᵀKφ/φᵀMφ (error quadratic in φ's).
        let mut omega2 = 1.0 / mu - sigma;
        if omega2 > sigma {
            omega2 = phi.dot(&(k * &phi));
        }
        out.push(RawMode {
            s: if omega2 >= 0.0 {
                (0.0, omega2.sqrt())
            } else {
                ((-omega2).sqrt(), 0.0)
            },
            omega2,
            shape: phi,
        });
    }
    out.sort_by(|a, b| a.omega2.total_cmp(&b.omega2));
    Ok(out)
}

/// The eigenvalues and right eigenvectors of a real matrix, by faer's unblocked Francis
/// double-shift QR (LAPACK's `dlahqr`, at most 30 iterations per eigenvalue, then an
/// error): the blocked multishift QR with aggressive early deflation (faer's default above
/// 75 rows) never returned on the state matrix of `decks/pd_flexible_arm.dat` with a PID
/// (a swap of its deflation window looping in `lasy2`), and a run's summary hung on it
/// past SIGTERM. Same factorisation (Hessenberg, Schur, back substitution), O(n³).
fn eigen_unblocked(a: &Mat<f64>) -> Option<(Vec<faer::c64>, Mat<faer::c64>)> {
    let (re, im, ur) = francis_unblocked(a, true)?;
    let ur = ur?;
    let n = a.nrows();
    // Real eigenvalues: their column; a conjugate pair: columns (re, im) of the first.
    let mut s = Vec::with_capacity(n);
    let mut u = Mat::<faer::c64>::zeros(n, n);
    let mut j = 0;
    while j < n {
        if im[j] == 0.0 || j + 1 == n {
            s.push(faer::c64::new(re[j], 0.0));
            for i in 0..n {
                u[(i, j)] = faer::c64::new(ur[(i, j)], 0.0);
            }
            j += 1;
        } else {
            s.push(faer::c64::new(re[j], im[j]));
            s.push(faer::c64::new(re[j], -im[j]));
            for i in 0..n {
                u[(i, j)] = faer::c64::new(ur[(i, j)], ur[(i, j + 1)]);
                u[(i, j + 1)] = faer::c64::new(ur[(i, j)], -ur[(i, j + 1)]);
            }
            j += 2;
        }
    }
    Some((s, u))
}

/// The first-order form's matrix `A = [0 σI; −K̂/σ −Ĉ]` in mass-orthonormal coordinates,
/// its blocks balanced by [`block_balance`]'s `σ`, and `L⁻¹` (`M = LLᵀ`).
fn first_order(
    k: &DMatrix<f64>,
    c: &DMatrix<f64>,
    m: &DMatrix<f64>,
) -> Result<(Mat<f64>, DMatrix<f64>), DenseError> {
    let n = k.nrows();
    let chol = m.clone().cholesky().ok_or(DenseError::MasslessDamped)?;
    // In the mass-orthonormal coordinates `u = Lᵀy` (`M = LLᵀ`) the matrices are
    // `K̂ = L⁻¹KL⁻ᵀ` (symmetric when K is) and `Ĉ = L⁻¹CL⁻ᵀ`: `A = [0 I; −K̂ −Ĉ]`, with
    // ‖A‖ ≈ ω²_max, and a low eigenvalue errs by ≈ ε ω²_max/(2ω) at best (balanced below:
    // ‖A‖ ≈ ω_max, the same bound, which the unbalanced QR missed by a factor of 1e3).
    // `M⁻¹K` instead is far from normal when the masses span decades (a beam's rotary
    // inertia 1e-6 of its mass: the rotating cantilever's second flapwise frequency at
    // ν = 12 moved by 4.6e-5 relative between beams of order 8 to 14; 3e-8 in these
    // coordinates, the lead-lag ones 7e-7; docs/modes.md).
    let linv = chol
        .l()
        .solve_lower_triangular(&DMatrix::identity(n, n))
        .ok_or(DenseError::MasslessDamped)?;
    let mk = &linv * k * linv.transpose();
    let mc = &linv * c * linv.transpose();
    let sc = block_balance(mk.amax());
    let a = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => 0.0,
        (true, false) => sc * f64::from(u8::from(j - n == i)),
        (false, true) => -mk[(i - n, j)] / sc,
        (false, false) => -mc[(i - n, j - n)],
    });
    Ok((a, linv))
}

/// The power of two `σ` nearest `√‖K̂‖` (max-abs; 1 without stiffness) by which
/// [`first_order`] balances its off-diagonal blocks: `A = [0 σI; −K̂/σ −Ĉ]`, the similarity
/// `D⁻¹[0 I; −K̂ −Ĉ]D` with `D = diag(I, σI)`: the same eigenvalues, and eigenvectors whose
/// displacement part (the first half, the shapes taken) is unchanged. A power of two makes
/// the scaling exact. Unbalanced, the blocks differ by `ω²_max` (3e12 1/s² on the flexible
/// slider-crank of `benches/peers/`, moving at its start), and the unblocked QR left its
/// lowest frequencies 1.9e-5–2.9e-5 relative off (131.91359 Hz where LAPACK's `dgeev`, which
/// balances, gives 131.909827 on either form; balanced here: 131.909827, within 1e-10),
/// in 22 % more instructions. Test (below; 1.6e-6 relative unbalanced, 9.5e-10 balanced):
/// `gyroscopic_frequencies_over_four_decades_match_the_hermitian_route`.
fn block_balance(k_max: f64) -> f64 {
    if k_max.is_finite() && k_max > 0.0 {
        2f64.powi(k_max.sqrt().log2().round() as i32)
    } else {
        1.0
    }
}

/// `ω²` of a first-order eigenvalue: `|s|²`, negative for a growing real root.
fn omega2_of(z: faer::c64) -> f64 {
    (z.re * z.re + z.im * z.im) * if z.re > 0.0 { -1.0 } else { 1.0 }
}

/// [`eigen_unblocked`]'s eigenvalues alone (the same Francis QR on the Hessenberg form,
/// without accumulating the Schur vectors or solving for the eigenvectors).
fn eigenvalues_unblocked(a: &Mat<f64>) -> Option<Vec<faer::c64>> {
    let (re, im, _) = francis_unblocked(a, false)?;
    Some(
        (0..a.nrows())
            .map(|j| faer::c64::new(re[j], im[j]))
            .collect(),
    )
}

/// The eigenvalues' real and imaginary parts and, when asked for, faer's real right
/// eigenvectors (a conjugate pair in two columns).
type Francis = (Vec<f64>, Vec<f64>, Option<Mat<f64>>);

/// [`Francis`] of `a` by the unblocked QR ([`eigen_unblocked`]), the eigenvectors with
/// `vectors`; `None` for a non-finite entry or no convergence.
fn francis_unblocked(a: &Mat<f64>, vectors: bool) -> Option<Francis> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{ComputeEigenvectors, EvdParams, evd_real, evd_scratch};
    if a.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return None;
    }
    let n = a.nrows();
    let mut params: faer::Spec<EvdParams, f64> =
        faer::Spec::new(<EvdParams as faer::Auto<f64>>::auto());
    params.config.schur.blocking_threshold = usize::MAX;
    let par = faer::Par::Seq;
    let mut ur = vectors.then(|| Mat::<f64>::zeros(n, n));
    let mut s_re = faer::diag::Diag::<f64>::zeros(n);
    let mut s_im = faer::diag::Diag::<f64>::zeros(n);
    let want = if vectors {
        ComputeEigenvectors::Yes
    } else {
        ComputeEigenvectors::No
    };
    let mut buf = MemBuffer::new(evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        want,
        par,
        params,
    ));
    evd_real(
        a.as_ref(),
        s_re.as_mut(),
        s_im.as_mut(),
        None,
        ur.as_mut().map(|u| u.as_mut()),
        par,
        MemStack::new(&mut buf),
        params,
    )
    .ok()?;
    let re = s_re.column_vector().iter().copied().collect();
    let im = s_im.column_vector().iter().copied().collect();
    Some((re, im, ur))
}

/// The reduced damped or gyroscopic problem's modes (first-order form), one per conjugate
/// pair (and one per real eigenvalue), sorted by `|s|`.
pub fn state_space(
    k: &DMatrix<f64>,
    c: &DMatrix<f64>,
    m: &DMatrix<f64>,
) -> Result<Vec<RawMode>, DenseError> {
    let n = k.nrows();
    let (a, linv) = first_order(k, c, m)?;
    let (s, u) = eigen_unblocked(&a).ok_or(DenseError::NoConvergence)?;
    let mut out = Vec::new();
    for i in 0..2 * n {
        let z = s[i];
        // One of each conjugate pair; a real eigenvalue is its own mode.
        if z.im < 0.0 {
            continue;
        }
        // The displacement part, turned so that its largest component is real.
        let col = |r: usize| u[(r, i)];
        let (mut best, mut big) = (0, 0.0);
        for r in 0..n {
            let v = col(r).re.hypot(col(r).im);
            if v > big {
                (best, big) = (r, v);
            }
        }
        let rot = if big > 0.0 {
            let p = col(best);
            (p.re / big, -p.im / big)
        } else {
            (1.0, 0.0)
        };
        let u = DVector::from_fn(n, |r, _| col(r).re * rot.0 - col(r).im * rot.1);
        let shape = linv.transpose() * u;
        out.push(RawMode {
            s: (z.re, z.im),
            omega2: omega2_of(z),
            shape,
        });
    }
    out.sort_by(|a, b| a.omega2.abs().total_cmp(&b.omega2.abs()));
    Ok(out)
}

/// [`state_space`]'s eigenvalues without the eigenvectors (the modes' shapes are empty),
/// and `‖L⁻¹‖_F²` (`M = LLᵀ`), which bounds `|φ|²/φᵀMφ` for any shape `φ`.
pub fn state_space_values(
    k: &DMatrix<f64>,
    c: &DMatrix<f64>,
    m: &DMatrix<f64>,
) -> Result<(Vec<RawMode>, f64), DenseError> {
    let (a, linv) = first_order(k, c, m)?;
    let s = eigenvalues_unblocked(&a).ok_or(DenseError::NoConvergence)?;
    let mut out: Vec<RawMode> = s
        .into_iter()
        .filter(|z| z.im >= 0.0)
        .map(|z| RawMode {
            s: (z.re, z.im),
            omega2: omega2_of(z),
            shape: DVector::zeros(0),
        })
        .collect();
    out.sort_by(|a, b| a.omega2.abs().total_cmp(&b.omega2.abs()));
    Ok((out, linv.norm_squared()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_spring_pair_has_one_zero_and_one_elastic_mode() {
        // Two unit masses joined by a spring k = 4: ω² = 0 (translation) and 2k/m = 8.
        let k = DMatrix::from_row_slice(2, 2, &[4.0, -4.0, -4.0, 4.0]);
        let m = DMatrix::identity(2, 2);
        let modes = conservative(&k, &m).unwrap();
        assert_eq!(modes.len(), 2);
        // ω² = 1/μ − σ (σ = 4e-8) for the zero, within ε σ; the Rayleigh quotient for 8.
        assert!(modes[0].omega2.abs() < 1e-12, "{}", modes[0].omega2);
        assert!((modes[1].omega2 - 8.0).abs() < 1e-12, "{}", modes[1].omega2);
        // Mass-normalised shapes.
        assert!((modes[1].shape.norm_squared() - 1.0).abs() < 1e-12);
    }

    /// A ratio of stiffness to mass that overflows, or a stiffness holding infinities, ends
    /// the solve with an error (issue 35: the shift loop never ended once 1e2 ω²_max
    /// overflowed); so does an indefinite one, after its bounded shifts.
    #[test]
    fn overflowing_or_indefinite_stiffness_ends_in_an_error() {
        let m = DMatrix::identity(2, 2) * 1e-3;
        for k in [1e308, f64::INFINITY] {
            let k = DMatrix::from_row_slice(2, 2, &[k, -k, -k, k]);
            assert_eq!(conservative(&k, &m).unwrap_err(), DenseError::NotFinite);
        }
        // ω²_max finite but 1e2 ω²_max not, and no shift makes K + σM positive: the
        // shifts overflow to infinity (the old loop's exit test `σ > 1e2 ω²_max` compared
        // two infinities forever); now an error after the last of them.
        let k = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1e307]);
        assert!(matches!(
            conservative(&k, &DMatrix::identity(2, 2)),
            Err(DenseError::Indefinite(_))
        ));
        // A negative stiffness on a massless direction: no shift reaches it.
        let k = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1.0]);
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        assert!(matches!(
            conservative(&k, &m),
            Err(DenseError::Indefinite(_))
        ));
    }

    #[test]
    fn massless_direction_is_dropped() {
        // Spring to ground k = 1 on a unit mass, plus a massless dof on a spring of 1.
        let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 1.0]);
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        let modes = conservative(&k, &m).unwrap();
        // Static condensation: k_eff = 2 − 1 = 1, ω² = 1.
        assert_eq!(modes.len(), 1);
        assert!((modes[0].omega2 - 1.0).abs() < 1e-12);
    }

    /// A gyroscopic model (`M = I`, `K` SPD, `G` skew) whose frequencies span four decades
    /// (100 … 1e6 rad/s, `ω²_max` = 1e12 as on the flexible slider-crank moving at its start)
    /// against an independent route: `z = (K^½ q, q̇)` turns it into `ż = T z` with
    /// `T = [0 K^½; −K^½ −G]` skew, whose eigenvalues ±iω are those of the Hermitian `iT`
    /// (nalgebra's symmetric QR: each to `ε‖T‖ = ε ω_max`, 2e-10 of the lowest ω). `K` itself
    /// is rounded when formed (`QΛQᵀ`, `ε‖K‖` = 2e-4 1/s² against ω² = 1e4: 1e-8 of the lowest
    /// ω); the first-order form must agree to 1e-7 relative.
    #[test]
    fn gyroscopic_frequencies_over_four_decades_match_the_hermitian_route() {
        let n = 24;
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let q = DMatrix::from_fn(n, n, |_, _| rnd()).qr().q();
        let w: Vec<f64> = (0..n)
            .map(|i| 100.0 * 1e4f64.powf(i as f64 / (n - 1) as f64))
            .collect();
        let diag = |f: &dyn Fn(f64) -> f64| {
            DMatrix::from_diagonal(&DVector::from_iterator(n, w.iter().map(|&x| f(x))))
        };
        let k = &q * diag(&|x| x * x) * q.transpose();
        let k = (&k + k.transpose()) * 0.5;
        let k_half = &q * diag(&|x| x) * q.transpose();
        let g0 = DMatrix::from_fn(n, n, |_, _| 100.0 * rnd());
        let g = &g0 - g0.transpose();
        let t = DMatrix::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => 0.0,
            (true, false) => k_half[(i, j - n)],
            (false, true) => -k_half[(i - n, j)],
            (false, false) => -g[(i - n, j - n)],
        });
        let it = t.map(|v| nalgebra::Complex::new(0.0, v));
        let mut exact: Vec<f64> = SymmetricEigen::new(it)
            .eigenvalues
            .iter()
            .copied()
            .filter(|v| *v > 0.0)
            .collect();
        exact.sort_by(f64::total_cmp);
        assert_eq!(exact.len(), n);
        let (modes, _) = state_space_values(&k, &g, &DMatrix::identity(n, n)).unwrap();
        assert_eq!(modes.len(), n);
        let mut worst = 0.0f64;
        for (m, e) in modes.iter().zip(&exact) {
            let (re, im) = m.s;
            assert!(re.abs() <= 1e-6 * e, "Re s = {re} at ω = {e}");
            worst = worst.max((im - e).abs() / e);
        }
        eprintln!("gyroscopic, four decades: worst relative error {worst:.2e}");
        assert!(worst <= 1e-7, "{worst:e}");
    }

    #[test]
    fn damped_oscillator_gives_its_damping_ratio() {
        // m = 2, k = 50, c = 2ζ√(km) with ζ = 0.05: s = −ζω ± iω√(1−ζ²), ω = 5.
        let (m, k, zeta) = (2.0f64, 50.0f64, 0.05f64);
        let c = 2.0 * zeta * (k * m).sqrt();
        let modes = state_space(
            &DMatrix::from_element(1, 1, k),
            &DMatrix::from_element(1, 1, c),
            &DMatrix::from_element(1, 1, m),
        )
        .unwrap();
        assert_eq!(modes.len(), 1);
        let (re, im) = modes[0].s;
        let w = (re * re + im * im).sqrt();
        assert!((w - 5.0).abs() < 1e-12);
        assert!((-re / w - zeta).abs() < 1e-12);
    }
}
