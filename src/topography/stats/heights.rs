//! Height statistics of a map and of a line profile: moments, RMS slope and curvature, by the
//! finite differences SurfaceTopography uses.
//!
//! Imports `missing`, `profile` and the map type of `topography`, never `psd` or `fit`; must not
//! import contact, friction, study, report, plot, shs, cli.

use super::super::map::Topography;
use super::super::missing::refuse_missing;
use super::super::profile::Profile;
use crate::error::Result;

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

#[cfg(test)]
pub(super) mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::topography::map::Provenance;
    use ndarray::Array2;

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

    pub(crate) fn map(heights: Array2<f64>, size: (f64, f64), periodic: bool) -> Topography {
        Topography {
            heights,
            physical_size: Some(size),
            periodic,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { format: "test".into(), ..Default::default() },
        }
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
}
