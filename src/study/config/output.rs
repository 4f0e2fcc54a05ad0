//! `[output]`: what a run writes besides the results table — pressure maps, measured points,
//! the figures ([`FigureKind`]) and their settings.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::places::{at, key, Checked, Segment};
use super::quantities::Force;

/// The most `[output] snapshot_fractions`: each is a row of 400 pixels in the stress-ratio
/// snapshot figure.
pub const MAX_SNAPSHOT_FRACTIONS: usize = 12;

/// The figures a study can draw, as the config file and the report name them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FigureKind {
    /// Friction drop vs load, a band over the topographies (and E ± ΔE) per law, measured
    /// points (Fig. 2).
    FrictionDrop,
    /// Friction drop vs load under equal and elastic sharing, per law, a band over the
    /// topographies each (the limit the paper names).
    FrictionDropSharing,
    /// Static and dynamic friction coefficients vs load, measured points (Fig. S1).
    StaticDynamicCoefficients,
    /// Friction drop vs load at the study's pixel size and 2× and 4× coarser.
    Resolution,
    /// Friction drop vs hold time at chosen loads, for the laws with a hold time.
    HoldTime,
    /// p(σ) of the local normal stress at 0.1, 1 and 10 mN (Fig. 3).
    PressureDistribution,
    /// Contact maps at 0.1, 1, 10 and 100 mN (Fig. S4).
    ContactMaps,
    /// Element classes at the critical state at 10 mN (Fig. 4f).
    ClassMap,
    /// Fractions of N and of F_S carried by each class vs load (Fig. 4g).
    ClassFractions,
    /// Friction coefficient vs imposed displacement at 0.1 mN (Fig. 4a).
    FrictionCurve,
    /// Histograms of the local stress ratio at the critical state: one element, the two
    /// two-element scenarios, the interface at 10 mN (Fig. 4b–e).
    StressRatioHistograms,
    /// Stress-ratio maps at δ/δ_peak = 0.25 … 1 for 0.1, 1 and 10 mN (Fig. S6).
    StressRatioSnapshots,
    /// Animated GIFs of the stress-ratio map as δ grows, at 0.1, 1 and 10 mN (the movies).
    Movies,
}

impl FigureKind {
    /// Every figure, in the report's order.
    pub const ALL: [FigureKind; 13] = [
        FigureKind::FrictionDrop,
        FigureKind::FrictionDropSharing,
        FigureKind::StaticDynamicCoefficients,
        FigureKind::Resolution,
        FigureKind::HoldTime,
        FigureKind::PressureDistribution,
        FigureKind::ContactMaps,
        FigureKind::ClassMap,
        FigureKind::ClassFractions,
        FigureKind::FrictionCurve,
        FigureKind::StressRatioHistograms,
        FigureKind::StressRatioSnapshots,
        FigureKind::Movies,
    ];
}

/// What to write besides the results table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [output] table")]
pub struct OutputSpec {
    /// Also keep every full pressure map \[Pa] as `DIR/pressure/<topography>/<stem>.npy`, the
    /// stem naming the load and its solve (`1e-3N-<digest>`, as its record in `DIR/solves`).
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
