//! The time integration scheme of a dynamic analysis (`ANALYSIS DYNAMIC … ALPHA a` or
//! `… GENALPHA RHOINF ρ`), and its name on the command line (`study --integrator`).
//!
//! A scheme is what the deck asks for; the solver derives its coefficients
//! (`solver::integrator::AlphaParams` for the α family) and `modes` its spectral
//! properties. A new integrator is a new variant here, an arm in [`Scheme::name`],
//! [`Scheme::parse`] and `Display`, its deck keyword (src/deck/build/analysis.rs) and its
//! canonical text (src/deck/write.rs).

use std::fmt;

/// Time integration scheme of `ANALYSIS DYNAMIC`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scheme {
    /// HHT-α (Hilber, Hughes & Taylor 1977) in the generalized-α form of Arnold & Brüls
    /// (2007) with `α_m = 0`, `α_f = −α`: `α ∈ [−1/3, 0]`, spectral radius at infinity
    /// `ρ∞ = (1 + α)/(1 − α)`. Deck: `ALPHA a` (default −0.1).
    Hht {
        /// HHT α ∈ [−1/3, 0].
        alpha: f64,
    },
    /// Generalized-α (Chung & Hulbert 1993) on the Lie group (Arnold & Brüls 2007; Brüls,
    /// Cardona & Arnold 2012): `α_m = (2ρ∞ − 1)/(ρ∞ + 1)`, `α_f = ρ∞/(ρ∞ + 1)`, second
    /// order, least low-frequency dissipation for the high-frequency spectral radius
    /// `ρ∞ ∈ [0, 1]`. Deck: `GENALPHA [RHOINF ρ]` (default ρ∞ = [`Scheme::DEFAULT_RHO_INF`]).
    GeneralizedAlpha {
        /// Spectral radius at infinite frequency, `ρ∞ ∈ [0, 1]` (1: no numerical damping).
        rho_inf: f64,
    },
    /// Kennedy & Carpenter's (2016) ESDIRK3(2)4L[2]SA on the Lie group
    /// (`solver::integrator::esdirk`): third order, L-stable (`ρ∞ = 0`), three implicit
    /// stages per step. Deck: `ESDIRK3`.
    Esdirk3,
    /// Kennedy & Carpenter's (2016) ESDIRK5(4)7L[2]SA2 on the Lie group: fifth order (third
    /// with index-3 constraints), L-stable, six implicit stages per step. Deck: `ESDIRK5`.
    Esdirk5,
}

impl Default for Scheme {
    /// HHT with α = −0.1 (the deck's default).
    fn default() -> Self {
        Scheme::Hht { alpha: -0.1 }
    }
}

/// A `--integrator` name that is not a scheme, or a parameter out of its range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SchemeNameError {
    /// Not one of [`Scheme::NAMES`].
    #[error(
        "unknown integrator '{0}' (expected hht[:alpha], genalpha[:rho_inf], esdirk3 or esdirk5)"
    )]
    Unknown(String),
    /// A parameter after `:` for a scheme that has none (the ESDIRK schemes).
    #[error("integrator '{name}' takes no parameter (got ':{value}')")]
    NoParameter {
        /// The scheme's name.
        name: &'static str,
        /// The text after `:`.
        value: String,
    },
    /// The parameter after `:` is not a number in the scheme's range.
    #[error("integrator '{name}': the parameter '{value}' is not a number in {range}")]
    Parameter {
        /// The scheme's name.
        name: &'static str,
        /// The text after `:`.
        value: String,
        /// The accepted range.
        range: &'static str,
    },
}

impl Scheme {
    /// ρ∞ of `GENALPHA` without `RHOINF`: 0.8, close to the high-frequency radius of the
    /// default HHT (α = −0.1: ρ∞ = 0.818), so switching scheme keeps the damping of the
    /// unresolved modes.
    pub const DEFAULT_RHO_INF: f64 = 0.8;

    /// The names [`Scheme::parse`] accepts (`study --integrator`).
    pub const NAMES: &'static [&'static str] = &["hht", "genalpha", "esdirk3", "esdirk5"];

    /// Short name: `hht`, `genalpha` (command line, file columns).
    pub fn name(&self) -> &'static str {
        match self {
            Scheme::Hht { .. } => "hht",
            Scheme::GeneralizedAlpha { .. } => "genalpha",
            Scheme::Esdirk3 => "esdirk3",
            Scheme::Esdirk5 => "esdirk5",
        }
    }

    /// `hht:-0.1`, `genalpha:0.8`: the name with its parameter, as [`Scheme::parse`]
    /// reads it back (study labels and files).
    pub fn label(&self) -> String {
        match *self {
            Scheme::Hht { alpha } => format!("hht:{alpha}"),
            Scheme::GeneralizedAlpha { rho_inf } => format!("genalpha:{rho_inf}"),
            Scheme::Esdirk3 | Scheme::Esdirk5 => self.name().to_string(),
        }
    }

    /// Whether the scheme is one of the ESDIRK family (stages, R(∞) = 0).
    pub fn is_esdirk(&self) -> bool {
        matches!(self, Scheme::Esdirk3 | Scheme::Esdirk5)
    }

    /// The ESDIRK scheme's deck keyword (`ESDIRK3`…), `None` for the α family.
    pub fn esdirk_keyword(&self) -> Option<&'static str> {
        match self {
            Scheme::Esdirk3 => Some("ESDIRK3"),
            Scheme::Esdirk5 => Some("ESDIRK5"),
            _ => None,
        }
    }

    /// HHT's α, `None` for another scheme.
    pub fn hht_alpha(&self) -> Option<f64> {
        match *self {
            Scheme::Hht { alpha } => Some(alpha),
            _ => None,
        }
    }

    /// Spectral radius of the scheme's amplification matrix as `ωh → ∞` (linear problems).
    pub fn rho_inf(&self) -> f64 {
        match *self {
            Scheme::Hht { alpha } => (1.0 + alpha) / (1.0 - alpha),
            Scheme::GeneralizedAlpha { rho_inf } => rho_inf,
            Scheme::Esdirk3 | Scheme::Esdirk5 => 0.0,
        }
    }

    /// `hht`, `hht:-0.05`, `genalpha`, `genalpha:0.9` (case-insensitive name; without a
    /// parameter: HHT's default α = −0.1, generalized-α's ρ∞ = [`Scheme::DEFAULT_RHO_INF`]).
    pub fn parse(s: &str) -> Result<Scheme, SchemeNameError> {
        let (name, value) = match s.split_once(':') {
            Some((n, v)) => (n.trim(), Some(v.trim())),
            None => (s.trim(), None),
        };
        let num = |name: &'static str, range: &'static str, ok: fn(f64) -> bool| {
            let v = value.unwrap_or_default();
            match v.parse::<f64>() {
                Ok(x) if ok(x) => Ok(x),
                _ => Err(SchemeNameError::Parameter {
                    name,
                    value: v.to_string(),
                    range,
                }),
            }
        };
        match name.to_ascii_lowercase().as_str() {
            "hht" => Ok(Scheme::Hht {
                alpha: match value {
                    None => -0.1,
                    Some(_) => num("hht", "[-1/3, 0]", Scheme::alpha_ok)?,
                },
            }),
            "genalpha" => Ok(Scheme::GeneralizedAlpha {
                rho_inf: match value {
                    None => Scheme::DEFAULT_RHO_INF,
                    Some(_) => num("genalpha", "[0, 1]", Scheme::rho_inf_ok)?,
                },
            }),
            "esdirk3" | "esdirk5" => {
                let scheme = if name.eq_ignore_ascii_case("esdirk3") {
                    Scheme::Esdirk3
                } else {
                    Scheme::Esdirk5
                };
                match value {
                    None => Ok(scheme),
                    Some(v) => Err(SchemeNameError::NoParameter {
                        name: scheme.name(),
                        value: v.to_string(),
                    }),
                }
            }
            _ => Err(SchemeNameError::Unknown(s.to_string())),
        }
    }

    /// HHT's range `α ∈ [−1/3, 0]` (to round-off at −1/3, so that `-1/3` typed as an
    /// expression passes).
    pub fn alpha_ok(alpha: f64) -> bool {
        (-1.0 / 3.0 - 1e-12..=0.0).contains(&alpha)
    }

    /// Generalized-α's range `ρ∞ ∈ [0, 1]`.
    pub fn rho_inf_ok(rho_inf: f64) -> bool {
        (0.0..=1.0).contains(&rho_inf)
    }
}

/// `HHT alpha -0.1`, `generalized-alpha rho_inf 0.8` (reports and summaries).
impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scheme::Hht { alpha } => write!(f, "HHT alpha {alpha}"),
            Scheme::GeneralizedAlpha { rho_inf } => {
                write!(f, "generalized-alpha rho_inf {rho_inf}")
            }
            Scheme::Esdirk3 => write!(f, "ESDIRK3"),
            Scheme::Esdirk5 => write!(f, "ESDIRK5"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_with_and_without_parameter() {
        assert_eq!(Scheme::parse("hht"), Ok(Scheme::default()));
        assert_eq!(Scheme::parse("HHT:-0.2"), Ok(Scheme::Hht { alpha: -0.2 }));
        assert_eq!(
            Scheme::parse("genalpha:0.9"),
            Ok(Scheme::GeneralizedAlpha { rho_inf: 0.9 })
        );
        assert_eq!(
            Scheme::parse("genalpha").map(|s| s.rho_inf()),
            Ok(Scheme::DEFAULT_RHO_INF)
        );
        assert!(matches!(
            Scheme::parse("genalpha:1.5"),
            Err(SchemeNameError::Parameter { .. })
        ));
        assert!(matches!(
            Scheme::parse("hht:0.1"),
            Err(SchemeNameError::Parameter { .. })
        ));
        assert!(matches!(
            Scheme::parse("newmark"),
            Err(SchemeNameError::Unknown(_))
        ));
        assert_eq!(
            Scheme::parse("esdirk5:0.3").map_err(|e| e.to_string()),
            Err("integrator 'esdirk5' takes no parameter (got ':0.3')".to_string())
        );
        for n in Scheme::NAMES {
            let s = Scheme::parse(n).unwrap();
            assert_eq!(s.name(), *n);
            assert_eq!(Scheme::parse(&s.label()), Ok(s));
        }
    }

    #[test]
    fn hht_radius_at_infinity() {
        // (1 + α)/(1 − α) at α = −0.1: 0.9/1.1.
        let r = Scheme::Hht { alpha: -0.1 }.rho_inf();
        assert!((r - 0.9 / 1.1).abs() < 1e-15);
    }
}
