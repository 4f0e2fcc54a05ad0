//! What the study's figures and report share: their input, the names and colours of the
//! figures, and the grouping of the result rows. The figure modules and the report import it;
//! it imports none of them.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use crate::contact::CohesiveLaw;
use crate::friction::FrictionLaw;
use crate::shs::ShsPoint;
use crate::study::adhesion::AdhesionLimit;
use crate::study::{FigureKind, MapSnapshot, Records, ResolutionRow, Row};
use plotters::style::RGBColor;

/// Everything the study's figures and report are drawn from.
pub struct FigureInput<'a> {
    /// The result rows under equal sharing (the paper's model), which every figure but the
    /// sharing comparison draws.
    pub rows: &'a [Row],
    /// The result rows under equal sharing with elastic sharing's slip weakening (empty
    /// without elastic sharing, or when its laws drop at once).
    pub weakening_rows: &'a [Row],
    /// The result rows under elastic sharing (empty unless the study asks for them).
    pub elastic_rows: &'a [Row],
    /// The rows at the ends of the band of d_c: equal sharing under the weakening and elastic
    /// sharing (empty without a band).
    pub band_rows: &'a [Row],
    /// The result rows of the adhesive solves under equal sharing (empty without adhesion).
    pub adhesive_rows: &'a [Row],
    /// The cohesive law of the adhesive solves, if any.
    pub cohesive_law: Option<CohesiveLaw>,
    /// Topography names, in the study's order.
    pub topographies: &'a [String],
    /// Friction laws, in the study's order; maps, curves and movies use the first.
    pub laws: &'a [FrictionLaw],
    /// The hold time \[s] of each law, where known (matches measured points to laws).
    pub hold_times: &'a [Option<f64>],
    /// E*₀/E* for the moduli the friction-drop band also covers (empty: the study's only):
    /// by linear elasticity drop(N; E*) = drop(N·E*₀/E*; E*₀).
    pub modulus_ratios: &'a [f64],
    /// The other counterface the friction-drop figure shows: its description and E*₀/E*.
    pub counterface: Option<(&'a str, f64)>,
    /// Where a single summit's DMT pull-off is no longer small beside the load.
    pub adhesion: Option<AdhesionLimit>,
    /// The resolution study's rows (empty when it was not asked for).
    pub resolution: &'a [ResolutionRow],
    /// Loads \[N] of the hold-time figure.
    pub hold_time_loads: &'a [f64],
    /// p(σ) on a logarithmic density axis.
    pub log_density: bool,
    /// The hardness \[Pa] marked on p(σ), when the study sets one.
    pub hardness_pa: Option<f64>,
    /// Elastic sharing's slip-weakening distance d_c \[m] (0: the instant drop); a law given by
    /// a measured curve follows its own.
    pub slip_distance_m: f64,
    /// The ends of the band of d_c \[m], low then high (empty without a band).
    pub slip_distance_band: &'a [f64],
    /// The contact grid (nx, ny) every topography was resampled to, when the study sets one.
    pub grid: Option<(usize, usize)>,
    /// Snapshots of the first topography at the loads nearest to [`FIGURE_LOADS_N`](crate::study::FIGURE_LOADS_N).
    pub maps: &'a [MapSnapshot],
    /// Measured points to overlay on the friction-drop figure (may be empty).
    pub experiments: &'a [ShsPoint],
    /// Which figures to draw.
    pub figures: &'a [FigureKind],
    /// δ/δ_peak of the stress-ratio snapshots.
    pub snapshot_fractions: &'a [f64],
    /// The study's parameters as run (the study file written beside the results), shown in
    /// the report.
    pub parameters: &'a str,
}

impl<'a> FigureInput<'a> {
    /// The input of a study's `records`, with the measured points `experiments`.
    pub fn new(records: &'a Records, experiments: &'a [ShsPoint]) -> FigureInput<'a> {
        FigureInput {
            rows: &records.rows,
            weakening_rows: &records.weakening_rows,
            elastic_rows: &records.elastic_rows,
            band_rows: &records.band_rows,
            adhesive_rows: &records.adhesive_rows,
            cohesive_law: records.cohesive_law,
            topographies: &records.topographies,
            laws: &records.laws,
            hold_times: &records.hold_times,
            modulus_ratios: &records.modulus_ratios,
            counterface: records.counterface.as_ref().map(|(name, ratio)| (name.as_str(), *ratio)),
            adhesion: records.adhesion,
            resolution: &records.resolution,
            hold_time_loads: &records.hold_time_loads,
            log_density: records.log_density,
            hardness_pa: records.hardness_pa,
            slip_distance_m: records.slip_distance_m,
            slip_distance_band: &records.slip_distance_band,
            grid: records.grid,
            maps: &records.maps,
            experiments,
            figures: &records.figures,
            snapshot_fractions: &records.snapshot_fractions,
            parameters: &records.parameters,
        }
    }
}

/// Colours of the figure loads 0.1, 1, 10, 100 mN: the p(σ) curves and their lines on the
/// friction-drop figure (dark to light, as the paper's black to yellow).
pub(super) const LOAD_COLOURS: [RGBColor; 4] =
    [RGBColor(25, 25, 25), RGBColor(120, 50, 160), RGBColor(215, 120, 20), RGBColor(40, 140, 190)];

/// What became of one requested figure.
pub(super) struct Drawn {
    pub kind: FigureKind,
    /// Files written, relative to the study directory, with what each shows.
    pub images: Vec<Image>,
    /// What could not be drawn, and why.
    pub notes: Vec<String>,
}

/// One image of the report: a figure (`.png` + `.svg`) or a movie (`.gif`).
pub(super) struct Image {
    /// Path relative to the study directory, e.g. `figures/friction-drop.png`.
    pub file: String,
    pub svg: Option<String>,
    pub caption: String,
}

/// The file stem of a figure.
pub(super) fn stem(kind: FigureKind) -> &'static str {
    match kind {
        FigureKind::FrictionDrop => "friction-drop",
        FigureKind::FrictionDropSharing => "friction-drop-sharing",
        FigureKind::StaticDynamicCoefficients => "static-dynamic-coefficients",
        FigureKind::Resolution => "resolution",
        FigureKind::HoldTime => "hold-time",
        FigureKind::StressRatioHistograms => "stress-ratio-histograms",
        FigureKind::PressureDistribution => "pressure-distribution",
        FigureKind::ContactMaps => "contact-maps",
        FigureKind::ClassMap => "class-map",
        FigureKind::ClassFractions => "class-fractions",
        FigureKind::FrictionCurve => "friction-curve",
        FigureKind::StressRatioSnapshots => "stress-ratio-snapshots",
        FigureKind::Movies => "movies",
    }
}

/// The rows of one law grouped by load, in increasing load.
pub(super) fn by_load<'a>(rows: &'a [Row], law: &str) -> Vec<(f64, Vec<&'a Row>)> {
    let mut mine: Vec<&Row> = rows.iter().filter(|r| r.law == law).collect();
    mine.sort_by(|a, b| a.load_n.total_cmp(&b.load_n));
    let mut groups: Vec<(f64, Vec<&Row>)> = Vec::new();
    for r in mine {
        match groups.last_mut() {
            Some((load, group)) if (r.load_n / *load - 1.0).abs() < 1e-9 => group.push(r),
            _ => groups.push((r.load_n, vec![r])),
        }
    }
    groups
}

/// A change of the friction drop with its sign, to 4 decimals; one that rounds to zero is
/// +0.0000, whatever its sign.
pub(super) fn signed(change: f64) -> String {
    let change = if change.abs() < 5e-5 { 0.0 } else { change };
    format!("{change:+.4}")
}

/// (min, mean, max) of `values`.
pub(super) fn spread(values: impl Iterator<Item = f64>) -> (f64, f64, f64) {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    for v in values {
        (lo, hi, sum, n) = (lo.min(v), hi.max(v), sum + v, n + 1);
    }
    (lo, sum / n as f64, hi)
}
