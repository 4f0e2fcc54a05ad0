//! The constrained tangential solve: shear tractions on a fixed contact set under an imposed
//! rigid tangential displacement, with a Coulomb bound at every point.
//!
//! The normal pressure p comes from the normal solve and is not changed (normal and
//! tangential problems uncoupled: exact for identical bodies, Goodman's approximation
//! otherwise). Unknown: the shear traction q_i = (q_x, q_y) [Pa] on the contact points. Given a
//! target surface displacement b_i [m] (the body's displacement minus the slip accumulated
//! before this increment) and a bound g_i [Pa] (μ_i p_i), q minimises
//!
//! ```text
//!     Π(q) = ½ qᵀ K q − bᵀ q     subject to |q_i| ≤ g_i,
//! ```
//!
//! K the Cerruti operator ([`TangentialInfluence`]). Its optimality conditions are the
//! frictional contact conditions: a stuck point (|q_i| < g_i) follows the target (u_i = b_i);
//! a slipping point carries |q_i| = g_i, with the slip increment b_i − u_i along q_i.
//!
//! The solve is MPRGP (Dostál's modified proportioning with reduced gradient projections)
//! carried over from boxes to disks: conjugate gradient steps on the points below their bound
//! and on the turning of the tractions held on it (a turn costs, besides K's energy, the
//! bound's curvature, the slip over the bound: the Lagrangian's Hessian); expansion steps that
//! put many points on their bounds at once (along the projected path past the first bound to
//! the minimum of an energy model, else as far as the bounds allow and a projected gradient
//! step of fixed length 1.9/‖K‖, which alone put about ten points on their bounds per step at
//! 1500², 10 mN, where ‖K‖ is 45 times K's diagonal); proportioning steps that release points
//! whose gradient pulls them off their bounds, taken when that part of the gradient outweighs
//! the free part. The conjugate gradient is preconditioned by K's inverse near the diagonal
//! (its offsets up to [`NEAR`] pixels, a pass over each point's neighbours), scaled at each
//! point by the Hessian's diagonal, K's diagonal plus the curvature term: a point that slipped
//! far in one increment has a curvature up to 10⁴ times K's diagonal, and without it such
//! points set the iteration count (measured: 0.47 of the iterations at 256², 10 mN, 0.13 at
//! 1500², 1 mN); the near inverse damps the rough modes that K, a smoothing operator, leaves
//! slow (1500² stand-in ball with its wafer at 10 mN: the sliding onset's iterations 4 151 →
//! 1 959 with offsets up to 2 pixels, 1 667 with 4). One application of K (two FFT pairs) per
//! iteration, a second one after an expansion or a release that needed projecting, against 1.4
//! for the projected conjugate gradient of Polonsky & Keer that stalled whenever the set of
//! points on their bound changed. Should the turning of many tractions at once keep it from
//! progressing (no new best residual in 25 iterations), the solve finishes with the accelerated
//! projected gradient (FISTA with adaptive restart), slower but sure to converge.
//!
//! Convergence: the projected gradient's norm relative to the target's, both over the contact
//! points, below the tolerance, on a displacement that is exact (recomputed from scratch).
//! Solves at a tolerance of 1e-6 or above apply K in single precision (and go on in double
//! should they stall); tighter ones in double throughout. Where a solve changes the traction
//! at a few points only (the bounds a slip cascade lowers), its displacement follows them
//! pair by pair, through K's coefficients at every offset, instead of through the transforms;
//! and the tractions near them are solved for first, as small dense problems of their own
//! ([`TangentialSolver::solve_after_change`]).

use rayon::prelude::*;

use super::influence::{Boundary, Offsets, ShearCompliance, TangentialInfluence};
use super::solver::Iterations;
use crate::error::{Error, Result};

/// Contact points per parallel task: below this, threads cost more than they save.
const CHUNK: usize = 4096;

/// Iterations without a new best residual after which the solve changes method.
const STALL: usize = 25;

/// Solves stopping at this relative residual or above apply K in single precision: its
/// round-off, a relative 1e-7 to 5e-7 measured on 256² to 1500² windows, is at most half of
/// it, and the transforms take 1.3–1.7 times less time. Tighter solves run in double
/// throughout. A check in double precision of the single-precision solves below 5e-5 once
/// converged (stop 27) moved the sliding onset's drop by 4e-7 (1500² with its wafer, 10 mN,
/// mu_s 0.6, mu_d 0.4: 1.0011985 with, 1.0011981 without) and 3e-7 (31.6 mN) for 9 % and 7 %
/// of the applications, each check a transform in double: not done.
const SINGLE: f64 = 1e-6;

/// Steps tried by the projected search of an expansion, from the first bound to the conjugate
/// gradient step (geometric ladder). Measured at 1500², 10 mN: 24 tried up to the conjugate
/// gradient step take 5 350 applications, up to twice and four times it 5 420 and 5 496,
/// against 7 439 without the search.
const SEARCH: usize = 24;

/// Proportioning constant Γ: a proportioning step is taken when the chopped gradient exceeds Γ
/// times the (reduced) free gradient.
const GAMMA: f64 = 1.0;

/// Settings of the tangential solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentialOptions {
    /// Relative norm of the projected gradient at convergence. The default 1e-6 moves the
    /// sliding onset's F_S by 6e-8 (256², 10 mN) and 2e-8 (1500², 0.1 mN) against 1e-8, with
    /// the same classes at the peak, for 0.52–0.53 of the iterations; 1e-5 moves it by 2e-6 and
    /// changes the path's history (other cascades).
    pub tolerance: f64,
    /// Iterations after which a solve that has not converged is an error.
    pub max_iterations: usize,
}

impl Default for TangentialOptions {
    fn default() -> Self {
        TangentialOptions { tolerance: 1e-6, max_iterations: 20_000 }
    }
}

impl TangentialOptions {
    /// An error naming `--tolerance` or `--max-iter` unless the tolerance lies in
    /// (0, [`MAX_TOLERANCE`](super::solver::MAX_TOLERANCE)) (at 1 the untouched start, q = 0,
    /// has converged already) and at least one iteration is allowed.
    pub fn check(&self) -> Result<()> {
        super::solver::check_tolerance(self.tolerance, self.max_iterations)
    }
}

/// What one tangential solve reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentialReport {
    /// Conjugate-gradient iterations (with those of the local solves before it, see
    /// [`TangentialSolver::solve_after_change`]).
    pub iterations: usize,
    /// Applications of the operator (two FFT pairs each).
    pub applications: usize,
    /// Residual at convergence.
    pub residual: f64,
}

/// The tangential problem on the contact set of one pressure map. The traction of the last
/// solve is the starting point of the next.
pub struct TangentialSolver {
    shape: (usize, usize),
    size: (f64, f64),
    operator: ShearOperator,
    options: TangentialOptions,
    /// Flat index y·nx + x of each contact point (p > 0), raster order.
    points: Vec<usize>,
    /// Normal pressure p [Pa] at each contact point.
    pressure: Vec<f64>,
    /// Shear traction q [Pa] at each contact point.
    traction: Vec<[f64; 2]>,
    /// Surface displacement u = K q [m] at each contact point.
    displacement: Vec<[f64; 2]>,
    direction: Vec<[f64; 2]>,
    product: Vec<[f64; 2]>,
    /// The accelerated projected gradient's previous iterate and its displacement.
    previous_traction: Vec<[f64; 2]>,
    previous_displacement: Vec<[f64; 2]>,
    /// The bound's curvature term per point for the current conjugate directions [m/Pa].
    curvature: Vec<f64>,
    /// The preconditioner: K's inverse near the diagonal, on the contact points.
    near_inverse: NearInverse,
    /// The preconditioned free gradient z, and the scaled free gradient it is made from.
    preconditioned: Vec<[f64; 2]>,
    scaled: Vec<[f64; 2]>,
    /// The largest eigenvalue of K on the contact set [m/Pa], once needed.
    lipschitz: Option<f64>,
    /// K's diagonal: a pixel's displacement under its own unit traction [m/Pa], the same at
    /// every point (K is a convolution) and in both directions (a square pixel); once needed.
    diagonal: Option<f64>,
}

impl TangentialSolver {
    /// The problem on the contact set (p > 0) of `pressure` [Pa] (row-major, `shape`) on a
    /// window of physical size `size` [m], with the bodies' shear compliance and the boundary
    /// of the normal solve.
    pub fn new(
        pressure: &[f64],
        shape: (usize, usize),
        size: (f64, f64),
        compliance: ShearCompliance,
        boundary: Boundary,
        options: TangentialOptions,
    ) -> Result<Self> {
        let (ny, nx) = shape;
        if ny < 2 || nx < 2 || pressure.len() != ny * nx {
            return Err(Error::invalid("pressure map", format!("{} values for a {ny}×{nx} grid", pressure.len())));
        }
        if let Some(i) = pressure.iter().position(|p| !(p.is_finite() && *p >= 0.0)) {
            return Err(Error::invalid(
                "pressure map",
                format!("pressure at row {}, column {} is {}; it must be finite and ≥ 0", i / nx, i % nx, pressure[i]),
            ));
        }
        if !(size.0 > 0.0 && size.1 > 0.0 && size.0.is_finite() && size.1.is_finite()) {
            return Err(Error::invalid("--size", format!("must be positive and finite, got {}×{} m", size.0, size.1)));
        }
        options.check()?;
        let points: Vec<usize> = (0..pressure.len()).filter(|&i| pressure[i] > 0.0).collect();
        if points.is_empty() {
            return Err(Error::invalid("pressure map", "no contact: every pressure is zero"));
        }
        let m = points.len();
        let mut operator = ShearOperator::grid(&points, shape, size, compliance, boundary);
        let near_inverse = NearInverse::of(&operator);
        if let ShearOperator::Grid { influence, .. } = &operator {
            operator = if dense_is_cheaper(m, influence.transform_points()) {
                operator.dense()
            } else {
                operator.only_contact_rows()
            };
        }
        let pressure = points.iter().map(|&i| pressure[i]).collect();
        Ok(Self::assemble(shape, size, operator, options, points, pressure, near_inverse))
    }

    /// The solver on `points` (flat indices) with their `pressure`, K as `operator`, from zero
    /// traction.
    fn assemble(
        shape: (usize, usize),
        size: (f64, f64),
        operator: ShearOperator,
        options: TangentialOptions,
        points: Vec<usize>,
        pressure: Vec<f64>,
        near_inverse: NearInverse,
    ) -> Self {
        let m = points.len();
        TangentialSolver {
            shape,
            size,
            operator,
            options,
            pressure,
            points,
            traction: vec![[0.0; 2]; m],
            displacement: vec![[0.0; 2]; m],
            direction: vec![[0.0; 2]; m],
            product: vec![[0.0; 2]; m],
            previous_traction: vec![[0.0; 2]; m],
            previous_displacement: vec![[0.0; 2]; m],
            curvature: vec![0.0; m],
            near_inverse,
            preconditioned: vec![[0.0; 2]; m],
            scaled: vec![[0.0; 2]; m],
            lipschitz: None,
            diagonal: None,
        }
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        self.shape
    }

    /// Area of one pixel [m²].
    pub fn pixel_area(&self) -> f64 {
        self.size.0 / self.shape.1 as f64 * (self.size.1 / self.shape.0 as f64)
    }

    /// Flat indices y·nx + x of the contact points.
    pub fn points(&self) -> &[usize] {
        &self.points
    }

    /// Normal pressure p [Pa] at the contact points.
    pub fn pressure(&self) -> &[f64] {
        &self.pressure
    }

    /// The normal force N = Σ p · a [N] (one sum, so that every N of a solver is the same bits).
    pub fn normal_force(&self) -> f64 {
        self.pressure.iter().sum::<f64>() * self.pixel_area()
    }

    /// Shear traction q [Pa] at the contact points, from the last solve.
    pub fn traction(&self) -> &[[f64; 2]] {
        &self.traction
    }

    /// Surface displacement u = K q [m] at the contact points, from the last solve.
    pub fn displacement(&self) -> &[[f64; 2]] {
        &self.displacement
    }

    /// Tangential force Σ q · a [N] of the current traction, (F_x, F_y).
    pub fn force(&self) -> [f64; 2] {
        let a = self.pixel_area();
        let (fx, fy) = self.traction.iter().fold((0.0, 0.0), |(x, y), q| (x + q[0], y + q[1]));
        [fx * a, fy * a]
    }

    /// Replace the traction (a saved state to go back to) and recompute its displacement.
    pub fn set_traction(&mut self, traction: &[[f64; 2]]) {
        self.traction.copy_from_slice(traction);
        self.refresh();
    }

    /// [`set_traction`](Self::set_traction) cut onto the disks |q_i| ≤ `bound` first, so that
    /// a solve with those bounds starts from it without recomputing its displacement.
    pub fn set_traction_within(&mut self, traction: &[[f64; 2]], bound: &[f64]) {
        self.traction.copy_from_slice(traction);
        cut_onto_disks(&mut self.traction, bound);
        self.refresh();
    }

    /// Relative norm of the projected gradient at which a solve has converged.
    pub fn tolerance(&self) -> f64 {
        self.options.tolerance
    }

    /// u = K q on the contact points, from scratch.
    fn refresh(&mut self) {
        self.operator.apply(&self.traction, &mut self.displacement);
    }

    /// Solve for the targets `target` b_i [m] and bounds `bound` g_i [Pa] (one per contact
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
        let mut count = Iterations::new("tangential solver", self.options.max_iterations, tolerance, STALL);
        let mut exact = true;
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
                if exact {
                    return Ok(TangentialReport { iterations: count.done(), applications, residual });
                }
                // Converged on the displacement updated step by step: check from scratch. The
                // residuals before were measured on the updated displacement, which misses the
                // turned tractions' return onto their bounds: progress counts from here.
                self.refresh();
                applications += 1;
                exact = true;
                restart = true;
                count.forget_best();
                continue;
            }
            let stalled = count.next(residual)?;
            if stalled && self.operator.set_single(false) {
                // Perhaps on the single precision's round-off: go on in double.
                self.refresh();
                applications += 1;
                exact = true;
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
                exact = true;
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
                self.move_along(chopped / pw);
                exact = false;
                if project(&mut self.traction, bound) {
                    self.refresh();
                    applications += 1;
                    exact = true;
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
                // are put back onto their bounds (a second-order change the displacement
                // misses until the next exact recomputation).
                self.move_along(cg);
                project(&mut self.traction, bound);
                exact = false;
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
                        exact = true;
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
                exact = true;
                restart = true;
            }
        }
    }

    /// [`solve_within`](Self::solve_within) after the bounds changed at the points `changed`
    /// (indices into the contact points) alone, as in a round of a slip cascade. The traction
    /// changes mostly near them (K's inverse is short-ranged), so the tractions within
    /// [`LOCAL_RADIUS`] pixels of them are first solved for, with the others held, to half the
    /// tolerance: each group of nearby points as a dense problem of its own, the groups side
    /// by side (their interaction left to what follows). The whole is then solved from there,
    /// as before, and often has converged at the one application that checks it (with one
    /// group of at most 1 024 points, 108 of the 180 rounds at 1500², 31.6 mN solved near
    /// first, 176 of which lowered fewer than 10 bounds; those took 2 applications each, 6.5
    /// before). The result is the whole's, to its tolerance: at
    /// 1500², 10 mN the drop with and without is 1.0011956 either way at a tolerance of 1e-7
    /// (2e-8 apart), 1.0011958 and 1.0011981 at 1e-6 (the path's cascades differ within it).
    /// The iterations reported include those of the groups' solves; the applications, of the
    /// transforms only.
    pub fn solve_after_change(
        &mut self,
        target: &[[f64; 2]],
        bound: &[f64],
        tolerance: f64,
        changed: &[usize],
    ) -> Result<TangentialReport> {
        let mut applications = 0;
        let mut iterations = 0;
        let groups = match &self.operator {
            // Worth it against the transforms only: a dense operator is as cheap on the whole.
            ShearOperator::Grid { influence, .. } => {
                let groups = self.near_groups(changed, LOCAL_RADIUS, LOCAL_POINTS, LOCAL_TOTAL);
                let g = influence.transform_points() as f64;
                let work: usize = groups.iter().map(|group| group.len() * group.len()).sum();
                if work as f64 <= LOCAL_WORK * g * g.log2() {
                    groups
                } else {
                    Vec::new()
                }
            }
            ShearOperator::Dense { .. } => Vec::new(),
        };
        if !groups.is_empty() {
            let cuts = cut_onto_disks(&mut self.traction, bound);
            self.take_cuts(&cuts, false, &mut applications);
            self.lipschitz(&mut applications);
            let solved: Vec<_> = groups.iter().map(|near| self.solve_near(near, target, bound, tolerance)).collect();
            for (near, result) in groups.iter().zip(solved) {
                // A group that does not converge keeps its tractions: the whole's solve follows.
                if let Ok((traction, its)) = result {
                    near.iter().zip(traction).for_each(|(&i, q)| self.traction[i] = q);
                    iterations += its;
                }
            }
            self.refresh();
            applications += 1;
        }
        let mut report = self.solve_within(target, bound, tolerance)?;
        report.applications += applications;
        report.iterations += iterations;
        Ok(report)
    }

    /// The contact points within `radius` pixels (each way) of the points `of` (indices into
    /// the contact points, increasing), in groups of at most `most` (each point in one): the
    /// neighbourhoods of consecutive points of `of` go into one group until it is full. None
    /// when they are more than `total` in all.
    fn near_groups(&self, of: &[usize], radius: i64, most: usize, total: usize) -> Vec<Vec<usize>> {
        let (ny, nx) = (self.shape.0 as i64, self.shape.1 as i64);
        let mut claimed = vec![false; self.points.len()];
        let mut groups: Vec<Vec<usize>> = vec![Vec::new()];
        let mut count = 0;
        for &c in of {
            let (y, x) = ((self.points[c] / nx as usize) as i64, (self.points[c] % nx as usize) as i64);
            let mut own = Vec::new();
            for yy in (y - radius).max(0)..=(y + radius).min(ny - 1) {
                let lo = (yy * nx + (x - radius).max(0)) as usize;
                let hi = (yy * nx + (x + radius).min(nx - 1)) as usize;
                let from = self.points.partition_point(|&p| p < lo);
                let to = self.points.partition_point(|&p| p <= hi);
                for (k, claimed) in claimed.iter_mut().enumerate().take(to).skip(from) {
                    if !*claimed {
                        *claimed = true;
                        own.push(k);
                    }
                }
            }
            count += own.len();
            if count > total {
                return Vec::new();
            }
            let last = groups.last_mut().expect("one group at least");
            if !last.is_empty() && last.len() + own.len() > most {
                groups.push(own);
            } else {
                last.extend(own);
            }
        }
        groups.retain(|g| !g.is_empty());
        groups.iter_mut().for_each(|g| g.sort_unstable());
        groups
    }

    /// The tractions at the points `near` that solve the problem with the others' held, to
    /// half the `tolerance` of the whole (relative to its target), and the iterations it took.
    fn solve_near(
        &self,
        near: &[usize],
        target: &[[f64; 2]],
        bound: &[f64],
        tolerance: f64,
    ) -> Result<(Vec<[f64; 2]>, usize)> {
        let mut sub = Self::assemble(
            self.shape,
            self.size,
            self.operator.subset(near),
            self.options,
            near.iter().map(|&i| self.points[i]).collect(),
            near.iter().map(|&i| self.pressure[i]).collect(),
            self.near_inverse.subset(near, self.points.len()),
        );
        near.iter().zip(&mut sub.traction).for_each(|(&i, q)| *q = self.traction[i]);
        // K's largest eigenvalue on a subset is at most that on the whole.
        sub.lipschitz = self.lipschitz;
        sub.diagonal = self.diagonal;
        sub.refresh();
        // The targets less what the held tractions displace there.
        let sub_target: Vec<[f64; 2]> = near
            .iter()
            .zip(&sub.displacement)
            .map(|(&i, w)| {
                let (b, u) = (target[i], self.displacement[i]);
                [b[0] - (u[0] - w[0]), b[1] - (u[1] - w[1])]
            })
            .collect();
        let sub_bound: Vec<f64> = near.iter().map(|&i| bound[i]).collect();
        let norm = |v: &[[f64; 2]]| v.iter().map(|b| b[0] * b[0] + b[1] * b[1]).sum::<f64>().sqrt();
        let local_tolerance = 0.5 * tolerance * norm(target) / norm(&sub_target);
        let report = sub.solve_within(&sub_target, &sub_bound, local_tolerance.min(0.5))?;
        Ok((sub.traction, report.iterations))
    }

    /// Make the displacement follow the traction's `cuts`: point by point when that is cheaper
    /// than an application, else (or when `refresh`) from scratch.
    fn take_cuts(&mut self, cuts: &[(usize, [f64; 2])], refresh: bool, applications: &mut usize) {
        if !refresh && self.operator.changes_are_cheaper(cuts.len()) {
            self.operator.add_changes(cuts, &mut self.displacement);
        } else {
            self.refresh();
            *applications += 1;
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

    /// q ← q − α p and u ← u − α K p.
    fn move_along(&mut self, alpha: f64) {
        self.traction
            .par_iter_mut()
            .zip(self.displacement.par_iter_mut())
            .zip(self.direction.par_iter().zip(self.product.par_iter()))
            .with_min_len(CHUNK)
            .for_each(|((q, u), (p, w))| {
                q[0] -= alpha * p[0];
                q[1] -= alpha * p[1];
                u[0] -= alpha * w[0];
                u[1] -= alpha * w[1];
            });
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
    fn lipschitz(&mut self, applications: &mut usize) -> f64 {
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

/// Cut every traction onto its disk |q_i| ≤ g_i; the cuts (point, change) the displacement
/// must follow, round-off left out.
fn cut_onto_disks(traction: &mut [[f64; 2]], bound: &[f64]) -> Vec<(usize, [f64; 2])> {
    traction
        .par_iter_mut()
        .zip(bound.par_iter())
        .enumerate()
        .with_min_len(CHUNK)
        .filter_map(|(i, (q, g))| {
            let n = magnitude(*q);
            if n <= *g {
                return None;
            }
            let s = g / n;
            let cut = [q[0] * (s - 1.0), q[1] * (s - 1.0)];
            *q = [q[0] * s, q[1] * s];
            (magnitude(cut) > ROUND_OFF * n).then_some((i, cut))
        })
        .collect()
}

/// A cut of a traction onto its bound below this fraction of the traction is round-off: the
/// displacement does not follow it.
const ROUND_OFF: f64 = 1e-12;

/// After a change of a few bounds, the points within this many pixels of them are solved for
/// first ([`TangentialSolver::solve_after_change`]), in groups of at most [`LOCAL_POINTS`],
/// [`LOCAL_TOTAL`] in all. Measured on the sliding onset at 1500², 31.6 mN (stand-in ball
/// with its wafer, mu_s 0.6, mu_d 0.4; applications, seconds on 2 cores): without 3 357,
/// 56 s; radius 6 2 849, 47 s; 8 2 805, 45 s; groups of 512 2 862, 48 s; one group of 1 024
/// at most 3 073, 51 s; 8 192 in all 2 778, 49 s (the dense solves' cost).
const LOCAL_RADIUS: i64 = 8;

/// The largest group: its dense operator holds 1 024² pairs of three coefficients, 24 MiB.
const LOCAL_POINTS: usize = 1024;

/// Local solves are made while their groups' pairs (Σ n²) are at most this many times g·log₂g
/// for a transform grid of g points (a dense application costs about as much as a transform
/// pair when n² is 0.4 g·log₂g, and a local solve takes some ten of them to save about five
/// applications). Measured: 256², 100 mN (2 546 points, the transforms cheap) 2.2 s without
/// local solves, 2.9 s with all, 1.9 s with this (2.0 s at 0.05 and 0.2); 1500², 10 mN the same
/// 2 310 applications at 0.1 and 0.2.
const LOCAL_WORK: f64 = 0.1;

/// The most points solved for first in all; more, and the whole is solved at once.
const LOCAL_TOTAL: usize = 4096;

/// Changes at k points are added pair by pair ([`ShearOperator::add_changes`]) while k times
/// the contact points is at most this many times the transform's grid points. Measured at
/// 1500², 31.6 mN (24 206 points, 2 cores): an application 13.8 ms, 85 changes 5 ms — a pair
/// costs about 0.4 of a grid point of an application.
const PAIRS_PER_POINT: usize = 2;

/// Project every traction onto its disk |q_i| ≤ g_i; whether any changed.
fn project(traction: &mut [[f64; 2]], bound: &[f64]) -> bool {
    traction
        .par_iter_mut()
        .zip(bound.par_iter())
        .with_min_len(CHUNK)
        .map(|(q, g)| {
            let qn = magnitude(*q);
            if qn > *g {
                let s = g / qn;
                *q = [q[0] * s, q[1] * s];
                true
            } else {
                false
            }
        })
        .reduce(|| false, |a, b| a || b)
}

/// A traction within this fraction of its bound is on it.
const ON_BOUND: f64 = 1e-12;

/// |v| of a traction [Pa] or displacement [m]: without `hypot`'s guard against overflow and
/// underflow, which these never come near (|v|² within 1e-300..1e300), and which made `hypot` 6 %
/// of a sliding onset's time at 1500², 100 mN.
pub(crate) fn magnitude(v: [f64; 2]) -> f64 {
    (v[0] * v[0] + v[1] * v[1]).sqrt()
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The gradient r = u − b at one point split into its free part φ (the whole gradient at a
/// point below its bound; on it, the part along the bound, which turns the traction) and its
/// chopped part β (on the bound, the radial part that pulls the traction into its disk).
fn gradient_parts(q: [f64; 2], u: [f64; 2], b: [f64; 2], g: f64) -> ([f64; 2], [f64; 2]) {
    let r = [u[0] - b[0], u[1] - b[1]];
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return (r, [0.0; 2]);
    }
    let n = [q[0] / qn, q[1] / qn];
    let radial = dot(r, n);
    let along = [r[0] - radial * n[0], r[1] - radial * n[1]];
    // The descent −r points into the disk where the radial part is positive.
    (along, if radial > 0.0 { [radial * n[0], radial * n[1]] } else { [0.0; 2] })
}

/// q projected onto the disk |q| ≤ g.
fn onto_disk(q: [f64; 2], g: f64) -> [f64; 2] {
    let qn = magnitude(q);
    if qn > g {
        [q[0] * g / qn, q[1] * g / qn]
    } else {
        q
    }
}

/// The reduced free gradient: the part of a step of length ᾱ along −φ that the bound lets
/// through, per unit step (φ itself where the whole step fits).
fn reduced_free_gradient(q: [f64; 2], phi: [f64; 2], g: f64, step: f64) -> [f64; 2] {
    if step == 0.0 || phi == [0.0; 2] {
        return phi;
    }
    let z = onto_disk([q[0] - step * phi[0], q[1] - step * phi[1]], g);
    [(q[0] - z[0]) / step, (q[1] - z[1]) / step]
}

/// The largest α with |q − α p| ≤ g, for q inside its disk; unlimited on the bound, where p
/// turns the traction along it.
fn feasible_step(q: [f64; 2], p: [f64; 2], g: f64) -> f64 {
    let pp = dot(p, p);
    if pp == 0.0 || g.is_infinite() || magnitude(q) >= g * (1.0 - ON_BOUND) {
        return f64::INFINITY;
    }
    let room = (g * g - dot(q, q)).max(0.0);
    let qp = dot(q, p);
    let root = (qp * qp + pp * room).sqrt();
    // Two forms of the same root: each free of cancellation on its side.
    if qp >= 0.0 {
        (qp + root) / pp
    } else {
        room / (root - qp)
    }
}

/// The bound's curvature term at a point held on it: the slip s = −r·n over the bound g
/// [m/Pa]; zero below the bound or where the gradient pulls the point off it.
fn turning(q: [f64; 2], u: [f64; 2], b: [f64; 2], g: f64) -> f64 {
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return 0.0;
    }
    let slip = -dot([u[0] - b[0], u[1] - b[1]], [q[0] / qn, q[1] / qn]);
    (slip / g).max(0.0)
}

/// p without its radial part where the traction is held on its bound.
fn tangent_if_held(p: [f64; 2], q: [f64; 2], g: f64) -> [f64; 2] {
    let qn = magnitude(q);
    if qn < g * (1.0 - ON_BOUND) {
        return p;
    }
    let n = [q[0] / qn, q[1] / qn];
    let radial = dot(p, n);
    [p[0] - radial * n[0], p[1] - radial * n[1]]
}

/// The dense operator's memory limit [bytes]: three coefficients per pair of points.
const DENSE_BYTES: usize = 256 << 20;

/// Whether K on `m` points costs less as a dense matrix (m² coefficient triples streamed from
/// memory per application) than through the transforms of a grid of `g` points, within the
/// memory limit. The break-even m² ≈ 0.4 g log₂ g is measured: at 256² periodic the dense
/// matrix is 4.7× faster on 292 points and several times slower on 2 500.
fn dense_is_cheaper(m: usize, g: usize) -> bool {
    let g = g as f64;
    24 * m * m <= DENSE_BYTES && (m * m) as f64 <= 0.4 * g * g.log2()
}

/// K on the contact points.
enum ShearOperator {
    /// Through the transforms of the contact set's bounding box: the points' flat indices in
    /// the box, and the box's input and output grids (x, y). The transforms run in single
    /// precision, on the operator's copy made on first use, while `in_single` holds.
    Grid {
        influence: Box<TangentialInfluence>,
        single: Option<Box<TangentialInfluence<f32>>>,
        in_single: bool,
        local: Vec<usize>,
        field_in: [Vec<f64>; 2],
        field_out: [Vec<f64>; 2],
        /// K's coefficients at every offset within the box, for the changes of a few points
        /// ([`ShearOperator::add_changes`]), and each point's (y, x) in the box.
        offsets: Offsets,
        cells: Vec<[i32; 2]>,
    },
    /// As a dense matrix: the (xx, xy, yy) coefficients of every pair, row-major [m/Pa].
    Dense { m: usize, coefficients: Vec<[f64; 3]> },
}

impl ShearOperator {
    /// K on `points` (flat indices y·nx + x of an (ny, nx) window of size `size` [m]) through
    /// the transforms of their bounding box only (exactly: see TangentialInfluence::window);
    /// the points are indexed in the box.
    fn grid(
        points: &[usize],
        (ny, nx): (usize, usize),
        size: (f64, f64),
        c: ShearCompliance,
        boundary: Boundary,
    ) -> Self {
        let (y0, y1) = points.iter().fold((ny, 0), |(a, b), &i| (a.min(i / nx), b.max(i / nx)));
        let (x0, x1) = points.iter().fold((nx, 0), |(a, b), &i| (a.min(i % nx), b.max(i % nx)));
        let mut influence = TangentialInfluence::window((ny, nx), size, c, boundary, (y1 - y0 + 1, x1 - x0 + 1));
        let (by, bx) = influence.shape();
        let (y0, x0) = (y0.min(ny - by), x0.min(nx - bx));
        let local: Vec<usize> = points.iter().map(|&i| (i / nx - y0) * bx + (i % nx - x0)).collect();
        let cells = local.iter().map(|&c| [(c / bx) as i32, (c % bx) as i32]).collect();
        ShearOperator::Grid {
            offsets: influence.offsets(),
            cells,
            influence: Box::new(influence),
            single: None,
            in_single: false,
            local,
            field_in: [vec![0.0; by * bx], vec![0.0; by * bx]],
            field_out: [vec![0.0; by * bx], vec![0.0; by * bx]],
        }
    }

    /// Whether `out += K Δ` for changes at `k` of the points costs less through
    /// [`add_changes`](Self::add_changes) than an application ([`PAIRS_PER_POINT`]).
    fn changes_are_cheaper(&self, k: usize) -> bool {
        match self {
            ShearOperator::Grid { influence, local, .. } => {
                k * local.len() <= PAIRS_PER_POINT * influence.transform_points()
            }
            ShearOperator::Dense { .. } => true,
        }
    }

    /// K on the points `near` (indices into its points) alone, as a dense matrix.
    fn subset(&self, near: &[usize]) -> ShearOperator {
        let n = near.len();
        let mut coefficients = Vec::with_capacity(n * n);
        match self {
            ShearOperator::Grid { offsets, cells, .. } => {
                for &i in near {
                    let [yi, xi] = cells[i];
                    coefficients.extend(near.iter().map(|&j| {
                        let [yj, xj] = cells[j];
                        offsets.at((yi - yj) as i64, (xi - xj) as i64)
                    }));
                }
            }
            ShearOperator::Dense { m, coefficients: all } => {
                for &i in near {
                    coefficients.extend(near.iter().map(|&j| all[i * m + j]));
                }
            }
        }
        ShearOperator::Dense { m: n, coefficients }
    }

    /// `out += K Δ` on the contact points, for the changes Δ at a few points (point, Δ):
    /// exact in double precision, one pass over the contact points per change.
    fn add_changes(&self, changes: &[(usize, [f64; 2])], out: &mut [[f64; 2]]) {
        if changes.is_empty() {
            return;
        }
        let add = |o: &mut [f64; 2], k: [f64; 3], d: [f64; 2]| {
            o[0] += k[0] * d[0] + k[1] * d[1];
            o[1] += k[1] * d[0] + k[2] * d[1];
        };
        match self {
            ShearOperator::Grid { offsets, cells, .. } => {
                let sources: Vec<([i32; 2], [f64; 2])> = changes.iter().map(|&(j, d)| (cells[j], d)).collect();
                out.par_chunks_mut(CHUNK).zip(cells.par_chunks(CHUNK)).for_each(|(out, cells)| {
                    for &([yj, xj], d) in &sources {
                        for (o, &[y, x]) in out.iter_mut().zip(cells) {
                            add(o, offsets.at((y - yj) as i64, (x - xj) as i64), d);
                        }
                    }
                });
            }
            ShearOperator::Dense { m, coefficients } => {
                let m = *m;
                out.par_iter_mut().enumerate().with_min_len((CHUNK / changes.len()).max(1)).for_each(|(i, o)| {
                    changes.iter().for_each(|&(j, d)| add(o, coefficients[i * m + j], d));
                });
            }
        }
    }

    /// Apply K in single precision from now on (`true`) or in double; whether that changed
    /// anything (a dense operator is always applied in double precision).
    fn set_single(&mut self, on: bool) -> bool {
        let ShearOperator::Grid { influence, single, in_single, .. } = self else { return false };
        if on == *in_single {
            return false;
        }
        if on && single.is_none() {
            *single = Some(Box::new(influence.single()));
        }
        *in_single = on;
        true
    }

    /// `out = K v` on the contact points.
    fn apply(&mut self, v: &[[f64; 2]], out: &mut [[f64; 2]]) {
        match self {
            ShearOperator::Grid { influence, single, in_single, local, field_in, field_out, .. } => {
                // Points off the contact set are never written: the input grids stay zero there.
                for (&i, v) in local.iter().zip(v) {
                    field_in[0][i] = v[0];
                    field_in[1][i] = v[1];
                }
                let [ox, oy] = field_out;
                match single.as_mut().filter(|_| *in_single) {
                    Some(single) => single.apply([&field_in[0], &field_in[1]], [ox, oy]),
                    None => influence.apply([&field_in[0], &field_in[1]], [ox, oy]),
                }
                out.par_iter_mut().zip(local.par_iter()).with_min_len(CHUNK).for_each(|(o, &i)| *o = [ox[i], oy[i]]);
            }
            ShearOperator::Dense { m, coefficients } => {
                let m = *m;
                out.par_iter_mut().with_min_len((CHUNK / m).max(1)).enumerate().for_each(|(i, o)| {
                    let row = &coefficients[i * m..(i + 1) * m];
                    *o = row.iter().zip(v).fold([0.0; 2], |[x, y], (k, v)| {
                        [x + k[0] * v[0] + k[1] * v[1], y + k[1] * v[0] + k[2] * v[1]]
                    });
                });
            }
        }
    }

    /// The same operator with the row transforms of the box's rows without contact points
    /// skipped: their tractions are zero and their displacements not wanted.
    fn only_contact_rows(mut self) -> Self {
        if let ShearOperator::Grid { influence, local, .. } = &mut self {
            let (by, bx) = influence.shape();
            let mut rows = vec![false; by];
            local.iter().for_each(|&i| rows[i / bx] = true);
            influence.only_rows(rows);
        }
        self
    }

    /// The same operator as a dense matrix, from the grid operator's responses to a unit
    /// traction at the box's corner: the kernel is even in each offset (xx, yy) or odd in
    /// each (xy), so these give every pair.
    fn dense(self) -> Self {
        let ShearOperator::Grid { influence, local, offsets, .. } = &self else { return self };
        let bx = influence.shape().1;
        let m = local.len();
        let mut coefficients = Vec::with_capacity(m * m);
        for &i in local.iter() {
            let (yi, xi) = ((i / bx) as i64, (i % bx) as i64);
            for &j in local.iter() {
                coefficients.push(offsets.at(yi - (j / bx) as i64, xi - (j % bx) as i64));
            }
        }
        ShearOperator::Dense { m, coefficients }
    }
}

/// Offsets of K's inverse the preconditioner keeps: |dy|, |dx| ≤ this many pixels. On the
/// stuck problem of the 1500² stand-in ball at 10 mN (a scalar 1/q kernel, 7 952 points) the
/// conjugate gradient takes 36 iterations without, 15 with radius 1, 16 with 2, 14 with 4 and
/// 12 with the whole inverse (an FFT pair more per iteration); at 256², 100 mN the sliding
/// onset takes 2 647, 2 642 and 2 590 applications with radius 1, 2 and 4 (3 681 without);
/// with the stand-in ball and its wafer at 1500² (mu_s 0.6, mu_d 0.4) radius 4 against 2
/// takes 3 483 against 3 922 at 10 mN, 3 884 against 4 491 at 31.6 mN and 6 130 against 7 681
/// at 100 mN (160 against 197 s); radius 6 at 31.6 mN 3 696.
const NEAR: usize = 4;

/// K's inverse near the diagonal on the contact points, scaled to 1 on it (its xx
/// coefficient at zero offset): the inverse is short-ranged (the traction under a unit
/// displacement falls off as 1/r³, where K's displacement under a unit traction falls as
/// 1/r), so its nearest offsets give most of it. Applied to the free gradient, it damps the
/// rough modes K leaves slow, at the cost of a pass over the points' neighbours.
struct NearInverse {
    /// The kept offsets' coefficients (xx, xy, yy).
    coefficients: Vec<[f64; 3]>,
    /// Each point's neighbours within the kept offsets, itself among them, as (point, index
    /// into `coefficients`): point i's are `neighbours[first[i]..first[i + 1]]`. Listed once,
    /// so that an application reads only the points that are there instead of looking up every
    /// offset in the box's grid.
    first: Vec<usize>,
    neighbours: Vec<(u32, u32)>,
}

impl NearInverse {
    fn of(operator: &ShearOperator) -> Self {
        let ShearOperator::Grid { influence, local, .. } = operator else { unreachable!("made on the grid") };
        Self::with_taps(&Self::taps(influence), local, influence.shape())
    }

    /// K's inverse at offsets up to [`NEAR`] pixels, scaled to 1 on the diagonal; the diagonal
    /// alone should the truncation lose positivity.
    fn taps(influence: &TangentialInfluence) -> Vec<((i64, i64), [f64; 3])> {
        let mut taps = influence.inverse_near(NEAR);
        let centre = taps.iter().find(|(d, _)| *d == (0, 0)).expect("the zero offset").1[0];
        taps.iter_mut().for_each(|(_, g)| *g = g.map(|v| v / centre));
        if centre > 0.0 && positive(&taps) {
            taps
        } else {
            vec![((0, 0), [1.0, 0.0, 1.0])]
        }
    }

    /// The operator with coefficients `taps` on the points at cells `cells` (y · bx + x) of a
    /// box of shape (by, bx).
    fn with_taps(taps: &[((i64, i64), [f64; 3])], cells: &[usize], (by, bx): (usize, usize)) -> Self {
        let mut point_at = vec![u32::MAX; by * bx];
        cells.iter().enumerate().for_each(|(j, &c)| point_at[c] = j as u32);
        let (by, bx) = (by as i64, bx as i64);
        let mut first = Vec::with_capacity(cells.len() + 1);
        let mut neighbours = Vec::new();
        for &c in cells {
            first.push(neighbours.len());
            let (y, x) = (c as i64 / bx, c as i64 % bx);
            for (t, ((dy, dx), _)) in taps.iter().enumerate() {
                let (yy, xx) = (y + dy, x + dx);
                if (0..by).contains(&yy) && (0..bx).contains(&xx) {
                    let j = point_at[(yy * bx + xx) as usize];
                    if j != u32::MAX {
                        neighbours.push((j, t as u32));
                    }
                }
            }
        }
        first.push(neighbours.len());
        NearInverse { coefficients: taps.iter().map(|t| t.1).collect(), first, neighbours }
    }

    /// The same operator on the points `near` (indices into the `m` points) alone.
    fn subset(&self, near: &[usize], m: usize) -> Self {
        let mut index = vec![u32::MAX; m];
        near.iter().enumerate().for_each(|(k, &i)| index[i] = k as u32);
        let mut first = Vec::with_capacity(near.len() + 1);
        let mut neighbours = Vec::new();
        for &i in near {
            first.push(neighbours.len());
            for &(j, t) in &self.neighbours[self.first[i]..self.first[i + 1]] {
                if index[j as usize] != u32::MAX {
                    neighbours.push((index[j as usize], t));
                }
            }
        }
        first.push(neighbours.len());
        NearInverse { coefficients: self.coefficients.clone(), first, neighbours }
    }

    /// `out = N v` on the contact points.
    fn apply(&self, v: &[[f64; 2]], out: &mut [[f64; 2]]) {
        out.par_iter_mut().enumerate().with_min_len(CHUNK).for_each(|(i, o)| {
            *o = self.neighbours[self.first[i]..self.first[i + 1]].iter().fold([0.0; 2], |[ax, ay], &(j, t)| {
                let (w, g) = (v[j as usize], self.coefficients[t as usize]);
                [ax + g[0] * w[0] + g[1] * w[1], ay + g[1] * w[0] + g[2] * w[1]]
            });
        });
    }
}

/// Whether the 2×2 symbol of `taps` (a kernel even in each offset along the diagonal, odd in
/// each across it) is positive definite at every wavevector of a 33 × 33 sampling of
/// [0, π]² (the symbol is even in each component): then so is N on any set of points.
fn positive(taps: &[((i64, i64), [f64; 3])]) -> bool {
    const SAMPLES: usize = 32;
    let angle = |i: usize| std::f64::consts::PI * i as f64 / SAMPLES as f64;
    (0..=SAMPLES).all(|a| {
        (0..=SAMPLES).all(|b| {
            let (ky, kx) = (angle(a), angle(b));
            let s = taps.iter().fold([0.0; 3], |s, ((dy, dx), g)| {
                let c = (ky * *dy as f64 + kx * *dx as f64).cos();
                [s[0] + g[0] * c, s[1] + g[1] * c, s[2] + g[2] * c]
            });
            s[0] > 0.0 && s[0] * s[2] - s[1] * s[1] > 0.0
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Skipping the rows without contact points changes no bit of K v on the points, in
    /// single and double precision, on both boundaries.
    #[test]
    fn skipping_rows_without_points_changes_nothing() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 96;
        // Two patches in rows 10–14 and 60–61 of a box from row 10 to 61, columns 5 to 80.
        let points: Vec<usize> =
            (10..15).chain(60..62).flat_map(|y| (5..81).step_by(3).map(move |x| y * n + x)).collect();
        let m = points.len();
        let v: Vec<[f64; 2]> = (0..m).map(|i| [((i * 37) % 11) as f64 - 5.0, ((i * 17) % 7) as f64 - 3.0]).collect();
        for boundary in [Boundary::Periodic, Boundary::Free] {
            for single in [false, true] {
                let mut results = Vec::new();
                for skip in [false, true] {
                    let mut op = ShearOperator::grid(&points, (n, n), (9.6e-6, 9.6e-6), c, boundary);
                    if skip {
                        op = op.only_contact_rows();
                    }
                    op.set_single(single);
                    let mut out = vec![[0.0; 2]; m];
                    op.apply(&v, &mut out);
                    results.push(out);
                }
                assert!(results[0].iter().any(|u| u[0] != 0.0));
                assert_eq!(results[0], results[1], "{boundary:?}, single {single}");
            }
        }
    }

    /// With every offset of a periodic window (odd sides, so that each periodic offset is one
    /// tap; rectangular pixels), the near inverse is K's inverse: it takes the displacement
    /// K q back to q, less q's mean (the mode the periodic kernel leaves out).
    #[test]
    fn near_inverse_with_every_offset_is_ks_inverse() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 15;
        let mut influence = TangentialInfluence::periodic(n, n, (3.0e-6, 2.2e-6), c);
        let q: [Vec<f64>; 2] = std::array::from_fn(|k| {
            (0..n * n).map(|i| 1e6 * (((i * (37 + 6 * k)) % 11) as f64 - 5.0 + 0.3 * k as f64)).collect()
        });
        let mut u = [vec![0.0; n * n], vec![0.0; n * n]];
        let [ux, uy] = &mut u;
        influence.apply([&q[0], &q[1]], [ux, uy]);
        let taps = influence.inverse_near(n / 2);
        assert_eq!(taps.len(), n * n);
        let mean = q.each_ref().map(|q| q.iter().sum::<f64>() / (n * n) as f64);
        let wrap = |i: usize, d: i64| (i as i64 + d).rem_euclid(n as i64) as usize;
        for y in 0..n {
            for x in 0..n {
                let back = taps.iter().fold([0.0; 2], |[a, b], ((dy, dx), g)| {
                    let j = wrap(y, *dy) * n + wrap(x, *dx);
                    [a + g[0] * u[0][j] + g[1] * u[1][j], b + g[1] * u[0][j] + g[2] * u[1][j]]
                });
                for k in 0..2 {
                    let want = q[k][y * n + x] - mean[k];
                    assert!((back[k] - want).abs() <= 1e-9 * 5e6, "({y}, {x}) component {k}: {} vs {want}", back[k]);
                }
            }
        }
    }

    /// The sampled symbol accepts the inverse's nearest offsets and refuses a stencil whose
    /// neighbours outweigh its centre.
    #[test]
    fn near_inverse_is_positive_and_a_heavy_stencil_is_not() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let points: Vec<usize> = (0..64 * 64).collect();
        let operator = ShearOperator::grid(&points, (64, 64), (1.3e-6, 1.3e-6), c, Boundary::Periodic);
        let ShearOperator::Grid { influence, .. } = &operator else { unreachable!("made on the grid") };
        let taps = NearInverse::taps(influence);
        assert_eq!(taps.len(), (2 * NEAR + 1).pow(2), "the truncated inverse, not the diagonal alone");
        assert!(taps.iter().any(|(d, g)| *d == (0, 0) && g[0] == 1.0));
        let heavy: Vec<_> = [(0, 0), (0, 1), (0, -1), (1, 0), (-1, 0)]
            .into_iter()
            .map(|d| (d, if d == (0, 0) { [1.0, 0.0, 1.0] } else { [-0.3, 0.0, -0.3] }))
            .collect();
        assert!(!positive(&heavy));
        assert!(positive(&heavy[..1]));
    }

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

    /// The dense operator equals the grid operator it is made from, on scattered points of
    /// both boundaries, with and without padding of the box.
    #[test]
    fn dense_operator_is_the_grid_operator() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        for boundary in [Boundary::Periodic, Boundary::Free] {
            for (n, spread) in [(64, 20), (32, 32)] {
                let mut pressure = vec![0.0; n * n];
                for k in 0..40 {
                    let (y, x) = ((k * 7) % spread + 3 * (spread < n) as usize, (k * 13 + k / 5) % spread);
                    pressure[y * n + x] = 1e9 * (1.0 + k as f64 / 40.0);
                }
                let mut solver = TangentialSolver::new(
                    &pressure,
                    (n, n),
                    (6.4e-6, 6.4e-6),
                    c,
                    boundary,
                    TangentialOptions::default(),
                )
                .unwrap();
                let ShearOperator::Dense { .. } = solver.operator else { panic!("40 points: dense") };
                let m = solver.points.len();
                let v: Vec<[f64; 2]> =
                    (0..m).map(|i| [((i * 37) % 11) as f64 - 5.0, ((i * 17) % 7) as f64 - 3.0]).collect();
                let mut dense = vec![[0.0; 2]; m];
                solver.operator.apply(&v, &mut dense);
                // The grid operator of the same box, as the solver made it before choosing.
                let mut grid = ShearOperator::grid(&solver.points, (n, n), (6.4e-6, 6.4e-6), c, boundary);
                let mut want = vec![[0.0; 2]; m];
                grid.apply(&v, &mut want);
                let scale = want.iter().map(|w| w[0].abs().max(w[1].abs())).fold(0.0, f64::max);
                for (d, w) in dense.iter().zip(&want) {
                    assert!(
                        (d[0] - w[0]).abs() <= 1e-12 * scale && (d[1] - w[1]).abs() <= 1e-12 * scale,
                        "{boundary:?} {n}: {d:?} vs {w:?}"
                    );
                }
            }
        }
    }

    /// Changes at a few points added pair by pair give what an application of K to them gives,
    /// on the grid operator of both boundaries and on the dense operator.
    #[test]
    fn changes_added_pair_by_pair_are_k_applied() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 64;
        let points: Vec<usize> = (0..n * n).filter(|i| (i * 7919) % 5 < 2 && i % n > 3).collect();
        for boundary in [Boundary::Periodic, Boundary::Free] {
            for (m, dense) in [(points.len(), false), (60, true)] {
                let mut op = ShearOperator::grid(&points[..m], (n, n), (6.4e-6, 6.4e-6), c, boundary);
                if dense {
                    op = op.dense();
                }
                let changes: Vec<(usize, [f64; 2])> = [3, m / 3, m / 2 + 1, m - 1]
                    .iter()
                    .map(|&j| (j, [1e8 * (1.0 + j as f64 / m as f64), -3e7]))
                    .collect();
                let mut v = vec![[0.0; 2]; m];
                changes.iter().for_each(|&(j, d)| v[j] = d);
                let mut want = vec![[0.0; 2]; m];
                op.apply(&v, &mut want);
                let scale = want.iter().map(|w| w[0].abs().max(w[1].abs())).fold(0.0, f64::max);
                assert!(scale > 0.0);
                // Added to what is there: twice K v.
                let mut got = want.clone();
                op.add_changes(&changes, &mut got);
                for (g, w) in got.iter().zip(&want) {
                    assert!(
                        (g[0] - 2.0 * w[0]).abs() <= 1e-12 * scale && (g[1] - 2.0 * w[1]).abs() <= 1e-12 * scale,
                        "{boundary:?}, dense {dense}: {g:?} vs twice {w:?}"
                    );
                }
            }
        }
    }

    /// After a few bounds fall, solving near them first gives the whole's solution (to the
    /// tolerance) in fewer applications: a Hertz-like disk of every third pixel each way (704
    /// points, so that the neighbourhoods are small against the 128² window's transforms), its
    /// rim slipping, the three stuck points nearest their bounds made to slip.
    #[test]
    fn solving_near_changed_bounds_first_gives_the_same_solution() {
        let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
        let n = 128;
        let mut pressure = vec![0.0; n * n];
        for y in (1..n).step_by(3) {
            for x in (1..n).step_by(3) {
                let r2 = ((y as f64 - 64.0).powi(2) + (x as f64 - 61.5).powi(2)) / 45.0f64.powi(2);
                if r2 < 1.0 {
                    pressure[y * n + x] = 1e9 * (1.0 - r2).sqrt();
                }
            }
        }
        let options = TangentialOptions { tolerance: 1e-9, ..TangentialOptions::default() };
        let make = || {
            let mut s =
                TangentialSolver::new(&pressure, (n, n), (2.56e-6, 2.56e-6), c, Boundary::Periodic, options).unwrap();
            let m = s.points().len();
            // The stuck force per metre, then half the sliding force at mu = 0.5.
            s.solve(&vec![[1.0, 0.0]; m], &vec![f64::INFINITY; m]).unwrap();
            let k = s.force()[0];
            let bound: Vec<f64> = s.pressure().iter().map(|p| 0.5 * p).collect();
            let delta = 0.5 * 0.5 * s.normal_force() / k;
            let target = vec![[delta, 0.0]; m];
            s.set_traction(&vec![[0.0; 2]; m]);
            s.solve(&target, &bound).unwrap();
            (s, target, bound)
        };
        let (mut near, target, mut bound) = make();
        let (mut whole, ..) = make();
        assert!(matches!(near.operator, ShearOperator::Grid { .. }), "{} points: the transforms", near.points.len());
        let m = near.points.len();
        let q = near.traction().to_vec();
        let ratio = |i: usize| magnitude(q[i]) / bound[i];
        let slipping = (0..m).filter(|&i| ratio(i) > 1.0 - 1e-9).count();
        assert!(slipping > 100 && slipping < m / 2, "{slipping} of {m} slipping");
        let mut stuck: Vec<usize> = (0..m).filter(|&i| ratio(i) < 1.0 - 1e-6).collect();
        stuck.sort_by(|&a, &b| ratio(b).total_cmp(&ratio(a)));
        let changed: Vec<usize> = {
            let mut c = stuck[..3].to_vec();
            c.sort_unstable();
            c
        };
        changed.iter().for_each(|&i| bound[i] *= 0.5);
        let local = near.solve_after_change(&target, &bound, 1e-9, &changed).unwrap();
        let global = whole.solve_within(&target, &bound, 1e-9).unwrap();
        let norm = |v: &[[f64; 2]]| v.iter().map(|q| q[0] * q[0] + q[1] * q[1]).sum::<f64>().sqrt();
        let difference: Vec<[f64; 2]> =
            near.traction().iter().zip(whole.traction()).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
        let relative = norm(&difference) / norm(whole.traction());
        assert!(relative < 1e-7, "tractions {relative:.2e} apart");
        assert!(
            local.applications < global.applications,
            "{} applications near first, {} at once",
            local.applications,
            global.applications
        );
    }
}
