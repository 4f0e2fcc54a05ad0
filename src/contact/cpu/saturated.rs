//! Elastic–perfectly-plastic normal contact: the pressure saturates at the hardness H,
//! 0 ≤ p ≤ H (the saturated-pressure problem; Tamaas's KatoSaturated solves the same).
//!
//! Every point is one of
//! - free: 0 < p < H, gap g = 0 (elastic contact);
//! - out of contact: p = 0, g ≥ 0;
//! - saturated: p = H, g ≤ 0 — the rigid surface penetrates the elastic one: the plastic
//!   indentation, which the elastic half-space does not see.
//!
//! The solve is Polonsky & Keer's constrained conjugate gradient on the free points, with the
//! projection at both bounds: a step that takes a point below 0 clips it, one that takes it
//! above H saturates it; a point out of contact that penetrates enters, a saturated point
//! whose gap opens leaves saturation (both restart the conjugacy). The load is restored by
//! p ← min(λp, H) with λ such that Σp matches N, which keeps saturated points at H; if the
//! points in contact cannot carry N even saturated, the rest goes, at H each, to the points
//! out of contact with the smallest gap. The residual is the elastic one plus the opening of
//! saturated points, H·max(g, 0), in the same normalisation.
//!
//! Each iteration recomputes u = K p and applies K to the search direction from scratch: two
//! FFT pairs. The elastic solver's one-pair iteration rests on restoring the load by a uniform
//! rescaling, which the cap breaks; this path runs only when a hardness is set.
//!
//! Imports its parent (`cpu`) and `options` inside `contact`; must not import friction, study,
//! report, plot, shs, cli.

use std::time::Instant;

use rayon::prelude::*;

use super::{sum_rows, CpuSolver};
use crate::contact::options::{Iterations, Scales, SolveReport, STALL};
use crate::error::Result;
use crate::fft::large_buffer;

/// Newton steps of the load restoration at most (it is exact after a few).
const NEWTON: usize = 64;

impl CpuSolver {
    /// [`Engine::solve`](crate::contact::options::Engine::solve) with the pressure capped at `hardness` [Pa].
    pub(super) fn solve_saturated(
        &mut self,
        hardness: f64,
        load: f64,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<SolveReport> {
        let start = Instant::now();
        let (ny, nx) = (self.ny, self.nx);
        let n = ny * nx;
        let Scales { p_mean, total, norm, stiffness } =
            Scales::of(hardness, load, self.size, (ny, nx), self.e_star, self.h_rms)?;

        let mut p = large_buffer(n, 0.0);
        if self.warm && self.contact.len() > 0 {
            for (&i, &q) in self.contact.index.iter().zip(&self.contact.pressure) {
                p[i as usize] = q.min(hardness);
            }
        } else {
            p.fill(p_mean);
        }
        let (mut t, mut kt) = (large_buffer(n, 0.0), large_buffer(n, 0.0));
        let h = &self.heights;
        self.operator.apply(&p, &mut self.displacement);
        restore_load(&mut p, hardness, total, nx, &self.displacement, h);

        let mut iterations = Iterations::new("contact solver", self.options.convergence, STALL);
        let mut applications = 0.0;
        let (mut conjugate, mut gap_norm_old) = (false, 1.0);
        let residual = loop {
            self.operator.apply(&p, &mut self.displacement);
            applications += 1.0;
            let u = &self.displacement;
            let gap_mean = free_gap_mean(&p, u, h, hardness, nx);
            // [free: Σ p|g|, Σ g²; saturated: Σ H max(g, 0); out: Σ max(−g, 0)]
            let sums: Vec<[f64; 4]> = rows(&p, nx)
                .map(|(y, row)| {
                    let mut a = [0.0; 4];
                    for (x, &q) in row.iter().enumerate() {
                        let g = u[y * nx + x] - h[y * nx + x] - gap_mean;
                        if q == 0.0 {
                            a[3] += (-g).max(0.0);
                        } else if q == hardness {
                            a[2] += hardness * g.max(0.0);
                        } else {
                            a[0] += q * g.abs();
                            a[1] += g * g;
                        }
                    }
                    a
                })
                .collect();
            let [complementarity, gap_norm, opening, penetration] = sum_rows(&sums);
            let residual = (complementarity + opening + p_mean * penetration) / norm;
            if iterations.done() > 0 && !progress(iterations.done(), residual) {
                return Err(Self::interrupted(load));
            }
            if residual <= self.options.convergence.tolerance {
                break residual;
            }
            if iterations.next(residual).inspect_err(|_| self.warm = false)? {
                conjugate = false;
            }
            let beta = if conjugate && gap_norm_old > 0.0 { gap_norm / gap_norm_old } else { 0.0 };
            gap_norm_old = gap_norm;

            // t ← g + β t on the free points, 0 elsewhere.
            let sums: Vec<[f64; 3]> = p
                .par_chunks(nx)
                .zip(t.par_chunks_mut(nx))
                .enumerate()
                .map(|(y, (row, t))| {
                    let mut a = [0.0; 3];
                    for (x, (&q, t)) in row.iter().zip(t).enumerate() {
                        if q > 0.0 && q < hardness {
                            let g = u[y * nx + x] - h[y * nx + x] - gap_mean;
                            *t = g + beta * *t;
                            a[0] += g * *t;
                            a[1] += *t;
                            a[2] += 1.0;
                        } else {
                            *t = 0.0;
                        }
                    }
                    a
                })
                .collect();
            let [along, t_sum, free] = sum_rows(&sums);
            self.operator.apply(&t, &mut kt);
            applications += 1.0;
            // t·(Kt − mean of Kt over the free points): the curvature along t at fixed load.
            let sums: Vec<[f64; 2]> = rows(&p, nx)
                .map(|(y, row)| {
                    let mut a = [0.0; 2];
                    for (x, &q) in row.iter().enumerate() {
                        if q > 0.0 && q < hardness {
                            let i = y * nx + x;
                            a[0] += kt[i] * t[i];
                            a[1] += kt[i];
                        }
                    }
                    a
                })
                .collect();
            let [tkt, kt_sum] = sum_rows(&sums);
            let curvature = if free > 0.0 { tkt - kt_sum / free * t_sum } else { 0.0 };
            // No direction (no free point, or a flat gap on them): only the projection has
            // work left, at the finest mode's stiffness.
            let step = if curvature > 0.0 && along > 0.0 { along / curvature } else { 1.0 / stiffness };

            let entered: Vec<bool> = p
                .par_chunks_mut(nx)
                .zip(t.par_chunks(nx))
                .enumerate()
                .map(|(y, (row, t))| {
                    let mut entered = false;
                    for (x, (q, &t)) in row.iter_mut().zip(t).enumerate() {
                        let g = u[y * nx + x] - h[y * nx + x] - gap_mean;
                        if *q > 0.0 && *q < hardness {
                            *q = (*q - step * t).clamp(0.0, hardness);
                        } else if *q == 0.0 && g < 0.0 {
                            *q = (-step * g).min(hardness);
                            entered = true;
                        } else if *q == hardness && g > 0.0 {
                            *q = (hardness - step * g).max(0.0);
                            entered = true;
                        }
                    }
                    entered
                })
                .collect();
            let filled = restore_load(&mut p, hardness, total, nx, u, h);
            conjugate = !(filled || entered.contains(&true));
        };
        self.pressure_field = p;
        self.adopt_pressure_field();
        self.warm = true;
        Ok(SolveReport {
            load,
            mean_pressure: p_mean,
            iterations: iterations.done(),
            residual,
            operator_applications: applications,
            seconds: start.elapsed().as_secs_f64(),
            hardness: Some(hardness),
        })
    }
}

/// The rows of `field` (row-major, `nx` wide), with their indices, in parallel.
fn rows(field: &[f64], nx: usize) -> impl IndexedParallelIterator<Item = (usize, &[f64])> {
    field.par_chunks(nx).enumerate()
}

/// ḡ: the mean of u − h over the free points (0 < p < H). Without free points, the largest
/// u − h over the saturated ones, so that no saturated point has an open gap.
fn free_gap_mean(p: &[f64], u: &[f64], h: &[f64], hardness: f64, nx: usize) -> f64 {
    let sums: Vec<[f64; 3]> = rows(p, nx)
        .map(|(y, row)| {
            let mut a = [0.0, 0.0, f64::NEG_INFINITY];
            for (x, &q) in row.iter().enumerate() {
                let g = u[y * nx + x] - h[y * nx + x];
                if q == hardness {
                    a[2] = a[2].max(g);
                } else if q > 0.0 {
                    a[0] += g;
                    a[1] += 1.0;
                }
            }
            a
        })
        .collect();
    let (sum, count) = sums.iter().fold((0.0, 0.0), |(s, c), a| (s + a[0], c + a[1]));
    if count > 0.0 {
        sum / count
    } else {
        sums.iter().map(|a| a[2]).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Restore the load: p ← min(λp, H) on the free points (0 < p < H) with Σp = `total`, by
/// Newton's method on the concave, piecewise-linear Σ min(λp, H), which from below lands on the
/// root in a few steps; saturated points stay at H. If they alone carry more than the load,
/// every point is scaled instead (and leaves saturation). If the points in contact cannot
/// carry the load even saturated, the rest goes at H each to the points out of contact with
/// the smallest u − h. Returns whether any point was let in so.
fn restore_load(p: &mut [f64], hardness: f64, total: f64, nx: usize, u: &[f64], h: &[f64]) -> bool {
    // [Σ free p, saturated load, Σ p]
    let sums: Vec<[f64; 3]> = rows(p, nx)
        .map(|(_, row)| {
            row.iter().fold(
                [0.0; 3],
                |[f, s, all], &q| {
                    if q == hardness {
                        [f, s + q, all + q]
                    } else {
                        [f + q, s, all + q]
                    }
                },
            )
        })
        .collect();
    let [free, saturated, all] = sum_rows(&sums);
    if saturated >= total {
        let scale = total / all;
        p.par_iter_mut().with_min_len(4096).for_each(|q| *q *= scale);
    } else if free > 0.0 {
        let mut lambda = (total - saturated) / free;
        for _ in 0..NEWTON {
            let sums: Vec<[f64; 2]> = rows(p, nx)
                .map(|(_, row)| {
                    row.iter().fold([0.0, 0.0], |[s, slope], &q| {
                        if q == hardness || lambda * q >= hardness {
                            [s + hardness, slope]
                        } else {
                            [s + lambda * q, slope + q]
                        }
                    })
                })
                .collect();
            let [carried, slope] = sum_rows(&sums);
            let missing = total - carried;
            if missing <= 1e-15 * total || slope == 0.0 {
                break;
            }
            lambda += missing / slope;
        }
        p.par_iter_mut().with_min_len(4096).for_each(|q| {
            if *q < hardness {
                *q = (lambda * *q).min(hardness);
            }
        });
    }
    let carried = sum_rows(&rows(p, nx).map(|(_, row)| [row.iter().sum::<f64>()]).collect::<Vec<_>>())[0];
    let mut missing = total - carried;
    if missing <= 1e-12 * total {
        return false;
    }
    let mut out: Vec<(f64, u32)> =
        p.iter().enumerate().filter(|(_, q)| **q == 0.0).map(|(i, _)| (u[i] - h[i], i as u32)).collect();
    let k = ((missing / hardness).ceil() as usize).clamp(1, out.len());
    out.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    out.truncate(k);
    out.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (_, i) in out {
        let q = missing.min(hardness);
        p[i as usize] = q;
        missing -= q;
    }
    true
}
