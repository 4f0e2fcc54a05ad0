//! Slide-hold-slide analysis in Python: the analysis of a friction trace, as JSON for the
//! package's `asperity.analyse_shs`.
//!
//! Must not import topography, contact, friction or study of this crate.

use asperity::shs::{self, ShsOptions, Trace};
use pyo3::prelude::*;

use crate::errors::{error, invalid};

/// The slide-hold-slide analysis as JSON ({"cycles", "groups", "skipped"}); see
/// ``asperity.analyse_shs``.
#[pyfunction]
#[pyo3(signature = (time_s, friction_n, normal_n, displacement_m, speed, window, window_start, peak_within,
                    min_duration, hold_fraction, slide_fraction, group_tolerance))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _analyse_shs(
    py: Python<'_>,
    time_s: Vec<f64>,
    friction_n: Vec<f64>,
    normal_n: Vec<f64>,
    displacement_m: Option<Vec<f64>>,
    speed: f64,
    window: f64,
    window_start: f64,
    peak_within: f64,
    min_duration: f64,
    hold_fraction: f64,
    slide_fraction: f64,
    group_tolerance: f64,
) -> PyResult<String> {
    let options = ShsOptions {
        speed,
        window,
        window_start,
        peak_within,
        min_duration,
        hold_fraction,
        slide_fraction,
        group_tolerance,
    };
    options.validate().map_err(error)?;
    let analysis = py
        .detach(|| {
            let trace = Trace::new("trace", time_s, friction_n, normal_n, displacement_m)?;
            shs::analyse(&trace, &options)
        })
        .map_err(error)?;
    serde_json::to_string(&analysis).map_err(|e| invalid("trace", e.to_string()))
}
