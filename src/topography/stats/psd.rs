//! The power spectral density of a map (isotropic) and of a line profile, with the window
//! applied before the transform, normalised as the parent module states.
//!
//! Imports `missing`, `profile` and the map type of `topography`, never `fit`; must not import
//! contact, friction, study, report, plot, shs, cli.

use std::f64::consts::PI;

use realfft::RealFftPlanner;

use super::super::map::Topography;
use super::super::missing::refuse_missing;
use super::super::profile::Profile;
use crate::error::Result;
use crate::fft::Fft2;

/// A window applied to the heights before the Fourier transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    /// None: right for periodic maps.
    None,
    /// Separable Hann window w(x)·w(y), w = sin²(πi/(n−1)), scaled so that ⟨w²⟩ = 1 (the
    /// total power of a stationary surface is kept). Suppresses the leakage of a
    /// non-periodic map's edges.
    Hann,
}

impl Window {
    /// No window for a periodic map, Hann otherwise.
    pub fn default_for(topo: &Topography) -> Self {
        if topo.periodic {
            Window::None
        } else {
            Window::Hann
        }
    }

    fn weights(self, n: usize) -> Vec<f64> {
        match self {
            Window::None => vec![1.0; n],
            Window::Hann => {
                let w: Vec<f64> = (0..n).map(|i| (PI * i as f64 / (n - 1).max(1) as f64).sin().powi(2)).collect();
                let rms = (w.iter().map(|w| w * w).sum::<f64>() / n as f64).sqrt();
                w.iter().map(|w| w / rms).collect()
            }
        }
    }
}

/// The isotropic power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Wavevector |q| [rad/m]: the mean over the modes of each annulus, ascending.
    pub q: Vec<f64>,
    /// C(q) \[m⁴]: the mean over the modes of each annulus (of a profile \[m³], see
    /// [`profile_psd`]).
    pub c: Vec<f64>,
    /// Number of Fourier modes (over the full q plane) in each annulus (of a profile: ±q).
    pub modes: Vec<usize>,
}

/// The isotropic PSD of `topo` after subtracting its mean and applying `window`; the q = 0
/// mode is left out. Needs the physical size; refuses missing points.
pub fn psd(topo: &Topography, window: Window) -> Result<Psd> {
    refuse_missing(topo)?;
    topo.pixel_size("the PSD")?;
    let (lx, ly) = topo.physical_size.expect("checked by pixel_size");
    let (ny, nx) = topo.heights.dim();
    if nx < 4 || ny < 4 {
        return Err(topo.error(format!("the PSD needs at least 4×4 points, the map has {nx}×{ny}")));
    }
    let mean = topo.heights.mean().expect("the map is not empty");
    let (wx, wy) = (window.weights(nx), window.weights(ny));
    let field: Vec<f64> = topo.heights.indexed_iter().map(|((j, i), &h)| (h - mean) * wx[i] * wy[j]).collect();
    let plan = Fft2::new(ny, nx);
    let mut spectrum = plan.make_spectrum();
    plan.forward(&field, ny, nx, &mut spectrum, &mut plan.make_work());

    let n = (nx * ny) as f64;
    let norm = lx * ly / (n * n);
    let dq = 2.0 * PI / lx.min(ly);
    let mut bins: Vec<(f64, f64, usize)> = Vec::new();
    for ((kx, ky), c) in plan.wavevectors().zip(&spectrum) {
        if kx == 0 && ky == 0 {
            continue;
        }
        // The half spectrum stores qx ≥ 0; interior qx columns stand for ±qx.
        let weight = if kx == 0 || (nx % 2 == 0 && kx == nx / 2) { 1 } else { 2 };
        let q = (2.0 * PI * kx as f64 / lx).hypot(2.0 * PI * ky as f64 / ly);
        let b = (q / dq).round() as usize;
        if b >= bins.len() {
            bins.resize(b + 1, (0.0, 0.0, 0));
        }
        let bin = &mut bins[b];
        bin.0 += weight as f64 * q;
        bin.1 += weight as f64 * norm * c.norm_sqr();
        bin.2 += weight;
    }
    let kept = bins.into_iter().filter(|b| b.2 > 0);
    let (mut q, mut c, mut modes) = (Vec::new(), Vec::new(), Vec::new());
    for (sq, sc, m) in kept {
        q.push(sq / m as f64);
        c.push(sc / m as f64);
        modes.push(m);
    }
    Ok(Psd { q, c, modes })
}

/// The power spectral density of a uniform line profile after subtracting its mean and
/// applying `window`: C(q) = |h̃(q)|² / L \[m³] with h̃(q) = Σ h(x) e^(−iqx) dx over the profile
/// of length L = n·dx (SurfaceTopography's `power_spectrum_from_profile`), at q = 2πk/L for
/// k = 1 … n/2, C(q) and C(−q) averaged (`modes` counts them: 2, and 1 at q = πn/L for even n),
/// so that (1/L) Σ modes · C is the variance of the windowed heights. Refuses a non-uniform
/// profile (its spectrum would need an interpolation) and missing points.
pub fn profile_psd(p: &Profile, window: Window) -> Result<Psd> {
    let Some(dx) = p.step() else {
        let why = match &p.stated_grid {
            Some(Err(why)) => format!(" ({why})"),
            _ => String::new(),
        };
        return Err(p.error(format!(
            "the profile is not uniform (its positions are not equally spaced{why}): its spectrum would need an \
             interpolation, which asperity does not make"
        )));
    };
    let n = p.points();
    if n < 4 {
        return Err(p.error(format!("the PSD needs at least 4 points, the profile has {n}")));
    }
    match p.missing_points() {
        0 => {}
        m => return Err(p.error(format!("{m} of {n} points are missing: the PSD needs every point"))),
    }
    let h = p.heights();
    let mean = h.iter().sum::<f64>() / n as f64;
    let mut field: Vec<f64> = h.iter().zip(window.weights(n)).map(|(h, w)| (h - mean) * w).collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    fft.process(&mut field, &mut spectrum).expect("buffers sized by the plan");
    let length = dx * n as f64;
    let (mut q, mut c, mut modes) = (Vec::new(), Vec::new(), Vec::new());
    for (k, z) in spectrum.iter().enumerate().skip(1) {
        q.push(2.0 * PI * k as f64 / length);
        c.push((z * dx).norm_sqr() / length);
        modes.push(if n.is_multiple_of(2) && k == n / 2 { 1 } else { 2 });
    }
    Ok(Psd { q, c, modes })
}

#[cfg(test)]
pub(super) mod tests {
    use super::super::heights::height_stats;
    use super::super::heights::tests::map;
    use super::*;
    use crate::topography::resample::{crop, CropWindow};
    use crate::topography::synth::{Amplitude, SelfAffine};
    use ndarray::Array2;

    /// Least-squares slope of log C against log q over q_lo ≤ q ≤ q_hi.
    pub(crate) fn log_slope(p: &Psd, q_lo: f64, q_hi: f64) -> f64 {
        let pts: Vec<(f64, f64)> =
            p.q.iter().zip(&p.c).filter(|(q, _)| (q_lo..=q_hi).contains(*q)).map(|(q, c)| (q.ln(), c.ln())).collect();
        assert!(pts.len() >= 5, "only {} points between {q_lo} and {q_hi}", pts.len());
        let n = pts.len() as f64;
        let (mx, my) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxy: f64 = pts.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = pts.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        sxy / sxx
    }

    fn surface(size: (f64, f64), grid: (usize, usize), hurst: f64) -> Topography {
        let params = SelfAffine {
            hurst,
            rolloff_wavelength: None,
            short_cutoff_wavelength: None,
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(1e-8),
        };
        params.generate(size, grid, 11).unwrap()
    }

    #[test]
    fn parseval_holds_to_round_off() {
        // ∫ C d²q/(2π)² = (1/A) Σ_modes C = h_rms², on odd and even, non-square grids.
        for (grid, size) in [((45, 32), (9e-6, 7e-6)), ((64, 64), (5e-6, 5e-6)), ((33, 17), (3e-6, 2e-6))] {
            let t = surface(size, grid, 0.7);
            for window in [Window::None, Window::Hann] {
                let p = psd(&t, window).unwrap();
                let total: f64 = p.c.iter().zip(&p.modes).map(|(c, m)| c * *m as f64).sum::<f64>() / (size.0 * size.1);
                // The variance of the windowed field (the q = 0 mode is left out), computed directly.
                let (wx, wy) = (window.weights(grid.0), window.weights(grid.1));
                let mean = t.heights.mean().unwrap();
                let windowed =
                    Array2::from_shape_fn(t.heights.dim(), |(j, i)| (t.heights[(j, i)] - mean) * wx[i] * wy[j]);
                let direct = windowed.var(0.0);
                assert!((total / direct - 1.0).abs() < 1e-12, "{grid:?} {window:?}: {total} vs {direct}");
                assert_eq!(p.modes.iter().sum::<usize>(), grid.0 * grid.1 - 1);
            }
            // Unwindowed, that is the RMS height.
            let rms = height_stats(&t).unwrap().rms_height;
            let p = psd(&t, Window::None).unwrap();
            let total: f64 = p.c.iter().zip(&p.modes).map(|(c, m)| c * *m as f64).sum::<f64>() / (size.0 * size.1);
            assert!((total / (rms * rms) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn the_radial_integral_gives_the_rms_height() {
        // (1/2π) ∫ q C(q) dq over the annuli of width dq (midpoint rule): within a few per cent,
        // the annuli at small q holding not quite 2πq·dq·A/(2π)² modes.
        let params = SelfAffine {
            hurst: 0.8,
            rolloff_wavelength: Some(2e-6),
            short_cutoff_wavelength: None,
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(1e-8),
        };
        let t = params.generate((10e-6, 10e-6), (128, 128), 5).unwrap();
        let p = psd(&t, Window::None).unwrap();
        let dq = 2.0 * PI / 10e-6;
        let integral: f64 = p.q.iter().zip(&p.c).map(|(q, c)| q * c * dq).sum::<f64>() / (2.0 * PI);
        let rms = height_stats(&t).unwrap().rms_height;
        assert!((integral / (rms * rms) - 1.0).abs() < 0.05, "{integral} vs {}", rms * rms);
    }

    #[test]
    fn the_hann_window_recovers_the_slope_of_a_non_periodic_crop() {
        let hurst = 0.8;
        let full = surface((20e-6, 20e-6), (512, 512), hurst);
        let part = crop(&full, &CropWindow::Pixels { x: 100..356, y: 50..306 }).unwrap();
        assert!(!part.periodic && Window::default_for(&part) == Window::Hann);
        let q0 = 2.0 * PI / 10e-6;
        let range = (4.0 * q0, 60.0 * q0);
        let hann = log_slope(&psd(&part, Window::Hann).unwrap(), range.0, range.1);
        let expected = -2.0 * (1.0 + hurst);
        assert!((hann / expected - 1.0).abs() < 0.05, "Hann: {hann}, expected {expected}");
        // Without the window the edges leak power and flatten the spectrum.
        let bare = log_slope(&psd(&part, Window::None).unwrap(), range.0, range.1);
        assert!((bare / expected - 1.0).abs() > 0.1, "unwindowed: {bare}");
    }

    #[test]
    fn profile_parseval_and_a_sine_peak() {
        let (n, dx) = (64, 0.5e-6);
        let h: Vec<f64> =
            (0..n).map(|i| 1e-8 * (2.0 * PI * 5.0 * i as f64 / n as f64).sin() + 3e-9 * (i % 3) as f64).collect();
        let p = Profile::new((0..n).map(|i| i as f64 * dx).collect(), h.clone()).unwrap();
        let length = dx * n as f64;
        for window in [Window::None, Window::Hann] {
            let s = profile_psd(&p, window).unwrap();
            assert_eq!((s.q.len(), s.modes.iter().sum::<usize>()), (n / 2, n - 1));
            let total: f64 = s.c.iter().zip(&s.modes).map(|(c, m)| c * *m as f64).sum::<f64>() / length;
            let mean = h.iter().sum::<f64>() / n as f64;
            // The variance of the windowed heights (the q = 0 mode is left out).
            let windowed: Vec<f64> = h.iter().zip(window.weights(n)).map(|(h, w)| (h - mean) * w).collect();
            let wmean = windowed.iter().sum::<f64>() / n as f64;
            let direct = windowed.iter().map(|v| (v - wmean).powi(2)).sum::<f64>() / n as f64;
            assert!((total / direct - 1.0).abs() < 1e-12, "{window:?}: {total} vs {direct}");
        }
        let s = profile_psd(&p, Window::None).unwrap();
        let peak = (0..s.c.len()).max_by(|&a, &b| s.c[a].total_cmp(&s.c[b])).unwrap();
        assert!((s.q[peak] - 2.0 * PI * 5.0 / length).abs() < 1e-6 * s.q[peak]);
        let bumpy = Profile::new(vec![0.0, 1.0, 2.5, 3.0, 4.0], vec![0.0; 5]).unwrap();
        assert!(profile_psd(&bumpy, Window::None).unwrap_err().to_string().contains("not uniform"));
    }

    #[test]
    fn the_psd_refuses_missing_points_and_needs_a_size() {
        let mut h = Array2::zeros((8, 8));
        h[(2, 2)] = f64::NAN;
        assert!(psd(&map(h, (1e-6, 1e-6), false), Window::None)
            .unwrap_err()
            .to_string()
            .contains("1 of 64 points are missing"));
        let mut t = map(Array2::zeros((8, 8)), (1e-6, 1e-6), false);
        t.physical_size = None;
        assert!(psd(&t, Window::None).unwrap_err().to_string().contains("the PSD needs the physical size"));
    }
}
