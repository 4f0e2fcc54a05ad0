//! Elastic influence operators of the half-space: surface displacement from surface pressure,
//! `u = K p`, evaluated on the FFT grid.
//!
//! Both boundaries multiply a spectrum by a real kernel; they differ only in the kernel and the
//! grid:
//! - periodic: the field repeats across the window; `û(q) = 2 p̂(q) / (E* |q|)` (Westergaard),
//!   the q = 0 mode set to zero (the mean displacement is a rigid-body shift the contact solver
//!   absorbs);
//! - free: an isolated window on an infinite half-space; the pressure is zero-padded to a
//!   (2ny, 2nx) grid and convolved with the exact displacement of uniformly loaded rectangular
//!   pixels (Love 1929; Johnson, *Contact Mechanics*, §3.9), so there are no periodic images.
//!
//! Imports `material` inside `contact`; must not import friction, study, report, plot, shs, cli.

use rayon::prelude::*;
use rustfft::num_complex::{Complex, Complex64};
use rustfft::FftNum;

use super::material::Material;
use crate::fft::{large_buffer, split_rows, split_rows_mut, Fft2, Fft2Work};

/// The boundary condition of the elastic half-space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Boundary {
    /// The window repeats periodically (rough surfaces larger than their correlation length).
    Periodic,
    /// The window is an isolated patch of an infinite half-space (a sphere on a flat).
    Free,
}

impl Boundary {
    /// Name as written in outputs: `"periodic"` or `"free"`.
    pub fn name(self) -> &'static str {
        match self {
            Boundary::Periodic => "periodic",
            Boundary::Free => "free",
        }
    }
}

/// `u = K p` on an (ny, nx) window of physical size (lx, ly) \[m], for effective modulus E* \[Pa].
/// Owns its FFT plan and buffers: applying it never allocates.
pub struct Influence {
    ny: usize,
    nx: usize,
    fft: Fft2,
    /// Real kernel in the FFT's transposed spectrum layout, normalisation 1/(grid size) folded in.
    kernel: Vec<f64>,
    spectrum: Vec<Complex64>,
    work: Fft2Work,
}

impl Influence {
    /// The periodic (Westergaard) operator.
    pub fn periodic(ny: usize, nx: usize, (lx, ly): (f64, f64), e_star: f64) -> Self {
        let fft = Fft2::new(ny, nx);
        let norm = 1.0 / (ny * nx) as f64;
        let two_pi = 2.0 * std::f64::consts::PI;
        let kernel = fft
            .wavevectors()
            .map(|(kx, ky)| {
                let q = two_pi * ((kx as f64 / lx).powi(2) + (ky as f64 / ly).powi(2)).sqrt();
                if q == 0.0 {
                    0.0
                } else {
                    2.0 / (e_star * q) * norm
                }
            })
            .collect();
        Self::with_kernel(ny, nx, fft, kernel)
    }

    /// The free-boundary operator: exact influence of uniformly loaded rectangular pixels,
    /// convolved on a zero-padded (2ny, 2nx) grid.
    pub fn free(ny: usize, nx: usize, size: (f64, f64), e_star: f64) -> Self {
        let (py, px) = (2 * ny, 2 * nx);
        let coefficients = free_coefficients(ny, nx, size, e_star);
        let fft = Fft2::new(py, px);
        let mut spectrum = fft.make_spectrum();
        let mut work = fft.make_work();
        fft.forward(&coefficients, py, px, &mut spectrum, &mut work);
        let norm = 1.0 / (py * px) as f64;
        let kernel = spectrum.iter().map(|c| c.re * norm).collect();
        Self::with_kernel(ny, nx, fft, kernel)
    }

    fn with_kernel(ny: usize, nx: usize, fft: Fft2, values: Vec<f64>) -> Self {
        // Read beside the spectrum in every column pass: the same huge pages.
        let mut kernel = large_buffer(values.len(), 0.0);
        kernel.copy_from_slice(&values);
        let spectrum = fft.make_spectrum();
        let work = fft.make_work();
        Influence { ny, nx, fft, kernel, spectrum, work }
    }

    /// Window shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// The plan, the kernel (spectrum layout, normalisation folded in), a spectrum buffer and
    /// the work buffers, for solvers that fuse their own passes into the transforms.
    pub fn parts(&mut self) -> (&Fft2, &[f64], &mut Vec<Complex64>, &mut Fft2Work) {
        (&self.fft, &self.kernel, &mut self.spectrum, &mut self.work)
    }

    /// The FFT plan (on the padded grid for the free boundary).
    pub fn fft(&self) -> &Fft2 {
        &self.fft
    }

    /// Displacement \[m] of the window's points under `pressure` \[Pa], both row-major (ny, nx).
    pub fn apply(&mut self, pressure: &[f64], displacement: &mut [f64]) {
        let Influence { ny, nx, fft, kernel, spectrum, work } = self;
        fft.forward(pressure, *ny, *nx, spectrum, work);
        spectrum.iter_mut().zip(kernel.iter()).for_each(|(s, k)| *s *= *k);
        fft.inverse(spectrum, displacement, *ny, *nx, work);
    }
}

/// Tangential compliance of an interface, for the Cerruti operator: A = Σ 1/G_i and
/// B = Σ ν_i/G_i [1/Pa] over its elastic bodies (G = E / (2(1 + ν)) the shear modulus). Normal
/// and tangential problems are uncoupled: exact for two identical bodies (the coupling terms
/// (1 − 2ν)/G of the two cancel), Goodman's approximation otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearCompliance {
    /// Σ 1/G_i [1/Pa].
    pub a: f64,
    /// Σ ν_i/G_i [1/Pa].
    pub b: f64,
}

impl ShearCompliance {
    /// The compliance of these bodies (one for a rigid counter-body, two otherwise).
    pub fn of(bodies: &[Material]) -> Self {
        bodies.iter().fold(ShearCompliance { a: 0.0, b: 0.0 }, |c, m| {
            let g = m.youngs / (2.0 * (1.0 + m.poisson));
            ShearCompliance { a: c.a + 1.0 / g, b: c.b + m.poisson / g }
        })
    }

    /// The normal compliance Σ (1 − ν_i)/G_i = 2/E* [1/Pa] of the same bodies.
    pub fn normal(&self) -> f64 {
        self.a - self.b
    }
}

/// The tangential influence operator of the half-space (Cerruti): surface displacement
/// (u_x, u_y) from surface shear traction (q_x, q_y),
///
/// ```text
///     û_α(k) = (A δ_αβ − B k_α k_β / k²) q̂_β(k) / k
/// ```
///
/// (one body: A = 1/G, B = ν/G), periodic with the k = 0 mode set to zero (displacements are
/// then measured from the mean surface displacement), or on a zero-padded (2ny, 2nx) grid with
/// the exact influence of uniformly sheared rectangular pixels (free boundary). Two FFT pairs
/// per application, on the same engine as [`Influence`]; in double precision, or in single
/// ([`single`](Self::single)) for solves that stop far above its round-off.
pub struct TangentialInfluence<T: FftNum = f64> {
    ny: usize,
    nx: usize,
    fft: Fft2<T>,
    /// Kernels xx, xy, yy in the spectrum layout, normalisation folded in.
    kernel: [Vec<T>; 3],
    spectrum: [Vec<Complex<T>>; 2],
    /// One work per field (x, y): their row passes' half spectra meet in one column pass.
    works: [Fft2Work<T>; 2],
    /// Rows of the fields that can hold tractions and whose displacements are wanted
    /// (empty: all); see [`only_rows`](Self::only_rows).
    rows: Vec<bool>,
}

/// An operator's coefficients at any offset (dy, dx) between two points of its fields:
/// [`TangentialInfluence::offsets`].
pub struct Offsets {
    nx: usize,
    /// (xx, xy, yy) at the non-negative offsets, row-major: one cache line per offset.
    table: Vec<[f64; 3]>,
}

impl Offsets {
    /// (xx, xy, yy) at offset (dy, dx): xx and yy are even in each offset, xy odd in each, so
    /// the responses at the non-negative offsets give all.
    #[inline]
    pub fn at(&self, dy: i64, dx: i64) -> [f64; 3] {
        let [xx, xy, yy] = self.table[dy.unsigned_abs() as usize * self.nx + dx.unsigned_abs() as usize];
        [xx, (dy.signum() * dx.signum()) as f64 * xy, yy]
    }
}

impl TangentialInfluence {
    /// The periodic operator on an (ny, nx) window of size (lx, ly) \[m].
    pub fn periodic(ny: usize, nx: usize, (lx, ly): (f64, f64), c: ShearCompliance) -> Self {
        let fft = Fft2::new(ny, nx);
        let norm = 1.0 / (ny * nx) as f64;
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut kernel = [Vec::new(), Vec::new(), Vec::new()];
        for (kx, ky) in fft.wavevectors() {
            let (qx, qy) = (two_pi * kx as f64 / lx, two_pi * ky as f64 / ly);
            let q2 = qx * qx + qy * qy;
            if q2 == 0.0 {
                kernel.iter_mut().for_each(|k| k.push(0.0));
                continue;
            }
            let q = q2.sqrt();
            // The cross term is odd in each component: zero on the Nyquist lines, where the
            // sign of the wavevector is undefined.
            let nyquist = (nx.is_multiple_of(2) && kx == nx / 2) || (ny.is_multiple_of(2) && ky == ny as i64 / 2);
            kernel[0].push((c.a - c.b * qx * qx / q2) / q * norm);
            kernel[1].push(if nyquist { 0.0 } else { -c.b * qx * qy / q2 / q * norm });
            kernel[2].push((c.a - c.b * qy * qy / q2) / q * norm);
        }
        Self::with_kernels(ny, nx, fft, kernel)
    }

    /// The free-boundary operator: uniformly sheared rectangular pixels (Cerruti's point
    /// solution integrated over each pixel), convolved on a zero-padded (2ny, 2nx) grid.
    pub fn free(ny: usize, nx: usize, (lx, ly): (f64, f64), c: ShearCompliance) -> Self {
        let (py, px) = (2 * ny, 2 * nx);
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let (ha, hb) = (dx / 2.0, dy / 2.0);
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut coefficients = [vec![0.0; py * px], vec![0.0; py * px], vec![0.0; py * px]];
        for i in 0..py {
            let oy = if i <= ny { i as f64 } else { i as f64 - py as f64 } * dy;
            for j in 0..px {
                let ox = if j <= nx { j as f64 } else { j as f64 - px as f64 } * dx;
                let k = i * px + j;
                let l1 = love_rectangle(ox, oy, ha, hb);
                coefficients[0][k] = ((c.a - c.b) * l1 + c.b * rectangle(cerruti_xx, ox, oy, ha, hb)) / two_pi;
                coefficients[2][k] = ((c.a - c.b) * l1 + c.b * rectangle(cerruti_yy, ox, oy, ha, hb)) / two_pi;
                // Odd in each offset: left zero on the offsets ±n the window never needs, so
                // that the spectrum is real.
                if i != ny && j != nx {
                    coefficients[1][k] = c.b * rectangle(cerruti_xy, ox, oy, ha, hb) / two_pi;
                }
            }
        }
        let fft = Fft2::new(py, px);
        let mut spectrum = fft.make_spectrum();
        let mut work = fft.make_work();
        let norm = 1.0 / (py * px) as f64;
        let kernel = coefficients.map(|coefficient| {
            fft.forward(&coefficient, py, px, &mut spectrum, &mut work);
            spectrum.iter().map(|s| s.re * norm).collect()
        });
        Self::with_kernels(ny, nx, fft, kernel)
    }

    /// The operator restricted to a box of (by, bx) points of an (ny, nx) window of size
    /// (lx, ly) \[m]: exact for tractions and displacements inside the box, on a grid no larger
    /// than the box's offsets need. Free boundary: the free operator of the box itself.
    /// Periodic: the window's periodic kernel in real space, kept for the offsets inside the
    /// box and convolved on a zero-padded grid along each axis where the box is at most half
    /// the window (along the others the window's own periodic grid). A contact set much
    /// smaller than the window then costs transforms of its own size. Its fields
    /// ([`shape`](Self::shape)) are the box, in the grid's corner: the row transforms skip
    /// the rows outside it.
    pub fn window(
        (ny, nx): (usize, usize),
        (lx, ly): (f64, f64),
        c: ShearCompliance,
        boundary: Boundary,
        (by, bx): (usize, usize),
    ) -> Self {
        assert!(by >= 1 && bx >= 1 && by <= ny && bx <= nx, "box {by}×{bx} in a {ny}×{nx} window");
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        if boundary == Boundary::Free {
            // The padded grid of the box must be at least 2 wide for the real transform.
            let bx = bx.max(2).min(nx);
            return Self::free(by, bx, (bx as f64 * dx, by as f64 * dy), c);
        }
        // Padded length along an axis, or None when the window's periodic grid is as small.
        let padded = |b: usize, n: usize| Some(fast_length(2 * b)).filter(|&p| p < n);
        let (py, px) = (padded(by, ny), padded(bx, nx));
        if py.is_none() && px.is_none() {
            // The window's own grid; the fields are the box only, so that the transforms skip
            // the rows outside it.
            let mut whole = Self::periodic(ny, nx, (lx, ly), c);
            (whole.ny, whole.nx) = (by, bx);
            return whole;
        }
        let (gy, gx) = (py.unwrap_or(ny), px.unwrap_or(nx));
        // The periodic kernel in real space: responses to a unit traction at the origin.
        let mut full = Self::periodic(ny, nx, (lx, ly), c);
        let mut unit = vec![0.0; ny * nx];
        unit[0] = 1.0;
        let zero = vec![0.0; ny * nx];
        let (mut g_xx, mut g_xy, mut g_yx, mut g_yy) =
            (vec![0.0; ny * nx], vec![0.0; ny * nx], vec![0.0; ny * nx], vec![0.0; ny * nx]);
        full.apply([&unit, &zero], [&mut g_xx, &mut g_yx]);
        full.apply([&zero, &unit], [&mut g_xy, &mut g_yy]);
        drop(full);
        // Offset of padded index i along an axis of padded length p, box b, window n; None
        // where no pair of points in the box is that far apart.
        let offset = |i: usize, p: usize, b: usize, n: usize| -> Option<usize> {
            if p == n || i < b {
                Some(i)
            } else if i > p - b {
                Some(n - (p - i))
            } else {
                None
            }
        };
        let mut coefficients = [vec![0.0; gy * gx], vec![0.0; gy * gx], vec![0.0; gy * gx]];
        for i in 0..gy {
            let Some(oy) = offset(i, gy, by, ny) else { continue };
            for j in 0..gx {
                let Some(ox) = offset(j, gx, bx, nx) else { continue };
                let (k, w) = (i * gx + j, oy * nx + ox);
                coefficients[0][k] = g_xx[w];
                // The cross kernel is symmetric (xy = yx); average the two round-offs.
                coefficients[1][k] = 0.5 * (g_xy[w] + g_yx[w]);
                coefficients[2][k] = g_yy[w];
            }
        }
        let fft = Fft2::new(gy, gx);
        let mut spectrum = fft.make_spectrum();
        let mut work = fft.make_work();
        let norm = 1.0 / (gy * gx) as f64;
        // Even (xx, yy) and odd in each offset (xy) kernels: real spectra.
        let kernel = coefficients.map(|coefficient| {
            fft.forward(&coefficient, gy, gx, &mut spectrum, &mut work);
            spectrum.iter().map(|s| s.re * norm).collect()
        });
        Self::with_kernels(by, bx, fft, kernel)
    }

    fn with_kernels(ny: usize, nx: usize, fft: Fft2, values: [Vec<f64>; 3]) -> Self {
        let kernel = values.map(|v| {
            let mut k = large_buffer(v.len(), 0.0);
            k.copy_from_slice(&v);
            k
        });
        let spectrum = [fft.make_spectrum(), fft.make_spectrum()];
        let works = [fft.make_work(), fft.make_work()];
        TangentialInfluence { ny, nx, fft, kernel, spectrum, works, rows: Vec::new() }
    }

    /// The same operator in single precision: its kernels rounded to `f32`, transforms in
    /// `f32` (relative round-off about 1e-6 against 1e-15).
    pub fn single(&self) -> TangentialInfluence<f32> {
        let (gy, gx) = self.fft.shape();
        let fft = Fft2::<f32>::new(gy, gx);
        let kernel = self.kernel.each_ref().map(|k| {
            let mut v = large_buffer(k.len(), 0.0f32);
            v.iter_mut().zip(k).for_each(|(v, k)| *v = *k as f32);
            v
        });
        let spectrum = [fft.make_spectrum(), fft.make_spectrum()];
        let works = [fft.make_work(), fft.make_work()];
        TangentialInfluence { ny: self.ny, nx: self.nx, fft, kernel, spectrum, works, rows: self.rows.clone() }
    }

    /// The inverse operator (the traction under a unit displacement) near the origin: its
    /// coefficients (xx, xy, yy) [Pa/m] at the offsets (dy, dx) of the fields' points with
    /// |dy|, |dx| ≤ `radius`, from the inverse of the kernel at every wavevector (a mode the
    /// kernel leaves out, such as the periodic k = 0, is left out of the inverse too).
    pub fn inverse_near(&self, radius: usize) -> Vec<((i64, i64), [f64; 3])> {
        let (gy, gx) = self.fft.shape();
        let norm = 1.0 / (gy * gx) as f64;
        let [kxx, kxy, kyy] = &self.kernel;
        let mut kernel = [kxx.clone(), kxy.clone(), kyy.clone()];
        for i in 0..kxx.len() {
            let (a, b, c) = (kxx[i], kxy[i], kyy[i]);
            let det = a * c - b * b;
            // The kernels hold the transform's normalisation once; their inverse must too.
            let s = if det > 0.0 { norm * norm / det } else { 0.0 };
            kernel[0][i] = c * s;
            kernel[1][i] = -b * s;
            kernel[2][i] = a * s;
        }
        let mut inverse = TangentialInfluence::with_kernels(self.ny, self.nx, Fft2::new(gy, gx), kernel);
        let near = inverse.offsets();
        let r = radius as i64;
        (-r..=r)
            .flat_map(|dy| (-r..=r).map(move |dx| (dy, dx)))
            .filter(|&(dy, dx)| dy.unsigned_abs() < self.ny as u64 && dx.unsigned_abs() < self.nx as u64)
            .map(|(dy, dx)| ((dy, dx), near.at(dy, dx)))
            .collect()
    }

    /// The coefficients (xx, xy, yy) at every offset of two points of the fields, from the
    /// responses to unit tractions at their corner (every row transformed, as before
    /// [`only_rows`](Self::only_rows)).
    pub fn offsets(&mut self) -> Offsets {
        assert!(self.rows.is_empty(), "every row's response");
        let (ny, nx) = (self.ny, self.nx);
        let mut unit = vec![0.0; ny * nx];
        unit[0] = 1.0;
        let zero = vec![0.0; ny * nx];
        let [mut xx, mut yx, mut xy, mut yy] = std::array::from_fn(|_| vec![0.0; ny * nx]);
        self.apply([&unit, &zero], [&mut xx, &mut yx]);
        self.apply([&zero, &unit], [&mut xy, &mut yy]);
        // The cross kernel is symmetric (xy = yx); average the two round-offs.
        xy.iter_mut().zip(&yx).for_each(|(a, b)| *a = 0.5 * (*a + b));
        let table = (0..ny * nx).map(|k| [xx[k], xy[k], yy[k]]).collect();
        Offsets { nx, table }
    }

    /// From now on take the tractions outside the rows marked in `rows` (one flag per row of
    /// the fields) as zero and leave the displacements there unwritten: their row transforms
    /// are skipped (the contact points of a rough contact lie in fewer than half of their
    /// bounding box's rows at 1500², 10 mN).
    pub fn only_rows(&mut self, rows: Vec<bool>) {
        assert_eq!(rows.len(), self.ny, "one flag per row");
        self.rows = rows;
    }
}

impl<T: FftNum + Into<f64>> TangentialInfluence<T> {
    /// Shape (ny, nx) of its fields: the window's, or the box's of [`window`](Self::window).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Points of the grid its transforms run on (the window's, or its zero-padded one).
    pub fn transform_points(&self) -> usize {
        let (ny, nx) = self.fft.shape();
        ny * nx
    }

    /// Displacements (u_x, u_y) \[m] of the window's points under the shear traction
    /// (q_x, q_y) \[Pa], all row-major (ny, nx), computed in the precision T; only in the rows
    /// of [`only_rows`](Self::only_rows) once it is set.
    pub fn apply(&mut self, q: [&[f64]; 2], u: [&mut [f64]; 2]) {
        let TangentialInfluence { ny, nx, fft, kernel, spectrum, works, rows } = self;
        let (ny, nx) = (*ny, *nx);
        let rows: &[bool] = rows;
        let live = |y: usize| rows.get(y).is_none_or(|l| *l);
        for (q, work) in q.into_iter().zip(works.iter_mut()) {
            let split = |st, mid| split_rows(st, mid, nx);
            fft.forward_rows(ny, work, (0, q), split, |(first, rows), y, line| {
                if !live(y) {
                    return false;
                }
                let row = &rows[(y - *first) * nx..][..nx];
                line[..nx].iter_mut().zip(row).for_each(|(l, v)| *l = T::from_f64(*v).expect("a float converts"));
                true
            });
        }
        // The kernel's rows (one qx, all qy) beside the spectra's, in the column pass.
        let [kxx, kxy, kyy] = &*kernel;
        let gy = fft.shape().0;
        let [sx, sy] = spectrum;
        let [wx, wy] = works;
        fft.convolve_columns([&mut *wx, &mut *wy], [&mut *sx, &mut *sy], |kx, x, y| {
            let at = kx * gy..(kx + 1) * gy;
            let kernels = kxx[at.clone()].iter().zip(&kxy[at.clone()]).zip(&kyy[at]);
            for ((x, y), ((kxx, kxy), kyy)) in x.iter_mut().zip(y.iter_mut()).zip(kernels) {
                let (a, b) = (*x, *y);
                *x = a * *kxx + b * *kxy;
                *y = a * *kxy + b * *kyy;
            }
        });
        for (s, u) in [sx, sy].into_iter().zip(u) {
            let split = |st, mid| split_rows_mut(st, mid, nx);
            fft.inverse_rows(s, ny, live, wx, (0, u), split, |(first, rows), y, line| {
                let row = &mut rows[(y - *first) * nx..][..nx];
                row.iter_mut().zip(&line[..nx]).for_each(|(v, l)| *v = (*l).into());
            });
        }
    }
}

/// The smallest length ≥ n whose only prime factors are 2, 3, 5 and 7 (fast transforms).
fn fast_length(n: usize) -> usize {
    (n.max(2)..)
        .find(|&m| {
            let mut r = m;
            for f in [2, 3, 5, 7] {
                while r % f == 0 {
                    r /= f;
                }
            }
            r == 1
        })
        .expect("a 7-smooth number follows every n")
}

/// ∫∫ f over the rectangle [−a, a] × [−b, b] seen from (x, y), from a primitive F of f in
/// both variables.
fn rectangle(primitive: fn(f64, f64) -> f64, x: f64, y: f64, a: f64, b: f64) -> f64 {
    primitive(x + a, y + b) - primitive(x + a, y - b) - primitive(x - a, y + b) + primitive(x - a, y - b)
}

/// A primitive of X²/r³ in X and Y: Y·asinh(X/|Y|) (zero on Y = 0).
fn cerruti_xx(x: f64, y: f64) -> f64 {
    if y == 0.0 {
        0.0
    } else {
        y * (x / y.abs()).asinh()
    }
}

/// A primitive of Y²/r³ in X and Y.
fn cerruti_yy(x: f64, y: f64) -> f64 {
    cerruti_xx(y, x)
}

/// A primitive of XY/r³ in X and Y: −r.
fn cerruti_xy(x: f64, y: f64) -> f64 {
    -x.hypot(y)
}

/// The free boundary's influence coefficients [m/Pa]: the displacement at every offset of
/// the padded (2ny, 2nx) grid, wrapped, under a unit pressure on one pixel of an (ny, nx)
/// window of size (lx, ly) [m]. They are even in both offsets, so their spectrum is real.
pub(crate) fn free_coefficients(ny: usize, nx: usize, (lx, ly): (f64, f64), e_star: f64) -> Vec<f64> {
    let (py, px) = (2 * ny, 2 * nx);
    let (dx, dy) = (lx / nx as f64, ly / ny as f64);
    let mut coefficients = large_buffer(py * px, 0.0);
    coefficients.par_chunks_exact_mut(px).enumerate().for_each(|(i, row)| {
        let oy = if i <= ny { i as f64 } else { i as f64 - py as f64 };
        for (j, c) in row.iter_mut().enumerate() {
            let ox = if j <= nx { j as f64 } else { j as f64 - px as f64 };
            *c = love_rectangle(ox * dx, oy * dy, dx / 2.0, dy / 2.0) / (std::f64::consts::PI * e_star);
        }
    });
    coefficients
}

/// ∫∫ dx' dy' / r over the rectangle [−a, a] × [−b, b], seen from the point (x, y) [m²/m = m].
/// Times p / (π E*), it is the surface displacement under a uniform pressure p on the rectangle
/// (Love's solution).
fn love_rectangle(x: f64, y: f64, a: f64, b: f64) -> f64 {
    corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) + corner(x - a, y - b)
}

/// A primitive F(X, Y) of 1/√(X² + Y²) in both variables, valid in every quadrant: the
/// first-quadrant integral X·asinh(Y/X) + Y·asinh(X/Y) extended oddly in X and in Y.
fn corner(x: f64, y: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    if ax == 0.0 || ay == 0.0 {
        return 0.0;
    }
    x.signum() * y.signum() * (ax * (ay / ax).asinh() + ay * (ax / ay).asinh())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn love_centre_of_a_square_is_johnsons_closed_form() {
        // Johnson (3.25): centre of a square of side 2a: ∫∫ 1/r = 8 a ln(1 + √2).
        let a = 0.7;
        let want = 8.0 * a * (1.0 + 2f64.sqrt()).ln();
        assert!((love_rectangle(0.0, 0.0, a, a) - want).abs() < 1e-14 * want);
    }

    #[test]
    fn love_far_field_is_a_point_force() {
        // Far away, the rectangle acts as a point load of area 4ab: ∫∫ 1/r → 4ab / r.
        let (a, b) = (0.5, 0.25);
        for &(x, y) in &[(40.0, 3.0), (-25.0, 30.0), (0.0, -60.0)] {
            let r: f64 = f64::hypot(x, y);
            let got = love_rectangle(x, y, a, b);
            assert!((got - 4.0 * a * b / r).abs() < 1e-3 * got, "{got} at ({x},{y})");
        }
    }

    #[test]
    fn periodic_operator_on_a_sinusoid_is_westergaard() {
        // p = cos(2πx/λ) ⇒ u = 2/(E* q) cos(2πx/λ), q = 2π/λ.
        let (ny, nx, lx, ly, e) = (4, 32, 2e-6, 0.25e-6, 1e11);
        let mut op = Influence::periodic(ny, nx, (lx, ly), e);
        let p: Vec<f64> =
            (0..ny * nx).map(|i| (2.0 * std::f64::consts::PI * (i % nx) as f64 / nx as f64).cos()).collect();
        let mut u = vec![0.0; ny * nx];
        op.apply(&p, &mut u);
        let amp = 2.0 / (e * 2.0 * std::f64::consts::PI / lx);
        for (ui, pi) in u.iter().zip(&p) {
            assert!((ui - amp * pi).abs() < 1e-12 * amp);
        }
    }

    #[test]
    fn free_operator_matches_direct_summation() {
        let (ny, nx, lx, ly, e) = (5, 7, 7e-6, 4e-6, 2e11);
        let mut op = Influence::free(ny, nx, (lx, ly), e);
        let p: Vec<f64> = (0..ny * nx).map(|i| ((i * 37) % 11) as f64 * 1e6).collect();
        let mut u = vec![0.0; ny * nx];
        op.apply(&p, &mut u);
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        for i in 0..ny {
            for j in 0..nx {
                let mut want = 0.0;
                for k in 0..ny {
                    for l in 0..nx {
                        let (ox, oy) = ((j as f64 - l as f64) * dx, (i as f64 - k as f64) * dy);
                        want += p[k * nx + l] * love_rectangle(ox, oy, dx / 2.0, dy / 2.0);
                    }
                }
                want /= std::f64::consts::PI * e;
                assert!((u[i * nx + j] - want).abs() < 1e-12 * want.abs().max(1e-30), "({i},{j})");
            }
        }
    }
}
