//! Legendre spectral machinery on the parent interval `ξ ∈ [−1, 1]`: Gauss–Legendre and
//! Gauss–Lobatto–Legendre (GLL) points and weights, and the Lagrange basis on given nodes.
//!
//! - Legendre polynomials by the three-term recurrence
//!   `(k+1) P_{k+1} = (2k+1) ξ P_k − k P_{k−1}` and `(1−ξ²) P_n' = n (P_{n−1} − ξ P_n)`
//!   (Abramowitz & Stegun 22.7.10, 22.8.5).
//! - Gauss–Legendre: the `n` roots of `P_n`, weights `2 / ((1−ξᵢ²) P_n'(ξᵢ)²)` (A&S 25.4.29);
//!   exact for polynomials of degree `2n − 1`.
//! - GLL: `±1` and the roots of `P_p'`, weights `2 / (p(p+1) P_p(ξᵢ)²)` (A&S 25.4.32); exact
//!   for degree `2p − 1`. These are the nodes of the spectral beam of order `p`
//!   (Patera 1984; BeamDyn, Wang et al. 2017): the Lagrange interpolant on them is
//!   well-conditioned at any order (Lebesgue constant `O(log p)`).
//! - Roots by Newton's method from the Chebyshev points `−cos(π(i + ¾)/(n + ½))` (Gauss) and
//!   `−cos(π i/p)` (GLL), to round-off.

/// `(P_n(ξ), P_n'(ξ))`. At `ξ = ±1` the derivative uses `P_n'(±1) = (±1)^{n−1} n(n+1)/2`.
pub fn legendre(n: usize, x: f64) -> (f64, f64) {
    if n == 0 {
        return (1.0, 0.0);
    }
    let (mut p0, mut p1) = (1.0, x);
    for k in 1..n {
        let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    let nf = n as f64;
    let d = if (1.0 - x * x).abs() < 1e-14 {
        let s = if x > 0.0 || n % 2 == 1 { 1.0 } else { -1.0 };
        s * nf * (nf + 1.0) / 2.0
    } else {
        nf * (p0 - x * p1) / (1.0 - x * x)
    };
    (p1, d)
}

/// The `n`-point Gauss–Legendre rule: `(points, weights)`, points increasing.
pub fn gauss(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = Vec::with_capacity(n);
    let mut w = Vec::with_capacity(n);
    for i in 0..n {
        let mut t = -(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, d) = legendre(n, t);
            let dt = p / d;
            t -= dt;
            if dt.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(n, t);
        x.push(t);
        w.push(2.0 / ((1.0 - t * t) * d * d));
    }
    (x, w)
}

/// The `p + 1` Gauss–Lobatto–Legendre points and weights of order `p ≥ 1`, increasing
/// from −1 to 1.
pub fn gll(p: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(p >= 1, "GLL rule of order 0");
    let pf = p as f64;
    let mut x = vec![-1.0];
    for i in 1..p {
        // Interior points: roots of P_p'. Newton on q = P_p' with
        // q' = (2ξ P_p' − p(p+1) P_p) / (1 − ξ²) (Legendre's equation).
        let mut t = -(std::f64::consts::PI * i as f64 / pf).cos();
        for _ in 0..100 {
            let (pp, d) = legendre(p, t);
            let d2 = (2.0 * t * d - pf * (pf + 1.0) * pp) / (1.0 - t * t);
            let dt = d / d2;
            t -= dt;
            if dt.abs() < 1e-16 {
                break;
            }
        }
        x.push(t);
    }
    x.push(1.0);
    let w = x
        .iter()
        .map(|&t| {
            let (pp, _) = legendre(p, t);
            2.0 / (pf * (pf + 1.0) * pp * pp)
        })
        .collect();
    (x, w)
}

/// Values `Nᵢ(ξ)` and derivatives `dNᵢ/dξ` of the Lagrange basis on `nodes` at `ξ`:
/// `Nᵢ = Π_{j≠i} (ξ − ξⱼ)/(ξᵢ − ξⱼ)`, `Nᵢ' = Nᵢ Σ_{j≠i} 1/(ξ − ξⱼ)` written without the
/// division (so that it holds at the nodes too).
pub fn lagrange(nodes: &[f64], x: f64) -> (Vec<f64>, Vec<f64>) {
    let n = nodes.len();
    let mut val = vec![0.0; n];
    let mut der = vec![0.0; n];
    for i in 0..n {
        let mut v = 1.0;
        let mut d = 0.0;
        for j in 0..n {
            if j == i {
                continue;
            }
            let den = nodes[i] - nodes[j];
            // Product rule on Π (ξ − ξⱼ)/den.
            d = d * (x - nodes[j]) / den + v / den;
            v *= (x - nodes[j]) / den;
        }
        val[i] = v;
        der[i] = d;
    }
    (val, der)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_rule_integrates_degree_2n_minus_1_exactly() {
        for n in 1..=14 {
            let (x, w) = gauss(n);
            for deg in 0..2 * n {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                // Round-off of a sum of n terms of size ≤ 2.
                assert!((q - exact).abs() < 1e-14 * n as f64, "n {n} deg {deg}: {q}");
            }
        }
    }

    #[test]
    fn gll_rule_has_the_end_points_and_is_exact_to_degree_2p_minus_1() {
        for p in 1..=14 {
            let (x, w) = gll(p);
            assert_eq!(x.len(), p + 1);
            assert!(x[0] == -1.0 && x[p] == 1.0);
            assert!(x.windows(2).all(|s| s[0] < s[1]));
            for deg in 0..2 * p {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 1 {
                    0.0
                } else {
                    2.0 / (deg as f64 + 1.0)
                };
                assert!((q - exact).abs() < 1e-14 * p as f64, "p {p} deg {deg}: {q}");
            }
        }
        // Known values: p = 2 → 0, weights 1/3, 4/3; p = 4 → ±√(3/7).
        let (x, w) = gll(2);
        assert!(x[1].abs() < 1e-16 && (w[1] - 4.0 / 3.0).abs() < 1e-15);
        let (x, _) = gll(4);
        assert!((x[3] - (3.0f64 / 7.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn lagrange_basis_is_cardinal_and_reproduces_polynomials() {
        let (nodes, _) = gll(6);
        for (k, &xk) in nodes.iter().enumerate() {
            let (v, _) = lagrange(&nodes, xk);
            for (i, vi) in v.iter().enumerate() {
                assert!((vi - if i == k { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        // Degree-6 polynomial and its derivative are reproduced exactly.
        let f = |x: f64| 1.0 - 2.0 * x + 0.5 * x.powi(3) + x.powi(6);
        let df = |x: f64| -2.0 + 1.5 * x * x + 6.0 * x.powi(5);
        for x in [-0.9, -0.3, 0.1, 0.77] {
            let (v, d) = lagrange(&nodes, x);
            let fi: f64 = v.iter().zip(&nodes).map(|(v, n)| v * f(*n)).sum();
            let di: f64 = d.iter().zip(&nodes).map(|(d, n)| d * f(*n)).sum();
            assert!((fi - f(x)).abs() < 1e-13 && (di - df(x)).abs() < 1e-12);
        }
    }
}
