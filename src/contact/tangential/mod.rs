//! The constrained tangential solve: shear tractions on a fixed contact set under an imposed
//! rigid tangential displacement, with a Coulomb bound at every point.
//!
//! The normal pressure p comes from the normal solve and is not changed (normal and
//! tangential problems uncoupled: exact for identical bodies, Goodman's approximation
//! otherwise). Unknown: the shear traction q_i = (q_x, q_y) \[Pa] on the contact points. Given a
//! target surface displacement b_i \[m] (the body's displacement minus the slip accumulated
//! before this increment) and a bound g_i \[Pa] (μ_i p_i), q minimises
//!
//! ```text
//!     Π(q) = ½ qᵀ K q − bᵀ q     subject to |q_i| ≤ g_i,
//! ```
//!
//! K the Cerruti operator ([`TangentialInfluence`](super::influence::TangentialInfluence)). Its
//! optimality conditions are the frictional contact conditions: a stuck point (|q_i| < g_i)
//! follows the target (u_i = b_i); a slipping point carries |q_i| = g_i, with the slip increment
//! b_i − u_i along q_i.
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
//! (its offsets up to `operator::NEAR` pixels, a pass over each point's neighbours),
//! scaled at each point by the Hessian's diagonal, K's diagonal plus the curvature term: a point that slipped
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
//! points, below the tolerance, on a displacement that is exact (recomputed from scratch), or
//! that was updated step by step and is known to be near enough to K q that the residual on
//! K q is below the tolerance too: a conjugate gradient step misses the turned tractions'
//! return onto their bounds (a change c of the traction that moves u by at most ‖K‖‖c‖) and
//! carries the step's round-off.
//! Solves at a tolerance of 1e-6 or above apply K in single precision (and go on in double
//! should they stall); tighter ones in double throughout. Where a solve changes the traction
//! at a few points only (the bounds a slip cascade lowers), its displacement follows them
//! pair by pair, through K's coefficients at every offset, instead of through the transforms;
//! and the tractions near them are solved for first, as small dense problems of their own
//! ([`TangentialSolver::solve_after_change`]).
//!
//! The parts: `operator` K on the contact points and its near inverse; `mprgp` the solve;
//! `local` the solves near a few changed bounds; `disk` the bound at one point.
//!
//! Imports `influence` and `options` inside `contact`, never the normal solvers; must not import
//! friction, study, report, plot, shs, cli.

mod disk;
mod local;
mod mprgp;
mod operator;

use super::influence::{Boundary, ShearCompliance};
use super::options::Convergence;
use crate::error::{Error, Result};
use crate::limits::{check_memory, grid_memory, TANGENTIAL_BYTES_PER_POINT};
use disk::cut_onto_disks;
pub(crate) use disk::magnitude;
use operator::{dense_bytes_at_most, dense_is_cheaper, NearInverse, ShearOperator};

/// Settings of the tangential solve: its convergence alone, the type the normal solve's
/// [`SolverOptions`](super::SolverOptions) hold theirs in.
pub type TangentialOptions = Convergence;

/// The tangential solve's settings (the normal solve's are [`SolverOptions`](super::SolverOptions)'s).
/// The tolerance, the relative norm of the projected gradient, 1e-6: it moves the sliding
/// onset's F_S by 6e-8 (256², 10 mN) and 2e-8 (1500², 0.1 mN) against 1e-8, with the same
/// classes at the peak, for 0.52–0.53 of the iterations; 1e-5 moves it by 2e-6 and changes the
/// path's history (other cascades).
impl Default for Convergence {
    fn default() -> Self {
        Convergence { tolerance: 1e-6, max_iterations: 20_000 }
    }
}

/// The memory of a tangential solve on an ny × nx window \[bytes], as if its contact spread over
/// the whole window ([`TANGENTIAL_BYTES_PER_POINT`]), with a dense operator at its largest.
pub fn solve_memory((ny, nx): (usize, usize), boundary: Boundary) -> u64 {
    let padding = if boundary == Boundary::Free { 4 } else { 1 };
    let grid = grid_memory(nx, ny, TANGENTIAL_BYTES_PER_POINT * padding);
    grid.saturating_add(dense_bytes_at_most(nx.saturating_mul(ny).saturating_mul(padding as usize)))
}

/// Whether a tangential solve on an ny × nx window fits in the memory available
/// ([`solve_memory`]); the reason, naming the estimate, when it does not.
pub fn check_solve_memory(shape: (usize, usize), boundary: Boundary) -> std::result::Result<(), String> {
    let (ny, nx) = shape;
    check_memory(solve_memory(shape, boundary), &format!("a tangential solve on {nx} × {ny} points"))
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
    /// The problem on the contact set (p > 0) of `pressure` \[Pa] (row-major, `shape`) on a
    /// window of physical size `size` \[m], with the bodies' shear compliance and the boundary
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
        check_solve_memory(shape, boundary).map_err(|r| Error::invalid("surface", r))?;
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

    /// Area of one pixel \[m²].
    pub fn pixel_area(&self) -> f64 {
        self.size.0 / self.shape.1 as f64 * (self.size.1 / self.shape.0 as f64)
    }

    /// Flat indices y·nx + x of the contact points.
    pub fn points(&self) -> &[usize] {
        &self.points
    }

    /// Normal pressure p \[Pa] at the contact points.
    pub fn pressure(&self) -> &[f64] {
        &self.pressure
    }

    /// The normal force N = Σ p · a \[N] (one sum, so that every N of a solver is the same bits).
    pub fn normal_force(&self) -> f64 {
        self.pressure.iter().sum::<f64>() * self.pixel_area()
    }

    /// Shear traction q \[Pa] at the contact points, from the last solve.
    pub fn traction(&self) -> &[[f64; 2]] {
        &self.traction
    }

    /// Surface displacement u = K q \[m] at the contact points, from the last solve.
    pub fn displacement(&self) -> &[[f64; 2]] {
        &self.displacement
    }

    /// Tangential force Σ q · a \[N] of the current traction, (F_x, F_y).
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
