//! Synthetic topographies: isotropic self-affine random-phase roughness, sphere or paraboloid
//! caps, and their sum — a stand-in for the paper's silicon ball when no measurement is at hand.
//!
//! Self-affine roughness has the isotropic power spectral density (see [`super::stats`] for
//! the normalisation)
//!
//! ```text
//! C(q) = C0                         q_L ≤ q < q_r   (roll-off plateau)
//! C(q) = C0 (q / q_r)^(−2(1+H))     q_r ≤ q ≤ q_s   (self-affine range)
//! C(q) = 0                          q < q_L or q > q_s
//! ```
//!
//! with q_L = 2π/λ_L, q_r = 2π/λ_r, q_s = 2π/λ_s the long cut-off, roll-off and short cut-off
//! wavevectors; C0 is set so that the surface has the requested RMS height or RMS slope
//! exactly. Every Fourier mode gets amplitude √C(q) and a uniformly random phase (random-phase
//! synthesis), so the realised spectrum is the prescribed one, with no scatter.
//!
//! Reproducibility: phases come from ChaCha20 seeded with the u64 seed, drawn in a fixed order
//! (spectrum order, qx outer, qy inner) as points on the unit circle by rejection from the
//! square, using only exactly rounded IEEE operations (+, ×, ÷, √): the random stream is the
//! same on every machine. The result is bit-identical for the same parameters, seed and build
//! on the same kind of CPU; across CPUs it may differ in the last bits through the FFT's
//! SIMD paths and the amplitudes' `powf`.
//!
//! Must not import `stats` (whose tests measure these surfaces), nor contact, friction, study,
//! report, plot, shs, cli (the layers above topography).

use std::f64::consts::PI;

use ndarray::Array2;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha20Rng;
use rayon::prelude::*;
use rustfft::num_complex::Complex64;
use serde::{Deserialize, Serialize};

use super::map::{Provenance, Topography, MAX_LENGTH_M, MIN_SIZE_M};
use crate::error::{Error, Result};
use crate::fft::Fft2;
use crate::limits::{check_memory, grid_memory, zeroed, Limits, GENERATE_BYTES_PER_POINT};

/// How large the roughness is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Amplitude {
    /// RMS height \[m], about the mean.
    RmsHeight(f64),
    /// RMS slope \[1], as [`super::stats::rms_slope`] measures it (forward differences).
    RmsSlope(f64),
}

/// Isotropic self-affine roughness (see the module doc for the spectrum).
///
/// In a config file (TOML, JSON) it is a table with `hurst`, exactly one of `rms_height_m` and
/// `rms_slope`, and the optional wavelengths `rolloff_wavelength_m`,
/// `short_cutoff_wavelength_m` and `long_cutoff_wavelength_m`; an absent wavelength means none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SelfAffineSpec", into = "SelfAffineSpec")]
pub struct SelfAffine {
    /// Hurst exponent H, 0 < H ≤ 1.
    pub hurst: f64,
    /// Roll-off wavelength λ_r \[m]: the spectrum is flat above it. `None`: no plateau.
    pub rolloff_wavelength: Option<f64>,
    /// Short cut-off wavelength λ_s \[m]: no roughness below it. `None`: down to the pixel.
    pub short_cutoff_wavelength: Option<f64>,
    /// Long cut-off wavelength λ_L \[m], the largest wavelength present. `None`: up to the
    /// window size.
    pub long_cutoff_wavelength: Option<f64>,
    /// Target RMS height or slope.
    pub amplitude: Amplitude,
}

/// [`SelfAffine`] as config files spell it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SelfAffineSpec {
    hurst: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rms_height_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rms_slope: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rolloff_wavelength_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    short_cutoff_wavelength_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    long_cutoff_wavelength_m: Option<f64>,
}

impl TryFrom<SelfAffineSpec> for SelfAffine {
    type Error = String;

    fn try_from(s: SelfAffineSpec) -> std::result::Result<Self, String> {
        let amplitude = match (s.rms_height_m, s.rms_slope) {
            (Some(h), None) => Amplitude::RmsHeight(h),
            (None, Some(g)) => Amplitude::RmsSlope(g),
            _ => return Err("give exactly one of rms_height_m and rms_slope".into()),
        };
        Ok(SelfAffine {
            hurst: s.hurst,
            rolloff_wavelength: s.rolloff_wavelength_m,
            short_cutoff_wavelength: s.short_cutoff_wavelength_m,
            long_cutoff_wavelength: s.long_cutoff_wavelength_m,
            amplitude,
        })
    }
}

impl From<SelfAffine> for SelfAffineSpec {
    fn from(s: SelfAffine) -> Self {
        let (rms_height_m, rms_slope) = match s.amplitude {
            Amplitude::RmsHeight(h) => (Some(h), None),
            Amplitude::RmsSlope(g) => (None, Some(g)),
        };
        SelfAffineSpec {
            hurst: s.hurst,
            rms_height_m,
            rms_slope,
            rolloff_wavelength_m: s.rolloff_wavelength,
            short_cutoff_wavelength_m: s.short_cutoff_wavelength,
            long_cutoff_wavelength_m: s.long_cutoff_wavelength,
        }
    }
}

impl Default for SelfAffine {
    /// [`SelfAffine::silicon_ball`].
    fn default() -> Self {
        SelfAffine::silicon_ball()
    }
}

impl SelfAffine {
    /// A stand-in for the roughness of the paper's silicon balls on their 31.13 µm window:
    /// H = 0.8, roll-off at 7 µm, no roughness below 0.25 µm, 21 nm RMS. On the 1.5 mm-radius
    /// sphere (34 nm RMS over that window by itself) the sum has ≈ 39 nm RMS, as the paper's AFM
    /// scans of the balls (≈ 40 nm, Fig. S3). The paper gives neither H, the roll-off nor the
    /// short cut-off: they are calibrated so that the contact looks like the paper's (Fig. S4) —
    /// at 0.1 mN 30–100 elements in a few patches close together, many patches at 10 mN, local
    /// pressures below silicon's hardness (12 GPa) up to 10 mN; without the short cut-off the
    /// surface is rough down to the pixel (RMS slope ≈ 0.1) and touches in scattered patches
    /// at 15–30 GPa. (docs/results.md gives the default study's numbers.)
    pub fn silicon_ball() -> Self {
        SelfAffine {
            hurst: 0.8,
            rolloff_wavelength: Some(7e-6),
            short_cutoff_wavelength: Some(0.25e-6),
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(21e-9),
        }
    }

    /// A stand-in for the roughness of the paper's silicon wafer: H = 0.8, roll-off at 5 µm,
    /// 0.2 nm RMS down to the pixel.
    pub fn silicon_wafer() -> Self {
        SelfAffine {
            hurst: 0.8,
            rolloff_wavelength: Some(5e-6),
            short_cutoff_wavelength: None,
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(0.2e-9),
        }
    }

    /// Check the parameters; errors name the CLI option.
    pub fn validate(&self) -> Result<()> {
        if !(self.hurst > 0.0 && self.hurst <= 1.0) {
            return Err(Error::invalid("--hurst", format!("must lie in (0, 1], got {}", self.hurst)));
        }
        let positive = |option: &str, v: Option<f64>| match v {
            Some(v) if !(v > 0.0 && v.is_finite()) => {
                Err(Error::invalid(option, format!("must be positive and finite, got {v}")))
            }
            _ => Ok(()),
        };
        positive("--rolloff", self.rolloff_wavelength)?;
        positive("--cutoff", self.short_cutoff_wavelength)?;
        positive("--long-cutoff", self.long_cutoff_wavelength)?;
        let (option, value) = self.amplitude_option();
        positive(option, Some(value))?;
        let order = |short: Option<f64>, long: Option<f64>, what: &str| match (short, long) {
            (Some(s), Some(l)) if s >= l => {
                Err(Error::invalid("--cutoff", format!("{s} m is not below the {what} {l} m")))
            }
            _ => Ok(()),
        };
        order(self.short_cutoff_wavelength, self.rolloff_wavelength, "roll-off wavelength")?;
        order(self.short_cutoff_wavelength, self.long_cutoff_wavelength, "long cut-off wavelength")?;
        if let (Some(r), Some(l)) = (self.rolloff_wavelength, self.long_cutoff_wavelength) {
            if r > l {
                return Err(Error::invalid("--rolloff", format!("{r} m is above the long cut-off wavelength {l} m")));
            }
        }
        Ok(())
    }

    /// The option giving the amplitude, with its value.
    fn amplitude_option(&self) -> (&'static str, f64) {
        match self.amplitude {
            Amplitude::RmsHeight(h) => ("--rms", h),
            Amplitude::RmsSlope(g) => ("--rms-slope", g),
        }
    }

    /// The spectral shape C(q)/C0 at |q| [rad/m].
    fn shape(&self, q: f64, q_min: f64) -> f64 {
        let wavevector = |lambda: Option<f64>| lambda.map(|l| 2.0 * PI / l);
        let q_long = wavevector(self.long_cutoff_wavelength).unwrap_or(0.0);
        let q_short = wavevector(self.short_cutoff_wavelength).unwrap_or(f64::INFINITY);
        let q_roll = wavevector(self.rolloff_wavelength).unwrap_or(q_min);
        // Wavevectors on a cut-off (to round-off) are kept.
        let tol = 1e-9;
        if q == 0.0 || q < q_long * (1.0 - tol) || q > q_short * (1.0 + tol) {
            0.0
        } else if q <= q_roll {
            1.0
        } else {
            (q / q_roll).powf(-2.0 * (1.0 + self.hurst))
        }
    }

    /// A periodic self-affine surface of physical size (lx, ly) \[m] on an (nx, ny) grid,
    /// zero mean, from `seed`.
    pub fn generate(&self, size: (f64, f64), grid: (usize, usize), seed: u64) -> Result<Topography> {
        self.validate()?;
        check_grid(size, grid)?;
        let ((lx, ly), (nx, ny)) = (size, grid);
        let plan = Fft2::new(ny, nx);
        let mut spectrum = plan.make_spectrum();

        let mut rng = ChaCha20Rng::seed_from_u64(seed);
        for c in spectrum.iter_mut() {
            *c = unit_phasor(&mut rng);
        }

        // Amplitudes, and the power and slope power of each qx row over the full plane (the
        // half spectrum stores qx ≥ 0; the interior rows stand for ±qx).
        let q_min = 2.0 * PI / lx.max(ly);
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let self_conjugate = |kx: usize| kx == 0 || (nx % 2 == 0 && kx == nx / 2);
        let sums: Vec<(f64, f64)> = spectrum
            .par_chunks_mut(ny)
            .enumerate()
            .map(|(kx, row)| {
                let weight = if self_conjugate(kx) { 1.0 } else { 2.0 };
                let qx = 2.0 * PI * kx as f64 / lx;
                let dx_gain = (2.0 * (PI * kx as f64 / nx as f64).sin() / dx).powi(2);
                let (mut power, mut slope_power) = (0.0, 0.0);
                for (j, c) in row.iter_mut().enumerate() {
                    let ky = if j <= ny / 2 { j as f64 } else { j as f64 - ny as f64 };
                    let qy = 2.0 * PI * ky / ly;
                    let shape = self.shape(qx.hypot(qy), q_min);
                    *c *= shape.sqrt();
                    let dy_gain = (2.0 * (PI * ky / ny as f64).sin() / dy).powi(2);
                    power += weight * shape;
                    slope_power += weight * shape * (dx_gain + dy_gain);
                }
                if self_conjugate(kx) {
                    make_hermitian(row);
                }
                (power, slope_power)
            })
            .collect();
        let (power, slope_power) = sums.iter().fold((0.0, 0.0), |(p, s), &(a, b)| (p + a, s + b));
        if power == 0.0 {
            return Err(Error::invalid(
                "--cutoff",
                "no wavevector of the grid lies between the long and short cut-offs".to_string(),
            ));
        }
        // The inverse transform is unnormalised, so mean(h²) = Σ|c|² over the full plane.
        let scale = match self.amplitude {
            Amplitude::RmsHeight(h) => h / power.sqrt(),
            Amplitude::RmsSlope(g) => g / slope_power.sqrt(),
        };
        spectrum.par_iter_mut().for_each(|c| *c *= scale);

        let mut heights = zeroed(nx * ny, "the heights").map_err(|r| Error::invalid("--grid", r))?;
        plan.inverse(&mut spectrum, &mut heights, ny, nx, &mut plan.make_work());
        let (option, value) = self.amplitude_option();
        within_half_range(&heights, option, value)?;
        Ok(Topography {
            heights: Array2::from_shape_vec((ny, nx), heights).expect("length is nx·ny"),
            physical_size: Some(size),
            periodic: true,
            height_unit_known: true,
            channel: "self-affine".into(),
            provenance: synthetic(),
        })
    }
}

/// Make a self-conjugate row of the transposed spectrum (qx = 0 or the Nyquist qx) describe
/// a real field: c(−qy) = conj c(qy), and the qy = 0 and Nyquist entries real (keeping their
/// magnitude, with a random sign taken from their phase).
fn make_hermitian(row: &mut [Complex64]) {
    let ny = row.len();
    for j in 1..ny.div_ceil(2) {
        row[ny - j] = row[j].conj();
    }
    let real = |c: Complex64| c.norm().copysign(c.re);
    row[0] = Complex64::new(real(row[0]), 0.0);
    if ny.is_multiple_of(2) {
        row[ny / 2] = Complex64::new(real(row[ny / 2]), 0.0);
    }
}

/// A uniformly distributed point on the unit circle, by rejection from the square [−1, 1)².
fn unit_phasor(rng: &mut ChaCha20Rng) -> Complex64 {
    // 53 random bits → a uniform double in [−1, 1), exactly.
    let uniform = |rng: &mut ChaCha20Rng| (rng.next_u64() >> 11) as f64 * (2.0 / (1u64 << 53) as f64) - 1.0;
    loop {
        let (u, v) = (uniform(rng), uniform(rng));
        let r2 = u * u + v * v;
        if r2 > 0.0 && r2 <= 1.0 {
            let r = r2.sqrt();
            return Complex64::new(u / r, v / r);
        }
    }
}

/// Refuse heights (of the roughness or of the cap) past half the lengths a topography may have
/// ([`Topography::require_representable`]), so that their sum stays within it: parameters
/// far outside any surface (an rms of 1e308 m) would otherwise give infinite or NaN heights.
fn within_half_range(heights: &[f64], option: &str, value: f64) -> Result<()> {
    let half = MAX_LENGTH_M / 2.0;
    match heights.iter().find(|h| h.is_nan() || h.abs() > half) {
        Some(h) => Err(Error::invalid(
            option,
            format!("{value:e} gives heights of {h:e} m, beyond ±{half:e} m: not representable"),
        )),
        None => Ok(()),
    }
}

fn check_grid(size: (f64, f64), grid: (usize, usize)) -> Result<()> {
    let (lx, ly) = size;
    if ![lx, ly].iter().all(|l| (MIN_SIZE_M..=MAX_LENGTH_M).contains(l)) {
        return Err(Error::invalid(
            "--size",
            format!("must lie between {MIN_SIZE_M:e} and {MAX_LENGTH_M:e} m, got {lx},{ly}"),
        ));
    }
    // How many points a caller may ask for is its input policy (`crate::limits`), checked
    // before it asks; here only what no grid can be.
    let (nx, ny) = grid;
    if nx < 2 || ny < 2 || nx.checked_mul(ny).and_then(|n| n.checked_mul(16)).is_none() {
        return Err(Error::invalid(
            "--grid",
            format!("needs at least 2 points per axis and a countable grid, got {nx}×{ny}"),
        ));
    }
    Ok(())
}

fn synthetic() -> Provenance {
    Provenance { file: None, format: "synthetic".into(), height_unit: None }
}

/// The shape of a cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CapShape {
    /// The exact sphere: h = −(R − √(R² − ρ²)).
    Sphere,
    /// Its paraboloid approximation, as in Hertz theory: h = −ρ²/(2R).
    Paraboloid,
}

/// A sphere or paraboloid cap centred on the window, apex (height 0) highest: the contact
/// solver's convention, where higher heights touch first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cap {
    /// Radius of curvature R \[m].
    #[serde(rename = "radius_m")]
    pub radius: f64,
    /// Sphere (default) or paraboloid.
    #[serde(default = "default_shape")]
    pub shape: CapShape,
}

fn default_shape() -> CapShape {
    CapShape::Sphere
}

impl Cap {
    /// Heights \[m] of the cap over a window of physical size (lx, ly) \[m] on an (nx, ny) grid,
    /// apex at (lx/2, ly/2) (a sample when n is even). A sphere must cover the window.
    pub fn heights(&self, size: (f64, f64), grid: (usize, usize)) -> Result<Array2<f64>> {
        check_grid(size, grid)?;
        let ((lx, ly), (nx, ny)) = (size, grid);
        let r = self.radius;
        if !(r > 0.0 && r.is_finite()) {
            return Err(Error::invalid("--sphere-radius", format!("must be positive and finite, got {r}")));
        }
        let half_diagonal = (lx / 2.0).hypot(ly / 2.0);
        if self.shape == CapShape::Sphere && r < half_diagonal {
            return Err(Error::invalid(
                "--sphere-radius",
                format!(
                    "{r} m is smaller than the window's half-diagonal {half_diagonal} m: the sphere does not cover it"
                ),
            ));
        }
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let heights = Array2::from_shape_fn((ny, nx), |(j, i)| {
            let rho2 = (i as f64 * dx - lx / 2.0).powi(2) + (j as f64 * dy - ly / 2.0).powi(2);
            match self.shape {
                // R − √(R² − ρ²) written without cancellation.
                CapShape::Sphere => -rho2 / (r + (r * r - rho2).sqrt()),
                CapShape::Paraboloid => -rho2 / (2.0 * r),
            }
        });
        within_half_range(heights.as_slice().expect("a new array is contiguous"), "--sphere-radius", r)?;
        Ok(heights)
    }
}

/// A synthetic topography: self-affine roughness, a cap, or their sum.
///
/// In a config file: `size_m = [lx, ly]`, `grid = [nx, ny]`, `seed`, and optional tables
/// `roughness` ([`SelfAffine`]) and `cap` ([`Cap`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SyntheticSurface {
    /// Physical size (lx, ly) \[m].
    #[serde(rename = "size_m")]
    pub size: (f64, f64),
    /// Grid (nx, ny) \[points].
    pub grid: (usize, usize),
    /// Roughness, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<SelfAffine>,
    /// Cap, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cap: Option<Cap>,
    /// Seed of the roughness's random phases.
    #[serde(default)]
    pub seed: u64,
}

impl Default for SyntheticSurface {
    /// The paper's silicon ball: a 31.13 µm square window on 1500 × 1500 points (20.75 nm
    /// pixels), [`SelfAffine::silicon_ball`] roughness on a sphere of radius 1.5 mm (the 3 mm
    /// ball), seed 0: ≈ 40 nm RMS over the window.
    fn default() -> Self {
        SyntheticSurface {
            size: (31.13e-6, 31.13e-6),
            grid: (1500, 1500),
            roughness: Some(SelfAffine::silicon_ball()),
            cap: Some(Cap { radius: 1.5e-3, shape: CapShape::Sphere }),
            seed: 0,
        }
    }
}

impl SyntheticSurface {
    /// Generate the surface within the default [`Limits`] (see [`SyntheticSurface::generate_within`]).
    pub fn generate(&self) -> Result<Topography> {
        self.generate_within(&Limits::default())
    }

    /// Generate the surface, its grid no larger than `limits` allow (else an error naming
    /// `--grid`). It is periodic when it is roughness only (a cap does not repeat).
    pub fn generate_within(&self, limits: &Limits) -> Result<Topography> {
        limits.check_grid(self.grid.0, self.grid.1).map_err(|r| Error::invalid("--grid", r))?;
        if self.roughness.is_none() && self.cap.is_none() {
            return Err(Error::invalid("surface", "neither roughness nor a cap: nothing to generate"));
        }
        check_grid(self.size, self.grid)?;
        let (nx, ny) = self.grid;
        check_memory(grid_memory(nx, ny, GENERATE_BYTES_PER_POINT), &format!("generating a {nx} × {ny} surface"))
            .map_err(|r| Error::invalid("--grid", r))?;
        let cap = self.cap.map(|c| c.heights(self.size, self.grid)).transpose()?;
        let mut topo = match &self.roughness {
            Some(r) => r.generate(self.size, self.grid, self.seed)?,
            None => Topography {
                heights: Array2::zeros((self.grid.1, self.grid.0)),
                physical_size: Some(self.size),
                periodic: false,
                height_unit_known: true,
                channel: "cap".into(),
                provenance: synthetic(),
            },
        };
        if let Some(cap) = cap {
            topo.heights += &cap;
            topo.periodic = false;
            if self.roughness.is_some() {
                topo.channel = "self-affine + cap".into();
            }
        }
        Ok(topo)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A self-affine surface of `hurst` and `amplitude` with a roll-off at 2.5 µm and a
    /// cut-off at 0.2 µm.
    pub(crate) fn rough(hurst: f64, amplitude: Amplitude) -> SelfAffine {
        SelfAffine {
            hurst,
            rolloff_wavelength: Some(2.5e-6),
            short_cutoff_wavelength: Some(0.2e-6),
            long_cutoff_wavelength: None,
            amplitude,
        }
    }

    fn bits(t: &Topography) -> Vec<u64> {
        t.heights.iter().map(|h| h.to_bits()).collect()
    }

    #[test]
    fn the_phase_stream_is_pinned_and_uniform() {
        // The first phasors of seed 2025, bit for bit: a change here changes every surface.
        let mut rng = ChaCha20Rng::seed_from_u64(2025);
        let golden = [
            (0x3feeeb7b2a82695a, 0xbfd07ce93f7455f8),
            (0x3fd409538d188ff4, 0x3fee6430cf4018bc),
            (0x3fe379d16ac7f081, 0x3fe9640980778fbf),
        ];
        for (re, im) in golden {
            let c = unit_phasor(&mut rng);
            assert_eq!((c.re.to_bits(), c.im.to_bits()), (re, im));
        }
        // Uniform on the circle: each of 8 sectors holds 1/8 of the draws.
        let n = 80_000;
        let mut sectors = [0usize; 8];
        for _ in 0..n {
            let c = unit_phasor(&mut rng);
            assert!((c.norm() - 1.0).abs() < 1e-15);
            sectors[((c.im.atan2(c.re) + PI) / (PI / 4.0)) as usize % 8] += 1;
        }
        for s in sectors {
            // 5 standard deviations of a binomial count.
            assert!((s as f64 - n as f64 / 8.0).abs() < 5.0 * (n as f64 * 7.0 / 64.0).sqrt(), "{sectors:?}");
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_bits_and_another_seed_another_surface() {
        let r = rough(0.7, Amplitude::RmsHeight(1e-8));
        let a = r.generate((10e-6, 8e-6), (64, 50), 7).unwrap();
        let b = r.generate((10e-6, 8e-6), (64, 50), 7).unwrap();
        assert_eq!(bits(&a), bits(&b));
        let c = r.generate((10e-6, 8e-6), (64, 50), 8).unwrap();
        let diff = (&a.heights - &c.heights).iter().map(|d| d * d).sum::<f64>() / a.heights.len() as f64;
        assert!(diff.sqrt() > 0.5e-8, "seeds 7 and 8 differ by only {} m RMS", diff.sqrt());
        assert!(a.periodic && a.physical_size == Some((10e-6, 8e-6)) && a.heights.dim() == (50, 64));
    }

    #[test]
    fn caps_have_their_apex_highest_at_the_centre() {
        let (l, n, r) = (30e-6, 64, 1e-3);
        let sphere = Cap { radius: r, shape: CapShape::Sphere }.heights((l, l), (n, n)).unwrap();
        let parab = Cap { radius: r, shape: CapShape::Paraboloid }.heights((l, l), (n, n)).unwrap();
        assert_eq!(sphere[(n / 2, n / 2)], 0.0);
        assert!(sphere.iter().all(|&h| h <= 0.0));
        // At the corner (ρ = 15√2 µm) the sphere lies ρ⁴/(8R³) below the paraboloid.
        let rho2: f64 = 2.0 * (15e-6f64).powi(2);
        let gap = parab[(0, 0)] - sphere[(0, 0)];
        assert!((gap / (rho2 * rho2 / (8.0 * r * r * r)) - 1.0).abs() < 1e-3, "gap {gap}");
        assert!((parab[(0, 0)] + rho2 / (2.0 * r)).abs() < 1e-20);
        let err = Cap { radius: 10e-6, shape: CapShape::Sphere }.heights((l, l), (n, n)).unwrap_err();
        assert!(err.to_string().starts_with("--sphere-radius: "), "{err}");
    }

    #[test]
    fn parameters_round_trip_through_toml_and_are_checked() {
        let ball = SyntheticSurface::default();
        let text = toml::to_string(&ball).unwrap();
        assert_eq!(toml::from_str::<SyntheticSurface>(&text).unwrap(), ball);
        let spec = r#"
            size_m = [1e-5, 2e-5]
            grid = [128, 256]
            seed = 4
            [roughness]
            hurst = 0.6
            rms_slope = 0.05
            short_cutoff_wavelength_m = 1e-7
        "#;
        let s: SyntheticSurface = toml::from_str(spec).unwrap();
        let r = s.roughness.unwrap();
        assert_eq!(r.amplitude, Amplitude::RmsSlope(0.05));
        assert_eq!((r.rolloff_wavelength, r.short_cutoff_wavelength), (None, Some(1e-7)));
        assert!(s.cap.is_none() && s.size == (1e-5, 2e-5) && s.grid == (128, 256));
        let both = spec.replace("rms_slope = 0.05", "rms_slope = 0.05\nrms_height_m = 1e-9");
        let err = toml::from_str::<SyntheticSurface>(&both).unwrap_err().to_string();
        assert!(err.contains("exactly one of rms_height_m and rms_slope"), "{err}");
        assert!(toml::from_str::<SyntheticSurface>(&spec.replace("hurst", "hurts")).is_err());
    }

    #[test]
    fn bad_parameters_name_their_option() {
        let cases = [
            (SelfAffine { hurst: 1.2, ..SelfAffine::silicon_ball() }, "--hurst"),
            (SelfAffine { short_cutoff_wavelength: Some(8e-6), ..SelfAffine::silicon_ball() }, "--cutoff"),
            (SelfAffine { long_cutoff_wavelength: Some(1e-6), ..SelfAffine::silicon_ball() }, "--rolloff"),
            (SelfAffine { amplitude: Amplitude::RmsHeight(-1.0), ..SelfAffine::silicon_ball() }, "--rms"),
            (SelfAffine { rolloff_wavelength: Some(f64::NAN), ..SelfAffine::silicon_ball() }, "--rolloff"),
        ];
        for (params, option) in cases {
            let err = params.generate((1e-5, 1e-5), (16, 16), 0).unwrap_err().to_string();
            assert!(err.starts_with(&format!("{option}: ")), "{err}");
        }
        // All wavelengths of a 16-point grid over 10 µm lie above 0.2 µm.
        let none = SelfAffine {
            rolloff_wavelength: None,
            long_cutoff_wavelength: Some(0.2e-6),
            short_cutoff_wavelength: Some(0.1e-6),
            ..SelfAffine::silicon_ball()
        };
        assert!(none.generate((1e-5, 1e-5), (16, 16), 0).unwrap_err().to_string().contains("no wavevector"));
        assert!(SelfAffine::silicon_ball().generate((1e-5, 1e-5), (1, 16), 0).is_err());
    }
}
