//! Statistics of a topography: height moments, RMS slope, isotropic power spectral density; of a
//! line profile: its mean, RMS height, RMS slope and power spectral density, as SurfaceTopography
//! defines them for line scans.
//!
//! PSD normalisation (as Jacobs, Junge & Pastewka, Surf. Topogr.: Metrol. Prop. 5, 013001
//! (2017), and SurfaceTopography): C(q) = |h̃(q)|² / A with h̃(q) = Σ h(x) e^(−iq·x) dx dy the
//! Fourier transform over the window of area A = lx·ly, so C is in m⁴ and
//! `h_rms² = ∫ C(q) d²q / (2π)²`, i.e. `h_rms² = (1/A) Σ_q C(q)` over the discrete wavevectors
//! q = 2π (kx/lx, ky/ly). The isotropic C(q) averages the modes in annuli of width 2π/min(lx, ly).

use std::f64::consts::PI;

use realfft::RealFftPlanner;

use super::missing::refuse_missing;
use super::profile::Profile;
use super::Topography;
use crate::error::Result;
use crate::fft::Fft2;

/// Moments of the defined heights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightStats {
    /// Mean height \[m].
    pub mean: f64,
    /// RMS height about the mean (Rq, Sq) \[m].
    pub rms_height: f64,
    /// Skewness m3/m2^(3/2) \[1]; `NaN` for a flat map.
    pub skewness: f64,
    /// Kurtosis m4/m2² \[1] (3 for Gaussian heights, not the excess); `NaN` for a flat map.
    pub kurtosis: f64,
    /// Number of defined (non-`NaN`) points.
    pub defined: usize,
}

/// Height moments over the defined points (two passes: the mean, then central moments).
pub fn height_stats(topo: &Topography) -> Result<HeightStats> {
    let defined = topo.heights.len() - topo.missing_points();
    if defined == 0 {
        return Err(topo.error("every point is missing: no statistics"));
    }
    let n = defined as f64;
    let mean = topo.heights.iter().filter(|h| !h.is_nan()).sum::<f64>() / n;
    let (mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0);
    for &h in topo.heights.iter().filter(|h| !h.is_nan()) {
        let d = h - mean;
        let d2 = d * d;
        m2 += d2;
        m3 += d2 * d;
        m4 += d2 * d2;
    }
    let (m2, m3, m4) = (m2 / n, m3 / n, m4 / n);
    let (skewness, kurtosis) = if m2 > 0.0 { (m3 / m2.powf(1.5), m4 / (m2 * m2)) } else { (f64::NAN, f64::NAN) };
    Ok(HeightStats { mean, rms_height: m2.sqrt(), skewness, kurtosis, defined })
}

/// RMS slope \[1]: √(⟨(∂h/∂x)²⟩ + ⟨(∂h/∂y)²⟩) with each derivative a forward difference
/// (h(i+1) − h(i))/dx averaged over the pairs of neighbouring defined points; a periodic map
/// includes the pairs across its edges. Needs the physical size.
pub fn rms_slope(topo: &Topography) -> Result<f64> {
    let (dx, dy) = topo.pixel_size("the RMS slope")?;
    let h = &topo.heights;
    let (ny, nx) = h.dim();
    let mean_square = |pairs: &mut dyn Iterator<Item = (f64, f64)>, d: f64| {
        let (mut sum, mut count) = (0.0, 0usize);
        for (a, b) in pairs.filter(|(a, b)| !a.is_nan() && !b.is_nan()) {
            sum += ((b - a) / d).powi(2);
            count += 1;
        }
        (count > 0).then(|| sum / count as f64)
    };
    let wrap = |n: usize| if topo.periodic && n > 1 { n } else { n.saturating_sub(1) };
    let along_x =
        mean_square(&mut (0..ny).flat_map(|j| (0..wrap(nx)).map(move |i| (h[(j, i)], h[(j, (i + 1) % nx)]))), dx);
    let along_y =
        mean_square(&mut (0..wrap(ny)).flat_map(|j| (0..nx).map(move |i| (h[(j, i)], h[((j + 1) % ny, i)]))), dy);
    match (along_x, along_y) {
        (None, None) => Err(topo.error("the RMS slope needs two neighbouring defined points")),
        (x, y) => Ok((x.unwrap_or(0.0) + y.unwrap_or(0.0)).sqrt()),
    }
}

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

/// RMS slopes and curvatures of a map, as SurfaceTopography 1.27 defines them (its default
/// finite differences, "linear" interpolation), with x along a row and y along a column:
///
/// - the first derivatives are forward differences, ∂h/∂x = (h(i+1, j) − h(i, j))/dx and
///   ∂h/∂y = (h(i, j+1) − h(i, j))/dy, taken where both exist (i < nx − 1, j < ny − 1);
/// - the second derivatives are central, ∂²h/∂x² = (h(i+1, j) − 2h(i, j) + h(i−1, j))/dx²
///   and likewise along y, taken where both exist (0 < i < nx − 1, 0 < j < ny − 1);
/// - a periodic map takes every point, its neighbours across the edges.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SlopeCurvature {
    /// RMS gradient √⟨(∂h/∂x)² + (∂h/∂y)²⟩ \[1] (SurfaceTopography's `rms_gradient`).
    pub rms_gradient: f64,
    /// RMS slope along x √⟨(∂h/∂x)²⟩ \[1] (`rms_slope_from_profile`, Rdq).
    pub rms_slope_from_profile: f64,
    /// RMS curvature √⟨(∇²h / 2)²⟩ [1/m], half the Laplacian: the mean curvature
    /// (`rms_curvature_from_area`).
    pub rms_curvature_from_area_per_m: f64,
    /// RMS curvature along x √⟨(∂²h/∂x²)²⟩ [1/m] (`rms_curvature_from_profile`, Rddq).
    pub rms_curvature_from_profile_per_m: f64,
}

/// [`SlopeCurvature`] of a map in metres with a physical size, every point defined and at
/// least 3 × 3 points (2 × 2 when periodic).
pub fn slope_curvature(topo: &Topography) -> Result<SlopeCurvature> {
    let (dx, dy) = topo.pixel_size("the RMS slope and curvature")?;
    refuse_missing(topo)?;
    let h = &topo.heights;
    let (ny, nx) = h.dim();
    let periodic = topo.periodic;
    let least = if periodic { 2 } else { 3 };
    if nx < least || ny < least {
        return Err(
            topo.error(format!("a {ny}×{nx} grid is too small for a curvature: at least {least}×{least} points"))
        );
    }
    // Indices where a stencil reaching `before` points back and `after` forward stays inside.
    let range = |n: usize, before: usize, after: usize| if periodic { 0..n } else { before..n - after };
    let at = |j: usize, i: usize, dj: isize, di: isize| {
        h[((j as isize + dj).rem_euclid(ny as isize) as usize, (i as isize + di).rem_euclid(nx as isize) as usize)]
    };
    let mean = |sum: f64, count: usize| sum / count as f64;
    let (mut gx2, mut gy2, mut count) = (0.0, 0.0, 0usize);
    for j in range(ny, 0, 1) {
        for i in range(nx, 0, 1) {
            let c = h[(j, i)];
            gx2 += ((at(j, i, 0, 1) - c) / dx).powi(2);
            gy2 += ((at(j, i, 1, 0) - c) / dy).powi(2);
            count += 1;
        }
    }
    let (gradient, slope_x) = (mean(gx2 + gy2, count).sqrt(), mean(gx2, count).sqrt());
    let (mut lap2, mut cx2, mut count) = (0.0, 0.0, 0usize);
    for j in range(ny, 1, 1) {
        for i in range(nx, 1, 1) {
            let c = h[(j, i)];
            let cx = (at(j, i, 0, 1) - 2.0 * c + at(j, i, 0, -1)) / (dx * dx);
            let cy = (at(j, i, 1, 0) - 2.0 * c + at(j, i, -1, 0)) / (dy * dy);
            lap2 += (cx + cy).powi(2);
            cx2 += cx * cx;
            count += 1;
        }
    }
    Ok(SlopeCurvature {
        rms_gradient: gradient,
        rms_slope_from_profile: slope_x,
        rms_curvature_from_area_per_m: mean(lap2, count).sqrt() / 2.0,
        rms_curvature_from_profile_per_m: mean(cx2, count).sqrt(),
    })
}

/// RMS curvature (Rddq) of a line profile [1/m, or as stored when the units differ], as
/// SurfaceTopography's `Rddq`: of a uniform profile √⟨((h_i+1 − 2h_i + h_i−1)/dx²)²⟩ over the
/// points whose two neighbours are defined; of a non-uniform one the second derivative
/// h″_i = 2((h_i+1 − h_i)/Δx₊ + (h_i−1 − h_i)/Δx₋)/(Δx₊ + Δx₋) at the inner points,
/// √(∫ h″² dx / (x_n−2 − x_1)) by the trapezoidal rule between them, which needs every point
/// defined.
pub fn profile_rms_curvature(p: &Profile) -> Result<f64> {
    let h = p.heights();
    if let Some(dx) = p.step() {
        let (mut sum, mut count) = (0.0, 0usize);
        for w in h.windows(3).filter(|w| w.iter().all(|h| !h.is_nan())) {
            sum += ((w[2] - 2.0 * w[1] + w[0]) / (dx * dx)).powi(2);
            count += 1;
        }
        if count == 0 {
            return Err(p.error("the RMS curvature needs three neighbouring defined points"));
        }
        return Ok((sum / count as f64).sqrt());
    }
    refuse_missing_nonuniform(p)?;
    let x = p.positions();
    if x.len() < 4 {
        return Err(p.error("the RMS curvature of a non-uniform profile needs at least 4 points"));
    }
    let second: Vec<f64> = x
        .windows(3)
        .zip(h.windows(3))
        .map(|(x, h)| {
            let (plus, minus) = (x[2] - x[1], x[1] - x[0]);
            2.0 * ((h[2] - h[1]) / plus + (h[0] - h[1]) / minus) / (plus + minus)
        })
        .collect();
    let inner = &x[1..x.len() - 1];
    let integral: f64 =
        inner.windows(2).zip(second.windows(2)).map(|(x, c)| (x[1] - x[0]) * (c[0] * c[0] + c[1] * c[1]) / 2.0).sum();
    Ok((integral / (inner[inner.len() - 1] - inner[0])).sqrt())
}

/// The mean and the RMS height about it (Rq) of a line profile [m, or as stored], as
/// SurfaceTopography's `mean` and `Rq`: over the defined points of a uniform profile; over the
/// length of a non-uniform one, the profile linear between its points (so ⟨h⟩ = Σ Δx (h_i +
/// h_i+1) / 2L and ⟨(h − ⟨h⟩)²⟩ = Σ Δx (a_i² + a_i a_i+1 + a_i+1²) / 3L, a = h − ⟨h⟩), which
/// needs every point defined.
pub fn profile_height(p: &Profile) -> Result<(f64, f64)> {
    let h = p.heights();
    if p.step().is_some() {
        let defined = || h.iter().filter(|h| !h.is_nan());
        let n = defined().count();
        if n == 0 {
            return Err(p.error("every point is missing: no statistics"));
        }
        // About the first height: a flat profile's mean is then exact.
        let first = defined().next().copied().unwrap_or(0.0);
        let mean = first + defined().map(|h| h - first).sum::<f64>() / n as f64;
        let var = defined().map(|h| (h - mean).powi(2)).sum::<f64>() / n as f64;
        return Ok((mean, var.sqrt()));
    }
    refuse_missing_nonuniform(p)?;
    let x = p.positions();
    let length = x[x.len() - 1];
    let segments = || x.windows(2).zip(h.windows(2)).map(|(x, h)| (x[1] - x[0], h[0], h[1]));
    let mean = segments().map(|(dx, a, b)| dx * (a + b)).sum::<f64>() / (2.0 * length);
    let var = segments()
        .map(|(dx, a, b)| {
            let (a, b) = (a - mean, b - mean);
            dx * (a * a + a * b + b * b)
        })
        .sum::<f64>()
        / (3.0 * length);
    Ok((mean, var.sqrt()))
}

/// RMS slope (Rdq) of a line profile [1, or as stored when the units differ], as
/// SurfaceTopography's `Rdq`: of a uniform profile √⟨((h_i+1 − h_i)/dx)²⟩ over the pairs of
/// neighbouring defined points; of a non-uniform one √(Σ Δh_i²/Δx_i / L), the profile linear
/// between its points, which needs every point defined.
pub fn profile_rms_slope(p: &Profile) -> Result<f64> {
    let h = p.heights();
    if let Some(dx) = p.step() {
        let (mut sum, mut pairs) = (0.0, 0usize);
        for w in h.windows(2).filter(|w| !w[0].is_nan() && !w[1].is_nan()) {
            sum += ((w[1] - w[0]) / dx).powi(2);
            pairs += 1;
        }
        if pairs == 0 {
            return Err(p.error("the RMS slope needs two neighbouring defined points"));
        }
        return Ok((sum / pairs as f64).sqrt());
    }
    refuse_missing_nonuniform(p)?;
    let x = p.positions();
    let sum: f64 = x.windows(2).zip(h.windows(2)).map(|(x, h)| (h[1] - h[0]).powi(2) / (x[1] - x[0])).sum();
    Ok((sum / x[x.len() - 1]).sqrt())
}

/// SurfaceTopography defines nothing of a non-uniform profile with a missing point (its line
/// between the neighbours would be a guess).
fn refuse_missing_nonuniform(p: &Profile) -> Result<()> {
    match p.missing_points() {
        0 => Ok(()),
        n => Err(p.error(format!(
            "{n} of {} points are missing in a non-uniform profile: no statistics (its line between the \
             neighbours would be a guess)",
            p.points()
        ))),
    }
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
pub(crate) mod tests {
    use super::*;
    use crate::topography::resample::{crop, CropWindow};
    use crate::topography::synth::{Amplitude, SelfAffine};
    use crate::topography::Provenance;
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

    #[test]
    fn slope_and_curvature_of_a_periodic_sine_are_the_finite_differences_closed_forms() {
        // h = a sin(2πi/n) along x: the forward difference has ⟨(Δh/dx)²⟩ = 2 (a/dx)² sin²(π/n),
        // the central second difference ⟨(Δ²h/dx²)²⟩ = 8 (a/dx²)² sin⁴(π/n).
        let (n, a, l) = (16usize, 3e-9, 8e-6);
        let dx = l / n as f64;
        let sine = Array2::from_shape_fn((4, n), |(_, i)| a * (2.0 * PI * i as f64 / n as f64).sin());
        let g = slope_curvature(&map(sine.clone(), (l, l), true)).unwrap();
        let s = (PI / n as f64).sin();
        let slope = (2.0f64).sqrt() * a / dx * s;
        let curvature = (8.0f64).sqrt() * a / (dx * dx) * s * s;
        assert!((g.rms_gradient / slope - 1.0).abs() < 1e-12, "{g:?}");
        assert!((g.rms_slope_from_profile / slope - 1.0).abs() < 1e-12, "{g:?}");
        assert!((g.rms_curvature_from_profile_per_m / curvature - 1.0).abs() < 1e-12, "{g:?}");
        assert!((g.rms_curvature_from_area_per_m / (curvature / 2.0) - 1.0).abs() < 1e-12, "{g:?}");
        // Not periodic, the differences stay inside: a plane has no curvature.
        let plane = Array2::from_shape_fn((5, 6), |(j, i)| 1e-9 * (2.0 * i as f64 + j as f64));
        let g = slope_curvature(&map(plane, (6e-6, 5e-6), false)).unwrap();
        assert!((g.rms_gradient - 1e-3 * 5f64.sqrt()).abs() < 1e-15, "{g:?}");
        assert!(g.rms_curvature_from_area_per_m.abs() < 1e-3, "{g:?}");
    }

    fn map(heights: Array2<f64>, size: (f64, f64), periodic: bool) -> Topography {
        Topography {
            heights,
            physical_size: Some(size),
            periodic,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { format: "test".into(), ..Default::default() },
        }
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
    fn moments_of_a_two_valued_map() {
        // One point in four at 1, the others at 0: mean 1/4, variance 3/16, skewness 2/√3,
        // kurtosis 7/3.
        let t = map(Array2::from_shape_fn((2, 4), |(_, i)| if i == 0 { 1.0 } else { 0.0 }), (1.0, 1.0), false);
        let s = height_stats(&t).unwrap();
        assert_eq!(s.defined, 8);
        assert!((s.mean - 0.25).abs() < 1e-15);
        assert!((s.rms_height - (3.0f64 / 16.0).sqrt()).abs() < 1e-15);
        assert!((s.skewness - 2.0 / 3.0f64.sqrt()).abs() < 1e-14, "{}", s.skewness);
        assert!((s.kurtosis - 7.0 / 3.0).abs() < 1e-14, "{}", s.kurtosis);
    }

    #[test]
    fn rms_slope_of_a_plane_and_of_a_periodic_sine() {
        let (nx, ny, l) = (40, 30, 4e-6);
        let plane =
            Array2::from_shape_fn((ny, nx), |(j, i)| 0.03 * i as f64 * l / nx as f64 - 0.04 * j as f64 * l / ny as f64);
        let g = rms_slope(&map(plane, (l, l), false)).unwrap();
        assert!((g - 0.05).abs() < 1e-14, "{g}");
        // h = a sin(2πi/n): forward differences give a·2 sin(π/n)/dx with RMS over a period /√2.
        let a = 1e-8;
        let sine = Array2::from_shape_fn((ny, nx), |(_, i)| a * (2.0 * PI * i as f64 / nx as f64).sin());
        let g = rms_slope(&map(sine, (l, l), true)).unwrap();
        let expected = a * 2.0 * (PI / nx as f64).sin() / (l / nx as f64) / 2f64.sqrt();
        assert!((g / expected - 1.0).abs() < 1e-12, "{g} vs {expected}");
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
    fn profile_statistics_follow_the_line_between_points() {
        // Non-uniform x = 0, 1, 3 and h = 0, 1, 1: the line's mean 5/6, variance 1/12, mean
        // square slope (1 + 0)/3.
        let p = Profile::new(vec![0.0, 1.0, 3.0], vec![0.0, 1.0, 1.0]).unwrap();
        let (mean, rms) = profile_height(&p).unwrap();
        assert!((mean - 5.0 / 6.0).abs() < 1e-15 && (rms - (1.0f64 / 12.0).sqrt()).abs() < 1e-15, "{mean} {rms}");
        assert!((profile_rms_slope(&p).unwrap() - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
        // Uniform: the points' own moments; the slope over pairs of defined neighbours only.
        let p = Profile::new(vec![0.0, 2.0, 4.0, 6.0, 8.0], vec![1.0, 3.0, f64::NAN, 3.0, 7.0]).unwrap();
        let (mean, rms) = profile_height(&p).unwrap();
        assert!(mean == 3.5 && (rms - 4.75f64.sqrt()).abs() < 1e-15, "{mean} {rms}");
        assert!((profile_rms_slope(&p).unwrap() - 2.5f64.sqrt()).abs() < 1e-15);
        // A non-uniform profile with a missing point has none.
        let p = Profile::new(vec![0.0, 1.0, 3.0], vec![0.0, f64::NAN, 1.0]).unwrap();
        assert!(profile_height(&p).unwrap_err().to_string().contains("1 of 3 points are missing in a non-uniform"));
        assert!(profile_rms_slope(&p).is_err());
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
