//! `[contact]`: the normal contact solver — boundary, convergence, grid, elastic or plastic
//! solves, device, adhesion — with its defaults and checks.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use serde::{Deserialize, Serialize};

use super::defaults;
use super::places::{at, key, reason_of, Checked};
use super::quantities::{Length, Stress, SurfaceEnergy};
use crate::contact::{Boundary, CohesiveLaw, Convergence, Device};
use crate::error::Error;
use crate::plausible::{self, Spelling};
use crate::quantity::{show, Dimension, LENGTH, PRESSURE, SURFACE_ENERGY};

/// Contact solver settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [contact] table")]
pub struct ContactSpec {
    /// `"periodic"` (the window repeats, as the paper's computation; the default) or `"free"`
    /// (an isolated window on an infinite half-space).
    #[serde(with = "boundary", default = "default_boundary")]
    pub boundary: Boundary,
    /// Relative residual at which a normal solve has converged (default 1e-8; see
    /// [`crate::contact`]'s solver).
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Iterations after which a solve that has not converged is an error (default 20 000).
    #[serde(default = "default_max_iterations")]
    pub max_iterations: usize,
    /// Solve every topography on this grid (nx, ny) over the same physical window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<(usize, usize)>,
    /// Elastic (false), elastic–perfectly-plastic with p ≤ `material.hardness` (true), or a
    /// list of both: each its own load sweep, told apart by the results' `plastic` column.
    #[serde(default, skip_serializing_if = "Plastic::is_elastic")]
    pub plastic: Plastic,
    /// Where the normal solves run: "cpu" or "gpu" (a build with the `gpu` feature).
    #[serde(default, skip_serializing_if = "is_cpu")]
    pub device: Device,
    /// Adhesive contact besides the non-adhesive one: every topography is solved again at every
    /// load with this cohesive law (on the CPU, elastic). Absent: no adhesion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adhesion: Option<AdhesionSpec>,
}

/// `adhesion = { work, stress | range, law }`: the cohesive law of an adhesive solve, as
/// `asperity contact`'s `--adhesion-*` options give it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a table such as { work = \"50 mJ/m2\", range = \"0.3 nm\" }")]
pub struct AdhesionSpec {
    /// Work of adhesion w \[J/m²].
    pub work: SurfaceEnergy,
    /// The law's strength \[Pa]: σ₀ (Maugis–Dugdale) or the peak tension w/ρ (exponential).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<Stress>,
    /// The law's range \[m]: h₀ = w/σ₀ (Maugis–Dugdale) or ρ (exponential).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<Length>,
    /// `"maugis"` (the default) or `"exponential"`.
    #[serde(default = "maugis")]
    pub law: String,
}

fn maugis() -> String {
    "maugis".to_string()
}

impl AdhesionSpec {
    /// The cohesive law, its keys checked; a refusal names the key (below `contact.adhesion`)
    /// and the reason.
    pub fn cohesive_law(&self) -> std::result::Result<CohesiveLaw, (&'static str, String)> {
        let positive = |key: &'static str, v: f64, dim: &Dimension| {
            if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                Err((key, format!("must be positive, got {}", show(v, dim))))
            }
        };
        let work = positive("work", self.work.0, &SURFACE_ENERGY)?;
        plausible::adhesion_work(work, Spelling::StudyFile).map_err(|r| ("work", r))?;
        let exponential = match self.law.as_str() {
            "maugis" => false,
            "exponential" => true,
            other => return Err(("law", format!("'{other}' is not \"maugis\" or \"exponential\""))),
        };
        let (stress, range) = match (self.stress, self.range) {
            (Some(s), None) => {
                let s = positive("stress", s.0, &PRESSURE)?;
                plausible::adhesion_stress(s, Spelling::StudyFile).map_err(|r| ("stress", r))?;
                (s, work / s)
            }
            (None, Some(r)) => {
                let r = positive("range", r.0, &LENGTH)?;
                plausible::adhesion_range(r, Spelling::StudyFile).map_err(|r| ("range", r))?;
                (work / r, r)
            }
            (Some(_), Some(_)) => {
                return Err(("stress", "give the law's strength `stress` or its `range`, not both".into()))
            }
            (None, None) => {
                return Err(("work", "needs `stress` or `range`: the cohesive law's strength or range".into()))
            }
        };
        let law = if exponential { CohesiveLaw::exponential(work, range) } else { CohesiveLaw::maugis(work, stress) };
        law.map_err(|e| ("work", reason_of(e)))
    }
}

// Keys a file leaves out take the default study's: called only for a key left out, so the
// default study itself, which gives every one, never recurses into them.
fn default_boundary() -> Boundary {
    defaults::section::<ContactSpec>("contact").boundary
}

fn default_tolerance() -> f64 {
    defaults::section::<ContactSpec>("contact").tolerance
}

fn default_max_iterations() -> usize {
    defaults::section::<ContactSpec>("contact").max_iterations
}

fn is_cpu(device: &Device) -> bool {
    *device == Device::Cpu
}

/// `plastic = false | true | [false, true]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
#[serde(expecting = "must be false, true or [false, true]")]
pub enum Plastic {
    /// One sweep: elastic (`false`) or elastic–perfectly-plastic (`true`).
    One(bool),
    /// One sweep per entry, in this order.
    Each(Vec<bool>),
}

impl Default for Plastic {
    fn default() -> Self {
        Plastic::One(false)
    }
}

impl Plastic {
    fn is_elastic(&self) -> bool {
        *self == Plastic::One(false)
    }

    /// The solves to run, in the order given: plastic or not.
    pub fn modes(&self) -> Vec<bool> {
        match self {
            Plastic::One(p) => vec![*p],
            Plastic::Each(list) => list.clone(),
        }
    }
}

/// `boundary = "periodic" | "free"`.
mod boundary {
    use serde::de::{self, Deserializer};
    use serde::Deserialize;

    use crate::contact::Boundary;

    pub fn serialize<S: serde::Serializer>(b: &Boundary, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(b.name())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Boundary, D::Error> {
        match String::deserialize(d)?.as_str() {
            "periodic" => Ok(Boundary::Periodic),
            "free" => Ok(Boundary::Free),
            other => Err(de::Error::custom(format!("'{other}' is not \"periodic\" or \"free\""))),
        }
    }
}

impl ContactSpec {
    /// The solver's convergence, device and grid, and the kinds of solve (a plastic one needs
    /// the material's `hardness`).
    pub(super) fn check(&self, hardness: Option<Stress>) -> Checked {
        if let Err(e) = (Convergence { tolerance: self.tolerance, max_iterations: self.max_iterations }).check() {
            let field = if matches!(&e, Error::Invalid { option, .. } if option == "--max-iter") {
                "max_iterations"
            } else {
                "tolerance"
            };
            return at(&[key("contact"), key(field)], reason_of(e));
        }
        if self.device == Device::Gpu && !Device::GPU_BUILT {
            return at(&[key("contact"), key("device")], Device::UNAVAILABLE.into());
        }
        if let Some((nx, ny)) = self.grid {
            if nx < 2 || ny < 2 {
                return at(&[key("contact"), key("grid")], format!("{nx}×{ny} is too small: at least 2×2 points"));
            }
        }
        let modes = self.plastic.modes();
        let plastic = [key("contact"), key("plastic")];
        if modes.is_empty() || (1..modes.len()).any(|i| modes[..i].contains(&modes[i])) {
            return at(&plastic, "give true, false, or a list of both, each once".into());
        }
        // Adhesion first: a plastic solve with it needs no hardness, it is refused either way.
        if let Some(adhesion) = &self.adhesion {
            let place = |k: &str| [key("contact"), key("adhesion"), key(k)];
            if let Err((k, reason)) = adhesion.cohesive_law() {
                return at(&place(k), reason);
            }
            if modes.contains(&true) {
                return at(&plastic, "is not solved with adhesion: the adhesive solver is elastic".into());
            }
        }
        match hardness {
            Some(h) if !(h.0 > 0.0 && h.0.is_finite()) => {
                return at(
                    &[key("material"), key("hardness")],
                    format!("must be positive, got {}", show(h.0, &PRESSURE)),
                );
            }
            None if modes.contains(&true) => {
                return at(&plastic, "a plastic solve needs `hardness` in [material]".into());
            }
            _ => {}
        }
        Ok(())
    }
}
