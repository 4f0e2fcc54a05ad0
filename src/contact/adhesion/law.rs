//! The cohesive laws of adhesive contact: Maugis–Dugdale and exponential, each of work of
//! adhesion w, with their checks.
//!
//! Imports nothing inside `contact`; must not import friction, study, report, plot, shs, cli.

use crate::error::{Error, Result};

/// The cohesive law between the surfaces: its tension t(g) \[Pa] at gap g \[m], of work of
/// adhesion w = ∫₀^∞ t(g) dg \[J/m²].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "law", rename_all = "lowercase")]
pub enum CohesiveLaw {
    /// Maugis–Dugdale: t = σ₀ for g < h₀ = w/σ₀, 0 beyond.
    Maugis {
        /// Work of adhesion w \[J/m²].
        work: f64,
        /// Cohesive stress σ₀ \[Pa].
        stress: f64,
    },
    /// Exponential: t = (w/ρ)·e^(−g/ρ).
    Exponential {
        /// Work of adhesion w \[J/m²].
        work: f64,
        /// Range ρ \[m].
        range: f64,
    },
}

impl CohesiveLaw {
    /// A Maugis–Dugdale law of work `work` \[J/m²] and stress `stress` \[Pa].
    pub fn maugis(work: f64, stress: f64) -> Result<Self> {
        positive("--adhesion-work", work, "J/m²")?;
        positive("--adhesion-stress", stress, "Pa")?;
        Ok(CohesiveLaw::Maugis { work, stress })
    }

    /// An exponential law of work `work` \[J/m²] and range `range` \[m].
    pub fn exponential(work: f64, range: f64) -> Result<Self> {
        positive("--adhesion-work", work, "J/m²")?;
        positive("--adhesion-range", range, "m")?;
        Ok(CohesiveLaw::Exponential { work, range })
    }

    /// The law named `name` (`"maugis"` or `"exponential"`) of work `work` \[J/m²], given by
    /// its strength `stress` \[Pa] (σ₀, or the exponential law's peak tension w/ρ) or its range
    /// `range` \[m] (h₀ = w/σ₀, or ρ): exactly one of the two. Errors name the command line's
    /// options.
    pub fn from_options(name: &str, work: f64, stress: Option<f64>, range: Option<f64>) -> Result<Self> {
        positive("--adhesion-work", work, "J/m²")?;
        let exponential = match name {
            "maugis" => false,
            "exponential" => true,
            other => {
                return Err(Error::invalid("--adhesion-law", format!("'{other}' is not maugis or exponential")));
            }
        };
        match (stress, range) {
            (Some(stress), None) => {
                positive("--adhesion-stress", stress, "Pa")?;
                if exponential {
                    Self::exponential(work, work / stress)
                } else {
                    Self::maugis(work, stress)
                }
            }
            (None, Some(range)) => {
                positive("--adhesion-range", range, "m")?;
                if exponential {
                    Self::exponential(work, range)
                } else {
                    Self::maugis(work, work / range)
                }
            }
            (Some(_), Some(_)) => Err(Error::invalid(
                "--adhesion-stress",
                "give the cohesive law's strength or its range (--adhesion-range), not both",
            )),
            (None, None) => Err(Error::invalid(
                "--adhesion-work",
                "needs --adhesion-stress S or --adhesion-range R: the cohesive law's strength or range",
            )),
        }
    }

    /// Name as written in options and outputs: `"maugis"` or `"exponential"`.
    pub fn name(&self) -> &'static str {
        match self {
            CohesiveLaw::Maugis { .. } => "maugis",
            CohesiveLaw::Exponential { .. } => "exponential",
        }
    }

    /// Work of adhesion w \[J/m²].
    pub fn work(&self) -> f64 {
        match *self {
            CohesiveLaw::Maugis { work, .. } | CohesiveLaw::Exponential { work, .. } => work,
        }
    }

    /// The largest tension, at contact: σ₀ or w/ρ \[Pa].
    pub fn strength(&self) -> f64 {
        match *self {
            CohesiveLaw::Maugis { stress, .. } => stress,
            CohesiveLaw::Exponential { work, range } => work / range,
        }
    }

    /// The gap over which the tension acts: h₀ = w/σ₀ or ρ \[m].
    pub fn range(&self) -> f64 {
        match *self {
            CohesiveLaw::Maugis { work, stress } => work / stress,
            CohesiveLaw::Exponential { range, .. } => range,
        }
    }

    /// Tension t(g) \[Pa] at gap `gap` ≥ 0 \[m].
    #[inline]
    pub fn tension(&self, gap: f64) -> f64 {
        match *self {
            CohesiveLaw::Maugis { work, stress } => {
                if gap < work / stress {
                    stress
                } else {
                    0.0
                }
            }
            CohesiveLaw::Exponential { work, range } => work / range * (-gap / range).exp(),
        }
    }
}

fn positive(option: &str, v: f64, unit: &str) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(option, format!("must be positive and finite, got {v} {unit}")))
    }
}
