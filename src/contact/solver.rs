//! Load-controlled normal contact: the constrained conjugate gradient of Polonsky & Keer
//! (Wear 231, 1999, 206–219) with the imposed mean pressure p̄ = N / (Lx·Ly).
//!
//! Unknown: the pressure p ≥ 0 on the window's pixels with mean p̄. Gap: g = u(p) − h − ḡ, the
//! displacement minus the rigid surface heights, shifted by its mean ḡ over the contact set (the
//! rigid-body approach). Solution: g = 0 where p > 0, g ≥ 0 where p = 0.
//!
//! Convergence criterion: the residual
//!
//! ```text
//!     r = ( Σ_{p>0} p_i |g_i|  +  p̄ Σ_{p=0} max(−g_i, 0) ) / ( n p̄ h_rms )
//! ```
//!
//! (complementarity violation on the contact set plus penetration outside it, relative to the
//! mean pressure times the RMS height h_rms of the surface, n pixels) must fall to the
//! tolerance. It is checked on a displacement recomputed from scratch, with the load exact.
//!
//! One iteration is one application of the influence operator: the forward FFT of the search
//! direction t and one inverse FFT. Polonsky & Keer's projection (clipping negative pressures,
//! letting in inadmissible points) changes the pressure at a few points; instead of recomputing
//! the displacement from scratch, that change D is carried into the next iteration, whose
//! inverse FFT applies `K(σD − τt)` at once (σ restores the load). Until then the gap misses
//! `σ K D`: the search direction and the projection's decisions see the gap one iteration
//! late, while the step length τ (an exact line search, through Parseval) and the displacement
//! stay exact. Pressure and search direction live on the contact points only (compressed rows);
//! displacement and heights are the only full fields an iteration streams through.
//!
//! Sums are taken per grid row and added in row order, so results do not depend on the number
//! of threads.

use std::time::Instant;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::influence::{Boundary, Influence};
use crate::error::{Error, Result};
use crate::fft::{split_rows, split_rows_mut};

/// Iterations without a new best residual after which the conjugate gradient restarts.
const STALL: usize = 50;

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverOptions {
    /// Residual at which a solve has converged (see the module documentation).
    pub tolerance: f64,
    /// Iterations after which a solve that has not converged is an error.
    pub max_iterations: usize,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions { tolerance: 1e-10, max_iterations: 20_000 }
    }
}

/// What one solve reports besides its fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    /// Normal load N [N].
    pub load: f64,
    /// Mean pressure over the window, N / (Lx·Ly) [Pa].
    pub mean_pressure: f64,
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// Residual at convergence.
    pub residual: f64,
    /// Applications of the influence operator (FFT pairs): one per iteration and one per
    /// check of convergence from scratch; iterations that change the contact set add a quarter
    /// (the column pass of the change's transform).
    pub operator_applications: f64,
    /// Wall-clock time of the solve [s].
    pub seconds: f64,
}

/// The contact set in compressed rows: the points with p > 0, in raster order.
#[derive(Default)]
struct ContactSet {
    /// Flat index y·nx + x of each contact point.
    index: Vec<u32>,
    /// `row_start[y]..row_start[y + 1]`: the contact points of row y.
    row_start: Vec<usize>,
    /// Pressure p [Pa] at each contact point.
    pressure: Vec<f64>,
    /// Search direction t [m] at each contact point.
    direction: Vec<f64>,
}

impl ContactSet {
    fn len(&self) -> usize {
        self.index.len()
    }

    fn rows(&self, y: usize) -> std::ops::Range<usize> {
        self.row_start[y]..self.row_start[y + 1]
    }
}

/// A pressure change of the projection at one point.
#[derive(Clone, Copy)]
struct Change {
    /// Flat index y·nx + x.
    index: u32,
    /// δp [Pa]: the pressure given to an entering point, or taken off a clipped one beyond
    /// its step (p − τt < 0 → 0).
    delta: f64,
    /// Whether the point enters the contact set (else it leaves it).
    entering: bool,
}

/// The gap's statistics over the contact set, as an iteration starts.
#[derive(Clone, Copy)]
struct Shifts {
    /// ḡ: mean of σu − h over the contact set [m].
    gap_mean: f64,
    /// G = Σ (g − ḡ)² over the contact set [m²].
    gap_norm: f64,
    /// Mean of the search direction over the contact set [m].
    direction_mean: f64,
}

/// A contact problem on one surface, solved for one load after another. The pressure of the
/// last solve is the starting point of the next (warm start).
pub struct ContactSolver {
    ny: usize,
    nx: usize,
    size: (f64, f64),
    boundary: Boundary,
    e_star: f64,
    /// Rigid surface heights h [m]: higher points touch first.
    heights: Vec<f64>,
    h_rms: f64,
    operator: Influence,
    options: SolverOptions,
    /// Stored displacement u [m]: K(p − σD) = σu.
    displacement: Vec<f64>,
    /// σ: the load restoration not yet applied to the displacement.
    scale: f64,
    contact: ContactSet,
    /// The next contact set, built while the current one is read.
    next: ContactSet,
    /// D: the projection's changes not yet applied to the displacement, per row.
    pending: Vec<Vec<Change>>,
    /// Spectrum of D.
    change_spectrum: Vec<Complex64>,
    /// Per-row and per-spectrum-row partial sums.
    row_sums: Vec<[f64; 4]>,
    spectrum_sums: Vec<[f64; 2]>,
    /// Dense pressure of the last solve [Pa].
    pressure_field: Vec<f64>,
    warm: bool,
}

impl ContactSolver {
    /// Set up the problem for `heights` [m] (row-major, ny × nx) on a window of physical size
    /// (lx, ly) [m], effective modulus E* [Pa] and the given boundary.
    pub fn new(
        heights: &[f64],
        (ny, nx): (usize, usize),
        (lx, ly): (f64, f64),
        e_star: f64,
        boundary: Boundary,
        options: SolverOptions,
    ) -> Result<Self> {
        if ny < 2 || nx < 2 {
            return Err(Error::invalid("surface", format!("grid {ny}×{nx} is too small: at least 2×2 points")));
        }
        if heights.len() != ny * nx {
            return Err(Error::invalid("surface", format!("{} heights for a {ny}×{nx} grid", heights.len())));
        }
        if ny * nx > u32::MAX as usize {
            return Err(Error::invalid("surface", format!("grid {ny}×{nx} has more than 2³² points")));
        }
        if let Some(i) = heights.iter().position(|h| !h.is_finite()) {
            return Err(Error::invalid(
                "surface",
                format!(
                    "height at row {}, column {} is {} (fill or crop missing points first)",
                    i / nx,
                    i % nx,
                    heights[i]
                ),
            ));
        }
        for (name, v) in [("--size (x)", lx), ("--size (y)", ly)] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(Error::invalid(name, format!("must be positive and finite, got {v} m")));
            }
        }
        if !(e_star > 0.0 && e_star.is_finite()) {
            return Err(Error::invalid("effective modulus", format!("must be positive and finite, got {e_star} Pa")));
        }
        if !(options.tolerance > 0.0 && options.tolerance.is_finite()) {
            return Err(Error::invalid("--tolerance", format!("must be positive, got {}", options.tolerance)));
        }
        if options.max_iterations == 0 {
            return Err(Error::invalid("--max-iter", "must be at least 1"));
        }
        let n = ny * nx;
        let mean = heights.iter().sum::<f64>() / n as f64;
        let h_rms = (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let operator = match boundary {
            Boundary::Periodic => Influence::periodic(ny, nx, (lx, ly), e_star),
            Boundary::Free => Influence::free(ny, nx, (lx, ly), e_star),
        };
        let nxh = operator.fft().shape().1 / 2 + 1;
        let change_spectrum = operator.fft().make_spectrum();
        Ok(ContactSolver {
            ny,
            nx,
            size: (lx, ly),
            boundary,
            e_star,
            heights: heights.to_vec(),
            h_rms,
            operator,
            options,
            displacement: vec![0.0; n],
            scale: 1.0,
            contact: ContactSet::default(),
            next: ContactSet::default(),
            pending: vec![Vec::new(); ny],
            change_spectrum,
            row_sums: vec![[0.0; 4]; ny],
            spectrum_sums: vec![[0.0; 2]; nxh],
            pressure_field: vec![0.0; n],
            warm: false,
        })
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// Physical size (lx, ly) [m].
    pub fn size(&self) -> (f64, f64) {
        self.size
    }

    /// The boundary condition.
    pub fn boundary(&self) -> Boundary {
        self.boundary
    }

    /// The heights h [m].
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// Pressure of the last solve [Pa], row-major (ny, nx).
    pub fn pressure(&self) -> &[f64] {
        &self.pressure_field
    }

    /// Gap of the last solve [m]: zero on the contact set, positive elsewhere.
    pub fn gap(&self) -> Vec<f64> {
        let mean =
            self.contact.index.iter().map(|&i| self.displacement[i as usize] - self.heights[i as usize]).sum::<f64>()
                / self.contact.len().max(1) as f64;
        (0..self.heights.len())
            .map(|i| {
                if self.pressure_field[i] > 0.0 {
                    0.0
                } else {
                    (self.displacement[i] - self.heights[i] - mean).max(0.0)
                }
            })
            .collect()
    }

    /// Surface displacement u = K p of the last solve [m]. In the periodic model its mean is
    /// zero: the rigid-body approach is not defined there.
    pub fn displacement(&self) -> Vec<f64> {
        self.displacement.clone()
    }

    /// Start the next solve from scratch rather than from the last pressure.
    pub fn reset(&mut self) {
        self.warm = false;
    }

    /// Start the next solve from `pressure` [Pa] (row-major (ny, nx), each ≥ 0) as if it were
    /// the last solve's: a load sweep resumed from a saved pressure map continues exactly as
    /// the uninterrupted sweep (a solve depends only on the pressure it starts from).
    pub fn warm_start(&mut self, pressure: &[f64]) -> Result<()> {
        let (ny, nx) = (self.ny, self.nx);
        if pressure.len() != ny * nx {
            return Err(Error::invalid("warm start", format!("{} pressures for a {ny}×{nx} grid", pressure.len())));
        }
        if let Some(i) = pressure.iter().position(|p| !(p.is_finite() && *p >= 0.0)) {
            return Err(Error::invalid("warm start", format!("pressure {} Pa at point {i}", pressure[i])));
        }
        let c = &mut self.contact;
        (c.index, c.pressure) = pressure.iter().enumerate().filter(|(_, p)| **p > 0.0).map(|(i, p)| (i as u32, *p)).unzip();
        c.row_start = (0..=ny).map(|y| c.index.partition_point(|&i| (i as usize) < y * nx)).collect();
        c.direction = vec![0.0; c.index.len()];
        self.pressure_field.copy_from_slice(pressure);
        self.warm = true;
        Ok(())
    }

    /// Solve for the normal load `load` [N]. `progress` is called after every iteration with
    /// the iteration count and the current residual.
    pub fn solve(&mut self, load: f64, mut progress: impl FnMut(usize, f64)) -> Result<SolveReport> {
        if !(load > 0.0 && load.is_finite()) {
            return Err(Error::invalid("--load", format!("must be positive and finite, got {load} N")));
        }
        let start = Instant::now();
        let n = self.ny * self.nx;
        let p_mean = load / (self.size.0 * self.size.1);
        let total = p_mean * n as f64;
        let norm = n as f64 * p_mean * if self.h_rms > 0.0 { self.h_rms } else { 1.0 };
        if !self.warm || self.contact.len() == 0 {
            self.start_uniform(p_mean);
        }
        let sum: f64 = self.contact.pressure.iter().sum();
        self.contact.pressure.iter_mut().for_each(|p| *p *= total / sum);
        self.contact.direction.fill(0.0);
        let (mut shifts, mut residual) = self.refresh(p_mean, norm);
        // Whether `residual` was measured on a displacement recomputed from scratch.
        let mut exact = true;
        let mut applications = 1.0;
        let mut iterations = 0;
        let mut conjugate = false;
        let mut gap_norm_old = 1.0;
        // Best residual so far and when it was reached: a stalled search restarts from the
        // steepest descent direction.
        let (mut best, mut best_at) = (f64::INFINITY, 0);
        loop {
            if !residual.is_finite() {
                self.warm = false;
                return Err(Error::invalid(
                    "contact solver",
                    format!("broke down at iteration {iterations} (non-finite residual)"),
                ));
            }
            if residual <= self.options.tolerance {
                if exact {
                    break;
                }
                // Converged as far as the lagging gap can tell: check from scratch.
                (shifts, residual) = self.refresh(p_mean, norm);
                exact = true;
                applications += 1.0;
                continue;
            }
            if iterations == self.options.max_iterations {
                self.warm = false;
                return Err(Error::NotConverged {
                    solver: "contact solver",
                    iterations,
                    residual,
                    tolerance: self.options.tolerance,
                });
            }
            iterations += 1;
            if residual < best {
                (best, best_at) = (residual, iterations);
            } else if iterations - best_at > STALL {
                (conjugate, best_at) = (false, iterations);
            }
            // Unlike Polonsky & Keer, conjugacy is kept when points enter the contact set:
            // resetting it there makes load sweeps, where the set keeps growing, converge like
            // steepest descent (2–3× more iterations on rough spheres).
            let beta = if conjugate && gap_norm_old > 0.0 { shifts.gap_norm / gap_norm_old } else { 0.0 };
            gap_norm_old = shifts.gap_norm;
            conjugate = true;
            let changes = !self.pending_is_empty();
            if changes {
                self.transform_changes();
                applications += 0.25;
            }
            let (along, curvature, cross) = self.transform_direction(&shifts, beta, changes);
            if !(curvature > 0.0) {
                // t = 0: the gap is flat on the contact set; only the projection has work left.
                (shifts, residual) = self.refresh(p_mean, norm);
                applications += 1.0;
                if residual > self.options.tolerance {
                    self.let_in_penetrating(&shifts, p_mean);
                    (shifts, residual) = self.refresh(p_mean, norm);
                    applications += 1.0;
                }
                exact = true;
                progress(iterations, residual);
                continue;
            }
            let step = (along + self.scale * cross) / curvature;
            applications += 1.0;
            residual = self.step(&shifts, step, changes, total, p_mean, norm)?;
            exact = false;
            shifts = self.shifts(shifts.gap_mean);
            progress(iterations, residual);
        }
        self.warm = true;
        self.pressure_field.fill(0.0);
        for (&i, &p) in self.contact.index.iter().zip(&self.contact.pressure) {
            self.pressure_field[i as usize] = p;
        }
        Ok(SolveReport {
            load,
            mean_pressure: p_mean,
            iterations,
            residual,
            operator_applications: applications,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    fn pending_is_empty(&self) -> bool {
        self.pending.iter().all(Vec::is_empty)
    }

    /// Every point in contact at the mean pressure.
    fn start_uniform(&mut self, p_mean: f64) {
        let n = self.ny * self.nx;
        let c = &mut self.contact;
        c.index = (0..n as u32).collect();
        c.row_start = (0..=self.ny).map(|y| y * self.nx).collect();
        c.pressure = vec![p_mean; n];
        c.direction = vec![0.0; n];
    }

    /// Recompute the displacement from the pressure (u = K p, σ = 1, nothing pending) and
    /// return the exact shifts and residual.
    fn refresh(&mut self, p_mean: f64, norm: f64) -> (Shifts, f64) {
        let (ny, nx) = (self.ny, self.nx);
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let c = &self.contact;
        fft.forward_rows(
            ny,
            work,
            (0, &c.pressure[..]),
            |(first, p), mid| {
                let (a, b) = p.split_at(c.row_start[mid] - c.row_start[first]);
                ((first, a), (mid, b))
            },
            |(first, p), y, line| {
                let base = c.row_start[*first];
                for j in c.rows(y) {
                    line[c.index[j] as usize - y * nx] = p[j - base];
                }
                !c.rows(y).is_empty()
            },
        );
        fft.forward_columns(work, spectrum, |_, _| (), &mut []);
        let grid_ny = fft.shape().0;
        fft.inverse_columns(spectrum, work, |kx, row| {
            row.iter_mut().zip(&kernel[kx * grid_ny..]).for_each(|(s, k)| *s *= *k);
        });
        fft.inverse_rows(
            spectrum,
            ny,
            work,
            (0, &mut self.displacement[..]),
            |s, mid| split_rows_mut(s, mid, nx),
            |(first, u), y, line| {
                u[(y - *first) * nx..][..nx].copy_from_slice(&line[..nx]);
            },
        );
        self.scale = 1.0;
        self.pending.iter_mut().for_each(Vec::clear);
        let shifts = self.shifts(0.0);
        (shifts, self.residual(&shifts, p_mean, norm))
    }

    /// ḡ, G and the direction's mean over the contact set, from σu − h. Sums are shifted by
    /// `guess` (the previous ḡ) so that one pass usually gives G without losing its digits to
    /// ḡ²; a second pass around the mean when the guess was far off.
    fn shifts(&mut self, guess: f64) -> Shifts {
        let sigma = self.scale;
        let (u, h, c) = (&self.displacement, &self.heights, &self.contact);
        let pass = |sums: &mut [[f64; 4]], shift: f64| {
            sums.par_iter_mut().enumerate().for_each(|(y, acc)| {
                let mut a = [0.0; 4];
                for j in c.rows(y) {
                    let i = c.index[j] as usize;
                    let d = sigma * u[i] - h[i] - shift;
                    a[0] += d;
                    a[1] += d * d;
                    a[2] += c.direction[j];
                }
                *acc = a;
            });
            sum_rows(sums)
        };
        let count = c.len() as f64;
        let [s1, s2, direction_sum, _] = pass(&mut self.row_sums, guess);
        let mut gap_mean = guess + s1 / count;
        let mut gap_norm = s2 - s1 * s1 / count;
        if s1 * s1 / count > 0.5 * s2 {
            let [r1, r2, ..] = pass(&mut self.row_sums, gap_mean);
            gap_mean += r1 / count;
            gap_norm = r2 - r1 * r1 / count;
        }
        Shifts { gap_mean, gap_norm: gap_norm.max(0.0), direction_mean: direction_sum / count }
    }

    /// The residual of the module documentation for the current state, on a full pass.
    fn residual(&mut self, s: &Shifts, p_mean: f64, norm: f64) -> f64 {
        let (nx, sigma, gap_mean) = (self.nx, self.scale, s.gap_mean);
        let (u, h, c) = (&self.displacement, &self.heights, &self.contact);
        self.row_sums.par_iter_mut().enumerate().for_each(|(y, acc)| {
            let (mut complementarity, mut penetration) = (0.0, 0.0);
            let mut j = c.row_start[y];
            for x in 0..nx {
                let i = y * nx + x;
                let g = sigma * u[i] - h[i] - gap_mean;
                if j < c.row_start[y + 1] && c.index[j] as usize == i {
                    complementarity += c.pressure[j] * g.abs();
                    j += 1;
                } else if g < 0.0 {
                    penetration -= g;
                }
            }
            *acc = [complementarity, penetration, 0.0, 0.0];
        });
        let [complementarity, penetration, ..] = sum_rows(&self.row_sums);
        (complementarity + p_mean * penetration) / norm
    }

    /// Spectrum of the pending changes D.
    fn transform_changes(&mut self) {
        let nx = self.nx;
        let (fft, _, _, work) = self.operator.parts();
        fft.forward_rows(
            self.ny,
            work,
            (0, &self.pending[..]),
            |s, mid| split_rows(s, mid, 1),
            |(first, rows), y, line| {
                let row = &rows[y - *first];
                for ch in row {
                    line[ch.index as usize - y * nx] = ch.delta;
                }
                !row.is_empty()
            },
        );
        fft.forward_columns(work, &mut self.change_spectrum, |_, _| (), &mut []);
    }

    /// t ← g − ḡ + β (t − t̄) on the contact set, transformed. Returns Σ (g − ḡ) t, t·K t and
    /// t·K D (Parseval; the last only when changes are pending).
    fn transform_direction(&mut self, s: &Shifts, beta: f64, changes: bool) -> (f64, f64, f64) {
        let (ny, nx, sigma) = (self.ny, self.nx, self.scale);
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let (grid_ny, grid_nx) = fft.shape();
        let (u, h) = (&self.displacement, &self.heights);
        let c = &mut self.contact;
        let (index, row_start) = (&c.index, &c.row_start);
        fft.forward_rows(
            ny,
            work,
            (0, &mut c.direction[..], &mut self.row_sums[..]),
            |(first, t, sums), mid| {
                let (ta, tb) = t.split_at_mut(row_start[mid] - row_start[first]);
                let (sa, sb) = sums.split_at_mut(mid - first);
                ((first, ta, sa), (mid, tb, sb))
            },
            |(first, t, sums), y, line| {
                let base = row_start[*first];
                let (mut along, mut total) = (0.0, 0.0);
                for j in row_start[y]..row_start[y + 1] {
                    let i = index[j] as usize;
                    let g = sigma * u[i] - h[i] - s.gap_mean;
                    let tj = g + beta * (t[j - base] - s.direction_mean);
                    t[j - base] = tj;
                    line[i - y * nx] = tj;
                    along += g * tj;
                    total += tj;
                }
                sums[y - *first] = [along, total, 0.0, 0.0];
                row_start[y] < row_start[y + 1]
            },
        );
        let change_spectrum = &self.change_spectrum;
        fft.forward_columns(
            work,
            spectrum,
            |kx, row| {
                // Each stored qx stands for ±qx, except the real-valued columns.
                let weight = if kx == 0 || 2 * kx == grid_nx { 1.0 } else { 2.0 };
                let k = &kernel[kx * grid_ny..][..grid_ny];
                let curvature: f64 = row.iter().zip(k).map(|(t, k)| k * t.norm_sqr()).sum();
                let cross: f64 = if changes {
                    let d = &change_spectrum[kx * grid_ny..][..grid_ny];
                    row.iter().zip(k).zip(d).map(|((t, k), d)| k * (t.re * d.re + t.im * d.im)).sum()
                } else {
                    0.0
                };
                [weight * curvature, weight * cross]
            },
            &mut self.spectrum_sums,
        );
        let [along, ..] = sum_rows(&self.row_sums);
        let (curvature, cross) = self.spectrum_sums.iter().fold((0.0, 0.0), |(a, b), s| (a + s[0], b + s[1]));
        (along, curvature, cross)
    }

    /// The step: u ← σu + K(σD − τt) by one inverse FFT; p ← p − τt with Polonsky & Keer's
    /// projection, whose changes become the next D; the load restored by the next σ. Returns
    /// the residual of the state the step started from (with the gap it could see).
    fn step(&mut self, s: &Shifts, step: f64, changes: bool, total: f64, p_mean: f64, norm: f64) -> Result<f64> {
        let (ny, nx, sigma, gap_mean) = (self.ny, self.nx, self.scale, s.gap_mean);
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let grid_ny = fft.shape().0;
        let change_spectrum = &self.change_spectrum;
        fft.inverse_columns(spectrum, work, |kx, row| {
            let k = &kernel[kx * grid_ny..][..grid_ny];
            if changes {
                let d = &change_spectrum[kx * grid_ny..][..grid_ny];
                row.iter_mut().zip(k).zip(d).for_each(|((t, k), d)| *t = (sigma * d - step * *t) * k);
            } else {
                row.iter_mut().zip(k).for_each(|(t, k)| *t *= -step * k);
            }
        });
        let h = &self.heights;
        let c = &mut self.contact;
        let (index, row_start) = (&c.index, &c.row_start);
        let direction = &c.direction;
        fft.inverse_rows(
            spectrum,
            ny,
            work,
            (0, &mut self.displacement[..], &mut c.pressure[..], &mut self.pending[..], &mut self.row_sums[..]),
            |(first, u, p, pending, sums), mid| {
                let (ua, ub) = u.split_at_mut((mid - first) * nx);
                let (pa, pb) = p.split_at_mut(row_start[mid] - row_start[first]);
                let (da, db) = pending.split_at_mut(mid - first);
                let (sa, sb) = sums.split_at_mut(mid - first);
                ((first, ua, pa, da, sa), (mid, ub, pb, db, sb))
            },
            |(first, u, p, pending, sums), y, line| {
                let base = row_start[*first];
                let u = &mut u[(y - *first) * nx..][..nx];
                let h = &h[y * nx..][..nx];
                let changed = &mut pending[y - *first];
                changed.clear();
                let (mut complementarity, mut penetration, mut load) = (0.0, 0.0, 0.0);
                let (mut j, end) = (row_start[y], row_start[y + 1]);
                for x in 0..nx {
                    let g = sigma * u[x] - h[x] - gap_mean;
                    u[x] = sigma * u[x] + line[x];
                    let i = y * nx + x;
                    if j < end && index[j] as usize == i {
                        let pj = &mut p[j - base];
                        complementarity += *pj * g.abs();
                        let q = *pj - step * direction[j];
                        if q > 0.0 {
                            *pj = q;
                            load += q;
                        } else {
                            // Clipped: it leaves the contact set.
                            *pj = 0.0;
                            changed.push(Change { index: i as u32, delta: -q, entering: false });
                        }
                        j += 1;
                    } else if g < 0.0 {
                        // Inadmissible: it enters the contact set.
                        penetration -= g;
                        let q = -step * g;
                        load += q;
                        changed.push(Change { index: i as u32, delta: q, entering: true });
                    }
                }
                sums[y - *first] = [complementarity, penetration, load, 0.0];
            },
        );
        let [complementarity, penetration, load, _] = sum_rows(&self.row_sums);
        if !(load > 0.0) {
            return Err(Error::invalid("contact solver", "broke down: the projection left no pressure"));
        }
        if !self.pending_is_empty() {
            self.rebuild_contact_set();
        }
        self.scale = total / load;
        let scale = self.scale;
        self.contact.pressure.par_iter_mut().with_min_len(4096).for_each(|p| *p *= scale);
        Ok((complementarity + p_mean * penetration) / norm)
    }

    /// The contact set after a step: clipped points (p = 0) leave, inadmissible ones enter.
    fn rebuild_contact_set(&mut self) {
        let (old, new) = (&self.contact, &mut self.next);
        new.index.clear();
        new.pressure.clear();
        new.direction.clear();
        new.row_start.clear();
        new.row_start.push(0);
        for (y, changed) in self.pending.iter().enumerate() {
            let mut entering = changed.iter().filter(|c| c.entering).peekable();
            for j in old.rows(y) {
                while let Some(c) = entering.next_if(|c| c.index < old.index[j]) {
                    new.index.push(c.index);
                    new.pressure.push(c.delta);
                    new.direction.push(0.0);
                }
                if old.pressure[j] > 0.0 {
                    new.index.push(old.index[j]);
                    new.pressure.push(old.pressure[j]);
                    new.direction.push(old.direction[j]);
                }
            }
            for c in entering {
                new.index.push(c.index);
                new.pressure.push(c.delta);
                new.direction.push(0.0);
            }
            new.row_start.push(new.index.len());
        }
        std::mem::swap(&mut self.contact, &mut self.next);
    }

    /// Let every penetrating point in at the finest mode's stiffness E*π/(2Δ) (used when the
    /// search direction vanishes: the gap is flat on the contact set but not outside it).
    fn let_in_penetrating(&mut self, s: &Shifts, p_mean: f64) {
        let spacing = (self.size.0 / self.nx as f64).min(self.size.1 / self.ny as f64);
        let stiffness = self.e_star * std::f64::consts::PI / (2.0 * spacing);
        let (nx, sigma) = (self.nx, self.scale);
        let c = &self.contact;
        for (y, changed) in self.pending.iter_mut().enumerate() {
            changed.clear();
            let mut j = c.row_start[y];
            for x in 0..nx {
                let i = y * nx + x;
                if j < c.row_start[y + 1] && c.index[j] as usize == i {
                    j += 1;
                    continue;
                }
                let g = sigma * self.displacement[i] - self.heights[i] - s.gap_mean;
                if g < 0.0 {
                    changed.push(Change { index: i as u32, delta: -stiffness * g, entering: true });
                }
            }
        }
        self.rebuild_contact_set();
        let total = p_mean * (self.ny * self.nx) as f64;
        let sum: f64 = self.contact.pressure.iter().sum();
        self.contact.pressure.iter_mut().for_each(|p| *p *= total / sum);
    }
}

/// Sum per-row partial sums in row order (deterministic).
fn sum_rows<const K: usize>(rows: &[[f64; K]]) -> [f64; K] {
    rows.iter().fold([0.0; K], |mut a, b| {
        a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        a
    })
}
