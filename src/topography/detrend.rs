//! Levelling: least-squares polynomial detrending, the sphere fit of a ball's apex, and the
//! levelling of each scan line on its own (AFM lines carry offsets and tilts of their own).
//!
//! Fits run over the defined points only (missing points are skipped and stay missing).
//! Sums are taken in fixed blocks of rows and added in order, so results do not depend on
//! the number of threads.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::str::FromStr;

use ndarray::{ArrayView2, Axis};
use rayon::prelude::*;

use super::map::Topography;
use super::profile::Profile;
use crate::error::{Error, Result};

/// Highest polynomial degree [`Detrend::Polynomial`] accepts.
pub const MAX_DEGREE: usize = 8;

/// Highest degree of the polynomial fitted to each scan line ([`LineFit::Polynomial`]).
pub const MAX_LINE_DEGREE: usize = 3;

/// How to level a topography.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Detrend {
    /// Leave the heights as they are.
    None,
    /// Subtract the least-squares polynomial of this total degree in x and y
    /// (0: the mean, 1: a plane).
    Polynomial(usize),
    /// Subtract the least-squares sphere ([`fit_sphere`]): a ball's curvature, leaving its
    /// roughness.
    Sphere,
    /// Level each scan line (a row, along the fast axis x) on its own, then the whole map.
    Lines(LineFit, WholeMap),
}

/// How each scan line is levelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineFit {
    /// Subtract the line's least-squares polynomial of this degree in x (≤ [`MAX_LINE_DEGREE`]).
    Polynomial(usize),
    /// Shift the line by its median (Gwyddion's median alignment of rows).
    Median,
}

/// The whole-map step after line levelling: one of [`Detrend`]'s own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WholeMap {
    /// None: the lines levelled only.
    None,
    /// [`Detrend::Polynomial`].
    Polynomial(usize),
    /// [`Detrend::Sphere`].
    Sphere,
}

impl From<WholeMap> for Detrend {
    fn from(w: WholeMap) -> Detrend {
        match w {
            WholeMap::None => Detrend::None,
            WholeMap::Polynomial(n) => Detrend::Polynomial(n),
            WholeMap::Sphere => Detrend::Sphere,
        }
    }
}

impl FromStr for Detrend {
    type Err = String;

    /// `none`, `mean`, `plane`, `poly:N` or `sphere`; or `line:N` (N ≤ 3) or `line:median`,
    /// alone or followed by a whole-map step: `line:1,plane`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || {
            format!(
                "'{s}' is not none, mean, plane, poly:N (N ≤ {MAX_DEGREE}), sphere, line:N (N ≤ {MAX_LINE_DEGREE}) or \
                 line:median, nor line:… followed by a whole-map step (line:1,plane)"
            )
        };
        if let Some(rest) = s.strip_prefix("line:") {
            let (line, whole) = rest.split_once(',').unwrap_or((rest, "none"));
            let fit = match line {
                "median" => LineFit::Median,
                n => match n.parse::<usize>() {
                    Ok(n) if n <= MAX_LINE_DEGREE => LineFit::Polynomial(n),
                    _ => return Err(bad()),
                },
            };
            let whole = match whole.parse::<Detrend>().map_err(|_| bad())? {
                Detrend::None => WholeMap::None,
                Detrend::Polynomial(n) => WholeMap::Polynomial(n),
                Detrend::Sphere => WholeMap::Sphere,
                Detrend::Lines(..) => return Err(bad()),
            };
            return Ok(Detrend::Lines(fit, whole));
        }
        match s {
            "none" => Ok(Detrend::None),
            "mean" => Ok(Detrend::Polynomial(0)),
            "plane" => Ok(Detrend::Polynomial(1)),
            "sphere" => Ok(Detrend::Sphere),
            _ => {
                let n: usize = s.strip_prefix("poly:").ok_or_else(bad)?.parse().map_err(|_| bad())?;
                if n > MAX_DEGREE {
                    return Err(bad());
                }
                Ok(Detrend::Polynomial(n))
            }
        }
    }
}

impl Detrend {
    /// Level `topo` in place. Returns the fitted sphere for [`Detrend::Sphere`].
    pub fn apply(self, topo: &mut Topography) -> Result<Option<SphereFit>> {
        match self {
            Detrend::None => Ok(None),
            Detrend::Polynomial(degree) => subtract_polynomial(topo, degree).map(|()| None),
            Detrend::Sphere => {
                let fit = fit_sphere(topo)?;
                let (dx, dy) = topo.pixel_size("the sphere fit")?;
                for ((j, i), h) in topo.heights.indexed_iter_mut() {
                    *h -= fit.height(i as f64 * dx, j as f64 * dy);
                }
                Ok(Some(fit))
            }
            Detrend::Lines(fit, whole) => {
                level_lines(topo, fit)?;
                Detrend::from(whole).apply(topo)
            }
        }
    }
}

impl Detrend {
    /// Level the line profile `p` in place, over its defined points: `mean`, `plane` and
    /// `poly:N` subtract its least-squares polynomial of degree N in x (0, 1 and N; a profile's
    /// plane is its straight line), `line:N` the same (a profile is one scan line),
    /// `line:median` its median. `sphere` and a whole-map step after `line:` are a map's.
    pub fn apply_to_profile(self, p: &mut Profile) -> Result<()> {
        let degree = match self {
            Detrend::None => return Ok(()),
            Detrend::Polynomial(n) | Detrend::Lines(LineFit::Polynomial(n), WholeMap::None) => n,
            Detrend::Lines(LineFit::Median, WholeMap::None) => {
                let mut v: Vec<f64> = p.heights().iter().copied().filter(|h| !h.is_nan()).collect();
                v.sort_by(f64::total_cmp);
                let m = v.len() / 2;
                let median = match v.len() {
                    0 => return Err(p.error("no defined point to take the median of")),
                    n if n % 2 == 1 => v[m],
                    _ => 0.5 * (v[m - 1] + v[m]),
                };
                p.heights_mut().iter_mut().for_each(|h| *h -= median);
                return Ok(());
            }
            Detrend::Sphere | Detrend::Lines(..) => {
                return Err(Error::invalid(
                    "--detrend",
                    format!(
                        "{}: a line profile is levelled by mean, plane, poly:N (N ≤ {MAX_DEGREE}), line:N or \
                         line:median; a sphere and a whole-map step are a 2-D map's",
                        p.provenance.file.as_deref().map_or("the profile".into(), |f| f.display().to_string())
                    ),
                ))
            }
        };
        if degree > MAX_DEGREE {
            return Err(Error::invalid("--detrend", format!("degree {degree} is above the maximum {MAX_DEGREE}")));
        }
        // Legendre polynomials in the positions mapped to [−1, 1]: well conditioned on any grid.
        let end = p.positions()[p.points() - 1];
        let u: Vec<f64> = p.positions().iter().map(|x| 2.0 * x / end - 1.0).collect();
        let basis = |u: f64, phi: &mut [f64]| {
            phi[0] = 1.0;
            if phi.len() > 1 {
                phi[1] = u;
            }
            for k in 1..phi.len().saturating_sub(1) {
                phi[k + 1] = ((2 * k + 1) as f64 * u * phi[k] - k as f64 * phi[k - 1]) / (k + 1) as f64;
            }
        };
        let terms = degree + 1;
        let mut ne = NormalEquations { gram: vec![0.0; terms * terms], rhs: vec![0.0; terms], ssr: 0.0, count: 0 };
        let mut phi = vec![0.0; terms];
        for (&u, &z) in u.iter().zip(p.heights()).filter(|(_, z)| !z.is_nan()) {
            basis(u, &mut phi);
            for k in 0..terms {
                ne.rhs[k] += phi[k] * z;
                for m in 0..terms {
                    ne.gram[k * terms + m] += phi[k] * phi[m];
                }
            }
            ne.count += 1;
        }
        let coef = ne.solve().ok_or_else(|| {
            p.error(format!(
                "too few defined points ({}) to fit a polynomial of degree {degree} along the profile",
                ne.count
            ))
        })?;
        for (&u, h) in u.iter().zip(p.heights_mut()) {
            basis(u, &mut phi);
            *h -= phi.iter().zip(&coef).map(|(f, c)| f * c).sum::<f64>();
        }
        Ok(())
    }
}

/// Level each row of `topo` (a scan line along x) by `fit`, over its defined points; a line with
/// too few of them for the fit is refused (never filled or left as it was).
pub fn level_lines(topo: &mut Topography, fit: LineFit) -> Result<()> {
    let nx = topo.nx();
    let (degree, needed) = match fit {
        LineFit::Polynomial(n) if n > MAX_LINE_DEGREE => {
            return Err(Error::invalid("--detrend", format!("line degree {n} is above the maximum {MAX_LINE_DEGREE}")))
        }
        LineFit::Polynomial(n) => (n, n + 1),
        LineFit::Median => (0, 1),
    };
    let px = legendre_table(nx, degree);
    let short = topo.heights.outer_iter().enumerate().find_map(|(j, line)| {
        let defined = line.iter().filter(|h| !h.is_nan()).count();
        (defined < needed).then_some((j, defined))
    });
    if let Some((j, defined)) = short {
        let what = match fit {
            LineFit::Polynomial(n) => format!("a polynomial of degree {n} along x ({needed} points)"),
            LineFit::Median => "its median".to_string(),
        };
        return Err(topo.error(format!(
            "scan line {j} (row {j} of {}) has {defined} defined points, too few to fit {what}: level it with a \
             whole-map mode, or crop it away",
            topo.ny()
        )));
    }
    let singular = topo.heights.axis_iter_mut(Axis(0)).into_par_iter().enumerate().try_for_each(|(j, mut line)| {
        let shift: Vec<f64> = match fit {
            LineFit::Median => {
                let mut v: Vec<f64> = line.iter().copied().filter(|h| !h.is_nan()).collect();
                v.sort_by(f64::total_cmp);
                let m = v.len() / 2;
                let median = if v.len() % 2 == 1 { v[m] } else { 0.5 * (v[m - 1] + v[m]) };
                vec![median; nx]
            }
            LineFit::Polynomial(_) => {
                let p = degree + 1;
                let mut ne = NormalEquations { gram: vec![0.0; p * p], rhs: vec![0.0; p], ssr: 0.0, count: 0 };
                for (i, &z) in line.iter().enumerate().filter(|(_, z)| !z.is_nan()) {
                    for k in 0..p {
                        ne.rhs[k] += px[k][i] * z;
                        for m in 0..p {
                            ne.gram[k * p + m] += px[k][i] * px[m][i];
                        }
                    }
                }
                let coef = ne.solve().ok_or(j)?;
                (0..nx).map(|i| (0..p).map(|k| coef[k] * px[k][i]).sum()).collect()
            }
        };
        line.iter_mut().zip(&shift).for_each(|(h, s)| *h -= s);
        Ok::<(), usize>(())
    });
    singular.map_err(|j| {
        topo.error(format!(
            "scan line {j}: its defined points are too close together to fit a polynomial of degree {degree} along x"
        ))
    })
}

/// Subtract from `topo` its least-squares polynomial of total degree `degree` in (x, y).
///
/// The basis is products of Legendre polynomials in the pixel indices mapped to [−1, 1], which
/// keeps the normal equations well conditioned; the fitted surface is the same in any basis.
pub fn subtract_polynomial(topo: &mut Topography, degree: usize) -> Result<()> {
    if degree > MAX_DEGREE {
        return Err(Error::invalid("--detrend", format!("degree {degree} is above the maximum {MAX_DEGREE}")));
    }
    let px = legendre_table(topo.nx(), degree);
    let py = legendre_table(topo.ny(), degree);
    let terms: Vec<(usize, usize)> = (0..=degree).flat_map(|d| (0..=d).map(move |b| (d - b, b))).collect();
    let basis = |i: usize, j: usize, phi: &mut [f64]| {
        for (p, &(a, b)) in phi.iter_mut().zip(&terms) {
            *p = px[a][i] * py[b][j];
        }
    };
    let ne = normal_equations(topo.heights.view(), terms.len(), |i, j, z, phi| {
        basis(i, j, phi);
        Some(z)
    })
    .expect("the polynomial is defined everywhere");
    let coef = ne.solve().ok_or_else(|| {
        topo.error(format!(
            "too few defined points ({}) to fit a polynomial of degree {degree} ({} terms)",
            ne.count,
            terms.len()
        ))
    })?;
    let mut phi = vec![0.0; terms.len()];
    for ((j, i), h) in topo.heights.indexed_iter_mut() {
        basis(i, j, &mut phi);
        *h -= phi.iter().zip(&coef).map(|(p, c)| p * c).sum::<f64>();
    }
    Ok(())
}

/// Legendre polynomials P_0…P_degree at the `n` points of [−1, 1]: `table[a][i]`.
fn legendre_table(n: usize, degree: usize) -> Vec<Vec<f64>> {
    let u: Vec<f64> = (0..n).map(|i| if n > 1 { 2.0 * i as f64 / (n - 1) as f64 - 1.0 } else { 0.0 }).collect();
    let mut table = vec![vec![1.0; n], u.clone()];
    for k in 1..degree {
        let next = (0..n)
            .map(|i| ((2 * k + 1) as f64 * u[i] * table[k][i] - k as f64 * table[k - 1][i]) / (k + 1) as f64)
            .collect();
        table.push(next);
    }
    table.truncate(degree + 1);
    table
}

/// A sphere fitted to a topography by least squares on the heights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereFit {
    /// Radius of curvature \[m]: positive when the apex is the highest point (a ball, the
    /// contact solver's convention), negative for a bowl.
    pub radius: f64,
    /// Apex position (x, y) \[m] in the map's coordinates (sample (row j, column i) at (i·dx, j·dy)).
    pub apex: (f64, f64),
    /// Height of the apex \[m].
    pub apex_height: f64,
    /// RMS height of the residual about the sphere \[m].
    pub rms_residual: f64,
}

impl SphereFit {
    /// Height of the sphere at (x, y) \[m]: the exact cap, `NaN` beyond its rim.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let rho2 = (x - self.apex.0).powi(2) + (y - self.apex.1).powi(2);
        self.apex_height - sag(1.0 / self.radius, rho2)
    }
}

/// Sag of a sphere of curvature `k` at squared distance `rho2` from the apex, in the form
/// that stays accurate for tiny curvature: k·ρ²/(1 + √(1 − k²ρ²)).
fn sag(k: f64, rho2: f64) -> f64 {
    k * rho2 / (1.0 + (1.0 - k * k * rho2).sqrt())
}

/// Fit a sphere (apex position, apex height, radius) to `topo` by least squares on the
/// heights: a paraboloid fit gives the start, Gauss–Newton on the exact cap refines it.
/// Needs the physical size; fails when the surface has no sphere-like curvature.
pub fn fit_sphere(topo: &Topography) -> Result<SphereFit> {
    let (dx, dy) = topo.pixel_size("the sphere fit")?;
    let (lx, ly) = topo.physical_size.expect("checked by pixel_size");
    // Dimensionless coordinates: centred on the window, lengths (heights too) in units of L.
    let l = lx.max(ly);
    let defined: Vec<f64> = topo.heights.iter().copied().filter(|h| !h.is_nan()).collect();
    if defined.len() < 8 {
        return Err(topo.error(format!("the sphere fit needs at least 8 defined points, found {}", defined.len())));
    }
    let z_mean = defined.iter().sum::<f64>() / defined.len() as f64;
    let pos = |i: usize, j: usize| ((i as f64 * dx - lx / 2.0) / l, (j as f64 * dy - ly / 2.0) / l);
    let scaled = topo.heights.mapv(|z| (z - z_mean) / l);
    let h = scaled.view();

    let parab = normal_equations(h, 4, |i, j, z, phi| {
        let (x, y) = pos(i, j);
        phi.copy_from_slice(&[1.0, x, y, x * x + y * y]);
        Some(z)
    })
    .expect("the paraboloid is defined everywhere");
    let c = parab.solve().ok_or_else(|| topo.error("the defined points are too few or collinear for a sphere fit"))?;
    let k = -2.0 * c[3];
    let (x0, y0) = (c[1] / k, c[2] / k);
    if !(x0.abs() < 100.0 && y0.abs() < 100.0) {
        return Err(topo.error("no sphere-like curvature to fit: the surface is flat or saddle-shaped"));
    }
    let mut p = [x0, y0, c[0] + 0.5 * k * (x0 * x0 + y0 * y0), k];

    // Gauss–Newton on the exact cap z = z0 − sag(k, ρ²); residuals are z − model.
    let system = |p: &[f64; 4]| {
        let [x0, y0, z0, k] = *p;
        normal_equations(h, 4, |i, j, z, phi| {
            let (x, y) = pos(i, j);
            let rho2 = (x - x0).powi(2) + (y - y0).powi(2);
            let s2 = 1.0 - k * k * rho2;
            if s2 <= 0.0 {
                return None;
            }
            let s = s2.sqrt();
            phi.copy_from_slice(&[k * (x - x0) / s, k * (y - y0) / s, 1.0, -rho2 / (s * (1.0 + s))]);
            Some(z - (z0 - k * rho2 / (1.0 + s)))
        })
    };
    let too_small = || topo.error("the fitted sphere is smaller than the window: no cap fits the surface");
    let mut ne = system(&p).ok_or_else(too_small)?;
    const MAX_ITER: usize = 100;
    for _ in 0..MAX_ITER {
        let delta = ne.solve().ok_or_else(|| topo.error("the sphere fit is singular"))?;
        let mut lambda = 1.0;
        let accepted = loop {
            let trial: [f64; 4] = std::array::from_fn(|m| p[m] + lambda * delta[m]);
            if let Some(t) = system(&trial) {
                if t.ssr <= ne.ssr * (1.0 + 1e-12) {
                    break Some((trial, t));
                }
            }
            lambda *= 0.5;
            if lambda < 1e-12 {
                break None;
            }
        };
        let step_small = |p: &[f64; 4]| {
            (lambda * delta[0]).abs() <= 1e-11
                && (lambda * delta[1]).abs() <= 1e-11
                && (lambda * delta[2]).abs() <= 1e-14 + 1e-11 * p[2].abs()
                && (lambda * delta[3]).abs() <= 1e-11 * p[3].abs()
        };
        match accepted {
            // No step lowers the residual: p is the minimum to round-off.
            None => break,
            Some((trial, t)) => {
                let done = step_small(&trial);
                p = trial;
                ne = t;
                if done {
                    break;
                }
            }
        }
    }
    let [x0, y0, z0, k] = p;
    Ok(SphereFit {
        radius: l / k,
        apex: (lx / 2.0 + x0 * l, ly / 2.0 + y0 * l),
        apex_height: z_mean + z0 * l,
        rms_residual: (ne.ssr / ne.count as f64).sqrt() * l,
    })
}

/// The normal equations of a linear least-squares problem.
struct NormalEquations {
    /// Σ φφᵀ, p×p row-major (full).
    gram: Vec<f64>,
    /// Σ φ·r.
    rhs: Vec<f64>,
    /// Σ r².
    ssr: f64,
    /// Number of points summed.
    count: usize,
}

impl NormalEquations {
    /// Solve by Cholesky; `None` when the system is singular to working precision.
    fn solve(&self) -> Option<Vec<f64>> {
        let p = self.rhs.len();
        let mut a = self.gram.clone();
        let max_diag = (0..p).map(|k| a[k * p + k]).fold(0.0, f64::max);
        for k in 0..p {
            let d = a[k * p + k] - (0..k).map(|m| a[k * p + m].powi(2)).sum::<f64>();
            if d.is_nan() || d <= 1e-13 * max_diag {
                return None;
            }
            let d = d.sqrt();
            a[k * p + k] = d;
            for i in k + 1..p {
                let s = a[i * p + k] - (0..k).map(|m| a[i * p + m] * a[k * p + m]).sum::<f64>();
                a[i * p + k] = s / d;
            }
        }
        let mut x = self.rhs.clone();
        for i in 0..p {
            x[i] = (x[i] - (0..i).map(|m| a[i * p + m] * x[m]).sum::<f64>()) / a[i * p + i];
        }
        for i in (0..p).rev() {
            x[i] = (x[i] - (i + 1..p).map(|m| a[m * p + i] * x[m]).sum::<f64>()) / a[i * p + i];
        }
        Some(x)
    }
}

/// Rows per block of the parallel sums.
const BLOCK: usize = 32;

/// Accumulate the normal equations over the defined points of `h`. `row(i, j, z, φ)` fills the
/// design row φ (length `p`) of sample (column i, row j) with height z and returns its target,
/// or `None` when the model is undefined there (then the whole result is `None`).
fn normal_equations(
    h: ArrayView2<f64>,
    p: usize,
    row: impl Fn(usize, usize, f64, &mut [f64]) -> Option<f64> + Sync,
) -> Option<NormalEquations> {
    let blocks: Vec<Option<NormalEquations>> = h
        .axis_chunks_iter(Axis(0), BLOCK)
        .into_par_iter()
        .enumerate()
        .map(|(b, rows)| {
            let mut ne = NormalEquations { gram: vec![0.0; p * p], rhs: vec![0.0; p], ssr: 0.0, count: 0 };
            let mut phi = vec![0.0; p];
            for (jj, line) in rows.outer_iter().enumerate() {
                for (i, &z) in line.iter().enumerate() {
                    if z.is_nan() {
                        continue;
                    }
                    let r = row(i, b * BLOCK + jj, z, &mut phi)?;
                    for k in 0..p {
                        ne.rhs[k] += phi[k] * r;
                        for m in 0..=k {
                            ne.gram[k * p + m] += phi[k] * phi[m];
                        }
                    }
                    ne.ssr += r * r;
                    ne.count += 1;
                }
            }
            Some(ne)
        })
        .collect();
    let mut total = NormalEquations { gram: vec![0.0; p * p], rhs: vec![0.0; p], ssr: 0.0, count: 0 };
    for ne in blocks {
        let ne = ne?;
        total.gram.iter_mut().zip(&ne.gram).for_each(|(t, g)| *t += g);
        total.rhs.iter_mut().zip(&ne.rhs).for_each(|(t, r)| *t += r);
        total.ssr += ne.ssr;
        total.count += ne.count;
    }
    for k in 0..p {
        for m in 0..k {
            total.gram[m * p + k] = total.gram[k * p + m];
        }
    }
    Some(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::map::Provenance;
    use ndarray::Array2;

    fn map(size: (f64, f64), grid: (usize, usize), f: impl Fn(f64, f64) -> f64) -> Topography {
        let ((lx, ly), (nx, ny)) = (size, grid);
        Topography {
            heights: Array2::from_shape_fn((ny, nx), |(j, i)| f(i as f64 * lx / nx as f64, j as f64 * ly / ny as f64)),
            physical_size: Some(size),
            periodic: false,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { format: "test".into(), ..Default::default() },
        }
    }

    /// Deterministic roughness with no polynomial structure [m].
    fn bumps(x: f64, y: f64) -> f64 {
        2e-9 * ((x * 3.1e6).sin() * (y * 2.3e6 + 1.0).cos() + 0.5 * (x * 7.7e6 - y * 5.3e6).sin())
    }

    fn max_abs(a: &Array2<f64>) -> f64 {
        a.iter().filter(|h| !h.is_nan()).fold(0.0, |m, h| m.max(h.abs()))
    }

    #[test]
    fn parses_the_modes() {
        assert_eq!("none".parse(), Ok(Detrend::None));
        assert_eq!("mean".parse(), Ok(Detrend::Polynomial(0)));
        assert_eq!("plane".parse(), Ok(Detrend::Polynomial(1)));
        assert_eq!("poly:3".parse(), Ok(Detrend::Polynomial(3)));
        assert_eq!("sphere".parse(), Ok(Detrend::Sphere));
        for bad in ["poly:", "poly:x", "poly:9", "cubic"] {
            assert!(bad.parse::<Detrend>().is_err(), "{bad}");
        }
    }

    #[test]
    fn a_plane_is_removed_to_round_off() {
        let plane = |x: f64, y: f64| 3e-7 + 0.02 * x - 0.015 * y;
        let mut t = map((10e-6, 6e-6), (50, 30), plane);
        t.heights[(3, 4)] = f64::NAN;
        Detrend::Polynomial(1).apply(&mut t).unwrap();
        // The plane spans ~4e-7 m over the window.
        assert!(max_abs(&t.heights) < 1e-14 * 4e-7, "{}", max_abs(&t.heights));
        assert!(t.heights[(3, 4)].is_nan(), "missing points stay missing");
    }

    #[test]
    fn a_polynomial_added_to_roughness_is_removed_exactly() {
        let poly = |x: f64, y: f64| {
            let (u, v) = (x / 1e-5, y / 1e-5);
            1e-7 * (0.3 + u - 2.0 * v + 0.7 * u * u - u * v + 1.5 * v * v + 0.4 * u * u * u - 0.9 * u * v * v)
        };
        let rough = map((12e-6, 9e-6), (60, 45), bumps);
        let mut tilted = map((12e-6, 9e-6), (60, 45), |x, y| bumps(x, y) + poly(x, y));
        let mut flat = rough.clone();
        subtract_polynomial(&mut tilted, 3).unwrap();
        subtract_polynomial(&mut flat, 3).unwrap();
        let diff = max_abs(&(&tilted.heights - &flat.heights));
        assert!(diff < 1e-13 * 1e-7, "difference {diff}");
        // And the cubic removed from the roughness alone changes it: the test can fail.
        assert!(max_abs(&(&flat.heights - &rough.heights)) > 1e-11);
    }

    #[test]
    fn parses_line_levelling_alone_and_before_a_whole_map_step() {
        assert_eq!("line:1".parse(), Ok(Detrend::Lines(LineFit::Polynomial(1), WholeMap::None)));
        assert_eq!("line:median".parse(), Ok(Detrend::Lines(LineFit::Median, WholeMap::None)));
        assert_eq!("line:0,plane".parse(), Ok(Detrend::Lines(LineFit::Polynomial(0), WholeMap::Polynomial(1))));
        assert_eq!("line:3,sphere".parse(), Ok(Detrend::Lines(LineFit::Polynomial(3), WholeMap::Sphere)));
        for bad in ["line:4", "line:", "line:1,line:0", "line:1,", "line:median,poly:9", "line:-1"] {
            let e = bad.parse::<Detrend>().unwrap_err();
            assert!(e.contains(&format!("'{bad}'")) && e.contains("line:N (N ≤ 3)"), "{e}");
        }
    }

    /// Random per-line terms: for row j, Σ c_jk x^k (x in pixels) with c_jk drawn from a fixed
    /// sequence, `scale` [m] the size of the offsets.
    fn line_terms(ny: usize, degree: usize, scale: f64) -> Vec<Vec<f64>> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        (0..ny).map(|_| (0..=degree).map(|k| scale * next() / 40f64.powi(k as i32)).collect()).collect()
    }

    #[test]
    fn line_levelling_removes_random_per_line_polynomials_exactly() {
        let (size, grid) = ((12e-6, 9e-6), (60, 45));
        for degree in 0..=MAX_LINE_DEGREE {
            let terms = line_terms(grid.1, degree, 1e-7);
            let rough = map(size, grid, bumps);
            let mut scanned = rough.clone();
            for ((j, i), h) in scanned.heights.indexed_iter_mut() {
                *h += terms[j].iter().enumerate().map(|(k, c)| c * (i as f64).powi(k as i32)).sum::<f64>();
            }
            // Missing points, left out of each line's fit, stay missing.
            let mut flat = rough.clone();
            for t in [&mut scanned, &mut flat] {
                for at in [[3, 7], [3, 8], [40, 0]] {
                    t.heights[at] = f64::NAN;
                }
            }
            let mode = Detrend::Lines(LineFit::Polynomial(degree), WholeMap::None);
            mode.apply(&mut scanned).unwrap();
            mode.apply(&mut flat).unwrap();
            assert!(scanned.heights[[3, 7]].is_nan() && scanned.heights[[40, 0]].is_nan());
            let diff = max_abs(&(&scanned.heights - &flat.heights));
            assert!(diff < 1e-12 * max_abs(&rough.heights), "degree {degree}: difference {diff:e}");
            // Each line of the result has no component of degree ≤ N left: its mean is zero.
            let row = flat.heights.row(10);
            assert!(row.sum().abs() < 1e-12 * max_abs(&rough.heights), "{}", row.sum());
            // And the levelling changed the roughness itself (its per-line terms): the test can fail.
            assert!(max_abs(&(&flat.heights - &rough.heights)) > 1e-11, "degree {degree}");
        }
    }

    #[test]
    fn median_alignment_shifts_each_line_by_its_median() {
        let terms = line_terms(45, 0, 1e-7);
        let rough = map((12e-6, 9e-6), (60, 45), bumps);
        let mut shifted = rough.clone();
        for ((j, _), h) in shifted.heights.indexed_iter_mut() {
            *h += terms[j][0];
        }
        let mode: Detrend = "line:median".parse().unwrap();
        mode.apply(&mut shifted).unwrap();
        let mut flat = rough.clone();
        mode.apply(&mut flat).unwrap();
        assert!(max_abs(&(&shifted.heights - &flat.heights)) < 1e-12 * max_abs(&rough.heights));
        // Every line's median is now 0: half its points above, half below.
        let line: Vec<f64> = flat.heights.row(5).to_vec();
        assert_eq!(line.iter().filter(|&&h| h > 0.0).count(), line.iter().filter(|&&h| h < 0.0).count());
    }

    #[test]
    fn line_levelling_then_a_plane_removes_the_tilt_along_y() {
        // Line levelling of degree 0 leaves no tilt along x; the plane then has none along y
        // either, since each line's mean is zero: the result equals line levelling alone.
        let tilted = map((12e-6, 9e-6), (60, 45), |x, y| bumps(x, y) + 0.01 * x + 0.02 * y);
        let mut a = tilted.clone();
        let mut b = tilted.clone();
        "line:1,plane".parse::<Detrend>().unwrap().apply(&mut a).unwrap();
        "line:1".parse::<Detrend>().unwrap().apply(&mut b).unwrap();
        assert!(max_abs(&(&a.heights - &b.heights)) < 1e-20);
        // A plane alone keeps each line's own offsets of the roughness: not the same map.
        let mut c = tilted.clone();
        Detrend::Polynomial(1).apply(&mut c).unwrap();
        assert!(max_abs(&(&a.heights - &c.heights)) > 1e-11);
    }

    #[test]
    fn a_line_with_too_few_points_is_refused_not_filled() {
        let mut t = map((1e-6, 1e-6), (8, 4), |x, y| x + y);
        for i in 1..8 {
            t.heights[[2, i]] = f64::NAN;
        }
        let e = Detrend::Lines(LineFit::Polynomial(1), WholeMap::None).apply(&mut t.clone()).unwrap_err().to_string();
        assert!(e.contains("scan line 2 (row 2 of 4) has 1 defined points") && e.contains("degree 1"), "{e}");
        // The median needs one point: that line is shifted to 0.
        Detrend::Lines(LineFit::Median, WholeMap::None).apply(&mut t).unwrap();
        assert_eq!(t.heights[[2, 0]], 0.0);
        for i in 0..8 {
            t.heights[[1, i]] = f64::NAN;
        }
        let e = Detrend::Lines(LineFit::Median, WholeMap::None).apply(&mut t).unwrap_err().to_string();
        assert!(e.contains("scan line 1 (row 1 of 4) has 0 defined points") && e.contains("its median"), "{e}");
    }

    #[test]
    fn too_few_points_for_the_degree_are_refused() {
        let mut t = map((1e-6, 1e-6), (3, 3), |x, y| x + y);
        let err = subtract_polynomial(&mut t, 3).unwrap_err().to_string();
        assert!(err.contains("too few defined points (9)") && err.contains("10 terms"), "{err}");
    }

    /// A cap of radius `r` (signed) with apex at (x0, y0) and height z0, plus roughness.
    fn cap(r: f64, x0: f64, y0: f64, z0: f64, noise: f64) -> impl Fn(f64, f64) -> f64 {
        move |x, y| {
            let rho2 = (x - x0).powi(2) + (y - y0).powi(2);
            z0 - r.signum() * (r.abs() - (r * r - rho2).sqrt()) + noise * bumps(x, y) / 2e-9
        }
    }

    #[test]
    fn the_sphere_fit_recovers_a_strongly_curved_cap() {
        // R = 20 µm over a 10 × 8 µm window: far from a paraboloid (the sag's ρ⁴ term is 4%).
        let (r, x0, y0, z0) = (20e-6, 4.2e-6, 4.5e-6, 1e-6);
        let t = map((10e-6, 8e-6), (100, 80), cap(r, x0, y0, z0, 1e-9));
        let fit = fit_sphere(&t).unwrap();
        assert!((fit.radius / r - 1.0).abs() < 1e-3, "{fit:?}");
        assert!((fit.apex.0 - x0).abs() < 1e-9 && (fit.apex.1 - y0).abs() < 1e-9, "{fit:?}");
        assert!((fit.apex_height - z0).abs() < 1e-10, "{fit:?}");
        assert!(fit.rms_residual < 2e-9, "{fit:?}");
    }

    #[test]
    fn the_sphere_fit_recovers_the_paper_ball_and_a_bowl() {
        // The paper's ball: R = 1.5 mm over 31.13 µm, here with 1 nm of roughness.
        let l = 31.13e-6;
        let t = map((l, l), (200, 200), cap(1.5e-3, l / 2.0 + 1e-6, l / 2.0 - 2e-6, 0.0, 1e-9));
        let fit = fit_sphere(&t).unwrap();
        assert!((fit.radius / 1.5e-3 - 1.0).abs() < 1e-3, "{fit:?}");
        let exact = map((l, l), (64, 64), cap(-0.5e-3, l / 3.0, l / 2.0, 2e-7, 0.0));
        let fit = fit_sphere(&exact).unwrap();
        assert!((fit.radius / -0.5e-3 - 1.0).abs() < 1e-9, "{fit:?}");
        // Subtracting it leaves nothing.
        let mut levelled = exact.clone();
        Detrend::Sphere.apply(&mut levelled).unwrap();
        assert!(max_abs(&levelled.heights) < 1e-15, "{}", max_abs(&levelled.heights));
    }

    #[test]
    fn the_sphere_fit_refuses_a_plane() {
        let t = map((1e-5, 1e-5), (32, 32), |x, y| 1e-3 * x + 2e-3 * y);
        assert!(fit_sphere(&t).unwrap_err().to_string().contains("no sphere-like curvature"));
    }
}
