//! Elastic materials: an isotropic body's modulus and Poisson ratio, and the effective modulus
//! E* of two bodies in contact.
//!
//! Imports nothing inside `contact`; must not import friction, study, report, plot, shs, cli.

use crate::error::{Error, Result};
use crate::quantity::{show, PRESSURE};

/// An isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Young's modulus E \[Pa].
    pub youngs: f64,
    /// Poisson's ratio ν, in (−1, 0.5).
    pub poisson: f64,
}

impl Material {
    /// Silicon as in the paper: E = 130 GPa, ν = 0.26.
    pub const SILICON: Material = Material { youngs: 130e9, poisson: 0.26 };

    /// A validated material. `option` names where the values came from, for the error.
    pub fn new(youngs: f64, poisson: f64, option: &str) -> Result<Self> {
        if !(youngs > 0.0 && youngs.is_finite()) {
            return Err(Error::invalid(
                format!("{option} Young's modulus"),
                format!("must be positive, got {}", show(youngs, &PRESSURE)),
            ));
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(Error::invalid(
                format!("{option} Poisson's ratio"),
                format!("must lie in (−1, 0.5), got {poisson}"),
            ));
        }
        Ok(Material { youngs, poisson })
    }

    /// Plane-strain modulus E / (1 − ν²) \[Pa]: the effective modulus E* of this body pressed
    /// by a rigid one.
    pub fn plane_strain_modulus(&self) -> f64 {
        self.youngs / (1.0 - self.poisson * self.poisson)
    }
}

/// Effective modulus E* \[Pa] of two elastic bodies: 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2.
pub fn combined_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / (1.0 / a.plane_strain_modulus() + 1.0 / b.plane_strain_modulus())
}
