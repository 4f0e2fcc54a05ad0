//! The MPRGP solve of the whole problem and its fallback, the accelerated projected gradient
//! (see the module above).
//!
//! Imports its parent (`tangential`), `disk` and `options` inside `contact`; must not import
//! friction, study, report, plot, shs, cli.

use rayon::prelude::*;

use super::disk::{
    cut_onto_disks, dot, feasible_step, gradient_parts, magnitude, onto_disk, project, reduced_free_gradient,
    tangent_if_held, turning, CHUNK, ON_BOUND,
};
use super::{TangentialOptions, TangentialReport, TangentialSolver};
use crate::contact::options::Iterations;
use crate::error::Result;

/// Iterations without a new best residual after which the solve changes method.
const STALL: usize = 25;

/// Solves stopping at this relative residual or above apply K in single precision: its
/// round-off, a relative 1e-7 to 5e-7 measured on 256² to 1500² windows, is at most half of
/// it, and the transforms take 1.3–1.7 times less time. Tighter solves run in double
/// throughout. A check in double precision of the single-precision solves below 5e-5 once
/// converged moved the sliding onset's drop by 4e-7 (1500² with its wafer, 10 mN,
/// mu_s 0.6, mu_d 0.4: 1.0011985 with, 1.0011981 without) and 3e-7 (31.6 mN) for 9 % and 7 %
/// of the applications, each check a transform in double: not done.
const SINGLE: f64 = 1e-6;

/// Relative round-off of an application of K in single precision (measured 1e-7 to 5e-7, see
/// [`SINGLE`]) and in double, as a bound on what a step by step update of the displacement
/// carries away from K q.
const SINGLE_ROUND_OFF: f64 = 1e-6;
const DOUBLE_ROUND_OFF: f64 = 1e-15;

/// Steps tried by the projected search of an expansion, from the first bound to the conjugate
/// gradient step (geometric ladder). Measured at 1500², 10 mN: 24 tried up to the conjugate
/// gradient step take 5 350 applications, up to twice and four times it 5 420 and 5 496,
/// against 7 439 without the search.
const SEARCH: usize = 24;

/// Proportioning constant Γ: a proportioning step is taken when the chopped gradient exceeds Γ
/// times the (reduced) free gradient.
const GAMMA: f64 = 1.0;

impl TangentialSolver {
    /// Solve for the targets `target` b_i \[m] and bounds `bound` g_i \[Pa] (one per contact
    /// point), starting from the last traction.
    pub fn solve(&mut self, target: &[[f64; 2]], bound: &[f64]) -> Result<TangentialReport> {
        self.solve_within(target, bound, self.options.tolerance)
    }

    /// [`solve`](Self::solve) to another relative norm of the projected gradient.
    pub fn solve_within(&mut self, target: &[[f64; 2]], bound: &[f64], tolerance: f64) -> Result<TangentialReport> {
        let m = self.points.len();
        assert!(target.len() == m && bound.len() == m, "one target and one bound per contact point");
        let scale = (target.iter().map(|b| b[0] * b[0] + b[1] * b[1]).sum::<f64>()).sqrt();
        if scale == 0.0 {
            self.traction.fill([0.0; 2]);
            self.displacement.fill([0.0; 2]);
            return Ok(TangentialReport { iterations: 0, applications: 0, residual: 0.0 });
        }
        let mut applications = 0;
        // The displacement of the last solve is exact for its traction: recompute it only
        // where the new bounds cut the traction, or when this solve needs double precision
        // and the last ran in single.
        let single = tolerance >= SINGLE;
        let to_double = self.operator.set_single(single) && !single;
        let cuts = cut_onto_disks(&mut self.traction, bound);
        if to_double || !cuts.is_empty() {
            self.take_cuts(&cuts, to_double, &mut applications);
        }
        // The fixed step ᾱ ∈ (0, 2/‖K‖] of the expansion steps; not needed without bounds.
        let step = if bound.iter().all(|g| g.is_infinite()) { 0.0 } else { 1.9 / self.lipschitz(&mut applications) };
        let mut count = Iterations::new("tangential solver", TangentialOptions { tolerance, ..self.options }, STALL);
        // How far [m] the displacement may be from K q: 0 just after it was recomputed; the
        // conjugate gradient steps add what they do not follow (see `drift`).
        let mut drift = 0.0;
        let mut round_off = if single { SINGLE_ROUND_OFF } else { DOUBLE_ROUND_OFF };
        // Whether the search direction starts afresh from the free gradient.
        let mut restart = true;
        let mut accelerated = false;
        let mut momentum = 1.0;
        loop {
            let (free, chopped, reduced) = self
                .traction
                .par_iter()
                .zip(self.displacement.par_iter())
                .zip(target.par_iter().zip(bound.par_iter()))
                .with_min_len(CHUNK)
                .map(|((q, u), (b, g))| {
                    let (phi, beta) = gradient_parts(*q, *u, *b, *g);
                    (dot(phi, phi), dot(beta, beta), dot(reduced_free_gradient(*q, phi, *g, step), phi))
                })
                .reduce(|| (0.0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
            let residual = (free + chopped).sqrt() / scale;
            if residual <= tolerance {
                // The gradient's parts move by at most as much as the displacement: converged
                // also on K q when the drift cannot lift the residual past the tolerance.
                if residual + drift / scale <= tolerance {
                    return Ok(TangentialReport { iterations: count.done(), applications, residual });
                }
                // Converged on the displacement updated step by step: check from scratch. The
                // residuals before were measured on the updated displacement, which misses the
                // turned tractions' return onto their bounds: progress counts from here.
                self.refresh();
                applications += 1;
                drift = 0.0;
                restart = true;
                count.forget_best();
                continue;
            }
            let stalled = count.next(residual)?;
            if stalled && self.operator.set_single(false) {
                // Perhaps on the single precision's round-off: go on in double.
                self.refresh();
                applications += 1;
                drift = 0.0;
                round_off = DOUBLE_ROUND_OFF;
                restart = true;
                continue;
            }
            if stalled && !accelerated && step > 0.0 {
                // Should the turning of many tractions at once keep it from converging, the
                // solve finishes with the accelerated projected gradient, which cannot stall.
                accelerated = true;
                self.previous_traction.copy_from_slice(&self.traction);
                self.previous_displacement.copy_from_slice(&self.displacement);
            }
            if accelerated {
                self.accelerated_step(target, bound, step / 1.9, &mut momentum);
                applications += 1;
                drift = 0.0;
                continue;
            }
            if chopped > GAMMA * GAMMA * reduced {
                // Proportioning step: release the points whose gradient pulls them off their
                // bounds, with the exact step length.
                self.set_direction(target, bound, |parts| parts.1);
                self.curvature.fill(0.0);
                self.apply_direction();
                applications += 1;
                restart = true;
                let pw = self.direction_energy();
                if pw.is_nan() || pw <= 0.0 {
                    continue;
                }
                drift += round_off * self.move_along(chopped / pw);
                if project(&mut self.traction, bound) > 0.0 {
                    self.refresh();
                    applications += 1;
                    drift = 0.0;
                }
                continue;
            }
            if restart {
                // Conjugate gradients on the free points and on the turning of the tractions
                // held on their bounds; a turn costs, besides K's energy, the bound's
                // curvature: the Lagrangian's Hessian there is K + (slip / bound).
                self.curvature
                    .par_iter_mut()
                    .zip(self.traction.par_iter().zip(self.displacement.par_iter()))
                    .zip(target.par_iter().zip(bound.par_iter()))
                    .with_min_len(CHUNK)
                    .for_each(|((c, (q, u)), (b, g))| *c = turning(*q, *u, *b, *g));
                let k = self.diagonal(&mut applications);
                self.precondition(target, bound, k);
                self.conjugate_direction(bound, None);
                restart = false;
            }
            self.apply_direction();
            applications += 1;
            let pw = self.direction_energy();
            if pw.is_nan() || pw <= 0.0 {
                restart = true;
                continue;
            }
            let rp: f64 = self
                .direction
                .par_iter()
                .zip(self.displacement.par_iter().zip(target.par_iter()))
                .with_min_len(CHUNK)
                .map(|(p, (u, b))| dot([u[0] - b[0], u[1] - b[1]], *p))
                .sum();
            let cg = rp / pw;
            let feasible = self
                .traction
                .par_iter()
                .zip(self.direction.par_iter().zip(bound.par_iter()))
                .with_min_len(CHUNK)
                .map(|(q, (p, g))| feasible_step(*q, *p, *g))
                .reduce(|| f64::INFINITY, f64::min);
            if cg <= feasible {
                // Conjugate gradient step: no free point reaches its bound; turned tractions
                // are put back onto their bounds, a second-order change the displacement
                // misses until the next recomputation: ‖K c‖ ≤ ‖K‖‖c‖ for the cuts c.
                drift += round_off * self.move_along(cg);
                let cut = project(&mut self.traction, bound);
                if cut > 0.0 {
                    drift += self.lipschitz.unwrap_or(f64::INFINITY) * cut;
                }
                let k = self.diagonal.expect("set at the restart");
                self.precondition(target, bound, k);
                let gamma = self
                    .preconditioned
                    .par_iter()
                    .zip(self.product.par_iter().zip(self.direction.par_iter().zip(self.curvature.par_iter())))
                    .with_min_len(CHUNK)
                    .map(|(z, (w, (p, c)))| dot(*z, [w[0] + c * p[0], w[1] + c * p[1]]))
                    .sum::<f64>()
                    / pw;
                self.conjugate_direction(bound, Some(gamma));
            } else {
                // Expansion step: past the first bound along the projected path, where the
                // energy model puts its minimum, many points reach their bounds at once; kept
                // when the energy falls below that at the first bound.
                let alpha = self.projected_search(target, bound, (rp, pw), feasible, cg);
                if alpha > feasible {
                    let first_bound = self.energy(target) - feasible * rp + 0.5 * feasible * feasible * pw;
                    self.previous_traction.copy_from_slice(&self.traction);
                    self.previous_displacement.copy_from_slice(&self.displacement);
                    self.traction
                        .par_iter_mut()
                        .zip(self.direction.par_iter().zip(bound.par_iter()))
                        .with_min_len(CHUNK)
                        .for_each(|(q, (p, g))| *q = onto_disk([q[0] - alpha * p[0], q[1] - alpha * p[1]], *g));
                    self.refresh();
                    applications += 1;
                    if self.energy(target) < first_bound {
                        drift = 0.0;
                        restart = true;
                        continue;
                    }
                    self.traction.copy_from_slice(&self.previous_traction);
                    self.displacement.copy_from_slice(&self.previous_displacement);
                }
                // Else as far as the bounds allow, then a projected gradient step of fixed
                // length on the free gradient.
                self.move_along(feasible);
                self.traction
                    .par_iter_mut()
                    .zip(self.displacement.par_iter())
                    .zip(target.par_iter().zip(bound.par_iter()))
                    .with_min_len(CHUNK)
                    .for_each(|((q, u), (b, g))| {
                        let q0 = onto_disk(*q, *g);
                        let phi = gradient_parts(q0, *u, *b, *g).0;
                        *q = onto_disk([q0[0] - step * phi[0], q0[1] - step * phi[1]], *g);
                    });
                self.refresh();
                applications += 1;
                drift = 0.0;
                restart = true;
            }
        }
    }

    /// direction ← one of the gradient's parts (free, chopped) at every point.
    fn set_direction(
        &mut self,
        target: &[[f64; 2]],
        bound: &[f64],
        part: impl Fn(([f64; 2], [f64; 2])) -> [f64; 2] + Sync,
    ) {
        self.direction
            .par_iter_mut()
            .zip(self.traction.par_iter().zip(self.displacement.par_iter()))
            .zip(target.par_iter().zip(bound.par_iter()))
            .with_min_len(CHUNK)
            .for_each(|((p, (q, u)), (b, g))| *p = part(gradient_parts(*q, *u, *b, *g)));
    }

    /// preconditioned ← z = S P N P S φ: the free gradient φ through K's inverse near the
    /// diagonal N (scaled to 1 on it), where S scales a point by √(k / (k + c)) (k K's diagonal,
    /// c the point's curvature term, zero at a free point) and P keeps only the part along the
    /// bound at the points held on it (φ has no other there). Symmetric and positive: with N's diagonal alone it is
    /// the Hessian's diagonal, k / (k + c).
    fn precondition(&mut self, target: &[[f64; 2]], bound: &[f64], k: f64) {
        self.scaled
            .par_iter_mut()
            .zip(self.traction.par_iter().zip(self.displacement.par_iter()))
            .zip(target.par_iter().zip(bound.par_iter().zip(self.curvature.par_iter())))
            .with_min_len(CHUNK)
            .for_each(|((z, (q, u)), (b, (g, c)))| {
                let s = (k / (k + c)).sqrt();
                let phi = gradient_parts(*q, *u, *b, *g).0;
                *z = [phi[0] * s, phi[1] * s];
            });
        self.near_inverse.apply(&self.scaled, &mut self.preconditioned);
        self.preconditioned
            .par_iter_mut()
            .zip(self.traction.par_iter().zip(bound.par_iter().zip(self.curvature.par_iter())))
            .with_min_len(CHUNK)
            .for_each(|(z, (q, (g, c)))| {
                let s = (k / (k + c)).sqrt();
                let t = tangent_if_held(*z, *q, *g);
                *z = [t[0] * s, t[1] * s];
            });
    }

    /// direction ← the preconditioned free gradient z, made conjugate to the last direction p
    /// with `gamma` (z − γ p, without its radial part at the points held on their bounds), or
    /// z alone at a restart (`None`).
    fn conjugate_direction(&mut self, bound: &[f64], gamma: Option<f64>) {
        self.direction
            .par_iter_mut()
            .zip(self.preconditioned.par_iter().zip(self.traction.par_iter().zip(bound.par_iter())))
            .with_min_len(CHUNK)
            .for_each(|(p, (z, (q, g)))| {
                let z = *z;
                *p = match gamma {
                    Some(gamma) => tangent_if_held([z[0] - gamma * p[0], z[1] - gamma * p[1]], *q, *g),
                    None => z,
                };
            });
    }

    /// product ← K direction.
    fn apply_direction(&mut self) {
        self.operator.apply(&self.direction, &mut self.product);
    }

    /// pᵀ(K + C)p of the direction, once its product Kp is known (C the curvature terms).
    fn direction_energy(&self) -> f64 {
        self.direction
            .par_iter()
            .zip(self.product.par_iter().zip(self.curvature.par_iter()))
            .with_min_len(CHUNK)
            .map(|(p, (w, c))| dot(*p, *w) + c * dot(*p, *p))
            .sum()
    }

    /// The energy Π = ½ qᵀu − bᵀq of the current traction [Pa·m: J over the pixel area].
    fn energy(&self, target: &[[f64; 2]]) -> f64 {
        self.traction
            .par_iter()
            .zip(self.displacement.par_iter().zip(target.par_iter()))
            .with_min_len(CHUNK)
            .map(|(q, (u, b))| 0.5 * dot(*q, *u) - dot(*b, *q))
            .sum()
    }

    /// The step α in [`feasible`, `cg`] along the projected path q(α) = P(q − α p) with the
    /// least modelled energy (`feasible` where no other is lower). Writing q(α) = q − α p − c(α),
    /// c the part the bounds cut, the energy change is −α rᵀp + ½ α² pᵀKp (`rp_pw`, known
    /// from K p) plus Σ c·(α K p − r) + ½ cᵀK c, the last term through K's diagonal only (the
    /// cut points' interaction, unknown without another application of K). Tried on a
    /// geometric ladder of steps, all in one pass over the points.
    fn projected_search(
        &self,
        target: &[[f64; 2]],
        bound: &[f64],
        (rp, pw): (f64, f64),
        feasible: f64,
        cg: f64,
    ) -> f64 {
        if !(feasible > 0.0 && cg > feasible && cg.is_finite()) {
            return feasible;
        }
        let k = self.diagonal.expect("set at the restart");
        let ladder: [f64; SEARCH + 1] =
            std::array::from_fn(|j| feasible * (cg / feasible).powf(j as f64 / SEARCH as f64));
        let cut = self
            .traction
            .par_iter()
            .zip(self.displacement.par_iter())
            .zip(self.direction.par_iter().zip(self.product.par_iter()))
            .zip(target.par_iter().zip(bound.par_iter()))
            .with_min_len(CHUNK)
            .fold(
                || [0.0; SEARCH + 1],
                |mut sum, (((q, u), (p, w)), (b, g))| {
                    // A point below its bound that the longest step leaves inside is never cut
                    // (one held on its bound is, as it turns).
                    let held = magnitude(*q) >= g * (1.0 - ON_BOUND);
                    if !held && feasible_step(*q, *p, *g) >= cg {
                        return sum;
                    }
                    for (s, alpha) in sum.iter_mut().zip(ladder) {
                        let t = [q[0] - alpha * p[0], q[1] - alpha * p[1]];
                        let z = onto_disk(t, *g);
                        let c = [t[0] - z[0], t[1] - z[1]];
                        *s +=
                            dot(c, [alpha * w[0] - (u[0] - b[0]), alpha * w[1] - (u[1] - b[1])]) + 0.5 * k * dot(c, c);
                    }
                    sum
                },
            )
            .reduce(|| [0.0; SEARCH + 1], |a, b| std::array::from_fn(|j| a[j] + b[j]));
        let mut best = (f64::INFINITY, feasible);
        for (alpha, cut) in ladder.into_iter().zip(cut) {
            let e = -alpha * rp + 0.5 * alpha * alpha * pw + cut;
            if e < best.0 {
                best = (e, alpha);
            }
        }
        best.1
    }

    /// q ← q − α p and u ← u − α K p; returns the norm of the displacement's change, |α| ‖K p‖
    /// [m], whose round-off the displacement carries from here.
    fn move_along(&mut self, alpha: f64) -> f64 {
        let moved = self
            .traction
            .par_iter_mut()
            .zip(self.displacement.par_iter_mut())
            .zip(self.direction.par_iter().zip(self.product.par_iter()))
            .with_min_len(CHUNK)
            .map(|((q, u), (p, w))| {
                q[0] -= alpha * p[0];
                q[1] -= alpha * p[1];
                u[0] -= alpha * w[0];
                u[1] -= alpha * w[1];
                dot(*w, *w)
            })
            .sum::<f64>();
        alpha.abs() * moved.sqrt()
    }

    /// One step of the accelerated projected gradient (FISTA with adaptive restart, step
    /// 1/L): from the extrapolated point y = q + β(q − q_prev), q ← P(y − (Ky − b)/L). Ky is
    /// combined from the stored displacements, so a step costs one application of K.
    fn accelerated_step(&mut self, target: &[[f64; 2]], bound: &[f64], step: f64, momentum: &mut f64) {
        let next = 0.5 * (1.0 + (1.0 + 4.0 * *momentum * *momentum).sqrt());
        let beta = (*momentum - 1.0) / next;
        *momentum = next;
        self.traction
            .par_iter_mut()
            .zip(self.displacement.par_iter())
            .zip(self.previous_traction.par_iter_mut().zip(self.previous_displacement.par_iter_mut()))
            .zip(self.direction.par_iter_mut().zip(target.par_iter().zip(bound.par_iter())))
            .with_min_len(CHUNK)
            .for_each(|(((q, u), (qp, up)), (y, (b, g)))| {
                *y = [q[0] + beta * (q[0] - qp[0]), q[1] + beta * (q[1] - qp[1])];
                let ky = [u[0] + beta * (u[0] - up[0]), u[1] + beta * (u[1] - up[1])];
                *qp = *q;
                *up = *u;
                let mut z = [y[0] - step * (ky[0] - b[0]), y[1] - step * (ky[1] - b[1])];
                let zn = magnitude(z);
                if zn > *g {
                    z = [z[0] * g / zn, z[1] * g / zn];
                }
                *q = z;
            });
        self.refresh();
        // Restart the momentum when it points uphill (O'Donoghue & Candès).
        let uphill: f64 = self
            .direction
            .par_iter()
            .zip(self.traction.par_iter().zip(self.previous_traction.par_iter()))
            .with_min_len(CHUNK)
            .map(|(y, (q, qp))| (y[0] - q[0]) * (q[0] - qp[0]) + (y[1] - q[1]) * (q[1] - qp[1]))
            .sum();
        if uphill > 0.0 {
            *momentum = 1.0;
        }
    }

    /// K's diagonal [m/Pa]: the displacement of the first contact point under its own unit
    /// traction (the same at every point: the kernel at zero offset).
    pub fn diagonal(&mut self, applications: &mut usize) -> f64 {
        if let Some(k) = self.diagonal {
            return k;
        }
        let mut unit = vec![[0.0; 2]; self.points.len()];
        unit[0] = [1.0, 0.0];
        let mut out = vec![[0.0; 2]; self.points.len()];
        self.operator.apply(&unit, &mut out);
        *applications += 1;
        *self.diagonal.insert(out[0][0])
    }

    /// The largest eigenvalue of K on the contact set [m/Pa], estimated on first need.
    pub(super) fn lipschitz(&mut self, applications: &mut usize) -> f64 {
        if let Some(l) = self.lipschitz {
            return l;
        }
        let l = self.largest_eigenvalue(applications);
        *self.lipschitz.insert(l)
    }

    /// The largest eigenvalue of K restricted to the contact set, by power iteration, with a
    /// margin for what the iteration has not yet reached.
    fn largest_eigenvalue(&mut self, applications: &mut usize) -> f64 {
        let m = self.points.len();
        let mut v: Vec<[f64; 2]> = (0..m).map(|i| [1.0, 0.5 + 0.25 * ((i * 7919) % 13) as f64 / 13.0]).collect();
        let mut w = vec![[0.0; 2]; m];
        let mut estimate = 0.0;
        for _ in 0..40 {
            let norm = v.iter().map(|x| x[0] * x[0] + x[1] * x[1]).sum::<f64>().sqrt();
            v.iter_mut().for_each(|x| *x = [x[0] / norm, x[1] / norm]);
            self.operator.apply(&v, &mut w);
            *applications += 1;
            estimate = v.iter().zip(&w).map(|(a, b)| a[0] * b[0] + a[1] * b[1]).sum::<f64>();
            std::mem::swap(&mut v, &mut w);
        }
        1.2 * estimate
    }
}

#[cfg(test)]
mod tests {
    use super::super::operator::{NearInverse, ShearOperator};
    use super::*;
    use crate::contact::influence::{Boundary, ShearCompliance};

    /// On a disk of stuck points the conjugate gradient with the near inverse takes at most half
    /// the iterations it takes with the diagonal alone (11 against 37), to the same traction.
    #[test]
    fn near_inverse_cuts_the_iterations_of_a_stuck_solve() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 96;
        let pressure: Vec<f64> = (0..n * n)
            .map(|i| {
                let (y, x) = ((i / n) as f64 - 48.0, (i % n) as f64 - 48.0);
                if y * y + x * x < 24.0 * 24.0 {
                    1e9
                } else {
                    0.0
                }
            })
            .collect();
        let options = TangentialOptions { tolerance: 1e-8, max_iterations: 1000 };
        let solve = |diagonal_only: bool| {
            let mut solver =
                TangentialSolver::new(&pressure, (n, n), (2e-6, 2e-6), c, Boundary::Periodic, options).unwrap();
            if diagonal_only {
                let ShearOperator::Grid { influence, local, .. } = &solver.operator else { unreachable!("a grid") };
                solver.near_inverse = NearInverse::with_taps(&[((0, 0), [1.0, 0.0, 1.0])], local, influence.shape());
            }
            let m = solver.points().len();
            let report = solver.solve(&vec![[1e-9, 0.0]; m], &vec![f64::INFINITY; m]).unwrap();
            (report.iterations, solver.traction().to_vec())
        };
        let (with, q) = solve(false);
        let (without, q0) = solve(true);
        assert!(2 * with <= without, "{with} iterations with the near inverse, {without} without");
        let scale = q0.iter().map(|q| q[0].abs()).fold(0.0, f64::max);
        assert!(q
            .iter()
            .zip(&q0)
            .all(|(a, b)| (a[0] - b[0]).abs() <= 1e-6 * scale && (a[1] - b[1]).abs() <= 1e-6 * scale));
    }
}
