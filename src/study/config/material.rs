//! `[material]`: the elastic body (E, ν), what it presses on (`counterface`), its hardness
//! and the uncertainty of E; the effective modulus E* the contact follows from them.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::fmt;

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

use super::defaults;
use super::places::{at, key, reason_of, Checked};
use super::quantities::Stress;
use crate::contact::Material;
use crate::plausible::{self, Spelling};
use crate::quantity::{self, PRESSURE};

/// The elastic body and its counter-body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [material] table")]
pub struct MaterialSpec {
    /// Young's modulus E \[Pa].
    #[serde(default = "default_youngs")]
    pub youngs: Stress,
    /// Poisson's ratio ν.
    #[serde(default = "default_poisson")]
    pub poisson: f64,
    /// The counter-body: rigid (the paper's, by default), of the same material, or an elastic
    /// body of its own.
    #[serde(default, skip_serializing_if = "Counterface::is_rigid")]
    pub counterface: Counterface,
    /// Hardness H \[Pa] of the softer body (silicon ≈ 12 GPa): the load carried at p ≥ H is
    /// reported and warned about; the cap on the pressure of plastic solves. None by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hardness: Option<Stress>,
    /// Uncertainty ΔE of `youngs` \[Pa]: the friction-drop figure's band also covers E ± ΔE.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_uncertainty: Option<Stress>,
}

// Keys a file leaves out take the default study's: called only for a key left out, so the
// default study itself, which gives every one, never recurses into them.
fn default_youngs() -> Stress {
    defaults::section::<MaterialSpec>("material").youngs
}

fn default_poisson() -> f64 {
    defaults::section::<MaterialSpec>("material").poisson
}

/// `counterface = "rigid" | "same" | { youngs, poisson }`: what the elastic body presses on.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Counterface {
    /// A rigid flat, as in the paper: E* = E / (1 − ν²).
    #[default]
    Rigid,
    /// A body of the same material (silicon on silicon): E* = E / (2 (1 − ν²)).
    Same,
    /// An elastic body of Young's modulus `youngs` \[Pa] and Poisson's ratio `poisson`:
    /// 1/E* = (1 − ν²)/E + (1 − ν₂²)/E₂.
    Body {
        /// Young's modulus E₂ \[Pa].
        youngs: Stress,
        /// Poisson's ratio ν₂.
        poisson: f64,
    },
}

impl Counterface {
    fn is_rigid(&self) -> bool {
        *self == Counterface::Rigid
    }
}

/// A counter-body's table: both keys, nothing else.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a table { youngs, poisson }")]
struct CounterBody {
    youngs: Stress,
    poisson: f64,
}

impl Serialize for Counterface {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Counterface::Rigid => s.serialize_str("rigid"),
            Counterface::Same => s.serialize_str("same"),
            Counterface::Body { youngs, poisson } => CounterBody { youngs, poisson }.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Counterface {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct CounterfaceVisitor;
        impl<'de> Visitor<'de> for CounterfaceVisitor {
            type Value = Counterface;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"rigid\", \"same\" or a table { youngs, poisson }")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Counterface, E> {
                match v {
                    "rigid" => Ok(Counterface::Rigid),
                    "same" => Ok(Counterface::Same),
                    _ => Err(E::invalid_value(de::Unexpected::Str(v), &self)),
                }
            }
            fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<Counterface, A::Error> {
                let body = CounterBody::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(Counterface::Body { youngs: body.youngs, poisson: body.poisson })
            }
        }
        d.deserialize_any(CounterfaceVisitor)
    }
}

impl MaterialSpec {
    /// The body's and the counter-body's moduli and Poisson's ratios, the hardness and E's
    /// uncertainty.
    pub(super) fn check(&self) -> Checked {
        let material = key("material");
        Material::new(self.youngs.0, self.poisson, "material").map_err(|e| (vec![material.clone()], reason_of(e)))?;
        let counter_youngs = match self.counterface {
            Counterface::Body { youngs, .. } => Some(youngs),
            _ => None,
        };
        let judged = [
            (vec![key("youngs")], Some(self.youngs), plausible::modulus as fn(f64, Spelling) -> plausible::Verdict),
            (vec![key("counterface"), key("youngs")], counter_youngs, plausible::modulus),
            (vec![key("hardness")], self.hardness, plausible::hardness),
        ];
        for (path, value, judge) in judged {
            if let Some(v) = value {
                judge(v.0, Spelling::StudyFile)
                    .map(drop)
                    .or_else(|r| at(&[vec![material.clone()], path].concat(), r))?;
            }
        }
        // The E band is drawn through E ± ΔE: both must be moduli.
        if let Some(delta) = self.youngs_uncertainty {
            if !(delta.0 >= 0.0 && delta.0 < self.youngs.0) {
                return at(
                    &[material.clone(), key("youngs_uncertainty")],
                    format!(
                        "{} must lie in [0, youngs) = [0, {})",
                        quantity::show(delta.0, &PRESSURE),
                        quantity::show(self.youngs.0, &PRESSURE)
                    ),
                );
            }
        }
        if let Counterface::Body { youngs, poisson } = self.counterface {
            Material::new(youngs.0, poisson, "counter-body")
                .map_err(|e| (vec![material.clone(), key("counterface")], reason_of(e)))?;
        }
        Ok(())
    }
}
