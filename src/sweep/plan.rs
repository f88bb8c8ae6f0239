//! A sweep plan (TOML) and the cases it means.
//!
//! ```toml
//! deck = "../decks/pendulum_sweep.dat"   # relative to the plan file
//! out = "out/sweeps/pendulum_E"          # relative to the working directory (default
//!                                        # out/sweeps/<plan name>; -o wins)
//! combine = "factorial"                  # or "zip": how the listed/ranged parameters combine
//! samples = 200                          # random parameters: number of samples
//! sampling = "latin-hypercube"           # or "monte-carlo"
//! seed = 1
//!
//! [[parameter]]
//! name = "E"
//! from = 2.1e10
//! to = 2.1e15
//! n = 26
//! scale = "log"                          # or "linear" (default)
//!
//! [[parameter]]
//! name = "k"
//! distribution = "uniform"               # low, high | normal: mean, sd | lognormal: median, sigma
//! low = 0.8e7
//! high = 1.2e7
//!
//! [[quantity]]                           # see quantity.rs
//! name = "z12"
//! node = 12
//! column = "z"
//! stat = "max_abs"
//! ```
//!
//! **Cases.** The listed (`values = [...]`) and ranged (`from`, `to`, `n`, `scale`)
//! parameters form the *grid*: their full factorial product (the first parameter varies
//! slowest) or, with `combine = "zip"`, their values taken together (all of one length).
//! The random parameters (`distribution`) are drawn `samples` times; each grid point is
//! combined with each sample (grid point slowest). Case `i` is the `i`-th of that list.
//!
//! **Random draws** are reproducible: a ChaCha8 stream (`rand_chacha`, whose output is
//! fixed for a seed on every platform) seeded with `seed` gives uniforms u in (0, 1), mapped
//! by the inverse CDF (uniform: low + u (high − low); normal: mean + sd Φ⁻¹(u); lognormal:
//! median exp(sigma Φ⁻¹(u)), i.e. ln X normal with standard deviation sigma). Monte Carlo
//! draws, sample by sample, one u per random parameter in plan order. Latin hypercube
//! (McKay, Beckman & Conover 1979): for each parameter in plan order, a random permutation
//! π of the n strata (Fisher–Yates) and then, sample by sample, u = (π(i) + v)/n with v
//! uniform: every parameter's n values fall one in each of n equiprobable strata. Φ⁻¹ is
//! Acklam's rational approximation (relative error < 1.15e-9).

use super::SweepError;
use super::quantity::{Quantity, QuantitySpec};
use rand::RngCore;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Most cases a plan may mean (a typo such as `n = 1e9` is an error, not a full disk).
pub const MAX_CASES: usize = 1_000_000;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanFile {
    deck: String,
    out: Option<String>,
    combine: Option<String>,
    samples: Option<usize>,
    sampling: Option<String>,
    seed: Option<u64>,
    #[serde(default)]
    parameter: Vec<ParamFile>,
    #[serde(default)]
    quantity: Vec<QuantitySpec>,
    #[serde(default)]
    reference: Vec<super::figures::Reference>,
    #[serde(default)]
    guide: Vec<super::figures::Guide>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamFile {
    name: String,
    values: Option<Vec<f64>>,
    from: Option<f64>,
    to: Option<f64>,
    n: Option<usize>,
    scale: Option<String>,
    distribution: Option<String>,
    low: Option<f64>,
    high: Option<f64>,
    mean: Option<f64>,
    sd: Option<f64>,
    median: Option<f64>,
    sigma: Option<f64>,
}

/// How a parameter varies.
#[derive(Debug, Clone, PartialEq)]
pub enum Variation {
    /// Given values (a list, or a linear or logarithmic range expanded); `log` when the
    /// range was logarithmic (figures use a log axis).
    Grid {
        /// The values.
        values: Vec<f64>,
        /// A logarithmic range.
        log: bool,
    },
    /// Uniform on [low, high].
    Uniform {
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
    /// Normal (mean, standard deviation).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        sd: f64,
    },
    /// Lognormal: ln X is normal with mean ln(median) and standard deviation sigma.
    Lognormal {
        /// Median.
        median: f64,
        /// Standard deviation of ln X.
        sigma: f64,
    },
}

impl Variation {
    /// A random parameter (drawn `samples` times).
    pub fn is_random(&self) -> bool {
        !matches!(self, Variation::Grid { .. })
    }

    /// The value at the uniform u in (0, 1) (inverse CDF).
    fn at(&self, u: f64) -> f64 {
        match *self {
            Variation::Uniform { low, high } => low + u * (high - low),
            Variation::Normal { mean, sd } => mean + sd * inverse_normal_cdf(u),
            Variation::Lognormal { median, sigma } => {
                median * (sigma * inverse_normal_cdf(u)).exp()
            }
            Variation::Grid { .. } => f64::NAN,
        }
    }
}

/// One varied parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The deck parameter's name.
    pub name: String,
    /// How it varies.
    pub variation: Variation,
}

/// Monte Carlo or Latin hypercube.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampling {
    /// Independent draws.
    MonteCarlo,
    /// Latin hypercube: one draw per equiprobable stratum and parameter.
    LatinHypercube,
}

/// A validated plan and its cases.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The plan file as given.
    pub path: PathBuf,
    /// The deck, resolved against the plan file's directory.
    pub deck: PathBuf,
    /// The sweep's output directory.
    pub out: PathBuf,
    /// The varied parameters, in plan order.
    pub params: Vec<Param>,
    /// The grid is zipped rather than factorial.
    pub zip: bool,
    /// Random sampling method.
    pub sampling: Sampling,
    /// Number of random samples (1 when no parameter is random).
    pub samples: usize,
    /// Seed of the random draws.
    pub seed: u64,
    /// Quantities of interest.
    pub quantities: Vec<Quantity>,
    /// Reference points for the figures.
    pub references: Vec<super::figures::Reference>,
    /// Power-law guide lines for the figures.
    pub guides: Vec<super::figures::Guide>,
    /// Case `i`'s parameter values, in the order of `params`.
    pub cases: Vec<Vec<f64>>,
    /// SHA-256 of the deck's text (hex; empty when unreadable): a finished case run
    /// with another deck text is run again.
    pub deck_hash: String,
}

fn bad(path: &Path, msg: impl Into<String>) -> SweepError {
    SweepError::Plan {
        path: path.to_path_buf(),
        msg: msg.into(),
    }
}

impl Plan {
    /// Reads and validates a plan; `out` overrides the plan's output directory.
    pub fn load(path: &Path, out: Option<&Path>) -> Result<Plan, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|e| SweepError::Io {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })?;
        Plan::parse(&text, path, out)
    }

    /// Validates the text of a plan read from `path`.
    pub fn parse(text: &str, path: &Path, out: Option<&Path>) -> Result<Plan, SweepError> {
        let f: PlanFile = toml::from_str(text).map_err(|e| bad(path, e.to_string()))?;
        let dir = path.parent().unwrap_or(Path::new(""));
        let deck = dir.join(&f.deck);
        let deck_hash = std::fs::read(&deck)
            .map(|b| crate::checkpoint::sha256_hex(&b))
            .unwrap_or_default();
        let stem = path
            .file_stem()
            .map_or_else(|| "sweep".into(), |s| s.to_string_lossy().into_owned());
        let out = match (out, &f.out) {
            (Some(o), _) => o.to_path_buf(),
            (None, Some(o)) => PathBuf::from(o),
            (None, None) => PathBuf::from("out").join("sweeps").join(stem),
        };
        let zip = match f.combine.as_deref() {
            None | Some("factorial") => false,
            Some("zip") => true,
            Some(o) => {
                return Err(bad(
                    path,
                    format!("combine = \"{o}\": expected \"factorial\" or \"zip\""),
                ));
            }
        };
        let sampling = match f.sampling.as_deref() {
            None | Some("monte-carlo") => Sampling::MonteCarlo,
            Some("latin-hypercube") => Sampling::LatinHypercube,
            Some(o) => {
                return Err(bad(
                    path,
                    format!("sampling = \"{o}\": expected \"monte-carlo\" or \"latin-hypercube\""),
                ));
            }
        };
        if f.parameter.is_empty() {
            return Err(bad(
                path,
                "no [[parameter]]: a plan varies at least one deck parameter",
            ));
        }
        let mut params = Vec::new();
        for p in &f.parameter {
            if params.iter().any(|q: &Param| q.name == p.name) {
                return Err(bad(path, format!("parameter `{}` is listed twice", p.name)));
            }
            params.push(Param {
                name: p.name.clone(),
                variation: variation(p)
                    .map_err(|m| bad(path, format!("parameter `{}`: {m}", p.name)))?,
            });
        }
        let any_random = params.iter().any(|p| p.variation.is_random());
        let samples = match (any_random, f.samples) {
            (true, Some(n)) if n >= 1 => n,
            (true, _) => return Err(bad(path, "random parameters need `samples` (>= 1)")),
            (false, Some(_)) => {
                return Err(bad(
                    path,
                    "`samples` is given but no parameter has a `distribution`",
                ));
            }
            (false, None) => 1,
        };
        if any_random && f.seed.is_none() {
            return Err(bad(
                path,
                "random parameters need a `seed` (so that the plan always means the same cases)",
            ));
        }
        let mut quantities = Vec::new();
        for q in &f.quantity {
            let q = Quantity::from_spec(q).map_err(|m| bad(path, m))?;
            if quantities.iter().any(|x: &Quantity| x.name == q.name)
                || params.iter().any(|p| p.name == q.name)
            {
                return Err(bad(
                    path,
                    format!(
                        "the name `{}` is used twice (quantities and parameters name the columns of sweep.csv)",
                        q.name
                    ),
                ));
            }
            quantities.push(q);
        }
        let mut plan = Plan {
            path: path.to_path_buf(),
            deck,
            out,
            params,
            zip,
            sampling,
            samples,
            seed: f.seed.unwrap_or(0),
            quantities,
            references: f.reference,
            guides: f.guide,
            cases: Vec::new(),
            deck_hash,
        };
        plan.cases = plan.generate().map_err(|m| bad(path, m))?;
        super::names::check(text, path, &plan)?;
        Ok(plan)
    }

    /// The grid points (factorial or zipped) of the non-random parameters: for each, the
    /// values of the grid parameters in plan order.
    fn grid(&self) -> Result<Vec<Vec<f64>>, String> {
        let lists: Vec<&Vec<f64>> = self
            .params
            .iter()
            .filter_map(|p| match &p.variation {
                Variation::Grid { values, .. } => Some(values),
                _ => None,
            })
            .collect();
        if lists.is_empty() {
            return Ok(vec![vec![]]);
        }
        if self.zip {
            let n = lists[0].len();
            if lists.iter().any(|l| l.len() != n) {
                let lens: Vec<String> = lists.iter().map(|l| l.len().to_string()).collect();
                return Err(format!(
                    "combine = \"zip\" needs lists of one length, found {}",
                    lens.join(", ")
                ));
            }
            return Ok((0..n)
                .map(|i| lists.iter().map(|l| l[i]).collect())
                .collect());
        }
        let total = lists
            .iter()
            .try_fold(1usize, |acc, l| {
                acc.checked_mul(l.len()).filter(|&t| t <= MAX_CASES)
            })
            .ok_or(format!(
                "the factorial product has more than {MAX_CASES} cases"
            ))?;
        let mut out = Vec::with_capacity(total);
        for mut i in 0..total {
            let mut row = vec![0.0; lists.len()];
            for (k, l) in lists.iter().enumerate().rev() {
                row[k] = l[i % l.len()];
                i /= l.len();
            }
            out.push(row);
        }
        Ok(out)
    }

    /// The random samples: for each, the values of the random parameters in plan order.
    fn random(&self) -> Vec<Vec<f64>> {
        let dists: Vec<&Variation> = self
            .params
            .iter()
            .map(|p| &p.variation)
            .filter(|v| v.is_random())
            .collect();
        if dists.is_empty() {
            return vec![vec![]];
        }
        let n = self.samples;
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let mut out = vec![vec![0.0; dists.len()]; n];
        match self.sampling {
            Sampling::MonteCarlo => {
                for row in out.iter_mut() {
                    for (j, d) in dists.iter().enumerate() {
                        row[j] = d.at(open_unit(&mut rng));
                    }
                }
            }
            Sampling::LatinHypercube => {
                for (j, d) in dists.iter().enumerate() {
                    let mut perm: Vec<usize> = (0..n).collect();
                    for i in (1..n).rev() {
                        let k = (rng.next_u64() % (i as u64 + 1)) as usize;
                        perm.swap(i, k);
                    }
                    for (i, row) in out.iter_mut().enumerate() {
                        let u = (perm[i] as f64 + open_unit(&mut rng)) / n as f64;
                        row[j] = d.at(u);
                    }
                }
            }
        }
        out
    }

    fn generate(&self) -> Result<Vec<Vec<f64>>, String> {
        let grid = self.grid()?;
        if grid.len().saturating_mul(self.samples) > MAX_CASES {
            return Err(format!("more than {MAX_CASES} cases"));
        }
        let random = self.random();
        let mut cases = Vec::with_capacity(grid.len() * random.len());
        for g in &grid {
            for r in &random {
                let (mut gi, mut ri) = (g.iter(), r.iter());
                let row: Vec<f64> = self
                    .params
                    .iter()
                    .map(|p| {
                        let v = if p.variation.is_random() {
                            ri.next()
                        } else {
                            gi.next()
                        };
                        v.copied().unwrap_or(f64::NAN)
                    })
                    .collect();
                cases.push(row);
            }
        }
        Ok(cases)
    }

    /// Case `i`'s overrides: (parameter name, value).
    pub fn overrides(&self, i: usize) -> Vec<(String, f64)> {
        self.params
            .iter()
            .zip(&self.cases[i])
            .map(|(p, v)| (p.name.clone(), *v))
            .collect()
    }

    /// The directory of case `i`: `<out>/cases/<i, zero-padded>`.
    pub fn case_dir(&self, i: usize) -> PathBuf {
        let width = self.cases.len().saturating_sub(1).to_string().len().max(4);
        self.out.join("cases").join(format!("{i:0width$}"))
    }

    /// Whether exactly one parameter varies, on a grid (a 1-D sweep: curves of the
    /// quantities against it).
    pub fn one_dimensional(&self) -> Option<usize> {
        let grid: Vec<usize> = (0..self.params.len())
            .filter(|&k| matches!(&self.params[k].variation, Variation::Grid { values, .. } if values.len() > 1))
            .collect();
        (grid.len() == 1 && !self.params.iter().any(|p| p.variation.is_random())).then(|| grid[0])
    }
}

fn variation(p: &ParamFile) -> Result<Variation, String> {
    let finite = |x: Option<f64>, what: &str| -> Result<f64, String> {
        match x {
            Some(v) if v.is_finite() => Ok(v),
            Some(v) => Err(format!("{what} = {v} is not finite")),
            None => Err(format!("needs `{what}`")),
        }
    };
    let range_keys = p.from.is_some() || p.to.is_some() || p.n.is_some() || p.scale.is_some();
    let dist_keys = [p.low, p.high, p.mean, p.sd, p.median, p.sigma]
        .iter()
        .any(Option::is_some);
    let kinds = [p.values.is_some(), range_keys, p.distribution.is_some()]
        .iter()
        .filter(|b| **b)
        .count();
    if kinds != 1 {
        return Err("give exactly one of `values = [...]`, a range (`from`, `to`, `n`, `scale`) or a `distribution`".into());
    }
    if dist_keys && p.distribution.is_none() {
        return Err("low/high/mean/sd/median/sigma belong to a `distribution`".into());
    }
    if let Some(v) = &p.values {
        if v.is_empty() || v.iter().any(|x| !x.is_finite()) {
            return Err("`values` must be a non-empty list of finite numbers".into());
        }
        return Ok(Variation::Grid {
            values: v.clone(),
            log: false,
        });
    }
    if range_keys {
        let (a, b) = (finite(p.from, "from")?, finite(p.to, "to")?);
        let n =
            p.n.ok_or("a range needs `n` (the number of values, >= 2, or 1 for `from` alone)")?;
        if n == 0 || n > MAX_CASES {
            return Err(format!("n = {n}: expected 1 to {MAX_CASES}"));
        }
        let log = match p.scale.as_deref() {
            None | Some("linear") => false,
            Some("log") => true,
            Some(o) => return Err(format!("scale = \"{o}\": expected \"linear\" or \"log\"")),
        };
        if log && (a <= 0.0 || b <= 0.0) {
            return Err("a logarithmic range needs from > 0 and to > 0".into());
        }
        let values = (0..n)
            .map(|i| {
                if n == 1 {
                    return a;
                }
                let s = i as f64 / (n - 1) as f64;
                if i == 0 {
                    a
                } else if i == n - 1 {
                    b
                } else if log {
                    10f64.powf(a.log10() + s * (b.log10() - a.log10()))
                } else {
                    a + s * (b - a)
                }
            })
            .collect();
        return Ok(Variation::Grid { values, log });
    }
    match p.distribution.as_deref().unwrap_or("") {
        "uniform" => {
            let (low, high) = (finite(p.low, "low")?, finite(p.high, "high")?);
            if low >= high {
                return Err(format!("uniform needs low < high, found {low} >= {high}"));
            }
            Ok(Variation::Uniform { low, high })
        }
        "normal" => {
            let (mean, sd) = (finite(p.mean, "mean")?, finite(p.sd, "sd")?);
            if sd <= 0.0 {
                return Err("normal needs sd > 0".into());
            }
            Ok(Variation::Normal { mean, sd })
        }
        "lognormal" => {
            let (median, sigma) = (finite(p.median, "median")?, finite(p.sigma, "sigma")?);
            if median <= 0.0 || sigma <= 0.0 {
                return Err("lognormal needs median > 0 and sigma > 0".into());
            }
            Ok(Variation::Lognormal { median, sigma })
        }
        o => Err(format!(
            "distribution = \"{o}\": expected \"uniform\", \"normal\" or \"lognormal\""
        )),
    }
}

/// A uniform draw in the open interval (0, 1): 53 random bits, offset by half a unit.
fn open_unit(rng: &mut ChaCha8Rng) -> f64 {
    ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
}

/// Φ⁻¹(p), the standard normal quantile, by Acklam's rational approximation (relative
/// error below 1.15e-9 on (0, 1)).
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    const LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - LOW {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(text: &str) -> Result<Plan, SweepError> {
        Plan::parse(text, Path::new("sweeps/p.toml"), None)
    }

    #[test]
    fn inverse_normal_matches_known_quantiles() {
        // Φ⁻¹ at 0.5, 0.975, 0.8413447460685429 (Φ(1)), 1e-6 (tables: −4.753424308822899).
        assert_eq!(inverse_normal_cdf(0.5), 0.0);
        assert!((inverse_normal_cdf(0.975) - 1.959963984540054).abs() < 1.15e-9 * 1.96);
        assert!((inverse_normal_cdf(0.8413447460685429) - 1.0).abs() < 2e-9);
        assert!((inverse_normal_cdf(1e-6) + 4.753424308822899).abs() < 1.15e-9 * 4.76);
        assert!((inverse_normal_cdf(1.0 - 0.975) + 1.959963984540054).abs() < 3e-9);
    }

    #[test]
    fn grids_factorial_zip_and_ranges() {
        let p = plan("deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nfrom = 1\nto = 100\nn = 3\nscale = \"log\"\n").expect("valid");
        assert_eq!(p.deck, PathBuf::from("sweeps/d.dat"));
        assert_eq!(p.out, PathBuf::from("out/sweeps/p"));
        assert_eq!(p.cases.len(), 6);
        assert_eq!(p.cases[0], [1.0, 1.0]);
        assert!((p.cases[1][1] - 10.0).abs() < 1e-12);
        assert_eq!(p.cases[2], [1.0, 100.0]);
        assert_eq!(p.cases[3], [2.0, 1.0]);
        assert_eq!(p.case_dir(3), PathBuf::from("out/sweeps/p/cases/0003"));
        let z = plan("deck = \"d.dat\"\ncombine = \"zip\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nfrom = 0\nto = 1\nn = 2\n").expect("valid");
        assert_eq!(z.cases, vec![vec![1.0, 0.0], vec![2.0, 1.0]]);
        assert_eq!(z.one_dimensional(), None);
        let bad = plan(
            "deck = \"d.dat\"\ncombine = \"zip\"\n[[parameter]]\nname = \"a\"\nvalues = [1, 2]\n[[parameter]]\nname = \"b\"\nvalues = [1]\n",
        );
        assert!(bad.is_err());
    }

    #[test]
    fn random_draws_are_reproducible_and_stratified() {
        let text = "deck = \"d.dat\"\nsamples = 100\nseed = 7\nsampling = \"latin-hypercube\"\n\
            [[parameter]]\nname = \"k\"\ndistribution = \"uniform\"\nlow = 0\nhigh = 1\n\
            [[parameter]]\nname = \"E\"\ndistribution = \"lognormal\"\nmedian = 2\nsigma = 0.05\n";
        let a = plan(text).expect("valid");
        let b = plan(text).expect("valid");
        assert_eq!(a.cases, b.cases, "same plan, same cases");
        // Latin hypercube: exactly one k in each of the 100 strata [i/100, (i+1)/100).
        let mut strata: Vec<usize> = a.cases.iter().map(|c| (c[0] * 100.0) as usize).collect();
        strata.sort_unstable();
        assert_eq!(strata, (0..100).collect::<Vec<_>>());
        // ln E: one value per normal stratum, so its sample mean is ln 2 within a few
        // 1e-4 (the stratified mean's error is far below the MC error sigma/10 = 5e-3).
        let m = a.cases.iter().map(|c| c[1].ln()).sum::<f64>() / 100.0;
        assert!((m - 2f64.ln()).abs() < 1e-3, "{m}");
        let other = plan(&text.replace("seed = 7", "seed = 8")).expect("valid");
        assert_ne!(a.cases, other.cases);
        let mc = plan(&text.replace("latin-hypercube", "monte-carlo")).expect("valid");
        assert!(
            mc.cases
                .iter()
                .all(|c| (0.0..1.0).contains(&c[0]) && c[1] > 0.0)
        );
    }

    #[test]
    fn mistakes_are_reported() {
        for (text, needle) in [
            ("deck = \"d.dat\"\n", "no [[parameter]]"),
            (
                "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\n",
                "exactly one",
            ),
            (
                "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\ndistribution = \"uniform\"\nlow = 1\nhigh = 2\n",
                "samples",
            ),
            (
                "deck = \"d.dat\"\nsamples = 3\n[[parameter]]\nname = \"a\"\ndistribution = \"uniform\"\nlow = 1\nhigh = 2\n",
                "seed",
            ),
            (
                "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nfrom = -1\nto = 2\nn = 3\nscale = \"log\"\n",
                "logarithmic",
            ),
            ("deck = \"d.dat\"\nbogus = 1\n", "bogus"),
            (
                "deck = \"d.dat\"\n[[parameter]]\nname = \"a\"\nvalues = [1]\n[[parameter]]\nname = \"a\"\nvalues = [2]\n",
                "twice",
            ),
        ] {
            let e = plan(text).expect_err(text).to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
