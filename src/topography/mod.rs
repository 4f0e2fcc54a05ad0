//! Topographies: measured or synthetic height maps in metres, ready for the contact solver.
//!
//! Reading instrument files lives in [`io`], one module per format behind one registry;
//! preparing them in [`detrend`], [`missing`] and [`resample`] (crop, resample, compound);
//! synthetic surfaces in [`synth`]; statistics and the power spectrum in [`stats`].

pub mod detrend;
pub mod io;
pub mod missing;
pub mod resample;
pub mod stats;
pub mod synth;
pub mod units;

use std::path::PathBuf;

use ndarray::Array2;

/// A height map.
#[derive(Debug, Clone, PartialEq)]
pub struct Topography {
    /// Heights [m], shape (ny, nx): row index = y, column index = x. `NaN` marks a missing
    /// point, kept as such until the user decides to fill or refuse it.
    pub heights: Array2<f64>,
    /// Physical size (lx, ly) [m], or `None` when the source carries none (a bare array).
    pub physical_size: Option<(f64, f64)>,
    /// Whether the map repeats across its edges (synthetic surfaces may; measurements do not).
    pub periodic: bool,
    /// Name of the channel the heights come from.
    pub channel: String,
    /// Where the heights come from.
    pub provenance: Provenance,
}

/// The origin of a topography.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Provenance {
    /// File read, if any.
    pub file: Option<PathBuf>,
    /// Format name as in the registry (`"nanoscope"`, `"gwy"`, …), or `"synthetic"`.
    pub format: String,
    /// Height unit as the file states it (`"nm"`, `"µm"`, `"m"`…), `None` when it states none.
    pub height_unit: Option<String>,
}

impl Topography {
    /// Number of points along x (columns).
    pub fn nx(&self) -> usize {
        self.heights.ncols()
    }

    /// Number of points along y (rows).
    pub fn ny(&self) -> usize {
        self.heights.nrows()
    }

    /// Number of missing (`NaN`) points.
    pub fn missing_points(&self) -> usize {
        self.heights.iter().filter(|h| h.is_nan()).count()
    }
}
