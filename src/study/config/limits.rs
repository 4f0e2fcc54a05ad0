//! `[limits]`: how large the study's inputs and grids may be.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use serde::{Deserialize, Serialize};

use super::places::{key, reason_of, Checked};
use crate::limits::{Limits, DEFAULT_MAX_POINTS};

/// How large the study's inputs and grids may be (see [`crate::limits`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [limits] table")]
pub struct LimitsSpec {
    /// The largest grid read from a file, generated, resampled or solved \[points].
    #[serde(default = "default_max_points")]
    pub max_points: usize,
}

fn default_max_points() -> usize {
    DEFAULT_MAX_POINTS
}

impl Default for LimitsSpec {
    fn default() -> Self {
        LimitsSpec { max_points: DEFAULT_MAX_POINTS }
    }
}

impl LimitsSpec {
    pub(super) fn is_default(&self) -> bool {
        *self == LimitsSpec::default()
    }

    /// The limits the study's inputs are held to.
    pub fn limits(&self) -> Limits {
        Limits { max_points: self.max_points }
    }

    /// `max_points`, as the library bounds it.
    pub(super) fn check(&self) -> Checked {
        Limits::new(self.max_points, "max_points")
            .map_err(|e| (vec![key("limits"), key("max_points")], reason_of(e)))?;
        Ok(())
    }
}
