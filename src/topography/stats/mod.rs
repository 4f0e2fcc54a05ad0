//! Statistics of a topography: height moments, RMS slope, isotropic power spectral density; of a
//! line profile: its mean, RMS height, RMS slope and power spectral density, as SurfaceTopography
//! defines them for line scans. The moments and slopes are in `heights`, the spectra in `psd`,
//! their power-law fit in `fit`; this file only gathers them.
//!
//! Imports within `topography` only (missing, profile, the map type); must not import contact,
//! friction, study, report, plot, shs, cli.

mod fit;
mod heights;
mod psd;

pub use fit::{fit_psd, psd_fit_window, PsdFit, SpectrumOf, PSD_FIT_BINS_PER_DECADE};
pub use heights::{
    height_stats, profile_height, profile_rms_curvature, profile_rms_slope, rms_slope, slope_curvature, HeightStats,
    SlopeCurvature,
};
#[cfg(test)]
pub(crate) use psd::tests::log_slope;
pub use psd::{profile_psd, psd, Psd, Window};
