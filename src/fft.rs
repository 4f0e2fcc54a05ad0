//! The shared FFT engine: 2-D real-to-complex transforms of (ny, nx) fields.
//!
//! A [`Fft2`] is a reusable plan; the buffers it works in ([`Fft2Work`]) and the spectra belong
//! to the caller, so iterative solvers transform many times without allocating. Spectra are
//! stored *transposed*, shape (nx/2 + 1, ny): row = qx, column = qy. Pointwise operators
//! (influence kernels, filters) only need to agree on it, which [`Fft2::wavevectors`] makes
//! easy.
//!
//! A transform is a row pass (real FFTs along x) and a column pass (complex FFTs along y). The
//! transpose between them is done a few rows or columns at a time inside the passes, so that
//! data is reorganised while it is in cache rather than in a pass of its own. Both passes
//! take caller code ([`Fft2::forward_rows`], [`Fft2::forward_columns`],
//! [`Fft2::inverse_columns`], [`Fft2::inverse_rows`]) so that iterative solvers compute their
//! fields as they go instead of streaming them through memory once more; a convolution of two
//! fields runs its forward and inverse column passes as one ([`Fft2::convolve_columns`]).
//!
//! Transforms are unnormalised (`inverse(forward(f)) = nx·ny·f`); kernels fold the 1/(nx·ny) in.
//! Inputs may be smaller than the grid (zero-padded, for the free half-space) and outputs
//! cropped, which skips the rows that are known to be zero or not wanted.
//!
//! Imports nothing of the crate; must not import topography, contact, friction, study, report,
//! plot, shs, cli.

use std::ops::Range;
use std::sync::Arc;

use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::num_complex::Complex;
use rustfft::num_traits::Zero;
use rustfft::{Fft, FftNum, FftPlanner};

/// Spectrum rows (qx) transposed and transformed together in the column passes: 16 rows of
/// 1500 values are 384 KiB, at home in L2.
const BAND: usize = 16;

/// Grid rows gathered together from the transposed spectrum in the inverse row pass: four
/// complex values fill one cache line.
const GROUP: usize = 8;

/// A plan for 2-D real FFTs on an (ny, nx) grid, in double (`f64`, the default) or single
/// (`f32`) precision.
pub struct Fft2<T: FftNum = f64> {
    ny: usize,
    nx: usize,
    r2c: Arc<dyn RealToComplex<T>>,
    c2r: Arc<dyn ComplexToReal<T>>,
    col_forward: Arc<dyn Fft<T>>,
    col_inverse: Arc<dyn Fft<T>>,
    /// Number of parallel tasks, one work slot each.
    tasks: usize,
}

/// Working memory for one [`Fft2`], owned by the caller and reused across transforms.
pub struct Fft2Work<T: FftNum = f64> {
    /// Half spectrum in natural layout (ny, nx/2 + 1), between the forward row and column passes.
    half: Vec<Complex<T>>,
    /// Whether each row of `half` holds anything: the others are zero, whatever `half` holds
    /// there, and the column pass does not read them.
    nonzero: Vec<bool>,
    /// One slot per task.
    slots: Vec<Slot<T>>,
}

/// The buffers of one task.
struct Slot<T> {
    /// A real grid row (nx).
    line: Vec<T>,
    /// FFT scratch.
    scratch: Vec<Complex<T>>,
    /// [`GROUP`] rows of the half spectrum, natural layout.
    group: Vec<Complex<T>>,
}

impl<T: FftNum> Fft2<T> {
    /// Plan transforms for an (ny, nx) grid.
    pub fn new(ny: usize, nx: usize) -> Self {
        assert!(ny >= 1 && nx >= 2, "FFT grid must be at least 1×2, got {ny}×{nx}");
        let mut real = RealFftPlanner::<T>::new();
        let mut complex = FftPlanner::<T>::new();
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
    pub fn make_spectrum(&self) -> Vec<Complex<T>> {
        large_buffer(self.spectrum_len(), Complex::zero())
    }

    /// Working memory for this plan.
    pub fn make_work(&self) -> Fft2Work<T> {
        let scratch = [
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
            half: large_buffer(self.ny * self.nxh(), Complex::zero()),
            nonzero: vec![false; self.ny],
            slots: (0..self.tasks)
                .map(|_| Slot {
                    line: vec![T::zero(); self.nx],
                    scratch: vec![Complex::zero(); scratch],
                    group: vec![Complex::zero(); GROUP * self.nxh()],
                })
                .collect(),
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
    pub fn forward(
        &self,
        input: &[T],
        in_ny: usize,
        in_nx: usize,
        spectrum: &mut [Complex<T>],
        work: &mut Fft2Work<T>,
    ) {
        assert!(in_ny <= self.ny && in_nx <= self.nx && input.len() == in_ny * in_nx);
        self.forward_rows(
            in_ny,
            work,
            (0, input),
            |st, mid| split_rows(st, mid, in_nx),
            |(first, rows), y, line| {
                line[..in_nx].copy_from_slice(&rows[(y - *first) * in_nx..][..in_nx]);
                true
            },
        );
        self.forward_columns(work, spectrum, |_, _| (), &mut []);
    }

    /// Inverse transform of `spectrum` (destroyed) into `output` (shape (out_ny, out_nx), the
    /// grid's top-left corner). Unnormalised.
    pub fn inverse(
        &self,
        spectrum: &mut [Complex<T>],
        output: &mut [T],
        out_ny: usize,
        out_nx: usize,
        work: &mut Fft2Work<T>,
    ) {
        assert!(out_ny <= self.ny && out_nx <= self.nx && output.len() == out_ny * out_nx);
        self.inverse_columns(spectrum, work, |_, _| ());
        let split = |st, mid| split_rows_mut(st, mid, out_nx);
        self.inverse_rows(
            spectrum,
            out_ny,
            |_| true,
            work,
            (0, output),
            split,
            |(first, rows), y, line| {
                rows[(y - *first) * out_nx..][..out_nx].copy_from_slice(&line[..out_nx]);
            },
        );
    }

    /// The row pass of a forward transform, the first half of [`Fft2::forward`] for callers
    /// that compute their input as they go. Rows `0..rows` are cut into one block per task;
    /// `split(state, row)` cuts the caller's `state` the same way (into the parts for the rows
    /// below `row` and from `row` on). `fill(state, y, line)` writes row y into `line` (zeroed,
    /// length nx) and returns whether the row holds anything; rows from `rows` on are zero.
    pub fn forward_rows<S: Send>(
        &self,
        rows: usize,
        work: &mut Fft2Work<T>,
        state: S,
        split: impl Fn(S, usize) -> (S, S) + Sync,
        fill: impl Fn(&mut S, usize, &mut [T]) -> bool + Sync,
    ) {
        let nxh = self.nxh();
        assert!(rows <= self.ny);
        let (nonzero, zero) = work.nonzero.split_at_mut(rows);
        zero.fill(false);
        row_blocks(
            0..rows,
            &mut work.slots,
            (state, ((0, &mut work.half[..rows * nxh]), (0, nonzero))),
            &|(s, (out, flags)), mid| {
                let (a, b) = split(s, mid);
                let (oa, ob) = split_rows_mut(out, mid, nxh);
                let (fa, fb) = split_rows_mut(flags, mid, 1);
                ((a, (oa, fa)), (b, (ob, fb)))
            },
            &|ys, (mut s, ((first, out), (_, flags))), slot| {
                for y in ys {
                    slot.line.fill(T::zero());
                    let o = &mut out[(y - first) * nxh..][..nxh];
                    let holds = fill(&mut s, y, &mut slot.line);
                    if holds {
                        self.r2c
                            .process_with_scratch(&mut slot.line, o, &mut slot.scratch)
                            .expect("buffer sizes match the plan");
                    }
                    flags[y - first] = holds;
                }
            },
        );
    }

    /// The column pass of a forward transform, after [`Fft2::forward_rows`]: the spectrum,
    /// transposed. Then `each(kx, row)` sees every spectrum row (all qy of one qx) while it is
    /// in cache; its results are stored in `out[kx]` (an empty `out` keeps none).
    pub fn forward_columns<A: Send>(
        &self,
        work: &mut Fft2Work<T>,
        spectrum: &mut [Complex<T>],
        each: impl Fn(usize, &mut [Complex<T>]) -> A + Sync,
        out: &mut [A],
    ) {
        let (ny, nxh) = (self.ny, self.nxh());
        assert_eq!(spectrum.len(), self.spectrum_len());
        assert!(out.is_empty() || out.len() == nxh);
        let per_task = nxh.div_ceil(self.tasks);
        let fft = &*self.col_forward;
        let (half, nonzero) = (&work.half, &work.nonzero);
        let run = |task: usize, chunk: &mut [Complex<T>], slot: &mut Slot<T>, mut results: Option<&mut [A]>| {
            let kx0 = task * per_task;
            for (b, band) in chunk.chunks_mut(BAND * ny).enumerate() {
                // This band of the transpose, then its transforms while it is in cache.
                transpose_band(half, nonzero, kx0 + b * BAND, band, ny, nxh);
                for (k, row) in band.chunks_exact_mut(ny).enumerate() {
                    fft.process_with_scratch(row, &mut slot.scratch);
                    let a = each(kx0 + b * BAND + k, row);
                    if let Some(r) = results.as_deref_mut() {
                        r[b * BAND + k] = a;
                    }
                }
            }
        };
        let tasks = spectrum.par_chunks_mut(per_task * ny).zip(work.slots.par_iter_mut()).enumerate();
        if out.is_empty() {
            tasks.for_each(|(task, (chunk, slot))| run(task, chunk, slot, None));
        } else {
            tasks
                .zip(out.par_chunks_mut(per_task))
                .for_each(|((task, (chunk, slot)), r)| run(task, chunk, slot, Some(r)));
        }
    }

    /// The column passes of two fields' forward transforms, a product of their spectra and the
    /// column passes of the inverse transforms, fused: after [`Fft2::forward_rows`] of each
    /// field into its own work, `each(kx, a, b)` replaces the two spectrum rows of one qx
    /// (all qy) by the spectra to invert while they are in cache, and `spectra` receive the
    /// results transformed back along qy (transposed layout), for [`Fft2::inverse_rows`]. The
    /// spectra pass through memory once instead of three times (forward, product, inverse).
    pub fn convolve_columns(
        &self,
        [first, second]: [&mut Fft2Work<T>; 2],
        [sa, sb]: [&mut [Complex<T>]; 2],
        each: impl Fn(usize, &mut [Complex<T>], &mut [Complex<T>]) + Sync,
    ) {
        let (ny, nxh) = (self.ny, self.nxh());
        assert!(sa.len() == self.spectrum_len() && sb.len() == self.spectrum_len());
        let per_task = nxh.div_ceil(self.tasks);
        let Fft2Work { half: ha, nonzero: na, slots } = first;
        let (ha, na, hb, nb) = (&*ha, &*na, &second.half, &second.nonzero);
        let chunks = sa.par_chunks_mut(per_task * ny).zip(sb.par_chunks_mut(per_task * ny));
        chunks.zip(slots.par_iter_mut()).enumerate().for_each(|(task, ((ca, cb), slot))| {
            let bands = ca.chunks_mut(BAND * ny).zip(cb.chunks_mut(BAND * ny));
            for (b, (band_a, band_b)) in bands.enumerate() {
                let kx = task * per_task + b * BAND;
                transpose_band(ha, na, kx, band_a, ny, nxh);
                transpose_band(hb, nb, kx, band_b, ny, nxh);
                self.col_forward.process_with_scratch(band_a, &mut slot.scratch);
                self.col_forward.process_with_scratch(band_b, &mut slot.scratch);
                let rows = band_a.chunks_exact_mut(ny).zip(band_b.chunks_exact_mut(ny));
                rows.enumerate().for_each(|(k, (a, b))| each(kx + k, a, b));
                self.col_inverse.process_with_scratch(band_a, &mut slot.scratch);
                self.col_inverse.process_with_scratch(band_b, &mut slot.scratch);
            }
        });
    }

    /// The column pass of an inverse transform, in place: `each(kx, row)` prepares every
    /// spectrum row (a kernel product, say) before its inverse FFT along qy.
    pub fn inverse_columns(
        &self,
        spectrum: &mut [Complex<T>],
        work: &mut Fft2Work<T>,
        each: impl Fn(usize, &mut [Complex<T>]) + Sync,
    ) {
        let ny = self.ny;
        assert_eq!(spectrum.len(), self.spectrum_len());
        let per_task = self.nxh().div_ceil(self.tasks);
        let fft = &*self.col_inverse;
        spectrum.par_chunks_mut(per_task * ny).zip(work.slots.par_iter_mut()).enumerate().for_each(
            |(task, (chunk, slot))| {
                for (k, row) in chunk.chunks_exact_mut(ny).enumerate() {
                    each(task * per_task + k, row);
                    fft.process_with_scratch(row, &mut slot.scratch);
                }
            },
        );
    }

    /// The row pass of an inverse transform, after [`Fft2::inverse_columns`] on `spectrum`:
    /// `consume(state, y, line)` receives row y (length nx) of the result for each y in
    /// `0..rows` that the caller `wanted` (the others are not transformed), with the caller's
    /// state cut into blocks as in [`Fft2::forward_rows`].
    #[allow(clippy::too_many_arguments)]
    pub fn inverse_rows<S: Send>(
        &self,
        spectrum: &[Complex<T>],
        rows: usize,
        wanted: impl Fn(usize) -> bool + Sync,
        work: &mut Fft2Work<T>,
        state: S,
        split: impl Fn(S, usize) -> (S, S) + Sync,
        consume: impl Fn(&mut S, usize, &[T]) + Sync,
    ) {
        let (ny, nx, nxh) = (self.ny, self.nx, self.nxh());
        assert!(rows <= ny && spectrum.len() == self.spectrum_len());
        row_blocks(0..rows, &mut work.slots, state, &split, &|ys, mut s, slot| {
            let mut next = ys.clone().filter(|&y| wanted(y)).peekable();
            while next.peek().is_some() {
                // A few rows of the transpose at a time: each spectrum row gives one cache line
                // when they are consecutive. That case (every row, as the normal solver wants)
                // keeps its slice copy: gathering it row by row took the sweep 4–6 % longer.
                let mut chosen = [0; GROUP];
                let mut group = 0;
                for y in next.by_ref().take(GROUP) {
                    chosen[group] = y;
                    group += 1;
                }
                let chosen = &chosen[..group];
                if chosen[group - 1] - chosen[0] == group - 1 {
                    for kx in 0..nxh {
                        for (r, v) in spectrum[kx * ny + chosen[0]..][..group].iter().enumerate() {
                            slot.group[r * nxh + kx] = *v;
                        }
                    }
                } else {
                    for kx in 0..nxh {
                        let column = &spectrum[kx * ny..][..ny];
                        for (r, &y) in chosen.iter().enumerate() {
                            slot.group[r * nxh + kx] = column[y];
                        }
                    }
                }
                for (r, &y) in chosen.iter().enumerate() {
                    let row = &mut slot.group[r * nxh..][..nxh];
                    // The field is real: round-off in the imaginary parts of the real-valued
                    // modes (qx = 0 and the Nyquist column) is dropped, as it must be.
                    row[0].im = T::zero();
                    if nx % 2 == 0 {
                        row[nxh - 1].im = T::zero();
                    }
                    self.c2r
                        .process_with_scratch(row, &mut slot.line, &mut slot.scratch)
                        .expect("buffer sizes match the plan");
                    consume(&mut s, y, &slot.line);
                }
            }
        });
    }
}

/// Columns kx0.. of the half spectrum (natural layout (ny, nxh), rows not `nonzero` read as
/// zero) into `band`, transposed: one row of ny values per column, as many as `band` holds.
fn transpose_band<T: FftNum>(
    half: &[Complex<T>],
    nonzero: &[bool],
    kx0: usize,
    band: &mut [Complex<T>],
    ny: usize,
    nxh: usize,
) {
    let width = band.len() / ny;
    for y in 0..ny {
        if nonzero[y] {
            for (k, v) in half[y * nxh + kx0..][..width].iter().enumerate() {
                band[k * ny + y] = *v;
            }
        } else {
            (0..width).for_each(|k| band[k * ny + y] = Complex::zero());
        }
    }
}

/// Rows of `width` values from row `first` on, as the row passes cut them between tasks.
pub type Rows<'a, T> = (usize, &'a [T]);
/// [`Rows`], mutable.
pub type RowsMut<'a, T> = (usize, &'a mut [T]);

/// Cut `(first row, rows of `width` values from it)` at row `mid`: the rows below and from it.
pub fn split_rows<T>((first, rows): Rows<T>, mid: usize, width: usize) -> (Rows<T>, Rows<T>) {
    let (a, b) = rows.split_at((mid - first) * width);
    ((first, a), (mid, b))
}

/// [`split_rows`] for mutable rows.
pub fn split_rows_mut<T>((first, rows): RowsMut<T>, mid: usize, width: usize) -> (RowsMut<T>, RowsMut<T>) {
    let (a, b) = rows.split_at_mut((mid - first) * width);
    ((first, a), (mid, b))
}

/// Run `body(rows, state, slot)` on contiguous blocks of rows, one per slot, in parallel,
/// cutting `state` with `split`.
/// `len` copies of `value` in memory backed by huge pages where the system offers them
/// (Linux, transparent huge pages in `madvise` mode). The column passes stride through whole
/// grids; with 4 KiB pages nearly every row they touch is a TLB miss.
pub fn large_buffer<T: Clone>(len: usize, value: T) -> Vec<T> {
    let mut v = Vec::with_capacity(len);
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let bytes = len * std::mem::size_of::<T>();
        if bytes >= HUGE {
            let start = v.as_mut_ptr() as usize;
            let (first, last) = (start.next_multiple_of(HUGE), (start + bytes) / HUGE * HUGE);
            if last > first {
                // SAFETY: the range lies inside the vector's allocation; the advice changes only
                // how the kernel backs the pages, not their contents. A refusal is harmless.
                unsafe { libc::madvise(first as *mut libc::c_void, last - first, libc::MADV_HUGEPAGE) };
            }
        }
    }
    // Touched only now, after the advice, so the pages are faulted in huge.
    v.resize(len, value);
    v
}

fn row_blocks<S: Send, T: Send>(
    rows: Range<usize>,
    slots: &mut [Slot<T>],
    state: S,
    split: &(impl Fn(S, usize) -> (S, S) + Sync),
    body: &(impl Fn(Range<usize>, S, &mut Slot<T>) + Sync),
) {
    if slots.len() <= 1 || rows.len() <= 1 {
        body(rows, state, &mut slots[0]);
        return;
    }
    let half = slots.len() / 2;
    let mid = rows.start + rows.len() * half / slots.len();
    let (a, b) = split(state, mid);
    let (sa, sb) = slots.split_at_mut(half);
    rayon::join(|| row_blocks(rows.start..mid, sa, a, split, body), || row_blocks(mid..rows.end, sb, b, split, body));
}

#[cfg(test)]
mod tests {
    use super::*;
    use rustfft::num_complex::Complex64;

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

    /// Rows the caller reports empty are zero in the spectrum, whatever an earlier transform
    /// left in the work buffers.
    #[test]
    fn rows_reported_empty_are_zero_after_a_full_transform() {
        let (ny, nx) = (9, 12);
        let plan = Fft2::new(ny, nx);
        let mut work = plan.make_work();
        let mut spec = plan.make_spectrum();
        plan.forward(&field(ny, nx), ny, nx, &mut spec, &mut work);
        let mut f = field(ny, nx);
        let empty = |y: usize| y % 3 == 1;
        for y in (0..ny).filter(|&y| empty(y)) {
            f[y * nx..(y + 1) * nx].fill(0.0);
        }
        plan.forward_rows(
            ny,
            &mut work,
            (0, &f[..]),
            |st, mid| split_rows(st, mid, nx),
            |(first, rows), y, line| {
                line.copy_from_slice(&rows[(y - *first) * nx..][..nx]);
                !empty(y)
            },
        );
        plan.forward_columns(&mut work, &mut spec, |_, _| (), &mut []);
        for kx in 0..nx / 2 + 1 {
            for ky in 0..ny {
                let want = dft(&f, ny, nx, kx, ky);
                assert!((spec[kx * ny + ky] - want).norm() < 1e-9, "mode ({kx},{ky})");
            }
        }
    }

    /// The fused column passes give what the separate ones give: each field's spectrum
    /// (checked against the direct DFT, a row left empty included) through the product, then
    /// the inverse column pass.
    #[test]
    fn fused_column_passes_are_the_separate_ones() {
        let (ny, nx) = (9, 12);
        let plan = Fft2::new(ny, nx);
        let (fa, mut fb) = (field(ny, nx), field(ny, nx).iter().map(|v| 0.5 - v * v).collect::<Vec<_>>());
        fb[4 * nx..5 * nx].fill(0.0);
        // A 2×2 product that differs from mode to mode and mixes the two fields.
        let mix = |kx: usize, ky: usize, a: Complex64, b: Complex64| {
            let (w, c) = (1.0 + (kx * ny + ky) as f64, 0.25 * kx as f64 - 0.1 * ky as f64);
            (a * w + b * c, a * c - b * (2.0 * w))
        };
        let mut works = [plan.make_work(), plan.make_work()];
        for ((f, empty), work) in [(&fa, None), (&fb, Some(4))].into_iter().zip(works.iter_mut()) {
            plan.forward_rows(
                ny,
                work,
                (0, &f[..]),
                |st, mid| split_rows(st, mid, nx),
                |(first, rows), y, line| {
                    line.copy_from_slice(&rows[(y - *first) * nx..][..nx]);
                    Some(y) != empty
                },
            );
        }
        let (mut sa, mut sb) = (plan.make_spectrum(), plan.make_spectrum());
        let [wa, wb] = &mut works;
        plan.convolve_columns([wa, wb], [&mut sa, &mut sb], |kx, a, b| {
            for (ky, (a, b)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
                (*a, *b) = mix(kx, ky, *a, *b);
            }
        });
        let mut want = [plan.make_spectrum(), plan.make_spectrum()];
        let mut work = plan.make_work();
        for kx in 0..nx / 2 + 1 {
            for ky in 0..ny {
                let (a, b) = mix(kx, ky, dft(&fa, ny, nx, kx, ky), dft(&fb, ny, nx, kx, ky));
                want[0][kx * ny + ky] = a;
                want[1][kx * ny + ky] = b;
            }
        }
        for w in &mut want {
            plan.inverse_columns(w, &mut work, |_, _| ());
        }
        for (got, want) in [&sa, &sb].into_iter().zip(&want) {
            let scale = want.iter().map(|v| v.norm()).fold(0.0, f64::max);
            for (k, (g, w)) in got.iter().zip(want).enumerate() {
                assert!((g - w).norm() < 1e-12 * scale, "entry {k}: {g} vs {w}");
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
