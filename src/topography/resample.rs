//! Cropping, resampling and compounding topographies on regular grids.
//!
//! Grid convention, shared by every module of [`crate::topography`]: sample (row j, column i)
//! of a topography of physical size (lx, ly) on an (ny, nx) grid sits at x = i·dx, y = j·dy
//! with pixel size dx = lx/nx, dy = ly/ny (as for the FFT, and as SurfaceTopography does), so
//! a periodic map repeats with period (lx, ly).
//!
//! Interpolation is cubic convolution (Keys 1981, a = −1/2, i.e. Catmull–Rom), applied
//! separably along x then y: exact for polynomials up to degree 2, error O(dx³) for smooth
//! fields. Periodic maps wrap around; along a non-periodic edge the missing neighbour is Keys'
//! cubic extrapolation `f(−1) = 3f(0) − 3f(1) + f(2)`, which keeps the third order. Points at
//! most one pixel beyond the last sample (the far edges of a non-periodic map when refining)
//! are extrapolated by the same cubic. On a sine sampled 16 times per wavelength the error is
//! below 1.5·10⁻³ of its amplitude in the interior, 4·10⁻³ within a pixel of a non-periodic
//! edge and 3·10⁻² in the extrapolated strip (tested). It is point sampling:
//! coarsening by a large factor aliases the wavelengths below the new pixel size, as a coarser
//! scan would.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::ops::Range;

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

use super::map::{Provenance, Topography};
use crate::error::{Error, Result};
use crate::limits::{check_memory, grid_memory, Limits, RESAMPLE_BYTES_PER_POINT};

impl Topography {
    /// Pixel size (dx, dy) \[m]; an error naming the topography when it has no physical size
    /// (`purpose` says what needs it).
    pub fn pixel_size(&self, purpose: &str) -> Result<(f64, f64)> {
        let (lx, ly) = self
            .physical_size
            .ok_or_else(|| self.error(format!("{purpose} needs the physical size: give it with --size LX[,LY] (m)")))?;
        Ok((lx / self.nx() as f64, ly / self.ny() as f64))
    }

    /// An error about this topography: names its file when it was read from one.
    pub fn error(&self, reason: impl Into<String>) -> Error {
        match &self.provenance.file {
            Some(path) => Error::file(path, reason),
            None => Error::invalid(format!("{} topography", self.provenance.format), reason),
        }
    }
}

/// A window to crop a topography to.
#[derive(Debug, Clone, PartialEq)]
pub enum CropWindow {
    /// Column range `x` and row range `y`, 0-based, end excluded.
    Pixels {
        /// Columns kept.
        x: Range<usize>,
        /// Rows kept.
        y: Range<usize>,
    },
    /// Physical ranges [x0, x1) and [y0, y1) \[m]: keeps the samples whose position lies inside.
    Physical {
        /// (x0, x1) \[m].
        x: (f64, f64),
        /// (y0, y1) \[m].
        y: (f64, f64),
    },
}

/// The part of `topo` inside `window`. The pixel size is kept; the result is periodic only
/// when the window is the whole map. A physical window's bounds are finite lengths ≥ 0.
pub fn crop(topo: &Topography, window: &CropWindow) -> Result<Topography> {
    let (nx, ny) = (topo.nx(), topo.ny());
    let (x, y) = match window {
        CropWindow::Pixels { x, y } => (x.clone(), y.clone()),
        CropWindow::Physical { x, y } => {
            let (dx, dy) = topo.pixel_size("cropping to a physical window")?;
            let bounds = [("x0", x.0), ("x1", x.1), ("y0", y.0), ("y1", y.1)];
            if let Some((name, v)) = bounds.into_iter().find(|(_, v)| !(*v >= 0.0 && v.is_finite())) {
                return Err(Error::invalid(
                    "--crop",
                    format!("{name} = {v:e} m: bounds are finite lengths ≥ 0, measured from the map's origin"),
                ));
            }
            // A bound past the map would be clamped to it: the window asked for is not there.
            let ends = [("x1", x.1, dx * nx as f64), ("y1", y.1, dy * ny as f64)];
            if let Some((name, v, l)) = ends.into_iter().find(|(_, v, l)| *v > l * (1.0 + 1e-9)) {
                return Err(Error::invalid(
                    "--crop",
                    format!("{name} = {v:e} m lies past the map's end at {l:e} m: give bounds within the map"),
                ));
            }
            (samples_within(x.0, x.1, dx, nx), samples_within(y.0, y.1, dy, ny))
        }
    };
    if x.start >= x.end || y.start >= y.end || x.end > nx || y.end > ny {
        return Err(Error::invalid(
            "--crop",
            format!(
                "window x {}..{}, y {}..{} (pixels) is empty or outside the {nx}×{ny} map",
                x.start, x.end, y.start, y.end
            ),
        ));
    }
    let whole = x == (0..nx) && y == (0..ny);
    let heights = topo.heights.slice(ndarray::s![y.clone(), x.clone()]).to_owned();
    let physical_size =
        topo.physical_size.map(|(lx, ly)| (lx * x.len() as f64 / nx as f64, ly * y.len() as f64 / ny as f64));
    Ok(Topography {
        heights,
        physical_size,
        periodic: topo.periodic && whole,
        height_unit_known: topo.height_unit_known,
        channel: topo.channel.clone(),
        provenance: topo.provenance.clone(),
    })
}

/// Indices i < n whose position i·d lies in [a, b); a bound within 1e-9 pixel of a sample
/// counts as on it, so that round-off in a/d does not move it.
fn samples_within(a: f64, b: f64, d: f64, n: usize) -> Range<usize> {
    let index = |v: f64| (v / d - 1e-9).ceil().max(0.0);
    let (first, end) = (index(a), index(b));
    (first.min(n as f64) as usize)..(end.min(n as f64) as usize)
}

/// `topo` resampled to a pixel size as close to `pixel_size` \[m] as the physical size allows:
/// the physical size is kept, the number of points along each axis is `round(l / pixel_size)`
/// (refused below 2), so the pixel size becomes `l / round(l / pixel_size)`.
pub fn resample(topo: &Topography, pixel_size: f64, limits: &Limits) -> Result<Topography> {
    if !(pixel_size > 0.0 && pixel_size.is_finite()) {
        return Err(Error::invalid("--pixel-size", format!("must be positive and finite, got {pixel_size}")));
    }
    topo.pixel_size("resampling")?;
    let (lx, ly) = topo.physical_size.expect("checked by pixel_size");
    let points = |l: f64| (l / pixel_size).round() as usize;
    let (nx2, ny2) = (points(lx), points(ly));
    if nx2.min(ny2) < 2 {
        return Err(Error::invalid(
            "--pixel-size",
            format!(
                "{pixel_size:e} m on a {lx:e} × {ly:e} m window leaves fewer than 2 points along an axis: \
                 give at most {:e} m",
                lx.min(ly) / 2.0
            ),
        ));
    }
    let memory = grid_memory(nx2, ny2, RESAMPLE_BYTES_PER_POINT);
    let what = format!("resampling to {nx2} × {ny2} points");
    if let Err(reason) = limits.check_grid(nx2, ny2).and_then(|()| check_memory(memory, &what)) {
        return Err(Error::invalid("--pixel-size", format!("{pixel_size} m on {lx} × {ly} m: {reason}")));
    }
    // Fractional source indices as exact ratios, so that an unchanged grid maps onto itself.
    let xs: Vec<f64> = (0..nx2).map(|i| (i * topo.nx()) as f64 / nx2 as f64).collect();
    let ys: Vec<f64> = (0..ny2).map(|j| (j * topo.ny()) as f64 / ny2 as f64).collect();
    Ok(Topography {
        heights: interpolate_grid(topo, &xs, &ys)?,
        physical_size: topo.physical_size,
        periodic: topo.periodic,
        height_unit_known: topo.height_unit_known,
        channel: topo.channel.clone(),
        provenance: topo.provenance.clone(),
    })
}

/// The compound roughness `h = h_ball − h_wafer` of the two surfaces in contact, on the
/// ball's grid.
///
/// The ball's scan defines the contact window and its grid wins: the wafer is interpolated
/// (cubic, see the module doc) at the ball's sample positions, the two windows centred on each
/// other, since the scans share no reference point. A wafer scan larger than the ball's
/// contributes its central part. A smaller one is tiled periodically when it is periodic;
/// otherwise it is refused (crop the ball scan to at most the wafer's size first), because
/// extrapolating roughness would invent it. The result is periodic when both are, with the
/// same physical size.
pub fn compound(ball: &Topography, wafer: &Topography) -> Result<Topography> {
    ball.pixel_size("compounding")?;
    let (dxw, dyw) = wafer.pixel_size("compounding")?;
    let (lxb, lyb) = ball.physical_size.expect("checked by pixel_size");
    let (lxw, lyw) = wafer.physical_size.expect("checked by pixel_size");
    let smaller = |w: f64, b: f64| w < b * (1.0 - 1e-9);
    if !wafer.periodic && (smaller(lxw, lxb) || smaller(lyw, lyb)) {
        return Err(wafer.error(format!(
            "the wafer scan ({lxw:e} × {lyw:e} m) is smaller than the ball scan ({lxb:e} × {lyb:e} m) and not \
             periodic: crop the ball scan to at most the wafer's size"
        )));
    }
    let (dxb, dyb) = ball.pixel_size("compounding")?;
    let xs: Vec<f64> = (0..ball.nx()).map(|i| (i as f64 * dxb + (lxw - lxb) / 2.0) / dxw).collect();
    let ys: Vec<f64> = (0..ball.ny()).map(|j| (j as f64 * dyb + (lyw - lyb) / 2.0) / dyw).collect();
    let wafer_on_ball = interpolate_grid(wafer, &xs, &ys)?;
    let same_size = !smaller(lxw, lxb) && !smaller(lxb, lxw) && !smaller(lyw, lyb) && !smaller(lyb, lyw);
    Ok(Topography {
        heights: &ball.heights - &wafer_on_ball,
        physical_size: ball.physical_size,
        periodic: ball.periodic && wafer.periodic && same_size,
        height_unit_known: ball.height_unit_known && wafer.height_unit_known,
        channel: format!("{} − {}", ball.channel, wafer.channel),
        provenance: Provenance { file: None, format: "compound".into(), height_unit: Some("m".into()) },
    })
}

/// Heights of `topo` at the tensor grid of fractional indices `xs` (columns) × `ys` (rows),
/// by separable cubic convolution. A missing point makes its neighbours within two pixels
/// missing too.
fn interpolate_grid(topo: &Topography, xs: &[f64], ys: &[f64]) -> Result<Array2<f64>> {
    let (nx, ny) = (topo.nx(), topo.ny());
    if nx < 4 || ny < 4 {
        return Err(topo.error(format!("interpolation needs at least 4×4 points, the map has {nx}×{ny}")));
    }
    let sx: Vec<Stencil> = xs.iter().map(|&t| stencil(t, nx, topo.periodic)).collect();
    let sy: Vec<Stencil> = ys.iter().map(|&t| stencil(t, ny, topo.periodic)).collect();
    // Along x for every source row, then along y.
    let h: ArrayView2<f64> = topo.heights.view();
    let mut along_x = Array2::<f64>::zeros((ny, xs.len()));
    along_x.axis_iter_mut(ndarray::Axis(0)).into_par_iter().enumerate().for_each(|(j, mut row)| {
        let src = h.row(j);
        for (out, s) in row.iter_mut().zip(&sx) {
            *out = s.iter().map(|&(k, w)| w * src[k]).sum();
        }
    });
    let mut out = Array2::<f64>::zeros((ys.len(), xs.len()));
    out.axis_iter_mut(ndarray::Axis(0)).into_par_iter().zip(&sy).for_each(|(mut row, s)| {
        for &(k, w) in s {
            row.scaled_add(w, &along_x.row(k));
        }
    });
    Ok(out)
}

/// Source indices and weights of one interpolated point along one axis.
type Stencil = [(usize, f64); 4];

/// The cubic-convolution stencil at fractional index `t` on an axis of `n ≥ 4` samples.
fn stencil(t: f64, n: usize, periodic: bool) -> Stencil {
    let base = t.floor();
    if periodic {
        let f = t - base;
        let w = catmull_rom(f);
        let i = base as i64;
        std::array::from_fn(|k| ((i - 1 + k as i64).rem_euclid(n as i64) as usize, w[k]))
    } else {
        // Clamped so the stencil stays on the grid; f then leaves [0, 1] when extrapolating.
        let i = (base as i64).clamp(0, n as i64 - 2) as usize;
        let w = catmull_rom(t - i as f64);
        if i == 0 {
            // Fold the ghost f(−1) = 3f(0) − 3f(1) + f(2) into the real neighbours.
            [(0, w[1] + 3.0 * w[0]), (1, w[2] - 3.0 * w[0]), (2, w[3] + w[0]), (0, 0.0)]
        } else if i == n - 2 {
            // Likewise f(n) = 3f(n−1) − 3f(n−2) + f(n−3).
            [(n - 3, w[0] + w[3]), (n - 2, w[1] - 3.0 * w[3]), (n - 1, w[2] + 3.0 * w[3]), (n - 1, 0.0)]
        } else {
            [(i - 1, w[0]), (i, w[1]), (i + 1, w[2]), (i + 2, w[3])]
        }
    }
}

/// Catmull–Rom weights of the samples at offsets −1, 0, 1, 2 for a point at offset `f`.
fn catmull_rom(f: f64) -> [f64; 4] {
    let (f2, f3) = (f * f, f * f * f);
    [0.5 * (-f3 + 2.0 * f2 - f), 0.5 * (3.0 * f3 - 5.0 * f2 + 2.0), 0.5 * (-3.0 * f3 + 4.0 * f2 + f), 0.5 * (f3 - f2)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// A map of `f(x, y)` [m] sampled at x = i·lx/nx, y = j·ly/ny.
    fn sampled(size: (f64, f64), grid: (usize, usize), periodic: bool, f: impl Fn(f64, f64) -> f64) -> Topography {
        let ((lx, ly), (nx, ny)) = (size, grid);
        Topography {
            heights: Array2::from_shape_fn((ny, nx), |(j, i)| f(i as f64 * lx / nx as f64, j as f64 * ly / ny as f64)),
            physical_size: Some(size),
            periodic,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { format: "test".into(), ..Default::default() },
        }
    }

    fn max_error(t: &Topography, f: impl Fn(f64, f64) -> f64) -> f64 {
        let (dx, dy) = t.pixel_size("test").unwrap();
        t.heights.indexed_iter().map(|((j, i), h)| (h - f(i as f64 * dx, j as f64 * dy)).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn crop_by_pixels_and_by_lengths_agree() {
        let t = sampled((10e-6, 8e-6), (50, 40), true, |x, y| x + 3.0 * y);
        let by_pixels = crop(&t, &CropWindow::Pixels { x: 5..25, y: 10..40 }).unwrap();
        assert_eq!(by_pixels.heights.dim(), (30, 20));
        assert_eq!(by_pixels.heights[(0, 0)], t.heights[(10, 5)]);
        let (lx, ly) = by_pixels.physical_size.unwrap();
        assert!((lx - 4e-6).abs() < 1e-18 && (ly - 6e-6).abs() < 1e-18);
        assert!(!by_pixels.periodic, "a part of a periodic map does not repeat");
        // Pixel 5 sits at x = 1 µm; the window [1 µm, 5 µm) holds pixels 5..25.
        let by_length = crop(&t, &CropWindow::Physical { x: (1e-6, 5e-6), y: (2e-6, 8e-6) }).unwrap();
        assert_eq!(by_length, by_pixels);
        assert!(crop(&t, &CropWindow::Pixels { x: 0..50, y: 0..40 }).unwrap().periodic);
        let err = crop(&t, &CropWindow::Pixels { x: 45..55, y: 0..10 }).unwrap_err().to_string();
        assert!(err.starts_with("--crop: ") && err.contains("50×40"), "{err}");
        // A bound that is not a length from the origin is refused, not read as 0 or as the end.
        for (x, y) in
            [((f64::NAN, 5e-6), (2e-6, 8e-6)), ((-1e-6, 5e-6), (2e-6, 8e-6)), ((1e-6, 5e-6), (2e-6, f64::INFINITY))]
        {
            let e = crop(&t, &CropWindow::Physical { x, y }).unwrap_err().to_string();
            assert!(e.starts_with("--crop: ") && e.contains("bounds are finite lengths ≥ 0"), "{e}");
        }
    }

    #[test]
    fn quadratics_are_resampled_exactly_even_at_the_edges() {
        let f = |x: f64, y: f64| 1e-9 + 2e-3 * x - 1e-3 * y + 4e2 * x * x - 3e2 * x * y + 1e2 * y * y;
        let t = sampled((10e-6, 6e-6), (40, 30), false, f);
        for p in [0.07e-6, 0.37e-6, 0.2e-6] {
            let r = resample(&t, p, &Limits::default()).unwrap();
            assert_eq!(r.physical_size, t.physical_size);
            assert!(max_error(&r, f) < 1e-12 * 5e-9, "pixel {p}: error {}", max_error(&r, f));
        }
    }

    #[test]
    fn smooth_fields_are_resampled_to_the_stated_accuracy() {
        // A sine sampled 16 times per wavelength; errors relative to its amplitude.
        let (lx, ly, amplitude) = (10e-6, 8e-6, 1e-8);
        let f = |x: f64, y: f64| amplitude * ((2.0 * PI * x / 2.5e-6 + 0.3).sin() * (2.0 * PI * y / 2e-6).cos());
        for periodic in [false, true] {
            let t = sampled((lx, ly), (64, 64), periodic, f);
            let (dx, dy) = t.pixel_size("test").unwrap();
            for p in [lx / 150.0, lx / 40.0] {
                let r = resample(&t, p, &Limits::default()).unwrap();
                let (dx2, dy2) = r.pixel_size("test").unwrap();
                // Worst error in the interior, within one pixel of an edge, beyond the last sample.
                let mut worst = [0.0f64; 3];
                for ((j, i), h) in r.heights.indexed_iter() {
                    let (x, y) = (i as f64 * dx2, j as f64 * dy2);
                    let zone = if x > lx - dx || y > ly - dy {
                        2
                    } else if x < dx || y < dy || x > lx - 2.0 * dx || y > ly - 2.0 * dy {
                        1
                    } else {
                        0
                    };
                    worst[zone] = worst[zone].max((h - f(x, y)).abs() / amplitude);
                }
                let bounds = if periodic { [1.5e-3; 3] } else { [1.5e-3, 4e-3, 3e-2] };
                for zone in 0..3 {
                    assert!(worst[zone] < bounds[zone], "periodic {periodic}, pixel {p}: errors {worst:?}");
                }
            }
            // An unchanged pixel size gives the same map back.
            let square = sampled((lx, lx), (64, 64), periodic, f);
            assert_eq!(resample(&square, lx / 64.0, &Limits::default()).unwrap().heights, square.heights);
        }
    }

    #[test]
    fn resampling_a_map_without_size_says_so() {
        let mut t = sampled((1.0, 1.0), (8, 8), false, |x, _| x);
        t.physical_size = None;
        let err = resample(&t, 0.1, &Limits::default()).unwrap_err().to_string();
        assert!(err.contains("resampling needs the physical size") && err.contains("--size"), "{err}");
        assert!(resample(&sampled((1.0, 1.0), (8, 8), false, |x, _| x), -1.0, &Limits::default()).is_err());
    }

    #[test]
    fn compound_interpolates_a_larger_wafer_at_the_ball_samples() {
        // Ball: 10 × 7.5 µm on 64 × 48; wafer: 14 × 12 µm on 90 × 100, a quadratic (exact).
        let ball_f = |x: f64, y: f64| 3e-8 * (x / 1e-6).sin() + 1e-3 * y;
        let wafer_f = |x: f64, y: f64| 2e-10 + 1e-4 * x - 3e-5 * y + 50.0 * x * y;
        let ball = sampled((10e-6, 7.5e-6), (64, 48), false, ball_f);
        let wafer = sampled((14e-6, 12e-6), (90, 100), false, wafer_f);
        let h = compound(&ball, &wafer).unwrap();
        assert_eq!(h.heights.dim(), (48, 64));
        assert_eq!(h.physical_size, ball.physical_size);
        // Centred windows: ball x sits at wafer x + 2 µm, ball y at wafer y + 2.25 µm.
        let expected = |x: f64, y: f64| ball_f(x, y) - wafer_f(x + 2e-6, y + 2.25e-6);
        assert!(max_error(&h, expected) < 1e-20, "error {}", max_error(&h, expected));
    }

    #[test]
    fn compound_tiles_a_smaller_periodic_wafer_and_refuses_a_non_periodic_one() {
        let (lw, nw) = (4e-6, 80);
        let wafer_f = |x: f64, y: f64| 1e-9 * ((2.0 * PI * x / lw).sin() + (4.0 * PI * y / lw).cos());
        let ball = sampled((10e-6, 10e-6), (128, 128), false, |_, _| 0.0);
        let wafer = sampled((lw, lw), (nw, nw), true, wafer_f);
        let h = compound(&ball, &wafer).unwrap();
        assert!(!h.periodic);
        // Offset (lw − lb)/2 = −3 µm: a whole number of wafer periods in y, half a period less in x.
        let expected = |x: f64, y: f64| -wafer_f(x - 3e-6, y - 3e-6);
        let err = max_error(&h, expected);
        assert!(err < 1e-4 * 1e-9, "error {err}");
        let err = compound(&ball, &Topography { periodic: false, ..wafer }).unwrap_err().to_string();
        assert!(err.contains("smaller than the ball scan") && err.contains("not periodic"), "{err}");
    }

    #[test]
    fn compound_of_two_periodic_maps_of_one_size_is_periodic() {
        let f = |x: f64, _: f64| (2.0 * PI * x / 5e-6).sin();
        let ball = sampled((5e-6, 5e-6), (32, 32), true, f);
        let wafer = sampled((5e-6, 5e-6), (20, 20), true, |_, _| 1.0);
        let h = compound(&ball, &wafer).unwrap();
        assert!(h.periodic);
        assert!(max_error(&h, |x, y| f(x, y) - 1.0) < 1e-12);
    }
}
