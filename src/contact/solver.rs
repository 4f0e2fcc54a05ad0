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

use std::ops::ControlFlow;
use std::time::Instant;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::influence::{Boundary, Influence};
use crate::error::{Error, Result};
use crate::fft::{large_buffer, split_rows, split_rows_mut};
use crate::limits::{check_memory, grid_memory, CONTACT_BYTES_PER_POINT};

mod saturated;

// The GPU iteration shares the capped solve's scales.
#[cfg(feature = "gpu")]
pub(crate) use saturated::Scales;

/// Iterations without a new best residual after which the conjugate gradient restarts.
pub(crate) const STALL: usize = 50;

/// Partial sums kept per grid row.
const SUMS: usize = 10;

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

/// Up to this many grid rows with changes, their transform is summed directly inside the
/// column passes (a few axpys per spectrum row) rather than computed by FFT.
const DIRECT_ROWS: usize = 8;

/// A row of pending changes keeps room for this many between iterations; more is given back
/// once their transform is taken (the first steps of a cold start clip most of the grid).
const RETAINED_CHANGES: usize = 256;

/// How the transform of the pending changes D is at hand.
#[derive(Clone, Copy, PartialEq)]
enum ChangeTransform {
    /// Nothing pending.
    None,
    /// In `change_spectrum`.
    Dense,
    /// As `change_rows`: D̂(qx, qy) = Σ_rows R_y(qx) · e^{−2πi qy y / ny}.
    Rows,
}

/// One grid row of changes, transformed along x: R_y(qx) = Σ δ e^{−2πi qx x / nx}, with the
/// phases e^{−2πi qy y / ny} that carry it along y.
#[derive(Default)]
struct ChangeRow {
    spectrum: Vec<Complex64>,
    phase: Vec<Complex64>,
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
    /// Residual at which a solve has converged: for the normal solve see the module
    /// documentation, for the tangential one the relative norm of its projected gradient.
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

/// The compressed rows of a contact set from some row on, for cutting it between tasks.
struct ContactRows<'a> {
    first: usize,
    index: &'a mut [u32],
    pressure: &'a mut [f64],
    direction: &'a mut [f64],
}

impl<'a> ContactRows<'a> {
    /// Cut at row `mid`, given where rows start.
    fn split(self, mid: usize, row_start: &[usize]) -> (Self, Self) {
        let at = row_start[mid] - row_start[self.first];
        let (i0, i1) = self.index.split_at_mut(at);
        let (p0, p1) = self.pressure.split_at_mut(at);
        let (t0, t1) = self.direction.split_at_mut(at);
        (
            ContactRows { first: self.first, index: i0, pressure: p0, direction: t0 },
            ContactRows { first: mid, index: i1, pressure: p1, direction: t1 },
        )
    }
}

impl ContactSet {
    /// Where rows start, and the compressed rows from row 0, ready to be cut between tasks.
    fn split_rows(&mut self) -> (&[usize], ContactRows<'_>) {
        let rows = ContactRows {
            first: 0,
            index: &mut self.index,
            pressure: &mut self.pressure,
            direction: &mut self.direction,
        };
        (&self.row_start, rows)
    }

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

/// Whether a contact solve and a tangential solve on its contact (a sliding onset, a stuck
/// contact's stiffness) on an ny × nx surface fit in the memory available together: checked
/// before the normal solve, so that a refusal comes before its work.
pub fn check_solves_memory((ny, nx): (usize, usize), boundary: Boundary) -> std::result::Result<(), String> {
    let bytes = solve_memory((ny, nx), boundary).saturating_add(super::tangential::solve_memory((ny, nx), boundary));
    check_memory(bytes, &format!("a contact solve and a tangential solve on {nx} × {ny} points"))
}

/// The CPU engine of [`ContactSolver`].
struct CpuSolver {
    ny: usize,
    nx: usize,
    size: (f64, f64),
    boundary: Boundary,
    e_star: f64,
    /// Rigid surface heights h [m]: higher points touch first.
    heights: Vec<f64>,
    h_rms: f64,
    /// A bound on how far the pressure that presses the surface flat strays from its mean,
    /// (E*/2)·q_max·√n·(max h − min h) [Pa]: a map whose bound lies within the tolerance of the
    /// mean pressure is flat to the solver, which could only iterate on its rounding.
    flat_spread: f64,
    operator: Influence,
    options: SolverOptions,
    /// Stored displacement u [m]: K(p − σD) = σu.
    displacement: Vec<f64>,
    /// σ: the load restoration not yet applied to the displacement.
    scale: f64,
    /// c: the shift of the contact points' stored gaps, u − h − c.
    reference: f64,
    contact: ContactSet,
    /// A cold start's contact set, kept implicit: every point at this pressure [Pa], search
    /// direction zero (`contact` is empty meanwhile). Stored, it would be the solve's largest
    /// array; the first step builds the points it keeps directly.
    uniform: Option<f64>,
    /// The next contact set, built while the current one is read.
    next: ContactSet,
    /// D: the projection's changes not yet applied to the displacement, per row.
    pending: Vec<Vec<Change>>,
    /// Spectrum of D, in one of the forms of [`ChangeTransform`]; allocated when first needed.
    change_transform: ChangeTransform,
    change_spectrum: Vec<Complex64>,
    change_rows: Vec<ChangeRow>,
    /// e^{−2πi k / n} on the FFT grid, along x and along y.
    twiddle_x: Vec<Complex64>,
    twiddle_y: Vec<Complex64>,
    /// How many of `change_rows` are in use.
    direct_rows: usize,
    /// Per-row and per-spectrum-row partial sums.
    row_sums: Vec<[f64; SUMS]>,
    spectrum_sums: Vec<[f64; 2]>,
    /// Dense pressure of the last solve [Pa].
    pressure_field: Vec<f64>,
    warm: bool,
    /// The cap on the pressure (elastic–perfectly-plastic contact) [Pa], if any.
    hardness: Option<f64>,
}

/// A contact problem on one surface, solved for one load after another. The pressure of the
/// last solve is the starting point of the next (warm start). It runs on the CPU, or on an
/// NVIDIA GPU ([`Device::Gpu`], in a build with the `gpu` feature).
pub struct ContactSolver {
    engine: Engine,
}

enum Engine {
    Cpu(Box<CpuSolver>),
    #[cfg(feature = "gpu")]
    Gpu(Box<super::gpu::GpuSolver>),
}

/// Calls the same method on whichever engine the solver has.
macro_rules! on_engine {
    ($self:expr, $s:ident => $call:expr) => {
        match $self {
            Engine::Cpu($s) => $call,
            #[cfg(feature = "gpu")]
            Engine::Gpu($s) => $call,
        }
    };
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

impl ContactSolver {
    /// Set up the problem for `heights` \[m] (row-major, ny × nx) on a window of physical size
    /// (lx, ly) \[m], effective modulus E* \[Pa] and the given boundary, on `options.device`.
    pub fn new(
        heights: &[f64],
        (ny, nx): (usize, usize),
        (lx, ly): (f64, f64),
        e_star: f64,
        boundary: Boundary,
        options: SolverOptions,
    ) -> Result<Self> {
        check_problem(heights, (ny, nx), (lx, ly), e_star)?;
        options.convergence.check()?;
        let n = ny * nx;
        let mean = heights.iter().sum::<f64>() / n as f64;
        let h_rms = (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let engine = match options.device {
            Device::Cpu => {
                check_solve_memory((ny, nx), boundary).map_err(|r| Error::invalid("surface", r))?;
                Engine::Cpu(Box::new(CpuSolver::new(heights, (ny, nx), (lx, ly), e_star, boundary, options, h_rms)?))
            }
            #[cfg(feature = "gpu")]
            Device::Gpu => Engine::Gpu(Box::new(super::gpu::GpuSolver::new(
                heights,
                (ny, nx),
                (lx, ly),
                e_star,
                boundary,
                options,
                h_rms,
            )?)),
            #[cfg(not(feature = "gpu"))]
            Device::Gpu => return Err(Error::invalid("--device", Device::UNAVAILABLE)),
        };
        Ok(ContactSolver { engine })
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        on_engine!(&self.engine, s => s.shape())
    }

    /// Physical size (lx, ly) \[m].
    pub fn size(&self) -> (f64, f64) {
        on_engine!(&self.engine, s => s.size())
    }

    /// The boundary condition.
    pub fn boundary(&self) -> Boundary {
        on_engine!(&self.engine, s => s.boundary())
    }

    /// The heights h \[m].
    pub fn heights(&self) -> &[f64] {
        on_engine!(&self.engine, s => s.heights())
    }

    /// Pressure of the last solve \[Pa], row-major (ny, nx); zero after a failed solve.
    pub fn pressure(&self) -> &[f64] {
        on_engine!(&self.engine, s => s.pressure())
    }

    /// Gap of the last solve \[m]: zero where 0 < p < H (the hardness, if set), positive where
    /// p = 0, and where p = H the penetration of the rigid surface as a negative gap (the
    /// plastic indentation).
    pub fn gap(&self) -> Vec<f64> {
        let (p, u, h) = (self.pressure(), on_engine!(&self.engine, s => s.displacement()), self.heights());
        gap_of(p, u, h, on_engine!(&self.engine, s => s.hardness()))
    }

    /// Surface displacement u = K p of the last solve \[m]. In the periodic model its mean is
    /// zero: the rigid-body approach is not defined there.
    pub fn displacement(&self) -> Vec<f64> {
        on_engine!(&self.engine, s => s.displacement().to_vec())
    }

    /// Start the next solve from scratch rather than from the last pressure.
    pub fn reset(&mut self) {
        on_engine!(&mut self.engine, s => s.reset())
    }

    /// Start the next solve from `pressure` \[Pa] (row-major (ny, nx), each ≥ 0) as if it were
    /// the last solve's: a load sweep resumed from a saved pressure map continues exactly as
    /// the uninterrupted sweep (a solve depends only on the pressure it starts from).
    pub fn warm_start(&mut self, pressure: &[f64]) -> Result<()> {
        let (ny, nx) = self.shape();
        if pressure.len() != ny * nx {
            return Err(Error::invalid("warm start", format!("{} pressures for a {ny}×{nx} grid", pressure.len())));
        }
        if let Some(i) = pressure.iter().position(|p| !(p.is_finite() && *p >= 0.0)) {
            return Err(Error::invalid("warm start", format!("pressure {} Pa at point {i}", pressure[i])));
        }
        on_engine!(&mut self.engine, s => s.warm_start(pressure))
    }

    /// Cap the pressure at the hardness H \[Pa] in the solves that follow (elastic–perfectly-
    /// plastic contact, 0 ≤ p ≤ H; two FFT pairs per iteration), or lift the cap with `None`.
    pub fn set_hardness(&mut self, hardness: Option<f64>) -> Result<()> {
        if let Some(h) = hardness {
            if !(h > 0.0 && h.is_finite()) {
                return Err(Error::invalid("--hardness", format!("must be positive and finite, got {h} Pa")));
            }
        }
        on_engine!(&mut self.engine, s => s.set_hardness(hardness));
        Ok(())
    }

    /// Solve for the normal load `load` \[N]. `progress` is called after every iteration with
    /// the iteration count and the current residual; it answers `()`, or a [`ControlFlow`]
    /// whose `Break` stops the solve with [`Error::Interrupted`] (the next solve then starts
    /// cold).
    pub fn solve<R: Proceed>(&mut self, load: f64, mut progress: impl FnMut(usize, f64) -> R) -> Result<SolveReport> {
        check_load(load, self.size(), on_engine!(&self.engine, s => s.e_star()))?;
        let mut proceed = |it: usize, residual: f64| progress(it, residual).proceed();
        on_engine!(&mut self.engine, s => s.solve(load, &mut proceed))
    }
}

/// The range of `heights`, max − min [m].
fn height_range(heights: &[f64]) -> f64 {
    let (low, high) = heights.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &z| (l.min(z), h.max(z)));
    high - low
}

/// The gap of a solution (see [`ContactSolver::gap`]) from its pressure, displacement and
/// heights, with the cap `hardness` if any.
fn gap_of(pressure: &[f64], displacement: &[f64], heights: &[f64], hardness: Option<f64>) -> Vec<f64> {
    let cap = hardness.unwrap_or(f64::INFINITY);
    let (sum, count) = pressure
        .iter()
        .zip(displacement.iter().zip(heights))
        .filter(|(p, _)| **p > 0.0 && **p < cap)
        .fold((0.0, 0usize), |(s, c), (_, (u, h))| (s + (u - h), c + 1));
    let mean = sum / count.max(1) as f64;
    (0..heights.len())
        .map(|i| {
            let (p, g) = (pressure[i], displacement[i] - heights[i] - mean);
            if p == 0.0 {
                g.max(0.0)
            } else if p == cap {
                g.min(0.0)
            } else {
                0.0
            }
        })
        .collect()
}

impl CpuSolver {
    /// The problem [`ContactSolver::new`] has checked, with the RMS height `h_rms` [m].
    fn new(
        heights: &[f64],
        (ny, nx): (usize, usize),
        (lx, ly): (f64, f64),
        e_star: f64,
        boundary: Boundary,
        options: SolverOptions,
        h_rms: f64,
    ) -> Result<Self> {
        let n = ny * nx;
        let operator = match boundary {
            Boundary::Periodic => Influence::periodic(ny, nx, (lx, ly), e_star),
            Boundary::Free => Influence::free(ny, nx, (lx, ly), e_star),
        };
        let nxh = operator.fft().shape().1 / 2 + 1;
        let (grid_ny, grid_nx) = operator.fft().shape();
        let twiddle = |n: usize| {
            (0..n).map(|k| Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * k as f64 / n as f64)).collect()
        };
        let mut heights_buffer = large_buffer(n, 0.0);
        heights_buffer.copy_from_slice(heights);
        // |F⁻¹[|q| ĥ]| ≤ q_max Σ|ĥ(q)|/n ≤ q_max √n h_rms (Parseval), and h_rms ≤ max − min.
        let q_max = std::f64::consts::PI * ((nx as f64 / lx).powi(2) + (ny as f64 / ly).powi(2)).sqrt();
        let flat_spread = 0.5 * e_star * q_max * (n as f64).sqrt() * height_range(heights);
        Ok(CpuSolver {
            ny,
            nx,
            size: (lx, ly),
            boundary,
            e_star,
            heights: heights_buffer,
            h_rms,
            flat_spread,
            operator,
            options,
            displacement: large_buffer(n, 0.0),
            scale: 1.0,
            reference: 0.0,
            contact: ContactSet::default(),
            uniform: None,
            next: ContactSet::default(),
            pending: vec![Vec::new(); ny],
            change_transform: ChangeTransform::None,
            change_spectrum: Vec::new(),
            change_rows: (0..DIRECT_ROWS).map(|_| ChangeRow::default()).collect(),
            twiddle_x: twiddle(grid_nx),
            twiddle_y: twiddle(grid_ny),
            direct_rows: 0,
            row_sums: vec![[0.0; SUMS]; ny],
            spectrum_sums: vec![[0.0; 2]; nxh],
            pressure_field: large_buffer(n, 0.0),
            warm: false,
            hardness: None,
        })
    }

    fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    fn size(&self) -> (f64, f64) {
        self.size
    }

    fn boundary(&self) -> Boundary {
        self.boundary
    }

    fn e_star(&self) -> f64 {
        self.e_star
    }

    fn hardness(&self) -> Option<f64> {
        self.hardness
    }

    fn heights(&self) -> &[f64] {
        &self.heights
    }

    fn pressure(&self) -> &[f64] {
        &self.pressure_field
    }

    fn displacement(&self) -> &[f64] {
        &self.displacement
    }

    fn reset(&mut self) {
        self.warm = false;
    }

    /// See [`ContactSolver::warm_start`], which checks `pressure`.
    fn warm_start(&mut self, pressure: &[f64]) -> Result<()> {
        self.pressure_field.copy_from_slice(pressure);
        self.adopt_pressure_field();
        self.warm = true;
        Ok(())
    }

    fn set_hardness(&mut self, hardness: Option<f64>) {
        self.hardness = hardness;
    }

    /// The contact set of the dense pressure field: its points with p > 0.
    fn adopt_pressure_field(&mut self) {
        let (ny, nx, pressure) = (self.ny, self.nx, &self.pressure_field);
        let c = &mut self.contact;
        (c.index, c.pressure) =
            pressure.iter().enumerate().filter(|(_, p)| **p > 0.0).map(|(i, p)| (i as u32, *p)).unzip();
        c.row_start = (0..=ny).map(|y| c.index.partition_point(|&i| (i as usize) < y * nx)).collect();
        c.direction = vec![0.0; c.index.len()];
        self.uniform = None;
    }

    /// See [`ContactSolver::solve`], which checks the load.
    fn solve(&mut self, load: f64, proceed: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport> {
        // The dense pressure is rebuilt at the end: the iteration needs only the contact set.
        self.pressure_field = Vec::new();
        let p_mean = load / (self.size.0 * self.size.1);
        let flat = self.flat_spread <= self.options.convergence.tolerance * p_mean;
        let report = match self.hardness {
            _ if flat && self.boundary == Boundary::Free => Err(Error::invalid(
                "surface",
                format!(
                    "the map is flat (heights within {:e} m of each other): pressed over a free window it is a \
                     flat punch, whose pressure is singular at the window's edges; solve it periodic (full \
                     contact at the uniform pressure N/(Lx·Ly))",
                    height_range(&self.heights)
                ),
            )),
            Some(hardness) if !(flat && p_mean <= hardness) => self.solve_saturated(hardness, load, proceed),
            _ if flat => Ok(self.press_flat(load)),
            _ => self.solve_elastic(load, proceed),
        };
        if report.is_ok() {
            // Converged in full contact at the start (a flat surface): the set is stored.
            self.materialise();
        } else {
            // A failed solve, whatever stopped it, is no warm start.
            self.warm = false;
            self.uniform = None;
        }
        if self.pressure_field.is_empty() {
            self.pressure_field = large_buffer(self.ny * self.nx, 0.0);
            if report.is_ok() {
                for (&i, &p) in self.contact.index.iter().zip(&self.contact.pressure) {
                    self.pressure_field[i as usize] = p;
                }
            }
        }
        // What only the iteration needs goes (the next solve allocates it again).
        self.pending.iter_mut().for_each(|r| *r = Vec::new());
        self.next = ContactSet::default();
        self.change_spectrum = Vec::new();
        let c = &mut self.contact;
        for v in [&mut c.pressure, &mut c.direction] {
            v.shrink_to_fit();
        }
        c.index.shrink_to_fit();
        report
    }

    fn solve_elastic(&mut self, load: f64, progress: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport> {
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
        let (mut shifts, mut residual) = self.refresh(p_mean, norm);
        // Whether `residual` was measured on a displacement recomputed from scratch.
        let mut exact = true;
        let mut applications = 1.0;
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
    fn press_flat(&mut self, load: f64) -> SolveReport {
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

    /// The error of a solve stopped by its caller.
    fn interrupted(load: f64) -> Error {
        Error::Interrupted { what: format!("contact solve at {load} N") }
    }

    fn pending_is_empty(&self) -> bool {
        self.pending.iter().all(Vec::is_empty)
    }

    /// Store the implicit uniform contact set, if that is what the solver holds.
    fn materialise(&mut self) {
        if let Some(p) = self.uniform.take() {
            let n = self.ny * self.nx;
            let c = &mut self.contact;
            c.index = (0..n as u32).collect();
            c.row_start = (0..=self.ny).map(|y| y * self.nx).collect();
            c.pressure = vec![p; n];
            c.direction = vec![0.0; n];
        }
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

    /// The residual of the module documentation for the current state, on a full pass.
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

/// Sum per-row partial sums in row order (deterministic).
fn sum_rows<const K: usize>(rows: &[[f64; K]]) -> [f64; K] {
    rows.iter().fold([0.0; K], |mut a, b| {
        a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        a
    })
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
