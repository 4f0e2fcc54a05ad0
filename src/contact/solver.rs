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
//! tolerance. It is checked on a gap recomputed from scratch, with the load restored exactly.
//!
//! Each iteration needs one application of the influence operator (`K t` for the search
//! direction t). The gap is then updated as `g ← g − τ K t`, which is exact while the contact
//! set does not change; when it does (points leave by clipping or enter as inadmissible
//! points), the load is restored and the gap recomputed as `K p − h`: a second operator
//! application, needed only on those iterations. The search direction is kept of zero mean over
//! the contact set, so the fast path conserves the load.

use std::time::Instant;

use rayon::prelude::*;

use super::influence::{Boundary, Influence};
use crate::error::{Error, Result};

/// Iterations without a new best residual after which the conjugate gradient restarts.
const STALL: usize = 50;

/// Pixels per reduction chunk. Fixed, so sums (and results) do not depend on the thread count.
const CHUNK: usize = 8192;

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
    /// Applications of the influence operator (FFT pairs): one per iteration, plus one per
    /// change of the contact set and per convergence check.
    pub operator_applications: usize,
    /// Wall-clock time of the solve [s].
    pub seconds: f64,
}

/// A contact problem on one surface, solved for one load after another. The pressure of the
/// last solve is the starting point of the next (warm start), which makes load sweeps cheap.
pub struct ContactSolver {
    ny: usize,
    nx: usize,
    size: (f64, f64),
    boundary: Boundary,
    /// Effective modulus E* [Pa].
    e_star: f64,
    /// Rigid surface heights h [m]: higher points touch first.
    heights: Vec<f64>,
    h_rms: f64,
    operator: Influence,
    options: SolverOptions,
    /// Pressure p [Pa].
    pressure: Vec<f64>,
    /// u − h [m]: the gap before its shift by ḡ.
    gap: Vec<f64>,
    /// Search direction t [m] and its image K t [m] (also scratch for K p).
    direction: Vec<f64>,
    image: Vec<f64>,
    partials: Vec<[f64; 6]>,
    warm: bool,
}

/// The state of the iteration that the passes share.
struct Shifts {
    /// ḡ, mean of u − h over the contact set [m].
    gap_mean: f64,
    /// G = Σ_{p>0} (g − ḡ)² [m²].
    gap_norm: f64,
    /// Mean of the previous search direction over the current contact set [m].
    direction_mean: f64,
    contact_points: usize,
    residual: f64,
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
            pressure: vec![0.0; n],
            gap: vec![0.0; n],
            direction: vec![0.0; n],
            image: vec![0.0; n],
            partials: Vec::with_capacity(n.div_ceil(CHUNK)),
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
        &self.pressure
    }

    /// Gap of the last solve [m]: zero on the contact set, positive elsewhere.
    pub fn gap(&self) -> Vec<f64> {
        let s = self.shifts_exact_view();
        self.gap.iter().zip(&self.pressure).map(|(g, p)| if *p > 0.0 { 0.0 } else { (g - s).max(0.0) }).collect()
    }

    /// Surface displacement u = K p of the last solve [m]. In the periodic model its mean is
    /// zero: the rigid-body approach is not defined there.
    pub fn displacement(&self) -> Vec<f64> {
        self.gap.iter().zip(&self.heights).map(|(g, h)| g + h).collect()
    }

    fn shifts_exact_view(&self) -> f64 {
        let (sum, count) = self
            .gap
            .iter()
            .zip(&self.pressure)
            .filter(|(_, p)| **p > 0.0)
            .fold((0.0, 0usize), |(s, c), (g, _)| (s + g, c + 1));
        if count == 0 {
            0.0
        } else {
            sum / count as f64
        }
    }

    /// Start the next solve from scratch rather than from the last pressure.
    pub fn reset(&mut self) {
        self.warm = false;
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
        let scale = if self.h_rms > 0.0 { self.h_rms } else { 1.0 };
        if self.warm {
            let total: f64 = self.pressure.par_iter().sum();
            let k = p_mean * n as f64 / total;
            self.pressure.par_iter_mut().for_each(|p| *p *= k);
        } else {
            self.pressure.fill(p_mean);
            self.direction.fill(0.0);
        }
        let norm = n as f64 * p_mean * scale;
        let mut s = self.refresh(p_mean, norm);
        // τ: step length [Pa/m].
        let mut step = 0.0;
        let mut conjugate = false;
        let mut gap_norm_old = 1.0;
        // Best residual so far and when it was reached: a stalled search restarts from the
        // steepest descent direction.
        let (mut best, mut best_at) = (f64::INFINITY, 0);
        let mut exact = true;
        let mut iterations = 0;
        let mut applications = 1;
        loop {
            if !s.residual.is_finite() {
                self.warm = false;
                return Err(Error::invalid(
                    "contact solver",
                    format!("broke down at iteration {iterations} (non-finite residual)"),
                ));
            }
            if s.residual <= self.options.tolerance {
                if exact {
                    break;
                }
                self.restore_load(p_mean * n as f64);
                s = self.refresh(p_mean, norm);
                applications += 1;
                exact = true;
                continue;
            }
            if iterations == self.options.max_iterations {
                self.warm = false;
                return Err(Error::NotConverged {
                    solver: "contact solver",
                    iterations,
                    residual: s.residual,
                    tolerance: self.options.tolerance,
                });
            }
            iterations += 1;
            if s.residual < best {
                (best, best_at) = (s.residual, iterations);
            } else if iterations - best_at > STALL {
                (conjugate, best_at) = (false, iterations);
            }
            let beta = if conjugate && gap_norm_old > 0.0 { s.gap_norm / gap_norm_old } else { 0.0 };
            gap_norm_old = s.gap_norm;

            let (along, direction_sum) = self.update_direction(&s, beta);
            self.operator.apply(&self.direction, &mut self.image);
            applications += 1;
            let (image_sum, curvature) = self.project_image();
            let n_c = s.contact_points as f64;
            let image_mean = image_sum / n_c;
            let denominator = curvature - image_mean * direction_sum;
            if denominator > 0.0 && along.is_finite() {
                step = along / denominator;
            } else if step == 0.0 {
                step = self.finest_stiffness();
            }
            let gap_mean_next = s.gap_mean - step * image_mean;
            let pass = self.update_pressure(&s, step, gap_mean_next, p_mean);
            if pass.changed {
                // The contact set changed: restore the load and recompute the gap exactly.
                self.restore_load(p_mean * n as f64);
                s = self.refresh(p_mean, norm);
                applications += 1;
                // Unlike Polonsky & Keer, conjugacy is kept when points enter the contact set:
                // resetting it there makes load sweeps, where the set keeps growing, converge
                // like steepest descent (2–3× more iterations on rough spheres).
                conjugate = true;
                exact = true;
            } else {
                s = Shifts {
                    gap_mean: gap_mean_next,
                    gap_norm: pass.gap_norm,
                    direction_mean: 0.0,
                    contact_points: s.contact_points,
                    residual: pass.residual / norm,
                };
                conjugate = true;
                exact = false;
            }
            progress(iterations, s.residual);
        }
        self.warm = true;
        Ok(SolveReport {
            load,
            mean_pressure: p_mean,
            iterations,
            residual: s.residual,
            operator_applications: applications,
            seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// Stiffness of the finest resolved mode, 1/K(π/Δ) = E* π / (2Δ) [Pa/m]: a step length of
    /// the right scale when the conjugate-gradient one is undefined (a gap already flat on the
    /// contact set, with penetration left outside it).
    fn finest_stiffness(&self) -> f64 {
        let spacing = (self.size.0 / self.nx as f64).min(self.size.1 / self.ny as f64);
        self.e_star * std::f64::consts::PI / (2.0 * spacing)
    }

    /// Scale the pressure so that it sums to `total` [Pa].
    fn restore_load(&mut self, total: f64) {
        let sum: f64 = self.pressure.par_iter().sum();
        let k = total / sum;
        self.pressure.par_iter_mut().for_each(|p| *p *= k);
    }

    /// Recompute u − h from the pressure and the shifts, residual and norms from it.
    fn refresh(&mut self, p_mean: f64, norm: f64) -> Shifts {
        self.operator.apply(&self.pressure, &mut self.image);
        // Pass 1: the gap, its mean over the contact set, the direction's mean over it.
        self.image
            .par_chunks(CHUNK)
            .zip(self.heights.par_chunks(CHUNK))
            .zip(self.gap.par_chunks_mut(CHUNK))
            .zip(self.pressure.par_chunks(CHUNK).zip(self.direction.par_chunks(CHUNK)))
            .map(|(((u, h), g), (p, t))| {
                let mut acc = [0.0; 6];
                for i in 0..g.len() {
                    g[i] = u[i] - h[i];
                    if p[i] > 0.0 {
                        acc[0] += g[i];
                        acc[1] += 1.0;
                        acc[2] += t[i];
                    }
                }
                acc
            })
            .collect_into_vec(&mut self.partials);
        let [gap_sum, count, direction_sum, ..] = sum_partials(&self.partials);
        let gap_mean = gap_sum / count;
        // Pass 2: the norm of the shifted gap on the contact set and the residual.
        self.gap
            .par_chunks(CHUNK)
            .zip(self.pressure.par_chunks(CHUNK))
            .map(|(g, p)| {
                let mut acc = [0.0; 6];
                for i in 0..g.len() {
                    let gs = g[i] - gap_mean;
                    if p[i] > 0.0 {
                        acc[0] += gs * gs;
                        acc[1] += p[i] * gs.abs();
                    } else if gs < 0.0 {
                        acc[2] -= gs;
                    }
                }
                acc
            })
            .collect_into_vec(&mut self.partials);
        let [gap_norm, complementarity, penetration, ..] = sum_partials(&self.partials);
        Shifts {
            gap_mean,
            gap_norm,
            direction_mean: direction_sum / count,
            contact_points: count as usize,
            residual: (complementarity + p_mean * penetration) / norm,
        }
    }

    /// t ← g − ḡ + β (t − t̄) on the contact set, 0 elsewhere. Returns Σ (g − ḡ) t and Σ t.
    fn update_direction(&mut self, s: &Shifts, beta: f64) -> (f64, f64) {
        let (gap_mean, direction_mean) = (s.gap_mean, s.direction_mean);
        self.direction
            .par_chunks_mut(CHUNK)
            .zip(self.gap.par_chunks(CHUNK))
            .zip(self.pressure.par_chunks(CHUNK))
            .map(|((t, g), p)| {
                let mut acc = [0.0; 6];
                for i in 0..t.len() {
                    if p[i] > 0.0 {
                        let gs = g[i] - gap_mean;
                        let ti = gs + beta * (t[i] - direction_mean);
                        t[i] = ti;
                        acc[0] += gs * ti;
                        acc[1] += ti;
                    } else {
                        t[i] = 0.0;
                    }
                }
                acc
            })
            .collect_into_vec(&mut self.partials);
        let [along, direction_sum, ..] = sum_partials(&self.partials);
        (along, direction_sum)
    }

    /// Σ_{p>0} K t and Σ t·K t (t vanishes outside the contact set).
    fn project_image(&mut self) -> (f64, f64) {
        self.image
            .par_chunks(CHUNK)
            .zip(self.direction.par_chunks(CHUNK))
            .zip(self.pressure.par_chunks(CHUNK))
            .map(|((r, t), p)| {
                let mut acc = [0.0; 6];
                for i in 0..r.len() {
                    if p[i] > 0.0 {
                        acc[0] += r[i];
                        acc[1] += r[i] * t[i];
                    }
                }
                acc
            })
            .collect_into_vec(&mut self.partials);
        let [image_sum, curvature, ..] = sum_partials(&self.partials);
        (image_sum, curvature)
    }

    /// p ← max(p − τ t, 0); inadmissible points (p = 0, g < 0) enter with p = −τ g; the gap
    /// moves to g − τ K t, and the residual of the new state is summed assuming an unchanged
    /// contact set (the caller recomputes everything when it did change).
    fn update_pressure(&mut self, s: &Shifts, step: f64, gap_mean_next: f64, p_mean: f64) -> PressurePass {
        let gap_mean = s.gap_mean;
        self.pressure
            .par_chunks_mut(CHUNK)
            .zip(self.gap.par_chunks_mut(CHUNK))
            .zip(self.direction.par_chunks(CHUNK).zip(self.image.par_chunks(CHUNK)))
            .map(|((p, g), (t, r))| {
                let mut acc = [0.0; 6];
                for i in 0..p.len() {
                    let mut q = p[i];
                    if q > 0.0 {
                        q -= step * t[i];
                        if q <= 0.0 {
                            q = 0.0;
                            acc[0] += 1.0;
                        }
                    }
                    let gs = g[i] - gap_mean;
                    if q == 0.0 && gs < 0.0 {
                        q = -step * gs;
                        acc[1] += 1.0;
                    }
                    p[i] = q;
                    let gn = g[i] - step * r[i];
                    g[i] = gn;
                    let gsn = gn - gap_mean_next;
                    if q > 0.0 {
                        acc[2] += gsn * gsn;
                        acc[3] += q * gsn.abs();
                    } else if gsn < 0.0 {
                        acc[4] -= gsn;
                    }
                }
                acc
            })
            .collect_into_vec(&mut self.partials);
        let [clipped, added, gap_norm, complementarity, penetration, _] = sum_partials(&self.partials);
        PressurePass {
            changed: clipped > 0.0 || added > 0.0,
            gap_norm,
            residual: complementarity + p_mean * penetration,
        }
    }
}

struct PressurePass {
    changed: bool,
    gap_norm: f64,
    /// Unnormalised residual.
    residual: f64,
}

/// Sum per-chunk partial sums in chunk order (deterministic).
fn sum_partials(partials: &[[f64; 6]]) -> [f64; 6] {
    partials.iter().fold([0.0; 6], |mut a, b| {
        a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        a
    })
}
