//! `[output]`: what a run writes besides the results table — pressure maps, measured points,
//! the figures and their settings.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::places::{at, key, Checked, Segment};
use super::quantities::Force;
use crate::study::FigureKind;

/// The most `[output] snapshot_fractions`: each is a row of 400 pixels in the stress-ratio
/// snapshot figure.
pub const MAX_SNAPSHOT_FRACTIONS: usize = 12;

/// What to write besides the results table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Also keep every full pressure map \[Pa] as `DIR/pressure/<topography>/NN.npy`.
    #[serde(default)]
    pub pressure_maps: bool,
    /// A CSV of measured points (as `asperity shs --out` writes it) to overlay on the figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub experiments: Option<PathBuf>,
    /// The figures to draw (default: all).
    #[serde(default = "all_figures")]
    pub figures: Vec<FigureKind>,
    /// δ/δ_peak of the stress-ratio snapshots, each in (0, 1] (default 0.25, 0.5, 0.75, 1).
    #[serde(default = "default_fractions")]
    pub snapshot_fractions: Vec<f64>,
    /// Loads \[N] of the hold-time figure.
    #[serde(default = "default_hold_time_loads")]
    pub hold_time_loads: Vec<Force>,
    /// p(σ) on a logarithmic density axis.
    #[serde(default)]
    pub log_density: bool,
}

fn all_figures() -> Vec<FigureKind> {
    FigureKind::ALL.to_vec()
}

fn default_fractions() -> Vec<f64> {
    vec![0.25, 0.5, 0.75, 1.0]
}

fn default_hold_time_loads() -> Vec<Force> {
    vec![Force(1e-4), Force(1e-3), Force(1e-2)]
}

impl OutputSpec {
    /// The snapshots' fractions: at most [`MAX_SNAPSHOT_FRACTIONS`], each in (0, 1], one at
    /// least when their figure is drawn.
    pub(super) fn check(&self) -> Checked {
        let fractions = self.snapshot_fractions.len();
        if fractions > MAX_SNAPSHOT_FRACTIONS {
            return at(
                &[key("output"), key("snapshot_fractions")],
                format!(
                    "{fractions} fractions: at most {MAX_SNAPSHOT_FRACTIONS} (each is a row of the snapshot figure)"
                ),
            );
        }
        if fractions == 0 && self.figures.contains(&FigureKind::StressRatioSnapshots) {
            return at(
                &[key("output"), key("snapshot_fractions")],
                "an empty list draws no stress-ratio snapshots: give at least one δ/δ_peak in (0, 1], or leave \
                 \"stress-ratio-snapshots\" out of figures"
                    .to_string(),
            );
        }
        for (i, f) in self.snapshot_fractions.iter().enumerate() {
            if !(*f > 0.0 && *f <= 1.0) {
                let path = [key("output"), key("snapshot_fractions"), Segment::Index(i)];
                return at(&path, format!("δ/δ_peak = {f} is not in (0, 1]"));
            }
        }
        Ok(())
    }
}
