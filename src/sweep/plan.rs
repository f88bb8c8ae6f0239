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
    reference: Vec<Reference>,
    #[serde(default)]
    guide: Vec<Guide>,
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
    pub references: Vec<Reference>,
    /// Power-law guide lines for the figures.
    pub guides: Vec<Guide>,
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
        // Bounded as a deck is (a plan read from a device or a pipe ends).
        let text = crate::deck::read_text(path).map_err(|e| SweepError::Io {
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
        let deck_hash = crate::deck::read_source(&deck)
            .map(|t| crate::checkpoint::sha256_hex(t.as_bytes()))
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
        names::check(text, path, &plan)?;
        Ok(plan)
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

mod cases;
mod draws;
mod names;
mod overlays;
#[cfg(test)]
mod tests;

pub use draws::inverse_normal_cdf;
pub use overlays::{Guide, Reference};
