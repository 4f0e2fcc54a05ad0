//! The shared FFT engine: 2-D real-to-complex transforms of (ny, nx) fields.
//!
//! A [`Fft2`] is a reusable plan; the buffers it works in ([`Fft2Work`]) and the spectra belong
//! to the caller, so iterative solvers transform many times without allocating. Spectra are
//! stored *transposed*, shape (nx/2 + 1, ny): row = qx, column = qy. That saves one transpose
//! per direction; pointwise operators (influence kernels, filters) only need to agree on it,
//! which [`Fft2::wavevectors`] makes easy.
//!
//! Transforms are unnormalised (`inverse(forward(f)) = nx·ny·f`); kernels fold the 1/(nx·ny) in.
//! Inputs may be smaller than the grid (zero-padded, for the free half-space) and outputs
//! cropped, which skips the rows that are known to be zero or not wanted.

use std::sync::Arc;

use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

/// A plan for 2-D real FFTs on an (ny, nx) grid.
pub struct Fft2 {
    ny: usize,
    nx: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_forward: Arc<dyn Fft<f64>>,
    col_inverse: Arc<dyn Fft<f64>>,
    /// Number of parallel tasks, one scratch slot each.
    tasks: usize,
}

/// Working memory for one [`Fft2`], owned by the caller and reused across transforms.
pub struct Fft2Work {
    /// Half spectrum in natural layout (ny, nx/2 + 1), between the row and column passes.
    rows: Vec<Complex64>,
    /// One real line of length nx per task.
    lines: Vec<f64>,
    /// FFT scratch, one slot per task.
    scratch: Vec<Complex64>,
    scratch_len: usize,
}

impl Fft2 {
    /// Plan transforms for an (ny, nx) grid.
    pub fn new(ny: usize, nx: usize) -> Self {
        assert!(ny >= 1 && nx >= 2, "FFT grid must be at least 1×2, got {ny}×{nx}");
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        Fft2 {
            ny,
            nx,
            r2c: real.plan_fft_forward(nx),
            c2r: real.plan_fft_inverse(nx),
            col_forward: complex.plan_fft_forward(ny),
            col_inverse: complex.plan_fft_inverse(ny),
            tasks: rayon::current_num_threads().max(1),
        }
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Number of complex values in a spectrum: (nx/2 + 1)·ny.
    pub fn spectrum_len(&self) -> usize {
        self.nxh() * self.ny
    }

    fn nxh(&self) -> usize {
        self.nx / 2 + 1
    }

    /// A zeroed spectrum buffer.
    pub fn make_spectrum(&self) -> Vec<Complex64> {
        vec![Complex64::default(); self.spectrum_len()]
    }

    /// Working memory for this plan.
    pub fn make_work(&self) -> Fft2Work {
        let scratch_len = [
            self.r2c.get_scratch_len(),
            self.c2r.get_scratch_len(),
            self.col_forward.get_inplace_scratch_len(),
            self.col_inverse.get_inplace_scratch_len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0)
        .max(1);
        Fft2Work {
            rows: vec![Complex64::default(); self.ny * self.nxh()],
            lines: vec![0.0; self.tasks * self.nx],
            scratch: vec![Complex64::default(); self.tasks * scratch_len],
            scratch_len,
        }
    }

    /// Integer wavenumbers (kx, ky) of each spectrum entry, in spectrum order (transposed:
    /// kx outer, ky inner); ky is folded to the signed range (−ny/2, ny/2].
    pub fn wavevectors(&self) -> impl Iterator<Item = (usize, i64)> + '_ {
        let ny = self.ny as i64;
        (0..self.nxh()).flat_map(move |kx| (0..ny).map(move |j| (kx, if j <= ny / 2 { j } else { j - ny })))
    }

    /// Forward transform of `input` (shape (in_ny, in_nx), placed at the grid's top-left corner,
    /// zeros elsewhere) into `spectrum` (transposed layout).
    pub fn forward(&self, input: &[f64], in_ny: usize, in_nx: usize, spectrum: &mut [Complex64], work: &mut Fft2Work) {
        let (ny, nx, nxh) = (self.ny, self.nx, self.nxh());
        assert!(in_ny <= ny && in_nx <= nx && input.len() == in_ny * in_nx);
        assert_eq!(spectrum.len(), self.spectrum_len());
        let Fft2Work { rows, lines, scratch, scratch_len } = work;
        let (live, zero) = rows.split_at_mut(in_ny * nxh);
        zero.par_iter_mut().for_each(|c| *c = Complex64::default());
        let rows_per_task = in_ny.div_ceil(self.tasks).max(1);
        live.par_chunks_mut(rows_per_task * nxh)
            .zip(input.par_chunks(rows_per_task * in_nx))
            .zip(lines.par_chunks_mut(nx).zip(scratch.par_chunks_mut(*scratch_len)))
            .for_each(|((out, inp), (line, scr))| {
                for (o, i) in out.chunks_exact_mut(nxh).zip(inp.chunks_exact(in_nx)) {
                    line[..in_nx].copy_from_slice(i);
                    line[in_nx..].fill(0.0);
                    self.r2c.process_with_scratch(line, o, scr).expect("buffer sizes match the plan");
                }
            });
        transpose(rows, ny, nxh, spectrum, self.tasks);
        self.columns(spectrum, &*self.col_forward, scratch, *scratch_len);
    }

    /// Inverse transform of `spectrum` (destroyed) into `output` (shape (out_ny, out_nx), the
    /// grid's top-left corner). Unnormalised.
    pub fn inverse(
        &self,
        spectrum: &mut [Complex64],
        output: &mut [f64],
        out_ny: usize,
        out_nx: usize,
        work: &mut Fft2Work,
    ) {
        let (ny, nx, nxh) = (self.ny, self.nx, self.nxh());
        assert!(out_ny <= ny && out_nx <= nx && output.len() == out_ny * out_nx);
        assert_eq!(spectrum.len(), self.spectrum_len());
        let Fft2Work { rows, lines, scratch, scratch_len } = work;
        self.columns(spectrum, &*self.col_inverse, scratch, *scratch_len);
        let live = &mut rows[..out_ny * nxh];
        transpose_rows(spectrum, nxh, ny, live, out_ny, self.tasks);
        let rows_per_task = out_ny.div_ceil(self.tasks).max(1);
        live.par_chunks_mut(rows_per_task * nxh)
            .zip(output.par_chunks_mut(rows_per_task * out_nx))
            .zip(lines.par_chunks_mut(nx).zip(scratch.par_chunks_mut(*scratch_len)))
            .for_each(|((inp, out), (line, scr))| {
                for (i, o) in inp.chunks_exact_mut(nxh).zip(out.chunks_exact_mut(out_nx)) {
                    // The field is real: round-off in the imaginary parts of the real-valued
                    // modes (qx = 0 and the Nyquist column) is dropped, as it must be.
                    i[0].im = 0.0;
                    if nx % 2 == 0 {
                        i[nxh - 1].im = 0.0;
                    }
                    self.c2r.process_with_scratch(i, line, scr).expect("buffer sizes match the plan");
                    o.copy_from_slice(&line[..out_nx]);
                }
            });
    }

    /// Complex FFTs along qy: every row of the transposed spectrum.
    fn columns(&self, spectrum: &mut [Complex64], fft: &dyn Fft<f64>, scratch: &mut [Complex64], scratch_len: usize) {
        let per_task = self.nxh().div_ceil(self.tasks).max(1) * self.ny;
        spectrum.par_chunks_mut(per_task).zip(scratch.par_chunks_mut(scratch_len)).for_each(|(chunk, scr)| {
            let need = fft.get_inplace_scratch_len();
            fft.process_with_scratch(chunk, &mut scr[..need]);
        });
    }
}

/// Transpose `src` (rows × cols) into `dst` (cols × rows), in parallel over bands of `dst` rows.
fn transpose(src: &[Complex64], rows: usize, cols: usize, dst: &mut [Complex64], tasks: usize) {
    transpose_rows(src, rows, cols, dst, cols, tasks)
}

/// Transpose the first `keep` columns of `src` (rows × cols) into `dst` (keep × rows).
fn transpose_rows(src: &[Complex64], rows: usize, cols: usize, dst: &mut [Complex64], keep: usize, tasks: usize) {
    const TILE: usize = 32;
    debug_assert_eq!(dst.len(), keep * rows);
    let band = keep.div_ceil(tasks * 4).max(1);
    dst.par_chunks_mut(band * rows).enumerate().for_each(|(b, out)| {
        let c0 = b * band;
        let nc = out.len() / rows;
        for r0 in (0..rows).step_by(TILE) {
            let r1 = (r0 + TILE).min(rows);
            for c in 0..nc {
                let o = &mut out[c * rows + r0..c * rows + r1];
                for (k, v) in o.iter_mut().enumerate() {
                    *v = src[(r0 + k) * cols + c0 + c];
                }
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(ny: usize, nx: usize) -> Vec<f64> {
        (0..ny * nx).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.3 + (i as f64 * 0.01).sin()).collect()
    }

    /// Direct DFT of one mode, for comparison.
    fn dft(f: &[f64], ny: usize, nx: usize, kx: usize, ky: usize) -> Complex64 {
        let mut s = Complex64::default();
        for y in 0..ny {
            for x in 0..nx {
                let ph = -2.0 * std::f64::consts::PI * ((kx * x) as f64 / nx as f64 + (ky * y) as f64 / ny as f64);
                s += f[y * nx + x] * Complex64::new(ph.cos(), ph.sin());
            }
        }
        s
    }

    #[test]
    fn forward_matches_direct_dft_on_odd_and_even_rectangles() {
        for &(ny, nx) in &[(6, 10), (7, 5), (1, 8), (9, 12)] {
            let plan = Fft2::new(ny, nx);
            let mut work = plan.make_work();
            let mut spec = plan.make_spectrum();
            let f = field(ny, nx);
            plan.forward(&f, ny, nx, &mut spec, &mut work);
            for kx in 0..nx / 2 + 1 {
                for ky in 0..ny {
                    let want = dft(&f, ny, nx, kx, ky);
                    let got = spec[kx * ny + ky];
                    assert!((got - want).norm() < 1e-9, "{ny}x{nx} mode ({kx},{ky}): {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn round_trip_with_padding_and_cropping() {
        let (ny, nx) = (10, 14);
        let (iny, inx) = (5, 7);
        let plan = Fft2::new(ny, nx);
        let mut work = plan.make_work();
        let mut spec = plan.make_spectrum();
        let f = field(iny, inx);
        plan.forward(&f, iny, inx, &mut spec, &mut work);
        // Padding with zeros: compare with the transform of the explicitly padded field.
        let mut padded = vec![0.0; ny * nx];
        for y in 0..iny {
            padded[y * nx..y * nx + inx].copy_from_slice(&f[y * inx..(y + 1) * inx]);
        }
        assert!((spec[3 * ny + 2] - dft(&padded, ny, nx, 3, 2)).norm() < 1e-9);
        let mut out = vec![0.0; iny * inx];
        plan.inverse(&mut spec, &mut out, iny, inx, &mut work);
        for (o, i) in out.iter().zip(&f) {
            assert!((o / (ny * nx) as f64 - i).abs() < 1e-12);
        }
    }
}
