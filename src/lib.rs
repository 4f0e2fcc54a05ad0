//! asperity: the static friction coefficient of rough interfaces from their measured
//! topography, after Peng, Roch, Bonn & Weber, Phys. Rev. Lett. 134, 176202 (2025).
//!
//! The modules follow the pipeline: [`topography`] (read, prepare, synthesise height maps) →
//! `contact` (elastic normal contact by the boundary integral method) → `friction` (the
//! stick-slip transition model) → `study` (loads × topographies × friction laws) → `plot`.
//! Units are SI everywhere: metres, pascals, newtons. Arrays are row-major, shape (ny, nx).

#![warn(missing_docs)]

pub mod contact;
pub mod error;
pub mod fft;
pub mod friction;
pub mod limits;
pub mod output;
pub mod plausible;
pub mod plot;
pub mod quantity;
pub mod report;
pub mod shs;
pub mod study;
pub mod topography;

pub use error::{Error, Result};

/// This asperity's version (the crate's, `0.2.0`), as `--version`, `results.json` and the report
/// state it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The commit this asperity was built from: a short git hash, with `-modified` when its tracked
/// sources differed from that commit, or `unknown` when built outside a git checkout.
pub const COMMIT: &str = env!("ASPERITY_COMMIT");
