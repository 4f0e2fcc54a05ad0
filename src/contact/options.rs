//! What every contact solve shares, below the solvers and their backends: the settings
//! ([`SolverOptions`], [`Convergence`], [`Device`]), the checks of a problem, its load and its
//! memory, the count of iterations, the report of a solve, the scales of a capped solve, and
//! [`Engine`], the interface the CPU and GPU backends of the normal solve implement.
//!
//! Imports only `influence` inside `contact`, never the solvers nor their backends; must not import
//! friction, study, report, plot, shs, cli.

use std::ops::ControlFlow;

use super::influence::Boundary;
use crate::error::{Error, Result};
use crate::limits::{check_memory, grid_memory, CONTACT_BYTES_PER_POINT};

/// Iterations without a new best residual after which the conjugate gradient restarts.
pub(crate) const STALL: usize = 50;

/// The iteration count of a solve: its limit, its breakdown on a non-finite residual, and
/// when its residual stalls (no new best for more than `stall` iterations).
pub(crate) struct Iterations {
    solver: &'static str,
    convergence: Convergence,
    stall: usize,
    done: usize,
    best: f64,
    best_at: usize,
}

impl Iterations {
    /// `solver` names the solver in its errors; `convergence` holds the residual it aims at.
    pub(crate) fn new(solver: &'static str, convergence: Convergence, stall: usize) -> Self {
        Iterations { solver, convergence, stall, done: 0, best: f64::INFINITY, best_at: 0 }
    }

    /// Iterations done.
    pub(crate) fn done(&self) -> usize {
        self.done
    }

    /// Counts one more iteration after `residual`, which has not converged: an error if it is
    /// not finite or the limit is reached; `true` when the residual has stalled (the count
    /// towards the next stall then starts again).
    pub(crate) fn next(&mut self, residual: f64) -> Result<bool> {
        if !residual.is_finite() {
            return Err(Error::invalid(
                self.solver,
                format!("broke down at iteration {} (non-finite residual)", self.done),
            ));
        }
        if self.done == self.convergence.max_iterations {
            return Err(Error::NotConverged {
                solver: self.solver,
                iterations: self.done,
                residual,
                tolerance: self.convergence.tolerance,
            });
        }
        self.done += 1;
        if residual < self.best {
            (self.best, self.best_at) = (residual, self.done);
        } else if self.done - self.best_at > self.stall {
            self.best_at = self.done;
            return Ok(true);
        }
        Ok(false)
    }

    /// Forget the best residual so far: the residuals before were measured on an approximate
    /// state, which an exact recomputation has just replaced.
    pub(crate) fn forget_best(&mut self) {
        (self.best, self.best_at) = (f64::INFINITY, self.done);
    }
}

/// What a progress callback answers: `()` to carry on, or a [`ControlFlow`] whose `Break`
/// stops the work (so callbacks that only report need not say so).
pub trait Proceed {
    /// Whether the work goes on.
    fn proceed(self) -> bool;
}

impl Proceed for () {
    fn proceed(self) -> bool {
        true
    }
}

impl Proceed for ControlFlow<()> {
    fn proceed(self) -> bool {
        self.is_continue()
    }
}

/// When an iterative solve has converged and when it gives up: the settings the normal solve
/// ([`SolverOptions`]) and the tangential one ([`TangentialOptions`](super::TangentialOptions))
/// share. The default is the tangential solve's; the normal solve's is [`SolverOptions`]'s.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Convergence {
    /// Residual at which a solve has converged: for the normal solve see [`super::solver`], for
    /// the tangential one the relative norm of its projected gradient.
    pub tolerance: f64,
    /// Iterations after which a solve that has not converged is an error.
    pub max_iterations: usize,
}

/// Settings of the normal solve.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SolverOptions {
    /// Its convergence (default: tolerance 1e-10, 20 000 iterations).
    #[serde(flatten)]
    pub convergence: Convergence,
    /// Where the normal solves run.
    #[serde(default, skip_serializing_if = "Device::is_cpu")]
    pub device: Device,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions { convergence: Convergence { tolerance: 1e-10, max_iterations: 20_000 }, device: Device::Cpu }
    }
}

/// Where a normal contact solve runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Device {
    /// The processor's cores (rayon).
    #[default]
    Cpu,
    /// The first NVIDIA GPU, through CUDA (a build with the `gpu` feature): the same
    /// Polonsky–Keer iteration as the capped CPU solve, every field on the GPU.
    Gpu,
}

impl Device {
    /// Whether this build has the GPU backend.
    pub const GPU_BUILT: bool = cfg!(feature = "gpu");

    /// Why `Gpu` is refused in a build without the backend.
    pub const UNAVAILABLE: &'static str =
        "this asperity was built without the GPU backend: build it with `cargo build --release --features gpu`";

    fn is_cpu(&self) -> bool {
        *self == Device::Cpu
    }

    /// Name as written in options and outputs: `"cpu"` or `"gpu"`.
    pub fn name(self) -> &'static str {
        match self {
            Device::Cpu => "cpu",
            Device::Gpu => "gpu",
        }
    }
}

/// The loosest tolerance a solver takes: a residual of a hundredth of the mean pressure times
/// the RMS height. The uniform start's is of order 1 (0.82 on a rough sphere whose contact
/// fraction is 0.047): at 1 it was returned as the solution, in full contact.
pub const MAX_TOLERANCE: f64 = 1e-2;

impl Convergence {
    /// An error naming `--tolerance` or `--max-iter` unless the tolerance lies in
    /// (0, [`MAX_TOLERANCE`]) (near 1 a solve's untouched start passes as its solution) and at
    /// least one iteration is allowed.
    pub fn check(&self) -> Result<()> {
        let Convergence { tolerance, max_iterations } = *self;
        if !(tolerance > 0.0 && tolerance < MAX_TOLERANCE) {
            return Err(Error::invalid(
                "--tolerance",
                format!(
                    "must lie in (0, {MAX_TOLERANCE}), got {tolerance} (from {MAX_TOLERANCE} on the starting guess can pass as the solution)"
                ),
            ));
        }
        if max_iterations == 0 {
            return Err(Error::invalid("--max-iter", "must be at least 1"));
        }
        Ok(())
    }
}

/// What one solve reports besides its fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    /// Normal load N \[N].
    pub load: f64,
    /// Mean pressure over the window, N / (Lx·Ly) \[Pa].
    pub mean_pressure: f64,
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// Residual at convergence.
    pub residual: f64,
    /// Applications of the influence operator in FFT pairs: one per iteration and one per
    /// check of convergence from scratch; an iteration whose projection changed points on many
    /// grid rows adds half a pair (the forward transform of the change).
    pub operator_applications: f64,
    /// Wall-clock time of the solve \[s].
    pub seconds: f64,
    /// The cap on the pressure the solve ran with (elastic–perfectly-plastic) \[Pa], if any.
    pub hardness: Option<f64>,
}

/// The range of mean pressures solved, relative to E*: beyond it the products the solver forms
/// (pressure × gap, their sums over the grid) leave the range of floats. It is a range of
/// representable numbers, not of physics: full contact at any strain is solved as linear
/// elasticity has it.
const STRAIN_RANGE: (f64, f64) = (1e-100, 1e100);

/// Whether a normal `load` \[N] on a window of `size` \[m] can be solved with effective modulus
/// `e_star` \[Pa]: its mean pressure must lie between 1e-100 E* and 1e100 E*.
pub fn check_load(load: f64, size: (f64, f64), e_star: f64) -> Result<()> {
    use crate::quantity::human;
    if !(load > 0.0 && load.is_finite()) {
        return Err(Error::invalid("--load", format!("must be positive and finite, got {} N", human(load))));
    }
    // In logarithms, so that what overflows (or underflows) a float is still told as a number.
    let log_p = load.log10() - size.0.log10() - size.1.log10();
    let log_strain = log_p - e_star.log10();
    if !(log_strain > STRAIN_RANGE.0.log10() && log_strain < STRAIN_RANGE.1.log10()) {
        let power = |log: f64| {
            let v = 10f64.powf(log);
            if v.is_normal() {
                format!("{v:.3e}")
            } else {
                format!("1e{:.0}", log.round())
            }
        };
        return Err(Error::invalid(
            "--load",
            format!(
                "{} N on {} × {} m is a mean pressure of {} Pa, {} times the effective modulus E* = \
                 {e_star:.3e} Pa: not representable (the mean pressure must lie between {:e} E* and {:e} E*)",
                human(load),
                human(size.0),
                human(size.1),
                power(log_p),
                power(log_strain),
                STRAIN_RANGE.0,
                STRAIN_RANGE.1
            ),
        ));
    }
    Ok(())
}

/// The memory of a contact solve on an ny × nx surface \[bytes].
pub fn solve_memory((ny, nx): (usize, usize), boundary: Boundary) -> u64 {
    // A free boundary solves on the grid padded to 2nx × 2ny.
    let padding = if boundary == Boundary::Free { 4 } else { 1 };
    grid_memory(nx, ny, CONTACT_BYTES_PER_POINT * padding)
}

/// Whether a contact solve on an ny × nx surface fits in the memory available
/// ([`crate::limits::check_memory`]); the reason, naming the estimate, when it does not.
pub fn check_solve_memory((ny, nx): (usize, usize), boundary: Boundary) -> std::result::Result<(), String> {
    check_memory(solve_memory((ny, nx), boundary), &format!("a contact solve on {nx} × {ny} points"))
}

/// An error unless `heights` \[m] fill a grid of (ny, nx) ≥ 2×2 points with finite values and
/// the window (lx, ly) \[m] and the effective modulus E* \[Pa] are positive and finite: what
/// every normal solve, adhesive or not, needs of its problem.
pub(crate) fn check_problem(
    heights: &[f64],
    (ny, nx): (usize, usize),
    (lx, ly): (f64, f64),
    e_star: f64,
) -> Result<()> {
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
    Ok(())
}

/// The scales of a capped solve at one load, shared by the CPU and the GPU iteration.
pub(crate) struct Scales {
    /// Mean pressure N / (Lx·Ly) [Pa].
    pub p_mean: f64,
    /// The load as a sum of pixel pressures, p̄·n [Pa].
    pub total: f64,
    /// The residual's normalisation n·p̄·h_rms (h_rms taken as 1 on a flat surface).
    pub norm: f64,
    /// The finest mode's stiffness E*π/(2·spacing) [Pa/m]: its inverse is the step taken when
    /// the search direction gives none.
    pub stiffness: f64,
}

impl Scales {
    /// An error naming `--hardness` unless `hardness` [Pa] is above the mean pressure of `load`
    /// [N] on a window of `size` [m] and (ny, nx) points.
    pub(crate) fn of(
        hardness: f64,
        load: f64,
        size: (f64, f64),
        (ny, nx): (usize, usize),
        e_star: f64,
        h_rms: f64,
    ) -> Result<Self> {
        let n = (ny * nx) as f64;
        let p_mean = load / (size.0 * size.1);
        if hardness <= p_mean {
            return Err(Error::invalid(
                "--hardness",
                format!(
                    "{hardness:.4e} Pa is not above the mean pressure N/(Lx·Ly) = {p_mean:.4e} Pa: the window cannot \
                     carry {load:e} N"
                ),
            ));
        }
        let spacing = (size.0 / nx as f64).min(size.1 / ny as f64);
        Ok(Scales {
            p_mean,
            total: p_mean * n,
            norm: n * p_mean * if h_rms > 0.0 { h_rms } else { 1.0 },
            stiffness: e_star * std::f64::consts::PI / (2.0 * spacing),
        })
    }
}

/// A backend of the normal solve ([`super::ContactSolver`] holds one): the problem as
/// [`super::ContactSolver::new`] checked it, solved for one load after another.
pub(crate) trait Engine: Send + Sync {
    /// Grid shape (ny, nx).
    fn shape(&self) -> (usize, usize);
    /// Physical size (lx, ly) \[m].
    fn size(&self) -> (f64, f64);
    /// The boundary condition.
    fn boundary(&self) -> Boundary;
    /// The effective modulus E* \[Pa].
    fn e_star(&self) -> f64;
    /// The cap on the pressure \[Pa], if any.
    fn hardness(&self) -> Option<f64>;
    /// The heights h \[m].
    fn heights(&self) -> &[f64];
    /// Pressure of the last solve \[Pa]; zero after a failed solve.
    fn pressure(&self) -> &[f64];
    /// Displacement of the last solve \[m].
    fn displacement(&self) -> &[f64];
    /// Start the next solve from scratch.
    fn reset(&mut self);
    /// Start the next solve from `pressure` \[Pa], already checked.
    fn warm_start(&mut self, pressure: &[f64]) -> Result<()>;
    /// Cap the pressure at `hardness` \[Pa] from the next solve on, or lift the cap.
    fn set_hardness(&mut self, hardness: Option<f64>);
    /// Replace the heights \[m] (already checked) and their RMS `h_rms` \[m], keeping the last
    /// pressure as the next solve's start.
    fn set_heights(&mut self, heights: &[f64], h_rms: f64) -> Result<()>;
    /// Solve to `tolerance` (already checked) from the next solve on.
    fn set_tolerance(&mut self, tolerance: f64);
    /// Whether a warm solve may start from the last solve's displacement, scaled with its
    /// pressure to the new load, rather than transform the pressure again: the displacement is
    /// linear in the pressure, so only rounding tells them apart. An engine may transform anyway.
    fn set_rescaled_start(&mut self, on: bool);
    /// Solve for `load` \[N], already checked; `proceed` hears the iteration count and the
    /// residual after every iteration and answers whether to go on.
    fn solve(&mut self, load: f64, proceed: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport>;
}

#[cfg(test)]
mod tests {
    /// A load beyond what a float holds as a pressure is told in numbers, never as `inf`.
    #[test]
    fn a_load_out_of_range_is_told_in_numbers() {
        let e = super::check_load(1e300, (1e-5, 1e-5), 1.394e11).unwrap_err().to_string();
        assert!(e.contains("a mean pressure of 1e310 Pa, 7.174e298 times") && !e.contains("inf"), "{e}");
        let e = super::check_load(1e-200, (1.0, 1.0), 1.394e11).unwrap_err().to_string();
        assert!(e.contains("a mean pressure of 1.000e-200 Pa, 7.174e-212 times"), "{e}");
    }
}
