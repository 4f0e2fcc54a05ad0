//! The elastic iteration of the CPU engine: Polonsky & Keer's constrained conjugate gradient
//! with the projection's changes carried into the next iteration (see the parent module), and
//! the exact solution of a flat map.
//!
//! Imports its parent (`cpu`) and `options` inside `contact`; must not import friction, study,
//! report, plot, shs, cli.

use std::time::Instant;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::{sum_rows, Change, ChangeTransform, ContactRows, ContactSet, CpuSolver, Shifts, DIRECT_ROWS, SUMS};
use crate::contact::options::{Iterations, SolveReport, STALL};
use crate::error::{Error, Result};
use crate::fft::{split_rows, split_rows_mut};

/// A row of pending changes keeps room for this many between iterations; more is given back
/// once their transform is taken (the first steps of a cold start clip most of the grid).
const RETAINED_CHANGES: usize = 256;

impl CpuSolver {
    /// `displaced`: the displacement is K p of the stored pressure, and the start may scale it
    /// with the pressure rather than transform the pressure again.
    pub(super) fn solve_elastic(
        &mut self,
        load: f64,
        displaced: bool,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<SolveReport> {
        let start = Instant::now();
        let n = self.ny * self.nx;
        let p_mean = load / (self.size.0 * self.size.1);
        let total = p_mean * n as f64;
        let norm = n as f64 * p_mean * if self.h_rms > 0.0 { self.h_rms } else { 1.0 };
        let cold = !self.warm || self.contact.len() == 0 && self.uniform.is_none();
        if cold {
            self.contact = ContactSet::default();
            self.uniform = Some(p_mean);
        }
        if let Some(p) = self.uniform {
            // As a stored set of n equal pressures would be summed and rescaled.
            let sum: f64 = std::iter::repeat_n(p, n).sum();
            self.uniform = Some(p * (total / sum));
        }
        let sum: f64 = self.contact.pressure.iter().sum();
        self.contact.pressure.iter_mut().for_each(|p| *p *= total / sum);
        self.contact.direction.fill(0.0);
        let rescale = displaced && !cold && self.uniform.is_none();
        let (mut shifts, mut residual) = if rescale {
            // u = K p of the pressure before its scaling, σ = 1 and nothing pending.
            self.displacement.par_iter_mut().for_each(|u| *u *= total / sum);
            let shifts = self.store_contact_gaps();
            let residual = self.residual(&shifts, p_mean, norm);
            (shifts, residual)
        } else {
            self.refresh(p_mean, norm)
        };
        // Whether `residual` was measured on a displacement recomputed from scratch.
        let mut exact = true;
        let mut applications = if rescale { 0.0 } else { 1.0 };
        let mut iterations = Iterations::new("contact solver", self.options.convergence, STALL);
        let mut conjugate = false;
        let mut gap_norm_old = 1.0;
        loop {
            // A cold start iterates at least once: its uniform guess is no solution.
            if residual <= self.options.convergence.tolerance && (iterations.done() > 0 || !cold) {
                if exact {
                    break;
                }
                // Converged as far as the lagging gap can tell: check from scratch.
                (shifts, residual) = self.refresh(p_mean, norm);
                exact = true;
                applications += 1.0;
                continue;
            }
            // A stalled search restarts from the steepest descent direction.
            if iterations.next(residual)? {
                conjugate = false;
            }
            // Unlike Polonsky & Keer, conjugacy is kept when points enter the contact set:
            // resetting it there makes load sweeps, where the set keeps growing, converge like
            // steepest descent (2–3× more iterations on rough spheres).
            let beta = if conjugate && gap_norm_old > 0.0 { shifts.gap_norm / gap_norm_old } else { 0.0 };
            gap_norm_old = shifts.gap_norm;
            conjugate = true;
            self.transform_changes();
            if self.change_transform == ChangeTransform::Dense {
                applications += 0.5;
            }
            let (along, curvature, cross) = self.transform_direction(&shifts, beta);
            if curvature.is_nan() || curvature <= 0.0 {
                // t = 0: the gap is flat on the contact set; only the projection has work left.
                self.materialise();
                (shifts, residual) = self.refresh(p_mean, norm);
                applications += 1.0;
                if residual > self.options.convergence.tolerance {
                    self.let_in_penetrating(&shifts, p_mean);
                    (shifts, residual) = self.refresh(p_mean, norm);
                    applications += 1.0;
                }
                exact = true;
                if !progress(iterations.done(), residual) {
                    return Err(Self::interrupted(load));
                }
                continue;
            }
            let step = (along + self.scale * cross) / curvature;
            applications += 1.0;
            (shifts, residual) = self.step(&shifts, beta, step, total, p_mean, norm)?;
            exact = false;
            if !progress(iterations.done(), residual) {
                return Err(Self::interrupted(load));
            }
        }
        self.warm = true;
        // Every way out of the loop above measured the residual exactly.
        self.displaced = true;
        Ok(SolveReport {
            load,
            mean_pressure: p_mean,
            iterations: iterations.done(),
            residual,
            operator_applications: applications,
            seconds: start.elapsed().as_secs_f64(),
            hardness: None,
        })
    }

    /// The exact solution of a flat map on a periodic window: full contact at the uniform
    /// pressure N/(Lx·Ly), no iteration. Its residual is the bound on the pressure's departure
    /// from it, relative to the mean pressure (see `flat_spread`).
    pub(super) fn press_flat(&mut self, load: f64) -> SolveReport {
        let start = Instant::now();
        let p_mean = load / (self.size.0 * self.size.1);
        self.contact = ContactSet::default();
        self.uniform = Some(p_mean);
        // The displacement of the uniform pressure (its residual is not the measure here).
        self.refresh(p_mean, 1.0);
        self.warm = true;
        SolveReport {
            load,
            mean_pressure: p_mean,
            iterations: 0,
            residual: self.flat_spread / p_mean,
            operator_applications: 1.0,
            seconds: start.elapsed().as_secs_f64(),
            hardness: self.hardness,
        }
    }

    fn pending_is_empty(&self) -> bool {
        self.pending.iter().all(Vec::is_empty)
    }

    /// Recompute the displacement from the pressure (u = K p, σ = 1, nothing pending) and
    /// return the exact shifts and residual.
    fn refresh(&mut self, p_mean: f64, norm: f64) -> (Shifts, f64) {
        let (ny, nx) = (self.ny, self.nx);
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let (c, uniform) = (&self.contact, self.uniform);
        fft.forward_rows(
            ny,
            work,
            (0, &c.pressure[..]),
            |(first, p), mid| {
                if uniform.is_some() {
                    return ((first, p), (mid, p));
                }
                let (a, b) = p.split_at(c.row_start[mid] - c.row_start[first]);
                ((first, a), (mid, b))
            },
            |(first, p), y, line| {
                if let Some(p) = uniform {
                    line[..nx].fill(p);
                    return true;
                }
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
            |_| true,
            work,
            (0, &mut self.displacement[..]),
            |s, mid| split_rows_mut(s, mid, nx),
            |(first, u), y, line| {
                u[(y - *first) * nx..][..nx].copy_from_slice(&line[..nx]);
            },
        );
        self.scale = 1.0;
        self.pending.iter_mut().for_each(Vec::clear);
        let shifts = self.store_contact_gaps();
        (shifts, self.residual(&shifts, p_mean, norm))
    }

    /// After the displacement was recomputed (σ = 1): the reference c = ḡ of the contact
    /// points' gaps u − h − c, and ḡ, G and the direction's mean.
    fn store_contact_gaps(&mut self) -> Shifts {
        let (u, h) = (&self.displacement, &self.heights);
        let c = &self.contact;
        // The contact points' indices, in raster order.
        let points = || -> Box<dyn Iterator<Item = usize> + '_> {
            match self.uniform {
                Some(_) => Box::new(0..u.len()),
                None => Box::new(c.index.iter().map(|&i| i as usize)),
            }
        };
        let count = points().count() as f64;
        let gap_mean = points().map(|i| u[i] - h[i]).sum::<f64>() / count;
        let direction_mean = if self.uniform.is_some() { 0.0 } else { c.direction.iter().sum::<f64>() / count };
        self.reference = gap_mean;
        let gap_norm = points()
            .map(|i| {
                let g = u[i] - h[i] - gap_mean;
                g * g
            })
            .sum();
        Shifts { gap_mean, gap_norm, direction_mean }
    }

    /// The residual of [`crate::contact::solver`] for the current state, on a full pass.
    fn residual(&mut self, s: &Shifts, p_mean: f64, norm: f64) -> f64 {
        let (nx, sigma, gap_mean) = (self.nx, self.scale, s.gap_mean);
        let (u, h, c, uniform) = (&self.displacement, &self.heights, &self.contact, self.uniform);
        self.row_sums.par_iter_mut().enumerate().for_each(|(y, acc)| {
            let (mut complementarity, mut penetration) = (0.0, 0.0);
            let mut j = c.row_start.get(y).copied().unwrap_or(0);
            for x in 0..nx {
                let i = y * nx + x;
                let g = sigma * u[i] - h[i] - gap_mean;
                if let Some(p) = uniform {
                    complementarity += p * g.abs();
                } else if j < c.row_start[y + 1] && c.index[j] as usize == i {
                    complementarity += c.pressure[j] * g.abs();
                    j += 1;
                } else if g < 0.0 {
                    penetration -= g;
                }
            }
            acc[..2].copy_from_slice(&[complementarity, penetration]);
        });
        let [complementarity, penetration, ..] = sum_rows(&self.row_sums);
        (complementarity + p_mean * penetration) / norm
    }

    /// The transform of the pending changes D: summed directly when they lie on a few grid
    /// rows, by FFT otherwise.
    fn transform_changes(&mut self) {
        let nx = self.nx;
        let rows = self.pending.iter().filter(|r| !r.is_empty()).count();
        if rows == 0 {
            self.change_transform = ChangeTransform::None;
            return;
        }
        if rows <= DIRECT_ROWS {
            let (tx, ty) = (&self.twiddle_x, &self.twiddle_y);
            let (grid_nx, grid_ny) = (tx.len(), ty.len());
            let nxh = grid_nx / 2 + 1;
            let pending = self.pending.iter().enumerate().filter(|(_, r)| !r.is_empty());
            for (slot, (y, changed)) in self.change_rows.iter_mut().zip(pending) {
                slot.spectrum.clear();
                slot.spectrum.extend((0..nxh).map(|kx| {
                    changed
                        .iter()
                        .map(|c| c.delta * tx[(kx * (c.index as usize - y * nx)) % grid_nx])
                        .sum::<Complex64>()
                }));
                slot.phase.clear();
                slot.phase.extend((0..grid_ny).map(|ky| ty[(ky * y) % grid_ny]));
            }
            self.change_transform = ChangeTransform::Rows;
            self.direct_rows = rows;
            return;
        }
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
        // The changes are in the transform's buffer now (and the contact set has them): the rows
        // that held many give their room back before their spectrum takes its own.
        let mut released = false;
        for r in self.pending.iter_mut().filter(|r| r.capacity() > RETAINED_CHANGES) {
            *r = Vec::new();
            released = true;
        }
        if released {
            give_back_freed_memory();
        }
        if self.change_spectrum.is_empty() {
            self.change_spectrum = fft.make_spectrum();
        }
        fft.forward_columns(work, &mut self.change_spectrum, |_, _| (), &mut []);
        self.change_transform = ChangeTransform::Dense;
    }

    /// t ← g − ḡ + β (t − t̄) on the contact set, transformed. Returns Σ (g − ḡ) t, t·K t and
    /// t·K D (Parseval; the last only when changes are pending).
    fn transform_direction(&mut self, s: &Shifts, beta: f64) -> (f64, f64, f64) {
        let (ny, nx) = (self.ny, self.nx);
        // σu − h − ḡ = (u − h − c) + (σ − 1)u + (c − ḡ).
        let (excess, offset) = (self.scale - 1.0, self.reference - s.gap_mean);
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let (grid_ny, grid_nx) = fft.shape();
        let c = &mut self.contact;
        let (index, row_start, reference, uniform) = (&c.index, &c.row_start, self.reference, self.uniform.is_some());
        let (u, h) = (&self.displacement, &self.heights);
        let search = Search { reference, excess, offset, beta, mean: s.direction_mean };
        fft.forward_rows(
            ny,
            work,
            (0, &mut c.direction[..], &mut self.row_sums[..]),
            |(first, t, sums), mid| {
                let at = if uniform { 0 } else { row_start[mid] - row_start[first] };
                let (ta, tb) = t.split_at_mut(at);
                let (sa, sb) = sums.split_at_mut(mid - first);
                ((first, ta, sa), (mid, tb, sb))
            },
            |(first, t, sums), y, line| {
                let (mut along, mut total) = (0.0, 0.0);
                if uniform {
                    // Every point, with t = 0 before; the first step computes t again.
                    for (x, v) in line[..nx].iter_mut().enumerate() {
                        let i = y * nx + x;
                        let (g, tj) = search.at(u[i], h[i], 0.0);
                        *v = tj;
                        along += g * tj;
                        total += tj;
                    }
                    sums[y - *first][..2].copy_from_slice(&[along, total]);
                    return true;
                }
                let base = row_start[*first];
                for j in row_start[y]..row_start[y + 1] {
                    let i = index[j] as usize;
                    let (g, tj) = search.at(u[i], h[i], t[j - base]);
                    t[j - base] = tj;
                    line[i - y * nx] = tj;
                    along += g * tj;
                    total += tj;
                }
                sums[y - *first][..2].copy_from_slice(&[along, total]);
                row_start[y] < row_start[y + 1]
            },
        );
        let (mode, change_spectrum) = (self.change_transform, &self.change_spectrum);
        let change_rows = &self.change_rows[..self.direct_rows];
        fft.forward_columns(
            work,
            spectrum,
            |kx, row| {
                // Each stored qx stands for ±qx, except the real-valued columns.
                let weight = if kx == 0 || 2 * kx == grid_nx { 1.0 } else { 2.0 };
                let k = &kernel[kx * grid_ny..][..grid_ny];
                let curvature: f64 = row.iter().zip(k).map(|(t, k)| k * t.norm_sqr()).sum();
                let cross: f64 = match mode {
                    ChangeTransform::None => 0.0,
                    ChangeTransform::Dense => {
                        let d = &change_spectrum[kx * grid_ny..][..grid_ny];
                        row.iter().zip(k).zip(d).map(|((t, k), d)| k * (t.re * d.re + t.im * d.im)).sum()
                    }
                    // Re(t̂* D̂) summed row by row: Σ_y Re(R_y · Σ_qy K t̂* e^{−2πi qy y/ny}).
                    ChangeTransform::Rows => change_rows
                        .iter()
                        .map(|r| {
                            let s: Complex64 =
                                row.iter().zip(k).zip(&r.phase).map(|((t, k), e)| *k * t.conj() * e).sum();
                            (r.spectrum[kx] * s).re
                        })
                        .sum(),
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
    /// the shifts for the next iteration and the residual of the state the step started from
    /// (with the gap it could see).
    fn step(&mut self, s: &Shifts, beta: f64, step: f64, total: f64, p_mean: f64, norm: f64) -> Result<(Shifts, f64)> {
        let (ny, nx, sigma, gap_mean) = (self.ny, self.nx, self.scale, s.gap_mean);
        let uniform = self.uniform;
        let search = Search {
            reference: self.reference,
            excess: sigma - 1.0,
            offset: self.reference - gap_mean,
            beta,
            mean: s.direction_mean,
        };
        if let Some(p) = uniform {
            // The points the step keeps, counted first: the new set is built directly.
            self.next = ContactSet::default();
            let (u, h) = (&self.displacement, &self.heights);
            let kept: Vec<usize> = (0..ny)
                .into_par_iter()
                .map(|y| (y * nx..(y + 1) * nx).filter(|&i| p - step * search.at(u[i], h[i], 0.0).1 > 0.0).count())
                .collect();
            let c = &mut self.contact;
            c.row_start = std::iter::once(0)
                .chain(kept.iter().scan(0, |a, k| {
                    *a += k;
                    Some(*a)
                }))
                .collect();
            let m = c.row_start[ny];
            (c.index, c.pressure, c.direction) = (vec![0; m], vec![0.0; m], vec![0.0; m]);
        }
        let (fft, kernel, spectrum, work) = self.operator.parts();
        let grid_ny = fft.shape().0;
        let (mode, change_spectrum) = (self.change_transform, &self.change_spectrum);
        let change_rows = &self.change_rows[..self.direct_rows];
        fft.inverse_columns(spectrum, work, |kx, row| {
            let k = &kernel[kx * grid_ny..][..grid_ny];
            match mode {
                ChangeTransform::Dense => {
                    let d = &change_spectrum[kx * grid_ny..][..grid_ny];
                    row.iter_mut().zip(k).zip(d).for_each(|((t, k), d)| *t = (sigma * d - step * *t) * k);
                }
                _ => row.iter_mut().zip(k).for_each(|(t, k)| *t *= -step * k),
            }
            if mode == ChangeTransform::Rows {
                for r in change_rows {
                    let c = sigma * r.spectrum[kx];
                    row.iter_mut().zip(k).zip(&r.phase).for_each(|((t, k), e)| *t += c * *k * e);
                }
            }
        });
        if self.contact.len() > self.ny * self.nx / 16 {
            // The first steps of a cold start: the changes' spectrum gives its room to the
            // contact sets and changes this step builds (it is allocated again when needed).
            self.change_spectrum = Vec::new();
        }
        let h = &self.heights;
        let (row_start, rows) = self.contact.split_rows();
        fft.inverse_rows(
            spectrum,
            ny,
            |_| true,
            work,
            (0, &mut self.displacement[..], rows, &mut self.pending[..], &mut self.row_sums[..]),
            |(first, u, rows, pending, sums), mid| {
                let (ua, ub) = u.split_at_mut((mid - first) * nx);
                let (ra, rb) = rows.split(mid, row_start);
                let (da, db) = pending.split_at_mut(mid - first);
                let (sa, sb) = sums.split_at_mut(mid - first);
                ((first, ua, ra, da, sa), (mid, ub, rb, db, sb))
            },
            |(first, u, rows, pending, sums), y, line| {
                let base = row_start[*first];
                let u = &mut u[(y - *first) * nx..][..nx];
                let h = &h[y * nx..][..nx];
                let changed = &mut pending[y - *first];
                changed.clear();
                // [complementarity, penetration, load, count, Σg, Σg², Σg·u, Σu, Σu², Σt] over
                // the next contact set, g = u − h − ḡ with the new u.
                let mut a = [0.0; SUMS];
                let (mut j, end) = (row_start[y], row_start[y + 1]);
                if let Some(p) = uniform {
                    // Every point was in contact, at pressure p, direction t as computed again.
                    for x in 0..nx {
                        let g_old = sigma * u[x] - h[x] - gap_mean;
                        let (_, t) = search.at(u[x], h[x], 0.0);
                        let un = sigma * u[x] + line[x];
                        u[x] = un;
                        let g = un - h[x] - gap_mean;
                        let i = y * nx + x;
                        a[0] += p * g_old.abs();
                        let q = p - step * t;
                        if q > 0.0 {
                            let k = j - base;
                            (rows.index[k], rows.pressure[k], rows.direction[k]) = (i as u32, q, t);
                            member(&mut a, q, g, un, t);
                            j += 1;
                        } else {
                            changed.push(Change { index: i as u32, delta: -q, entering: false });
                        }
                    }
                    sums[y - *first] = a;
                    return;
                }
                for x in 0..nx {
                    let g_old = sigma * u[x] - h[x] - gap_mean;
                    let un = sigma * u[x] + line[x];
                    u[x] = un;
                    let g = un - h[x] - gap_mean;
                    let i = y * nx + x;
                    if j < end && rows.index[j - base] as usize == i {
                        let k = j - base;
                        a[0] += rows.pressure[k] * g_old.abs();
                        let q = rows.pressure[k] - step * rows.direction[k];
                        if q > 0.0 {
                            rows.pressure[k] = q;
                            member(&mut a, q, g, un, rows.direction[k]);
                        } else {
                            // Clipped: it leaves the contact set.
                            rows.pressure[k] = 0.0;
                            changed.push(Change { index: i as u32, delta: -q, entering: false });
                        }
                        j += 1;
                    } else if g_old < 0.0 {
                        // Inadmissible: it enters the contact set.
                        a[1] -= g_old;
                        let q = -step * g_old;
                        changed.push(Change { index: i as u32, delta: q, entering: true });
                        member(&mut a, q, g, un, 0.0);
                    }
                }
                sums[y - *first] = a;
            },
        );
        let [complementarity, penetration, load, count, s_g, s_gg, s_gu, s_u, s_uu, s_t] = sum_rows(&self.row_sums);
        if load.is_nan() || load <= 0.0 {
            return Err(Error::invalid("contact solver", "broke down: the projection left no pressure"));
        }
        if self.uniform.take().is_none() && !self.pending_is_empty() {
            self.rebuild_contact_set();
        }
        self.scale = total / load;
        let scale = self.scale;
        self.contact.pressure.par_iter_mut().with_min_len(4096).for_each(|p| *p *= scale);
        self.reference = gap_mean;
        // The next gap is σu − h − ḡ' = g + εu + (c − ḡ') with ε = σ − 1: its sums follow from
        // those of g and u.
        let e = scale - 1.0;
        let sum = s_g + e * s_u;
        let squares = s_gg + 2.0 * e * s_gu + e * e * s_uu;
        let mut shifts = Shifts {
            gap_mean: gap_mean + sum / count,
            gap_norm: (squares - sum * sum / count).max(0.0),
            direction_mean: s_t / count,
        };
        if sum * sum / count > 0.5 * squares {
            // The mean moved more than the gap varies: sum again around the new mean.
            let (offset, c) = (gap_mean - shifts.gap_mean, &self.contact);
            let (u, h) = (&self.displacement, &self.heights);
            shifts.gap_norm = c
                .index
                .iter()
                .map(|&i| {
                    let (u, h) = (u[i as usize], h[i as usize]);
                    (u - h - gap_mean + e * u + offset).powi(2)
                })
                .sum();
        }
        Ok((shifts, (complementarity + p_mean * penetration) / norm))
    }

    /// The contact set after a step: clipped points (p = 0) leave, inadmissible ones enter.
    fn rebuild_contact_set(&mut self) {
        let (old, new, pending) = (&self.contact, &mut self.next, &self.pending);
        new.row_start.clear();
        new.row_start.push(0);
        for (y, changed) in pending.iter().enumerate() {
            let entering = changed.iter().filter(|c| c.entering).count();
            let size = old.rows(y).len() + 2 * entering - changed.len();
            new.row_start.push(new.row_start[y] + size);
        }
        let n = new.row_start[self.ny];
        if new.index.capacity() > 2 * n {
            // Room of a set much larger than this one: allocate afresh rather than keep it.
            (new.index, new.pressure, new.direction) = Default::default();
        }
        for v in [&mut new.pressure, &mut new.direction] {
            v.resize(n, 0.0);
        }
        new.index.resize(n, 0);
        let (row_start, rows) = new.split_rows();
        merge_rows(0..self.ny, rows, row_start, old, pending);
        std::mem::swap(&mut self.contact, &mut self.next);
        if self.next.index.capacity() > 2 * self.contact.len() {
            // The set shrank a lot (the first steps of a cold start): give its old room back.
            self.next = ContactSet::default();
        }
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

/// Fill the new contact set's rows `ys` (`out`, from row `ys.start`): the old rows without
/// their clipped points, with the entering points merged in raster order. In parallel.
fn merge_rows(
    ys: std::ops::Range<usize>,
    out: ContactRows,
    row_start: &[usize],
    old: &ContactSet,
    pending: &[Vec<Change>],
) {
    if ys.len() > 64 {
        let mid = ys.start + ys.len() / 2;
        let (a, b) = out.split(mid, row_start);
        rayon::join(
            || merge_rows(ys.start..mid, a, row_start, old, pending),
            || merge_rows(mid..ys.end, b, row_start, old, pending),
        );
        return;
    }
    let mut k = 0;
    let mut put = |out: &mut ContactRows, index: u32, p: f64, t: f64| {
        (out.index[k], out.pressure[k], out.direction[k]) = (index, p, t);
        k += 1;
    };
    let mut out = out;
    for y in ys {
        let mut entering = pending[y].iter().filter(|c| c.entering).peekable();
        for j in old.rows(y) {
            while let Some(c) = entering.next_if(|c| c.index < old.index[j]) {
                put(&mut out, c.index, c.delta, 0.0);
            }
            if old.pressure[j] > 0.0 {
                put(&mut out, old.index[j], old.pressure[j], old.direction[j]);
            }
        }
        for c in entering {
            put(&mut out, c.index, c.delta, 0.0);
        }
    }
}

/// How an iteration computes the search direction at a contact point.
#[derive(Clone, Copy)]
struct Search {
    /// c, the stored gaps' reference [m].
    reference: f64,
    /// σ − 1.
    excess: f64,
    /// c − ḡ [m].
    offset: f64,
    /// β, the conjugation.
    beta: f64,
    /// t̄, the previous direction's mean over the contact set [m].
    mean: f64,
}

impl Search {
    /// The gap g − ḡ and the new direction t ← g − ḡ + β (t − t̄) at a point of displacement u
    /// and height h whose previous direction was t [m].
    fn at(&self, u: f64, h: f64, t: f64) -> (f64, f64) {
        // σu − h − ḡ = (u − h − c) + (σ − 1)u + (c − ḡ): the gap as the pass that set the
        // reference wrote it, then shifted.
        let g = (u - h - self.reference) + self.excess * u + self.offset;
        (g, g + self.beta * (t - self.mean))
    }
}

/// Count a point of the next contact set into a row's sums (see [`CpuSolver::step`]):
/// pressure q, gap g, displacement u, direction t.
fn member(a: &mut [f64; SUMS], q: f64, g: f64, u: f64, t: f64) {
    a[2] += q;
    a[3] += 1.0;
    a[4] += g;
    a[5] += g * g;
    a[6] += g * u;
    a[7] += u;
    a[8] += u * u;
    a[9] += t;
}

/// Return the heap's free pages to the system: many small rows freed at once stay resident
/// in the allocator's arenas otherwise (glibc keeps what lies below the top of an arena).
fn give_back_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free memory of the allocator; it touches no live block.
    unsafe {
        libc::malloc_trim(0);
    }
}
