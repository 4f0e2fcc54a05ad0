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
//! [`ContactSolver`] solves one problem for one load after another, on the engine its
//! [`Device`] names: the CPU (`cpu`) or, in a build with the `gpu` feature, an NVIDIA GPU
//! (`gpu`). Both implement `Engine`, defined below them in [`super::options`].
//!
//! Imports `options`, `influence`, `cpu` and `gpu` inside `contact`; must not import friction,
//! study, report, plot, shs, cli.

use super::cpu::CpuSolver;
#[cfg(feature = "gpu")]
use super::gpu::GpuSolver;
use super::influence::Boundary;
use super::options::{
    check_load, check_problem, check_solve_memory, Device, Engine, Proceed, SolveReport, SolverOptions,
};
use crate::error::{Error, Result};

/// A contact problem on one surface, solved for one load after another. The pressure of the
/// last solve is the starting point of the next (warm start). It runs on the CPU, or on an
/// NVIDIA GPU ([`Device::Gpu`], in a build with the `gpu` feature).
pub struct ContactSolver {
    engine: Box<dyn Engine>,
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
        let h_rms = rms(heights);
        let engine: Box<dyn Engine> = match options.device {
            Device::Cpu => {
                check_solve_memory((ny, nx), boundary).map_err(|r| Error::invalid("surface", r))?;
                Box::new(CpuSolver::new(heights, (ny, nx), (lx, ly), e_star, boundary, options, h_rms)?)
            }
            #[cfg(feature = "gpu")]
            Device::Gpu => Box::new(GpuSolver::new(heights, (ny, nx), (lx, ly), e_star, boundary, options, h_rms)?),
            #[cfg(not(feature = "gpu"))]
            Device::Gpu => return Err(Error::invalid("--device", Device::UNAVAILABLE)),
        };
        Ok(ContactSolver { engine })
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        self.engine.shape()
    }

    /// Physical size (lx, ly) \[m].
    pub fn size(&self) -> (f64, f64) {
        self.engine.size()
    }

    /// The boundary condition.
    pub fn boundary(&self) -> Boundary {
        self.engine.boundary()
    }

    /// The heights h \[m].
    pub fn heights(&self) -> &[f64] {
        self.engine.heights()
    }

    /// Pressure of the last solve \[Pa], row-major (ny, nx); zero after a failed solve.
    pub fn pressure(&self) -> &[f64] {
        self.engine.pressure()
    }

    /// Gap of the last solve \[m]: zero where 0 < p < H (the hardness, if set), positive where
    /// p = 0, and where p = H the penetration of the rigid surface as a negative gap (the
    /// plastic indentation).
    pub fn gap(&self) -> Vec<f64> {
        let mut gap = vec![0.0; self.heights().len()];
        self.gap_into(&mut gap);
        gap
    }

    /// [`gap`](Self::gap) into `out` (ny·nx values), for a caller that asks after every solve.
    pub(crate) fn gap_into(&self, out: &mut [f64]) {
        let (p, u, h) = (self.pressure(), self.engine.displacement(), self.heights());
        gap_of(p, u, h, self.engine.hardness(), out)
    }

    /// Surface displacement u = K p of the last solve \[m]. In the periodic model its mean is
    /// zero: the rigid-body approach is not defined there.
    pub fn displacement(&self) -> Vec<f64> {
        self.engine.displacement().to_vec()
    }

    /// Start the next solve from scratch rather than from the last pressure.
    pub fn reset(&mut self) {
        self.engine.reset()
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
        self.engine.warm_start(pressure)
    }

    /// Cap the pressure at the hardness H \[Pa] in the solves that follow (elastic–perfectly-
    /// plastic contact, 0 ≤ p ≤ H; two FFT pairs per iteration), or lift the cap with `None`.
    pub fn set_hardness(&mut self, hardness: Option<f64>) -> Result<()> {
        if let Some(h) = hardness {
            if !(h > 0.0 && h.is_finite()) {
                return Err(Error::invalid("--hardness", format!("must be positive and finite, got {h} Pa")));
            }
        }
        self.engine.set_hardness(hardness);
        Ok(())
    }

    /// Replace the heights \[m] (row-major (ny, nx)), keeping the operator and the last pressure
    /// as the next solve's start: the adhesive solver's frozen tension shifts them by its
    /// displacement.
    pub(crate) fn set_heights(&mut self, heights: &[f64]) -> Result<()> {
        check_problem(heights, self.shape(), self.size(), self.engine.e_star())?;
        self.engine.set_heights(heights, rms(heights))
    }

    /// Solve to `tolerance` from the next solve on: the adhesive solver's early steps, far from
    /// their equilibrium, need no more than a rough one.
    pub(crate) fn set_tolerance(&mut self, tolerance: f64) -> Result<()> {
        crate::contact::options::Convergence { tolerance, max_iterations: 1 }.check()?;
        self.engine.set_tolerance(tolerance);
        Ok(())
    }

    /// Let a warm solve start from the last solve's displacement, scaled with its pressure to
    /// the new load, rather than transform the pressure again (one FFT pair less, rounding
    /// aside the same): the adhesive solver's steps change the load and the heights, not the
    /// pressure they start from. Off unless asked, so that a solve without adhesion is the same
    /// to the last bit whoever calls it.
    pub(crate) fn set_rescaled_start(&mut self, on: bool) {
        self.engine.set_rescaled_start(on)
    }

    /// Solve for the normal load `load` \[N]. `progress` is called after every iteration with
    /// the iteration count and the current residual; it answers `()`, or a [`ControlFlow`]
    /// whose `Break` stops the solve with [`Error::Interrupted`] (the next solve then starts
    /// cold).
    pub fn solve<R: Proceed>(&mut self, load: f64, mut progress: impl FnMut(usize, f64) -> R) -> Result<SolveReport> {
        check_load(load, self.size(), self.engine.e_star())?;
        let mut proceed = |it: usize, residual: f64| progress(it, residual).proceed();
        self.engine.solve(load, &mut proceed)
    }
}

/// The RMS of `heights` about their mean \[m].
fn rms(heights: &[f64]) -> f64 {
    let n = heights.len() as f64;
    let mean = heights.iter().sum::<f64>() / n;
    (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt()
}

/// The gap of a solution (see [`ContactSolver::gap`]) from its pressure, displacement and
/// heights, with the cap `hardness` if any, into `out`.
fn gap_of(pressure: &[f64], displacement: &[f64], heights: &[f64], hardness: Option<f64>, out: &mut [f64]) {
    let cap = hardness.unwrap_or(f64::INFINITY);
    let (sum, count) = pressure
        .iter()
        .zip(displacement.iter().zip(heights))
        .filter(|(p, _)| **p > 0.0 && **p < cap)
        .fold((0.0, 0usize), |(s, c), (_, (u, h))| (s + (u - h), c + 1));
    let mean = sum / count.max(1) as f64;
    for (i, g) in out.iter_mut().enumerate() {
        let (p, d) = (pressure[i], displacement[i] - heights[i] - mean);
        *g = if p == 0.0 {
            d.max(0.0)
        } else if p == cap {
            d.min(0.0)
        } else {
            0.0
        };
    }
}
