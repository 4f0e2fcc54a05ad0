//! The fit of a power spectral density: the Hurst exponent of its power law and the roll-off
//! below which it is flat, over a window of wavevectors.
//!
//! Imports `psd` inside `stats`, nothing else of `topography`; must not import contact, friction,
//! study, report, plot, shs, cli.

use std::f64::consts::PI;

use super::psd::{Psd, Window};

/// Whose spectrum a [`Psd`] is, which fixes how its power-law slope gives the Hurst exponent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpectrumOf {
    /// The isotropic PSD of a map: C(q) ∝ q^(−2(1+H)) above the roll-off.
    Map,
    /// The 1-D PSD of a line profile: C(q) ∝ q^(−(1+2H)).
    Profile,
}

impl SpectrumOf {
    /// H from the log–log slope s of C(q).
    fn hurst(self, slope: f64) -> f64 {
        match self {
            SpectrumOf::Map => -slope / 2.0 - 1.0,
            SpectrumOf::Profile => (-slope - 1.0) / 2.0,
        }
    }
}

/// Log-spaced bins per decade of q in [`fit_psd`].
pub const PSD_FIT_BINS_PER_DECADE: usize = 10;
/// Steps per decade in which [`fit_psd`] scans the roll-off and the short end.
const PSD_FIT_BREAKS_PER_DECADE: f64 = 40.0;
/// The power law must span at least this many bins (half a decade) for H to mean anything.
const PSD_FIT_MIN_POWER_BINS: usize = 5;

/// A roll-off model fitted to a PSD by [`fit_psd`]; wavevectors [rad/m], C in the PSD's unit
/// (m⁴ of a map, m³ of a profile).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PsdFit {
    /// Hurst exponent H; `None` when refused (see `refusal`).
    pub hurst: Option<f64>,
    /// Why H is not reported, in one line.
    pub refusal: Option<String>,
    /// The power law's slope d log C / d log q (−2(1+H) of a map, −(1+2H) of a profile).
    pub slope: f64,
    /// Roll-off wavevector q_r: C is flat below it; `None` when the spectrum rises down to the
    /// window's smallest q (no roll-off in the window).
    pub rolloff_q: Option<f64>,
    /// C0: the plateau below q_r, or C at the window's start when there is no roll-off.
    pub c0: f64,
    /// The power law's range: from q_r (or the window's start) to the window's end.
    pub power_law_q: (f64, f64),
    /// The window fitted, as the caller gave it.
    pub window_q: (f64, f64),
    /// Log bins in the window.
    pub bins: usize,
    /// RMS residual of log10 C about the model over the window's bins \[decades].
    pub rms_residual_log10: f64,
    /// The RMS residual a random surface's PSD leaves by its scatter alone \[decades]: per bin
    /// of m independent modes (each power exponentially distributed) log10 e·√ψ′(m), ψ′ the
    /// trigamma function (0.56 for one mode, ≈ 0.43/√m for many); 0 would mean no scatter.
    pub expected_scatter_log10: f64,
}

/// Fit a roll-off model to `psd` in log–log over the wavevectors in `window` [rad/m]:
///
/// - the annuli are averaged (their modes weighted) in [`PSD_FIT_BINS_PER_DECADE`] log-spaced
///   bins, each weighing the same in the fit, so that a decade counts the same however many
///   wavevectors it holds;
/// - the model is continuous in (log q, log C): the plateau C0 below q_r, then the power law
///   C0 (q/q_r)^s. q_r is scanned in fortieths of a decade, "no roll-off" (q_r at the window's
///   start) included; each choice is a linear least-squares fit, and the one of least
///   Bayesian information criterion n ln(max(RSS/n, σ²)) + k ln n (k = 2, 3 with a roll-off;
///   σ the scatter a random surface's PSD has, `expected_scatter_log10`) wins, so that a
///   roll-off is kept only when it explains more of the spectrum than its scatter (of equal
///   criteria, the least residual);
/// - H comes from s ([`SpectrumOf`]); it is refused (`hurst: None`, `refusal` says why) when
///   the RMS residual exceeds 0.1 + twice the scatter expected of a random surface's PSD
///   (C is no power law there), when the power law spans under half a decade, or when H falls
///   outside (0, 1].
///
/// The callers' windows ([`psd_fit_window`]) leave out the last octave below the Nyquist
/// wavevector, shaped by the pixel, the instrument's tip and interpolation. A short cut-off
/// or noise floor inside the window is no power law: refused, not modelled.
pub fn fit_psd(psd: &Psd, of: SpectrumOf, window: (f64, f64)) -> std::result::Result<PsdFit, String> {
    if window.0 >= window.1 {
        return Err(format!(
            "no wavevector between q = {:.3e} and {:.3e} rad/m to fit: too few points along the scan",
            window.0, window.1
        ));
    }
    let bins = log_bins(psd, window);
    let n = bins.len();
    if n < PSD_FIT_MIN_POWER_BINS + 2 {
        return Err(format!(
            "the spectrum holds {n} log bins between q = {:.3e} and {:.3e} rad/m (a tenth of a decade each): too \
             few for a fit",
            window.0, window.1
        ));
    }
    let x: Vec<f64> = bins.iter().map(|b| b.x).collect();
    let y: Vec<f64> = bins.iter().map(|b| b.y).collect();
    let (first, last) = (x[0], x[n - 1]);
    let steps = ((last - first) * PSD_FIT_BREAKS_PER_DECADE).floor() as usize;
    let breaks: Vec<f64> = (0..=steps).map(|i| first + i as f64 / PSD_FIT_BREAKS_PER_DECADE).collect();
    let within = |lo: f64, hi: f64| x.iter().filter(|&&x| x >= lo && x <= hi).count();
    // A random surface's PSD scatters by this much (RMS, log10) whatever the model: residuals
    // below it tell no model from another, so the simplest that reaches it wins.
    let expected = (bins.iter().map(|b| b.scatter * b.scatter).sum::<f64>() / n as f64).sqrt();
    let mut best: Option<(f64, RollOff, f64)> = None;
    for &x_r in &breaks {
        if within(x_r, last) < PSD_FIT_MIN_POWER_BINS {
            break;
        }
        let Some((model, rss)) = (RollOff { x_r, coef: [0.0; 2] }).fitted(&x, &y) else { continue };
        let k = if x_r > first { 3 } else { 2 };
        let bic = n as f64 * (rss / n as f64).max(expected * expected).ln() + k as f64 * (n as f64).ln();
        // Equal criteria (residuals below the scatter): the closer fit.
        if best.as_ref().is_none_or(|&(b, _, r)| bic < b || (bic == b && rss < r)) {
            best = Some((bic, model, rss));
        }
    }
    let (_, m, rss) = best.expect("the power law over the whole window fits");
    let rms = (rss / n as f64).sqrt();
    let limit = 0.1 + 2.0 * expected;
    let slope = m.coef[1];
    let hurst = of.hurst(slope);
    let to_q = |x: f64| 10f64.powf(x);
    let span = within(m.x_r, last);
    let refusal = if rms > limit {
        Some(format!(
            "the PSD is not a power law between q = {:.3e} and {:.3e} rad/m: the model leaves {rms:.2} decades of C \
             RMS, more than the {limit:.2} a random surface's scatter would",
            to_q(first),
            to_q(last)
        ))
    } else if span < PSD_FIT_MIN_POWER_BINS {
        Some(format!("the power law spans only {span} log bins (under half a decade): no exponent"))
    } else if !(hurst > 0.0 && hurst <= 1.0) {
        Some(format!("the slope {slope:.3} gives H = {hurst:.2}, outside (0, 1]: not a self-affine spectrum"))
    } else {
        None
    };
    Ok(PsdFit {
        hurst: refusal.is_none().then_some(hurst),
        refusal,
        slope,
        rolloff_q: (m.x_r > first).then(|| to_q(m.x_r)),
        c0: to_q(m.coef[0]),
        power_law_q: (to_q(m.x_r), to_q(last)),
        window_q: window,
        bins: n,
        rms_residual_log10: rms,
        expected_scatter_log10: expected,
    })
}

/// The wavevectors [rad/m] `topo info --psd-fit` fits for a spectrum of length `length` \[m]
/// and pixel `pixel` \[m]: from the smallest (2π/L) without a window, from 3 × 2π/L with a Hann
/// window, whose main lobe (±2 × 2π/L) carries the power of longer wavelengths into the first
/// annuli; up to π/(2·pixel), half the Nyquist wavevector.
pub fn psd_fit_window(length: f64, pixel: f64, window: Window) -> (f64, f64) {
    let first = match window {
        Window::None => 1.0,
        Window::Hann => 3.0,
    };
    (first * 2.0 * PI / length, PI / (2.0 * pixel))
}

/// One log bin of [`fit_psd`]: mode-weighted mean log10 q, log10 of the mean C, and the
/// scatter of that log10 expected of a random surface.
struct LogBin {
    x: f64,
    y: f64,
    scatter: f64,
}

/// The log-spaced bins of the wavevectors in `window`, the first centred on the smallest;
/// bins without a positive C are left out.
fn log_bins(psd: &Psd, window: (f64, f64)) -> Vec<LogBin> {
    let tol = 1e-9;
    let inside = |q: f64| q >= window.0 * (1.0 - tol) && q <= window.1 * (1.0 + tol);
    let Some(q0) = psd.q.iter().copied().find(|&q| inside(q)) else { return Vec::new() };
    let per_decade = PSD_FIT_BINS_PER_DECADE as f64;
    // Σ m log q, Σ m C, Σ m, independent modes (C(q) and C(−q) of a real surface are one).
    let mut sums: Vec<(f64, f64, f64, f64)> = Vec::new();
    for ((&q, &c), &m) in psd.q.iter().zip(&psd.c).zip(&psd.modes) {
        if !inside(q) {
            continue;
        }
        let b = ((q / q0).log10() * per_decade + 0.5).floor() as usize;
        if b >= sums.len() {
            sums.resize(b + 1, (0.0, 0.0, 0.0, 0.0));
        }
        let m = m as f64;
        sums[b].0 += m * q.log10();
        sums[b].1 += m * c;
        sums[b].2 += m;
        sums[b].3 += (m / 2.0).max(1.0);
    }
    sums.into_iter()
        .filter(|s| s.2 > 0.0 && s.1 > 0.0)
        .map(|s| LogBin {
            x: s.0 / s.2,
            y: (s.1 / s.2).log10(),
            scatter: std::f64::consts::LOG10_E * trigamma(s.3).sqrt(),
        })
        .collect()
}

/// The trigamma function ψ′(m) for m ≥ 1: the variance of the log of a mean of m exponential
/// variables. By recurrence up to 10, then the asymptotic series (error below 1e-10).
fn trigamma(mut m: f64) -> f64 {
    let mut sum = 0.0;
    while m < 10.0 {
        sum += 1.0 / (m * m);
        m += 1.0;
    }
    let m2 = m * m;
    sum + 1.0 / m + 1.0 / (2.0 * m2) + 1.0 / (6.0 * m2 * m) - 1.0 / (30.0 * m2 * m2 * m)
        + 1.0 / (42.0 * m2 * m2 * m2 * m)
}

/// The model of [`fit_psd`] in (log10 q, log10 C): a + s (max(x, x_r) − x_r), `coef` = [a, s].
#[derive(Debug, Clone, Copy)]
struct RollOff {
    x_r: f64,
    coef: [f64; 2],
}

impl RollOff {
    fn at(&self, x: f64) -> f64 {
        self.coef[0] + self.coef[1] * (x.max(self.x_r) - self.x_r)
    }

    /// The least-squares coefficients and the residual sum of squares; `None` when the power
    /// law holds a single abscissa.
    fn fitted(mut self, x: &[f64], y: &[f64]) -> Option<(RollOff, f64)> {
        let n = x.len() as f64;
        let u: Vec<f64> = x.iter().map(|&x| x.max(self.x_r) - self.x_r).collect();
        let (mu, my) = (u.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
        let suu: f64 = u.iter().map(|u| (u - mu).powi(2)).sum();
        if suu <= 0.0 {
            return None;
        }
        let suy: f64 = u.iter().zip(y).map(|(u, y)| (u - mu) * (y - my)).sum();
        let slope = suy / suu;
        self.coef = [my - slope * mu, slope];
        let rss = x.iter().zip(y).map(|(&x, &y)| (y - self.at(x)).powi(2)).sum();
        Some((self, rss))
    }
}

#[cfg(test)]
mod tests {
    use super::super::heights::tests::map;
    use super::super::psd::{profile_psd, psd};
    use super::*;
    use crate::topography::map::Topography;
    use crate::topography::profile::Profile;
    use crate::topography::resample::{crop, CropWindow};
    use crate::topography::synth::{Amplitude, SelfAffine};
    use ndarray::Array2;

    /// The self-affine map of `hurst`, 512² on 10 µm, RMS 10 nm, with a roll-off at λ_r.
    fn rough(hurst: f64, rolloff: Option<f64>, seed: u64) -> Topography {
        let params = SelfAffine {
            hurst,
            rolloff_wavelength: rolloff,
            short_cutoff_wavelength: None,
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(1e-8),
        };
        params.generate((10e-6, 10e-6), (512, 512), seed).unwrap()
    }

    /// `fit_psd` of a map over the window `topo info --psd-fit` takes.
    fn fit_map(t: &Topography, window: Window) -> PsdFit {
        let (lx, ly) = t.physical_size.unwrap();
        let (dx, dy) = t.pixel_size("test").unwrap();
        fit_psd(&psd(t, window).unwrap(), SpectrumOf::Map, psd_fit_window(lx.min(ly), dx.max(dy), window)).unwrap()
    }

    #[test]
    fn the_psd_fit_finds_the_hurst_exponent_and_the_rolloff_of_synthetic_maps() {
        // Random-phase spectra are exact: what is left is the binning at the knee. The tolerances
        // (H ± 0.05, λ_r ± 15 %) are a tenth of H's range and a quarter of a log bin's width.
        for (hurst, rolloff) in [(0.3, 2e-6), (0.8, 2e-6), (0.5, 1e-6)] {
            let f = fit_map(&rough(hurst, Some(rolloff), 7), Window::None);
            let h = f.hurst.unwrap_or_else(|| panic!("{f:?}"));
            let lambda = 2.0 * PI / f.rolloff_q.unwrap_or_else(|| panic!("no roll-off: {f:?}"));
            println!("H {hurst} λ_r {rolloff}: H {h:.3}, λ_r {lambda:.3e}, residual {:.3}", f.rms_residual_log10);
            assert!((h - hurst).abs() < 0.05, "{f:?}");
            assert!((lambda / rolloff - 1.0).abs() < 0.15, "λ_r {lambda} vs {rolloff}");
            assert!(f.rms_residual_log10 < 0.03, "{f:?}");
        }
        // No roll-off: none found, the power law from the window's start.
        let f = fit_map(&rough(0.8, None, 7), Window::None);
        println!("no roll-off: {f:?}");
        assert!(f.rolloff_q.is_none() && (f.hurst.unwrap() - 0.8).abs() < 0.05, "{f:?}");
        // A non-periodic crop under the Hann window, 256² on 5 µm: the roll-off (q_r = 3.1e6 rad/m)
        // lies below the window's start (3 × 2π/5 µm = 3.8e6 rad/m), so none is found.
        let part = crop(&rough(0.8, Some(2e-6), 7), &CropWindow::Pixels { x: 100..356, y: 50..306 }).unwrap();
        let f = fit_map(&part, Window::Hann);
        println!("crop: {f:?}");
        assert!((f.hurst.unwrap() - 0.8).abs() < 0.1 && f.rolloff_q.is_none(), "{f:?}");
    }

    #[test]
    fn the_psd_fit_finds_the_one_dimensional_exponent_of_profiles() {
        // Rows of a map without roll-off: their 1-D spectrum is C ∝ q^−(1+2H).
        let t = rough(0.8, None, 3);
        let dx = 10e-6 / 512.0;
        let spectra: Vec<Psd> = (0..512)
            .step_by(8)
            .map(|j| {
                let p = Profile::new((0..512).map(|i| i as f64 * dx).collect(), t.heights.row(j).to_vec()).unwrap();
                profile_psd(&p, Window::Hann).unwrap()
            })
            .collect();
        let window = psd_fit_window(10e-6, dx, Window::Hann);
        // Averaged over 64 rows the scatter is gone: H within 0.05.
        let mut mean = spectra[0].clone();
        for (k, c) in mean.c.iter_mut().enumerate() {
            *c = spectra.iter().map(|s| s.c[k]).sum::<f64>() / spectra.len() as f64;
        }
        let f = fit_psd(&mean, SpectrumOf::Profile, window).unwrap();
        println!("mean of rows: {f:?}");
        assert!((f.hurst.unwrap() - 0.8).abs() < 0.05, "{f:?}");
        // One row: its single modes scatter by 0.56 decades, and its H by 0.125 over these 64
        // rows (mean 0.75, the roll-off of a single row unresolved): the mean within 0.1.
        let hs: Vec<f64> =
            spectra.iter().filter_map(|s| fit_psd(s, SpectrumOf::Profile, window).unwrap().hurst).collect();
        let m = hs.iter().sum::<f64>() / hs.len() as f64;
        let sd = (hs.iter().map(|h| (h - m).powi(2)).sum::<f64>() / hs.len() as f64).sqrt();
        println!("single rows: {} of {} reported, mean H {m:.3} ± {sd:.3}", hs.len(), spectra.len());
        assert!(hs.len() >= 60 && (m - 0.8).abs() < 0.1 && sd < 0.15, "{hs:?}");
    }

    #[test]
    fn the_psd_fit_refuses_white_noise_and_a_spectrum_that_is_no_power_law() {
        // White noise: C flat, H = −1.
        let mut state = 1u64;
        let mut uniform = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let noise = map(Array2::from_shape_fn((256, 256), |_| 1e-9 * uniform()), (5e-6, 5e-6), true);
        let f = fit_map(&noise, Window::None);
        println!("white noise: {f:?}");
        assert!(f.hurst.is_none() && f.refusal.as_deref().unwrap().contains("outside (0, 1]"), "{f:?}");
        // A self-affine map plus a sine of 0.5 µm five times as strong: a spike a power law cannot follow.
        let mut t = rough(0.8, Some(2e-6), 7);
        let n = t.nx();
        t.heights.indexed_iter_mut().for_each(|((_, i), h)| *h += 5e-8 * (2.0 * PI * 20.0 * i as f64 / n as f64).sin());
        let f = fit_map(&t, Window::None);
        println!("spike: {f:?}");
        assert!(f.hurst.is_none() && f.refusal.as_deref().unwrap().contains("not a power law"), "{f:?}");
    }

    #[test]
    fn trigamma_is_the_variance_of_a_mean_logarithm() {
        assert!((trigamma(1.0) - PI * PI / 6.0).abs() < 1e-8);
        assert!((trigamma(2.0) - (PI * PI / 6.0 - 1.0)).abs() < 1e-8);
        assert!((trigamma(100.0) - 0.010050166663333571).abs() < 1e-10);
    }
}
