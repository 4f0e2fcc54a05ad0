//! A height map ([`Topography`]) with its provenance, and the limits of a length asperity
//! takes: the type every file of `topography` works on. Imports none of them.
//!
//! Imports the base row (error, plausible); must not import contact, friction, study, report,
//! plot, shs, cli.

use std::path::PathBuf;

use ndarray::Array2;

/// The largest magnitude of a height or a size asperity takes \[m]: far beyond any surface,
/// and small enough that the fourth powers and Fourier sums of the statistics stay finite.
pub const MAX_LENGTH_M: f64 = 1e50;

/// The smallest physical size \[m]: its inverse (a wavevector, a slope) stays finite too.
pub const MIN_SIZE_M: f64 = 1e-50;

/// A height map.
#[derive(Debug, Clone, PartialEq)]
pub struct Topography {
    /// Heights \[m], shape (ny, nx): row index = y, column index = x. `NaN` marks a missing
    /// point, kept as such until the user decides to fill or refuse it.
    pub heights: Array2<f64>,
    /// Physical size (lx, ly) \[m], or `None` when the source carries none (a bare array).
    pub physical_size: Option<(f64, f64)>,
    /// Whether the map repeats across its edges (synthetic surfaces may; measurements do not).
    pub periodic: bool,
    /// Whether the heights are known to be metres. False when the file states no height unit
    /// (and the user gave none) or a unit that is not a length with no factor to metres: the
    /// values are then as stored, and nothing may be solved on them ([`Topography::require_metres`]).
    pub height_unit_known: bool,
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

    /// An error naming the file unless the heights are known to be metres: a height unit the
    /// file does not state is never guessed.
    pub fn require_metres(&self) -> crate::error::Result<()> {
        if self.height_unit_known {
            return Ok(());
        }
        Err(self.error(match &self.provenance.height_unit {
            Some(unit) => format!(
                "channel '{}' holds values in {unit}, not a length, and the file gives no factor to metres: \
                 choose a height channel (--channel, study: channel)",
                self.channel
            ),
            None => "the file states no height unit: give it with --height-unit U (study: height_unit), \
                     e.g. nm or µm"
                .to_string(),
        }))
    }

    /// An error naming the file when the heights span more than the window is wide: no rough
    /// surface measured in metres looks like that (nor can the half-space's small slopes hold
    /// on it), while heights in nm or µm taken as metres do (a bare array's are taken as
    /// metres). Without a physical size there is nothing to compare with.
    pub fn require_plausible_heights(&self) -> crate::error::Result<()> {
        let Some((lx, ly)) = self.physical_size else { return Ok(()) };
        let (lo, hi) = self
            .heights
            .iter()
            .filter(|h| h.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| (lo.min(h), hi.max(h)));
        let span = hi - lo;
        if span > lx.max(ly) {
            let remedy = match (&self.provenance.file, self.provenance.format.as_str()) {
                (Some(_), _) => {
                    "not heights in metres; give their unit with --height-unit U (study: height_unit), e.g. nm or µm"
                }
                (None, "synthetic") => "no rough surface looks like that; lower its rms height or rms slope",
                // Heights handed over as an array are metres: the unit is the caller's to apply.
                (None, _) => "not heights in metres; give their unit, e.g. nm: heights in nm × 1e-9 are metres",
            };
            return Err(self.error(format!(
                "the heights span {span:.3e} m, more than the {lx:.3e} × {ly:.3e} m window is wide: {remedy}"
            )));
        }
        Ok(())
    }

    /// An error naming the topography when a height is beyond ±[`MAX_LENGTH_M`] (infinite
    /// included; `NaN` marks a missing point) or its physical size is not between
    /// [`MIN_SIZE_M`] and [`MAX_LENGTH_M`]: such numbers overflow the statistics, spectra and
    /// solves made of them (an x3p increment of 1e308 m gives an infinite size). Heights that
    /// differ, but by less than any instrument measures, are refused too
    /// ([`crate::plausible::height_span`]): a contact on them never converges.
    pub fn require_representable(&self) -> crate::error::Result<()> {
        /// Heights apart by at most this [m] differ by rounding only.
        const FLAT_M: f64 = 1e-20;
        if let Some(((j, i), h)) = self.heights.indexed_iter().find(|(_, h)| h.abs() > MAX_LENGTH_M) {
            return Err(self.error(format!(
                "the value at row {j}, column {i} is {h:e}, beyond ±{MAX_LENGTH_M:e} (m): not representable"
            )));
        }
        let finite = self.heights.iter().filter(|h| h.is_finite());
        let (low, high) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
        // Heights a rounding apart (a levelled plane) are a flat map; apart by more, yet by less
        // than any instrument measures, they are no surface.
        if high - low > FLAT_M {
            crate::plausible::height_span(high - low)
                .map_err(|e| self.error(format!("the heights span {e}: a flat map has equal heights")))?;
        }
        match self.physical_size {
            Some((lx, ly)) if ![lx, ly].iter().all(|l| (MIN_SIZE_M..=MAX_LENGTH_M).contains(l)) => Err(self.error(
                format!("the physical size {lx:e} × {ly:e} m is not between {MIN_SIZE_M:e} and {MAX_LENGTH_M:e} m"),
            )),
            _ => Ok(()),
        }
    }

    /// Number of missing (`NaN`) points.
    pub fn missing_points(&self) -> usize {
        self.heights.iter().filter(|h| h.is_nan()).count()
    }
}
