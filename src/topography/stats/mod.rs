//! Statistics of a topography: height moments, RMS slope, isotropic power spectral density; of a
//! line profile: its mean, RMS height, RMS slope and power spectral density, as SurfaceTopography
//! defines them for line scans. The moments and slopes are in `heights`, the spectra in `psd`,
//! their power-law fit in `fit`; this file only gathers them.
//!
//! PSD normalisation (as Jacobs, Junge & Pastewka, Surf. Topogr.: Metrol. Prop. 5, 013001
//! (2017), and SurfaceTopography): C(q) = |h̃(q)|² / A with h̃(q) = Σ h(x) e^(−iq·x) dx dy the
//! Fourier transform over the window of area A = lx·ly, so C is in m⁴ and
//! `h_rms² = ∫ C(q) d²q / (2π)²`, i.e. `h_rms² = (1/A) Σ_q C(q)` over the discrete wavevectors
//! q = 2π (kx/lx, ky/ly). The isotropic C(q) averages the modes in annuli of width 2π/min(lx, ly).
//!
//! Imports only its own files; must not import contact, friction, study, report, plot, shs, cli.

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
