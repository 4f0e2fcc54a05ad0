//! Statistics of a topography: height moments, RMS slope, isotropic power spectral density; of a
//! line profile: its mean, RMS height, RMS slope and power spectral density, as SurfaceTopography
//! defines them for line scans. The moments and slopes are in `heights`, the spectra in `psd`,
//! their power-law fit in `fit`; this file gathers them, and tests the synthetic surfaces
//! (`synth`) against them.
//!
//! PSD normalisation (as Jacobs, Junge & Pastewka, Surf. Topogr.: Metrol. Prop. 5, 013001
//! (2017), and SurfaceTopography): C(q) = |h̃(q)|² / A with h̃(q) = Σ h(x) e^(−iq·x) dx dy the
//! Fourier transform over the window of area A = lx·ly, so C is in m⁴ and
//! `h_rms² = ∫ C(q) d²q / (2π)²`, i.e. `h_rms² = (1/A) Σ_q C(q)` over the discrete wavevectors
//! q = 2π (kx/lx, ky/ly). The isotropic C(q) averages the modes in annuli of width 2π/min(lx, ly).
//!
//! Imports only its own files (its tests also `synth` and `resample`, which import nothing of
//! `stats`); must not import contact, friction, study, report, plot, shs, cli.

mod fit;
mod heights;
mod psd;

pub use fit::{fit_psd, psd_fit_window, PsdFit, SpectrumOf, PSD_FIT_BINS_PER_DECADE};
pub use heights::{
    height_stats, profile_height, profile_rms_curvature, profile_rms_slope, rms_slope, slope_curvature, HeightStats,
    SlopeCurvature,
};
pub use psd::{profile_psd, psd, Psd, Window};

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::psd::tests::log_slope;
    use super::*;
    use crate::topography::resample::compound;
    use crate::topography::synth::tests::rough;
    use crate::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};

    #[test]
    fn the_target_rms_height_or_slope_is_met_exactly() {
        for grid in [(64, 64), (63, 50)] {
            let t = rough(0.8, Amplitude::RmsHeight(3e-8)).generate((10e-6, 8e-6), grid, 1).unwrap();
            let s = height_stats(&t).unwrap();
            assert!((s.rms_height / 3e-8 - 1.0).abs() < 1e-12, "{grid:?}: {}", s.rms_height);
            assert!(s.mean.abs() < 1e-12 * 3e-8, "{grid:?}: mean {}", s.mean);
            let t = rough(0.5, Amplitude::RmsSlope(0.1)).generate((10e-6, 8e-6), grid, 1).unwrap();
            let g = rms_slope(&t).unwrap();
            assert!((g / 0.1 - 1.0).abs() < 1e-12, "{grid:?}: slope {g}");
        }
    }

    #[test]
    fn the_spectrum_follows_the_prescribed_power_law() {
        let (l, n) = (10e-6, 256);
        for hurst in [0.3, 0.8] {
            let t = rough(hurst, Amplitude::RmsHeight(1e-8)).generate((l, l), (n, n), 3).unwrap();
            let p = psd(&t, Window::None).unwrap();
            let (q_r, q_s) = (2.0 * PI / 2.5e-6, 2.0 * PI / 0.2e-6);
            let slope = log_slope(&p, 1.2 * q_r, q_s / 1.2);
            let expected = -2.0 * (1.0 + hurst);
            assert!((slope / expected - 1.0).abs() < 0.05, "H = {hurst}: slope {slope}, expected {expected}");
            // Flat below the roll-off, nothing beyond the short cut-off.
            let plateau: Vec<f64> = p.q.iter().zip(&p.c).filter(|(q, _)| **q < 0.9 * q_r).map(|(_, c)| *c).collect();
            let (lo, hi) = plateau.iter().fold((f64::MAX, 0.0f64), |(a, b), &c| (a.min(c), b.max(c)));
            assert!(plateau.len() >= 3 && hi / lo < 1.02, "plateau {plateau:?}");
            assert!(p.q.iter().zip(&p.c).filter(|(q, _)| **q > 1.05 * q_s).all(|(_, c)| *c < 1e-30 * hi));
        }
    }

    #[test]
    fn the_default_silicon_ball_has_about_40_nm_rms() {
        // The paper's window on a coarser grid (the RMS hardly depends on the pixel).
        for seed in 0..3 {
            let ball = SyntheticSurface { grid: (300, 300), seed, ..SyntheticSurface::default() };
            let t = ball.generate().unwrap();
            assert!(!t.periodic && t.channel == "self-affine + cap");
            let rms = height_stats(&t).unwrap().rms_height;
            assert!((36e-9..44e-9).contains(&rms), "seed {seed}: {rms} m");
            // The sum of the parts.
            let roughness = ball.roughness.unwrap().generate(ball.size, ball.grid, seed).unwrap();
            let cap = SyntheticSurface { roughness: None, ..ball.clone() }.generate().unwrap();
            assert_eq!(cap.channel, "cap");
            assert_eq!(t.heights, &roughness.heights + &cap.heights);
        }
    }

    #[test]
    fn a_synthetic_wafer_compounds_with_a_synthetic_ball() {
        let ball = SyntheticSurface { grid: (128, 128), ..SyntheticSurface::default() }.generate().unwrap();
        let wafer = SelfAffine::silicon_wafer().generate((40e-6, 40e-6), (256, 256), 1).unwrap();
        assert!((height_stats(&wafer).unwrap().rms_height / 0.2e-9 - 1.0).abs() < 1e-12);
        let h = compound(&ball, &wafer).unwrap();
        assert!(!h.periodic && h.physical_size == ball.physical_size);
        // What the wafer takes away is its own roughness, seen through the ball's window.
        let wafer_part = &ball.heights - &h.heights;
        let rms = wafer_part.std(0.0);
        assert!((0.1e-9..0.3e-9).contains(&rms), "{rms}");
    }

    #[test]
    fn parameters_that_overflow_the_heights_are_refused() {
        // An rms of 1e308 m gave NaN heights, 1e200 m infinite statistics, written with exit 0.
        for (amplitude, option) in [
            (Amplitude::RmsHeight(1e308), "--rms"),
            (Amplitude::RmsHeight(1e50), "--rms"),
            (Amplitude::RmsSlope(1e300), "--rms-slope"),
        ] {
            let err = rough(0.8, amplitude).generate((1e-5, 1e-5), (16, 16), 0).unwrap_err().to_string();
            assert!(err.starts_with(&format!("{option}: ")) && err.contains("not representable"), "{err}");
        }
        // Just within the range, every height is finite.
        let t = rough(0.8, Amplitude::RmsHeight(1e48)).generate((1e-5, 1e-5), (16, 16), 0).unwrap();
        assert!(t.heights.iter().all(|h| h.is_finite()) && height_stats(&t).unwrap().rms_height.is_finite());
        let tiny_paraboloid = Cap { radius: 1e-300, shape: CapShape::Paraboloid };
        let err = tiny_paraboloid.heights((1e-5, 1e-5), (16, 16)).unwrap_err().to_string();
        assert!(err.starts_with("--sphere-radius: "), "{err}");
        for size in [(1e308, 1e308), (1e-60, 1e-5)] {
            let err = rough(0.8, Amplitude::RmsSlope(0.1)).generate(size, (16, 16), 0).unwrap_err().to_string();
            assert!(err.starts_with("--size: "), "{err}");
        }
    }
}
