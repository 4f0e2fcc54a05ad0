//! Elastic normal contact of a rigid rough surface on an elastic half-space, by the boundary
//! integral method on an FFT grid (the pipeline's second stage).
//!
//! - `material`: elastic materials and the effective modulus;
//! - [`influence`]: the half-space operators u = K p (periodic, free boundary);
//! - [`options`]: what every solve shares: settings, checks, iteration count, report, and the
//!   interface of a normal-solve backend;
//! - [`solver`]: the Polonsky–Keer constrained conjugate gradient at imposed load, on the CPU
//!   (`cpu`) or (`gpu` feature) on an NVIDIA GPU (`gpu`);
//! - [`adhesion`]: adhesive normal contact (Maugis–Dugdale or exponential cohesive zone) at
//!   imposed load or separation, and the pull-off force;
//! - [`patches`]: contact patches (4-connected clusters);
//! - [`tangential`]: shear tractions on a fixed contact set under a tangential displacement,
//!   with Coulomb bounds (the sliding onset's elastic solve);
//! - here: the contact state, the distribution of local pressure, and the memory of a normal
//!   and a tangential solve together.
//!
//! Inside `contact` imports go one way (`python3 tools/file-imports.py src/contact`): `influence`
//! imports `material`; `options` imports `influence`; `cpu`, `gpu`, `adhesion` and `tangential`
//! import `options`; `solver` imports `cpu` and `gpu`; no file imports this one, and `patches`
//! and `material` import nothing of `contact`. Imports topography; must not import friction,
//! study, report, plot, shs, cli.

pub mod adhesion;
mod cpu;
#[cfg(feature = "gpu")]
mod gpu;
pub mod influence;
mod material;
pub mod options;
pub mod patches;
pub mod solver;
pub mod tangential;

pub use adhesion::{AdhesiveReport, AdhesiveSolver, CohesiveLaw, PullOff};
pub use influence::{Boundary, Influence, ShearCompliance, TangentialInfluence};
pub use material::{combined_modulus, Material};
pub use options::{check_load, check_solve_memory, Convergence, Device, Proceed, SolveReport, SolverOptions};
pub use solver::ContactSolver;
pub use tangential::{TangentialOptions, TangentialReport, TangentialSolver};

use crate::error::{Error, Result};
use crate::limits::check_memory;
use crate::topography::Topography;

/// Whether a contact solve and a tangential solve on its contact (a sliding onset, a stuck
/// contact's stiffness) on an ny × nx surface fit in the memory available together: checked
/// before the normal solve, so that a refusal comes before its work.
pub fn check_solves_memory((ny, nx): (usize, usize), boundary: Boundary) -> std::result::Result<(), String> {
    let bytes = options::solve_memory((ny, nx), boundary).saturating_add(tangential::solve_memory((ny, nx), boundary));
    check_memory(bytes, &format!("a contact solve and a tangential solve on {nx} × {ny} points"))
}

/// Every load \[N] positive and finite: checked before any long work.
pub fn check_loads(loads: &[f64]) -> Result<()> {
    match loads.iter().find(|l| !(**l > 0.0 && l.is_finite())) {
        Some(load) => Err(Error::invalid("--load", format!("loads must be positive and finite, got {load} N"))),
        None => Ok(()),
    }
}

/// The physical size (lx, ly) \[m] of a surface the contact solver can take: heights known to
/// be metres, no missing heights, at least 2×2 points, a known size and heights spanning less
/// than the window is wide; otherwise a one-line reason naming its file.
pub fn contact_size(surface: &Topography) -> Result<(f64, f64)> {
    surface.require_metres()?;
    let bad = surface.heights.iter().filter(|h| !h.is_finite()).count();
    if bad > 0 {
        return Err(surface.error(format!(
            "{bad} heights are missing, NaN or infinite: fill them (asperity topo convert --fill-missing) or crop them away"
        )));
    }
    if surface.nx() < 2 || surface.ny() < 2 {
        return Err(surface.error(format!(
            "a {}×{} grid is too small for contact: at least 2×2 points",
            surface.ny(),
            surface.nx()
        )));
    }
    let size = surface
        .physical_size
        .ok_or_else(|| surface.error("the file states no physical size: give it with --size LX[,LY] (metres)"))?;
    surface.require_plausible_heights()?;
    Ok(size)
}

/// The width of the band along a window's edges, as a fraction of its points along each axis
/// (at least [`EDGE_BAND_MIN_POINTS`]): load carried there is cut by the window.
pub const EDGE_BAND_FRACTION: f64 = 0.02;

/// The narrowest edge band \[points].
pub const EDGE_BAND_MIN_POINTS: usize = 2;

/// Above this fraction of the load in the edge band a solve is warned about: its contact is
/// cut by the window (a periodic solve wraps it into the opposite edge).
pub const EDGE_LOAD_LIMIT: f64 = 0.01;

/// Summary of a contact state, from its pressure map.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ContactSummary {
    /// Pixels with p > 0.
    pub contact_points: usize,
    /// Fraction of the window in contact.
    pub contact_fraction: f64,
    /// Real contact area \[m²].
    pub contact_area: f64,
    /// Sizes of the contact patches in pixels, largest first (wrapping across the edges only
    /// when the boundary is periodic).
    pub patch_sizes: Vec<usize>,
    /// Largest local pressure \[Pa].
    pub max_pressure: f64,
    /// Fraction of the load carried by points in the edge band ([`edge_band`]).
    pub edge_load_fraction: f64,
    /// Fraction of the load carried by points where p ≥ the hardness, when one is given.
    pub load_above_hardness_fraction: Option<f64>,
}

/// Width \[points] of the edge band of an axis of `n` points: 2 % of them, at least 2.
pub fn edge_band(n: usize) -> usize {
    ((EDGE_BAND_FRACTION * n as f64).round() as usize).max(EDGE_BAND_MIN_POINTS)
}

/// Contact points, area, patches and the plausibility figures of the pressure map `pressure`
/// \[Pa] (row-major, `shape`) on a window of physical size `size` \[m]; `hardness` \[Pa] is the
/// material's, if known (it states a limit, it does not change the elastic solution).
pub fn summarize(
    pressure: &[f64],
    shape: (usize, usize),
    size: (f64, f64),
    boundary: Boundary,
    hardness: Option<f64>,
) -> ContactSummary {
    let mask: Vec<bool> = pressure.iter().map(|p| *p > 0.0).collect();
    let contact_points = mask.iter().filter(|m| **m).count();
    let (_, mut patch_sizes) = patches::label(&mask, shape, boundary == Boundary::Periodic);
    patch_sizes.sort_unstable_by(|a, b| b.cmp(a));
    let fraction = contact_points as f64 / pressure.len() as f64;
    let (ny, nx) = shape;
    let (bx, by) = (edge_band(nx), edge_band(ny));
    let (mut total, mut edge, mut above) = (0.0, 0.0, 0.0);
    let mut max_pressure = 0.0f64;
    for (k, &p) in pressure.iter().enumerate().filter(|(_, p)| **p > 0.0) {
        let (j, i) = (k / nx, k % nx);
        total += p;
        max_pressure = max_pressure.max(p);
        if i < bx || i + bx >= nx || j < by || j + by >= ny {
            edge += p;
        }
        if hardness.is_some_and(|h| p >= h) {
            above += p;
        }
    }
    let share = |part: f64| if total > 0.0 { part / total } else { 0.0 };
    ContactSummary {
        contact_points,
        contact_fraction: fraction,
        contact_area: fraction * size.0 * size.1,
        patch_sizes,
        max_pressure,
        edge_load_fraction: share(edge),
        load_above_hardness_fraction: hardness.map(|_| share(above)),
    }
}

impl ContactSummary {
    /// What a physicist must be told about this solve, one line each: load cut by the window
    /// (more than [`EDGE_LOAD_LIMIT`] of it in the edge band), or carried above the hardness.
    /// `remedies` are the ways left to keep the contact inside the window, as the caller's
    /// language writes them (`a free boundary (--free)`, `boundary = "free"`).
    pub fn warnings(&self, remedies: &[String]) -> Vec<String> {
        plausibility_warnings(self.edge_load_fraction, self.load_above_hardness_fraction, self.max_pressure, remedies)
    }
}

/// The largest cohesive tension at a free window's edge, as a fraction of the law's strength
/// ([`AdhesiveSolver::edge_tension`]), above which it is warned about.
pub const EDGE_TENSION_LIMIT: f64 = 0.01;

/// The warning for a cohesive tension `fraction` of the law's strength at the window's edge
/// ([`AdhesiveSolver::edge_tension`]), if above [`EDGE_TENSION_LIMIT`].
pub fn edge_tension_warning(fraction: f64) -> Option<String> {
    (fraction > EDGE_TENSION_LIMIT).then(|| {
        format!(
            "the cohesive tension at the window's edge reaches {:.0} % of the law's strength: the cohesive zone \
             is cut by the window and the adhesive force and pull-off come out too small; enlarge the window",
            100.0 * fraction
        )
    })
}

/// The warnings of [`ContactSummary::warnings`] from its figures.
pub fn plausibility_warnings(
    edge_load_fraction: f64,
    load_above_hardness_fraction: Option<f64>,
    max_pressure: f64,
    remedies: &[String],
) -> Vec<String> {
    let mut warnings = Vec::new();
    if edge_load_fraction > EDGE_LOAD_LIMIT {
        let remedy = match remedies {
            [] => String::new(),
            [one] => format!("; try {one}"),
            [first @ .., last] => format!("; try {} or {last}", first.join(", ")),
        };
        warnings.push(format!(
            "{:.1} % of the load sits within 2 % of the window's edges: the contact is cut by the window \
             (periodic images or a missing part){remedy}",
            100.0 * edge_load_fraction
        ));
    }
    if let Some(f) = load_above_hardness_fraction.filter(|&f| f > 0.0) {
        warnings.push(format!(
            "{:.2} % of the load is carried at pressures at or above the material's hardness (largest \
             {:.3e} Pa): outside the mainly elastic regime of the model",
            100.0 * f,
            max_pressure
        ));
    }
    warnings
}

/// The load \[N] from which a periodic window of `heights` \[m] (shape (ny, nx), row-major) over
/// `size` (Lx, Ly) \[m] touches everywhere on a half-space of modulus `e_star` \[Pa]: the pressure
/// that flattens the surface, p̄ + (E*/2)·F⁻¹[|q| ĥ(q)], is then nowhere negative. For a
/// sinusoid of amplitude Δ and wavelength λ it is Westergaard's p* = π E* Δ / λ times the area.
/// Known before any solve, so that what needs a partial contact can refuse such a load first.
pub fn full_contact_load(heights: &[f64], (ny, nx): (usize, usize), (lx, ly): (f64, f64), e_star: f64) -> f64 {
    use std::f64::consts::PI;
    let plan = crate::fft::Fft2::<f64>::new(ny, nx);
    let mut work = plan.make_work();
    let mut spectrum = plan.make_spectrum();
    plan.forward(heights, ny, nx, &mut spectrum, &mut work);
    // The inverse is unnormalised: 1/(nx·ny) with the operator's E*/2 |q|.
    let scale = 0.5 * e_star / (nx * ny) as f64;
    for (c, (kx, ky)) in spectrum.iter_mut().zip(plan.wavevectors()) {
        let q = (2.0 * PI * kx as f64 / lx).hypot(2.0 * PI * ky as f64 / ly);
        *c *= q * scale;
    }
    let mut flattening = vec![0.0; nx * ny];
    plan.inverse(&mut spectrum, &mut flattening, ny, nx, &mut work);
    let lowest = flattening.iter().copied().fold(f64::INFINITY, f64::min);
    (-lowest).max(0.0) * lx * ly
}

/// Probability density p(σ) of the local normal stress σ over the contact points: `bins`
/// equal bins from 0 to the largest pressure. Returns (bin centre \[Pa], density [1/Pa]).
pub fn pressure_density(pressure: &[f64], bins: usize) -> Vec<(f64, f64)> {
    let contact: Vec<f64> = pressure.iter().copied().filter(|p| *p > 0.0).collect();
    let max = contact.iter().copied().fold(0.0, f64::max);
    if contact.is_empty() || bins == 0 {
        return Vec::new();
    }
    let width = max / bins as f64;
    let mut counts = vec![0usize; bins];
    for p in &contact {
        counts[((p / width) as usize).min(bins - 1)] += 1;
    }
    let norm = 1.0 / (contact.len() as f64 * width);
    counts.iter().enumerate().map(|(i, c)| ((i as f64 + 0.5) * width, *c as f64 * norm)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moduli() {
        let si = Material::SILICON;
        assert!((si.plane_strain_modulus() - 130e9 / (1.0 - 0.26 * 0.26)).abs() < 1.0);
        // Two equal bodies: half the plane-strain modulus.
        assert!((combined_modulus(&si, &si) - si.plane_strain_modulus() / 2.0).abs() < 1.0);
        assert!(Material::new(1e9, 0.5, "--poisson").is_err());
        assert!(Material::new(-1e9, 0.3, "--youngs").is_err());
    }

    #[test]
    fn edge_load_and_hardness_shares() {
        // 100 × 50 points: bands of 2 columns and 2 rows (2 % of 100 is 2; of 50, 1 → 2).
        let (ny, nx) = (50, 100);
        let mut p = vec![0.0; nx * ny];
        p[25 * nx + 50] = 3.0; // centre
        p[25 * nx + 1] = 1.0; // column 1: in the band
        p[48 * nx + 50] = 4.0; // row 48: in the band (ny − 2)
        p[47 * nx + 2] = 2.0; // row 47, column 2: outside both
        let s = summarize(&p, (ny, nx), (1.0, 0.5), Boundary::Free, Some(3.0));
        assert_eq!((edge_band(100), edge_band(50), edge_band(1000)), (2, 2, 20));
        assert!((s.edge_load_fraction - 5.0 / 10.0).abs() < 1e-15);
        assert_eq!(s.load_above_hardness_fraction, Some(7.0 / 10.0));
        assert_eq!(s.max_pressure, 4.0);
        let w = s.warnings(&["a crop".into(), "a cap".into()]);
        assert_eq!(w.len(), 2);
        assert!(
            w[0].starts_with("50.0 % of the load sits within 2 %") && w[0].ends_with("; try a crop or a cap"),
            "{}",
            w[0]
        );
        assert!(w[1].starts_with("70.00 % of the load is carried at pressures at or above"), "{}", w[1]);
        let w = summarize(&p, (ny, nx), (1.0, 0.5), Boundary::Free, None).warnings(&[]);
        assert!(w.len() == 1 && w[0].ends_with("(periodic images or a missing part)"), "{w:?}");
    }

    #[test]
    fn free_boundary_patches_never_wrap() {
        // Two pixels on opposite edges of a row, and two on opposite edges of a column.
        let (ny, nx) = (4, 5);
        let mut p = vec![0.0; nx * ny];
        p[nx] = 1.0;
        p[2 * nx - 1] = 1.0;
        p[2] = 1.0;
        p[3 * nx + 2] = 1.0;
        let free = summarize(&p, (ny, nx), (1.0, 1.0), Boundary::Free, None);
        assert_eq!(free.patch_sizes, vec![1, 1, 1, 1]);
        let periodic = summarize(&p, (ny, nx), (1.0, 1.0), Boundary::Periodic, None);
        assert_eq!(periodic.patch_sizes, vec![2, 2]);
    }

    #[test]
    fn density_integrates_to_one() {
        let p: Vec<f64> = (0..1000).map(|i| if i % 3 == 0 { 0.0 } else { (i as f64).sqrt() }).collect();
        let d = pressure_density(&p, 17);
        let width = d[1].0 - d[0].0;
        let total: f64 = d.iter().map(|(_, v)| v * width).sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
}
