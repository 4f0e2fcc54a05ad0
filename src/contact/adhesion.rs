//! Adhesive normal contact: a cohesive zone between the rigid rough surface and the elastic
//! half-space, Maugis–Dugdale (a constant tension σ₀ while the gap is below h₀ = w/σ₀) or
//! exponential (a tension (w/ρ)·e^(−g/ρ)), each of work of adhesion w.
//!
//! Algorithm: the projected conjugate gradient on the gap of Rey, Anciaux & Molinari (Comput.
//! Mech. 60, 2017, 69–81), as Tamaas solves adhesion. The unknown is the displacement field
//! (the gap on the window); the energy is the elastic energy plus the cohesive potential Σφ(g)
//! (φ' the tension, φ(0) = −w), minimised with the gap g ≥ 0. Its gradient at a point is the
//! traction residual σ + t(g) (σ the traction, compressive positive; t the cohesive tension),
//! which the iteration drives to zero where the surfaces are apart and keeps non-negative where
//! they touch: Polonsky & Keer's scheme with gap and pressure exchanged. Why the gap: the
//! cohesive law is a function of the gap, so it enters each iteration exactly (on the pressure,
//! updated every iteration, it would lag one behind, a fixed point that holds only while the
//! cohesive stiffness stays below the elastic one, the DMT side; load control freezes it for
//! whole solves instead, which always descends). Without adhesion the energy is convex
//! and the scheme is Polonsky & Keer's, which converges; with it the energy is convex plus a
//! concave cohesive term, and what the iteration reaches is an equilibrium connected to its
//! starting state: the solver therefore keeps its state between solves (load and separation
//! sweeps follow one branch, as a loaded and unloaded ball does).
//!
//! Both boundaries use the half-space operator of [`Influence`] inverted on its FFT grid
//! (traction from displacement): periodic, the window's grid, E*|q|/2, the mean gap (the
//! *separation*) imposed as a constraint as Tamaas does; free, the zero-padded (2ny, 2nx)
//! grid, whose circulant Love kernel is positive definite, the displacement of the padding free
//! (its traction driven to zero) and the rigid body's position (the separation, zero when the
//! highest point just touches) imposed.
//!
//! This iteration solves at imposed separation. Load control (in `search`) is the
//! difference-of-convex algorithm on the same energy: each step freezes the cohesive tension
//! of the last gap and solves the contact without adhesion that is left, by Polonsky & Keer's
//! conjugate gradient on the pressure with the load imposed inside it, on the window's points
//! only; a few steps, each from the last pressure, reach the equilibrium. Why not this
//! iteration with the separation searched for the load: each trial separation is a solve, and
//! the free boundary's unknowns fill the padded grid, four times the window (at 512², 3 mN it
//! cost 55 times the solve without adhesion; load control costs about twice). The pull-off
//! force, the most tensile load with an equilibrium, is passed by the separation, not the
//! load: [`AdhesiveSolver::pull_off`] sweeps the separation from the equilibrium at zero load
//! with this iteration, refining around the least load found. A cold solve of a compressive
//! load starts from the equilibrium without adhesion at that load; one of a zero or tensile
//! load from one pressed harder, and unloads. Where the discrete problem has several
//! equilibria at one load (a Maugis–Dugdale zone of a few pixels, whose edge the grid pins),
//! the one reached depends on that start.
//!
//! One iteration applies the inverse operator once (to the search direction) and once more
//! when the projection moved points (the change's traction); the traction is carried along
//! and recomputed from scratch before convergence is accepted. Sums are taken per grid row and
//! added in row order, so results do not depend on the number of threads.
//!
//! The cohesive laws are in `law`, load control and the pull-off search in `search`; here the
//! solver's state and its iteration at imposed separation.
//!
//! Imports `influence` and `options` inside `contact` (and `search` the solver without
//! adhesion); must not import friction, study, report, plot, shs, cli.

use std::time::Instant;

use rayon::prelude::*;
use rustfft::num_complex::Complex64;

use super::influence::{Boundary, Influence};
use super::options::{check_problem, Convergence, Iterations, STALL};
use crate::error::{Error, Result};
use crate::fft::{Fft2, Fft2Work};
use crate::limits::{check_memory, grid_memory};

mod law;
mod search;

pub use law::CohesiveLaw;

/// What an adhesive solve reports besides its fields.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct AdhesiveReport {
    /// Normal load N = N_c − N_a \[N] (compressive positive).
    pub load: f64,
    /// Compressive force N_c: the integral of the compressive pressure
    /// ([`AdhesiveSolver::compressive_pressure`]) \[N].
    pub compressive_force: f64,
    /// Adhesive force N_a = N_c − N: the integral of the tension, as a positive number \[N].
    pub adhesive_force: f64,
    /// Separation \[m]: the mean gap (periodic) or the rigid body's position from first touch
    /// of its highest point, negative when pressed in (free boundary).
    pub separation: f64,
    /// Points in contact (gap zero).
    pub contact_points: usize,
    /// Conjugate-gradient iterations, over all the solves.
    pub iterations: usize,
    /// Solves: one at imposed separation; under load control, the steps of the
    /// difference-of-convex algorithm, each a solve without adhesion (and, where the contact
    /// opened, the pull-off sweep's solves at imposed separation).
    pub solves: usize,
    /// Residual: the traction residual σ + t(g) where the surfaces are apart, in L2 norm,
    /// relative to the traction's plus √n times the larger of the cohesive strength and the
    /// sought load's mean pressure (n the window's points).
    pub residual: f64,
    /// Wall-clock time \[s].
    pub seconds: f64,
}

/// The pull-off force and where it is reached.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PullOff {
    /// The most tensile load with an equilibrium \[N] (negative).
    pub load: f64,
    /// The separation at which it is reached \[m].
    pub separation: f64,
    /// Points in contact there.
    pub contact_points: usize,
    /// Solves at imposed separation the sweep took.
    pub solves: usize,
}

/// Partial sums kept per grid row.
const SUMS: usize = 4;

/// Bytes per grid point of an adhesive solve: nine fields of f64 (with the operator's two
/// kernels) and the spectrum.
const BYTES_PER_POINT: u64 = 9 * 8 + 16;

/// The memory of an adhesive solve on an ny × nx surface \[bytes].
pub fn solve_memory((ny, nx): (usize, usize), boundary: Boundary) -> u64 {
    let padding = if boundary == Boundary::Free { 4 } else { 1 };
    grid_memory(nx, ny, BYTES_PER_POINT * padding)
}

/// Adhesive normal contact of one surface, solved for one load (or separation) after another;
/// each solve starts from the last one's state.
pub struct AdhesiveSolver {
    ny: usize,
    nx: usize,
    size: (f64, f64),
    /// Effective modulus E* \[Pa].
    e_star: f64,
    boundary: Boundary,
    law: CohesiveLaw,
    convergence: Convergence,
    /// FFT grid (gy, gx): the window's (periodic) or the padded one (free).
    gy: usize,
    gx: usize,
    fft_plan: Influence,
    /// Inverse operator (traction from displacement) in the spectrum layout, normalisation
    /// folded in.
    stiffness: Vec<f64>,
    /// Heights h on the grid \[m]: periodic as given, free less the highest (≤ 0, zero in the
    /// padding).
    heights: Vec<f64>,
    /// Mean gap of the undeformed surface touching at its highest point (periodic) \[m].
    touching: f64,
    /// Primal field x on the grid \[m]: the gap (periodic) or the displacement (free).
    x: Vec<f64>,
    /// M x: the traction of x \[Pa] (periodic: without M h and the mean traction).
    mx: Vec<f64>,
    /// M h (periodic) \[Pa]; empty for the free boundary.
    mh: Vec<f64>,
    /// Search direction t \[m] and its traction M t \[Pa] (this and the next three fields are
    /// made by the first solve at imposed separation).
    direction: Vec<f64>,
    m_direction: Vec<f64>,
    /// The projection's changes to x \[m].
    change: Vec<f64>,
    /// The cohesive tension t(g) \[Pa] at each window point of the iterate (zero outside):
    /// evaluated once per iteration, read by every pass over the residual.
    cohesive: Vec<f64>,
    row_sums: Vec<[f64; SUMS]>,
    /// The mean traction (periodic: the multiplier of the imposed mean gap) \[Pa].
    mean_traction: f64,
    /// The mean pressure of the load sought \[Pa] (zero at imposed separation): with the
    /// cohesive strength, the traction scale below which the residual is not resolved.
    pressure_scale: f64,
    separation: f64,
    /// Whether x holds an equilibrium at `separation` (a warm start).
    warm: bool,
    /// Load control's state (see `search`), made on the first load-controlled solve.
    frozen: Option<search::Frozen>,
}

impl AdhesiveSolver {
    /// Set up the problem for `heights` \[m] (row-major, ny × nx) on a window of physical size
    /// (lx, ly) \[m], effective modulus E* \[Pa], the boundary, the cohesive law and the
    /// convergence of each solve at imposed separation.
    pub fn new(
        heights: &[f64],
        (ny, nx): (usize, usize),
        (lx, ly): (f64, f64),
        e_star: f64,
        boundary: Boundary,
        law: CohesiveLaw,
        convergence: Convergence,
    ) -> Result<Self> {
        check_problem(heights, (ny, nx), (lx, ly), e_star)?;
        match law {
            CohesiveLaw::Maugis { work, stress } => CohesiveLaw::maugis(work, stress)?,
            CohesiveLaw::Exponential { work, range } => CohesiveLaw::exponential(work, range)?,
        };
        convergence.check()?;
        check_memory(solve_memory((ny, nx), boundary), &format!("an adhesive contact solve on {nx} × {ny} points"))
            .map_err(|r| Error::invalid("surface", r))?;
        let op = match boundary {
            Boundary::Periodic => Influence::periodic(ny, nx, (lx, ly), e_star),
            Boundary::Free => Influence::free(ny, nx, (lx, ly), e_star),
        };
        let (gy, gx) = op.fft().shape();
        let norm = 1.0 / (gy * gx) as f64;
        let mut op = op;
        let stiffness = {
            let (_, kernel, _, _) = op.parts();
            kernel.iter().map(|k| if *k > 0.0 { norm * norm / k } else { 0.0 }).collect()
        };
        let top = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut grid = vec![0.0; gy * gx];
        for y in 0..ny {
            for x in 0..nx {
                let h = heights[y * nx + x];
                grid[y * gx + x] = if boundary == Boundary::Free { h - top } else { h };
            }
        }
        let touching = heights.iter().map(|h| top - h).sum::<f64>() / (ny * nx) as f64;
        let mut solver = AdhesiveSolver {
            ny,
            nx,
            size: (lx, ly),
            e_star,
            boundary,
            law,
            convergence,
            gy,
            gx,
            fft_plan: op,
            stiffness,
            heights: grid,
            touching,
            x: vec![0.0; gy * gx],
            mx: vec![0.0; gy * gx],
            mh: Vec::new(),
            direction: Vec::new(),
            m_direction: Vec::new(),
            change: Vec::new(),
            cohesive: Vec::new(),
            row_sums: vec![[0.0; SUMS]; gy],
            mean_traction: 0.0,
            pressure_scale: 0.0,
            separation: 0.0,
            warm: false,
            frozen: None,
        };
        if boundary == Boundary::Periodic {
            let mut mh = vec![0.0; gy * gx];
            let h = std::mem::take(&mut solver.heights);
            solver.apply(&h, &mut mh);
            (solver.heights, solver.mh) = (h, mh);
        }
        Ok(solver)
    }

    /// Grid shape (ny, nx).
    pub fn shape(&self) -> (usize, usize) {
        (self.ny, self.nx)
    }

    /// The cohesive law.
    pub fn law(&self) -> CohesiveLaw {
        self.law
    }

    /// Start the next solve from scratch rather than from the last state.
    pub fn reset(&mut self) {
        self.lose_state();
    }

    /// Start the next solve from the gap map `gap` \[m] (row-major (ny, nx), each ≥ 0) of a
    /// state at separation `separation` \[m], as from a saved solve (the displacement of the
    /// free boundary's padding starts at zero).
    pub fn warm_start(&mut self, gap: &[f64], separation: f64) -> Result<()> {
        let (ny, nx) = (self.ny, self.nx);
        if gap.len() != ny * nx {
            return Err(Error::invalid("warm start", format!("{} gaps for a {ny}×{nx} grid", gap.len())));
        }
        if let Some(i) = gap.iter().position(|g| !(g.is_finite() && *g >= 0.0)) {
            return Err(Error::invalid("warm start", format!("gap {} m at point {i}", gap[i])));
        }
        if !separation.is_finite() {
            return Err(Error::invalid("warm start", format!("separation {separation} m")));
        }
        self.lose_state();
        self.separation = separation;
        self.x.iter_mut().for_each(|v| *v = 0.0);
        for y in 0..ny {
            for x in 0..nx {
                let i = y * self.gx + x;
                self.x[i] = self.floor_at(i) + gap[y * nx + x];
            }
        }
        self.refresh_traction();
        self.warm = true;
        Ok(())
    }

    /// Whether grid point `i` lies in the window.
    #[inline]
    fn in_window(&self, i: usize) -> bool {
        self.boundary == Boundary::Periodic || (i / self.gx < self.ny && i % self.gx < self.nx)
    }

    /// Traction \[Pa] on the window (row-major (ny, nx)), compressive positive.
    pub fn traction(&self) -> Vec<f64> {
        self.window_map(|s, i| s.traction_at(i))
    }

    /// The largest cohesive tension on the free window's outermost rows and columns, as a
    /// fraction of the law's strength (zero on a periodic window, which has no edge): where it
    /// is not small the cohesive zone reaches the edge, and the window cuts off part of the
    /// adhesive force.
    pub fn edge_tension(&self) -> f64 {
        if self.boundary == Boundary::Periodic {
            return 0.0;
        }
        let (ny, nx, gx) = (self.ny, self.nx, self.gx);
        let edge = (0..nx).flat_map(|x| [x, (ny - 1) * gx + x]).chain((0..ny).flat_map(|y| [y * gx, y * gx + nx - 1]));
        edge.map(|i| (-self.traction_at(i)).max(0.0)).fold(0.0, f64::max) / self.law.strength()
    }

    /// The compressive part max(σ, 0) of the traction \[Pa] on the window: the pressure that
    /// carries friction (the cohesive tension outside the contact carries none).
    pub fn compressive_pressure(&self) -> Vec<f64> {
        self.window_map(|s, i| s.compressive_at(i))
    }

    /// max(σ, 0) at window point `i` where the surfaces touch, zero where they are apart: there
    /// the traction is the cohesive tension, and a positive value is the residual's.
    #[inline]
    fn compressive_at(&self, i: usize) -> f64 {
        if self.gap_at(i, self.x[i]) <= 0.0 {
            self.traction_at(i).max(0.0)
        } else {
            0.0
        }
    }

    /// Gap \[m] on the window (row-major (ny, nx)): zero in contact.
    pub fn gap(&self) -> Vec<f64> {
        self.window_map(|s, i| s.gap_at(i, s.x[i]))
    }

    /// Surface displacement \[m] on the window (row-major (ny, nx)), into the body positive:
    /// periodic, with zero mean (the mean is not defined there); free, that of the half-space.
    pub fn displacement(&self) -> Vec<f64> {
        match self.boundary {
            Boundary::Free => self.window_map(|s, i| s.x[i]),
            Boundary::Periodic => {
                let u = self.window_map(|s, i| s.x[i] + s.heights[i]);
                let mean = u.iter().sum::<f64>() / u.len() as f64;
                u.iter().map(|u| u - mean).collect()
            }
        }
    }

    fn window_map(&self, f: impl Fn(&Self, usize) -> f64) -> Vec<f64> {
        (0..self.ny).flat_map(|y| (0..self.nx).map(move |x| (y, x))).map(|(y, x)| f(self, y * self.gx + x)).collect()
    }

    #[inline]
    fn traction_at(&self, i: usize) -> f64 {
        match self.boundary {
            Boundary::Periodic => self.mx[i] + self.mh[i] + self.mean_traction,
            Boundary::Free => self.mx[i],
        }
    }

    /// The gap at grid point `i` of the window if x there were `x`.
    #[inline]
    fn gap_at(&self, i: usize, x: f64) -> f64 {
        match self.boundary {
            Boundary::Periodic => x,
            Boundary::Free => x - (self.heights[i] - self.separation),
        }
    }

    /// The lowest x at window point `i`: zero gap.
    #[inline]
    fn floor_at(&self, i: usize) -> f64 {
        match self.boundary {
            Boundary::Periodic => 0.0,
            Boundary::Free => self.heights[i] - self.separation,
        }
    }

    /// out = M v on the grid (one FFT pair).
    fn apply(&mut self, v: &[f64], out: &mut [f64]) {
        let (gy, gx) = (self.gy, self.gx);
        let stiffness = &self.stiffness;
        let (fft, _, spectrum, work): (&Fft2, _, &mut Vec<Complex64>, &mut Fft2Work) = self.fft_plan.parts();
        fft.forward(v, gy, gx, spectrum, work);
        spectrum.par_iter_mut().zip(stiffness.par_iter()).for_each(|(s, k)| *s *= *k);
        fft.inverse(spectrum, out, gy, gx, work);
    }

    /// Recompute M x from scratch.
    fn refresh_traction(&mut self) {
        let x = std::mem::take(&mut self.x);
        let mut mx = std::mem::take(&mut self.mx);
        self.apply(&x, &mut mx);
        (self.x, self.mx) = (x, mx);
    }

    /// Per-row sums of `f(i)` over the grid, added in row order.
    fn sum_rows(&mut self, f: impl Fn(&Self, usize) -> [f64; SUMS] + Sync) -> [f64; SUMS] {
        let gx = self.gx;
        let mut sums = std::mem::take(&mut self.row_sums);
        let this = &*self;
        sums.par_iter_mut().enumerate().for_each(|(y, s)| {
            *s = (y * gx..(y + 1) * gx).fold([0.0; SUMS], |mut a, i| {
                a.iter_mut().zip(f(this, i)).for_each(|(a, v)| *a += v);
                a
            });
        });
        let total = sums.iter().fold([0.0; SUMS], |mut a, s| {
            a.iter_mut().zip(s).for_each(|(a, v)| *a += v);
            a
        });
        self.row_sums = sums;
        total
    }

    /// Residual r = σ + t(g) at grid point `i` (t only on the window, as last evaluated by
    /// [`evaluate_cohesion`](Self::evaluate_cohesion)), and whether the point is free to move:
    /// apart (g > 0), outside the window, or in contact with r < 0 (pulled open).
    #[inline]
    fn residual_at(&self, i: usize) -> (f64, bool) {
        let sigma = self.traction_at(i);
        if !self.in_window(i) {
            return (sigma, true);
        }
        let g = self.gap_at(i, self.x[i]);
        let r = sigma + self.cohesive[i];
        (r, g > 0.0 || r < 0.0)
    }

    /// v ← f(self, i, v) at every grid point i of the field `field` picks, rows in parallel
    /// (`f` must not read that field: it is taken out meanwhile).
    fn update(&mut self, field: fn(&mut Self) -> &mut Vec<f64>, f: impl Fn(&Self, usize, f64) -> f64 + Sync) {
        let gx = self.gx;
        let mut values = std::mem::take(field(self));
        let this = &*self;
        values.par_chunks_mut(gx).enumerate().for_each(|(y, row)| {
            for (j, v) in row.iter_mut().enumerate() {
                *v = f(this, y * gx + j, *v);
            }
        });
        *field(self) = values;
    }

    /// The cohesive tension of the current iterate at every window point.
    fn evaluate_cohesion(&mut self) {
        self.update(
            |s| &mut s.cohesive,
            |s, i, _| if s.in_window(i) { s.law.tension(s.gap_at(i, s.x[i]).max(0.0)) } else { 0.0 },
        );
    }

    /// Take the equilibrium load control reached: its traction σ \[Pa] and gap \[m] on the
    /// window, at the load `load` \[N]. Periodic: x is the gap, its mean the separation. Free:
    /// x is the displacement of the traction on the whole padded grid, and the separation the
    /// mean of h − u over the points in contact; there x is the floor, so that the gap is zero
    /// to the last bit.
    fn adopt(&mut self, traction: &[f64], gap: &[f64], load: f64) {
        let (ny, nx, gx) = (self.ny, self.nx, self.gx);
        let mut grid = std::mem::take(&mut self.mx);
        grid.iter_mut().for_each(|v| *v = 0.0);
        for y in 0..ny {
            grid[y * gx..y * gx + nx].copy_from_slice(&traction[y * nx..(y + 1) * nx]);
        }
        match self.boundary {
            Boundary::Periodic => {
                self.x.copy_from_slice(gap);
                self.separation = gap.iter().sum::<f64>() / gap.len() as f64;
                self.mean_traction = load / (self.size.0 * self.size.1);
                // σ = M(g + h) + the mean traction.
                grid.iter_mut().zip(&self.mh).for_each(|(m, mh)| *m -= mh + self.mean_traction);
            }
            Boundary::Free => {
                let mut u = std::mem::take(&mut self.x);
                self.displace(&grid, &mut u);
                let (sum, count) = (0..ny * nx)
                    .filter(|&k| gap[k] <= 0.0)
                    .map(|k| (k / nx) * gx + k % nx)
                    .fold((0.0, 0usize), |(sum, count), i| (sum + self.heights[i] - u[i], count + 1));
                self.separation = sum / count.max(1) as f64;
                for y in 0..ny {
                    for x in 0..nx {
                        let i = y * gx + x;
                        u[i] = self.heights[i] - self.separation + gap[y * nx + x];
                    }
                }
                self.x = u;
            }
        }
        self.mx = grid;
        self.warm = true;
    }

    /// out = G v on the grid: the displacement of the traction v (one FFT pair).
    fn displace(&mut self, v: &[f64], out: &mut [f64]) {
        let (gy, gx) = (self.gy, self.gx);
        let (fft, kernel, spectrum, work) = self.fft_plan.parts();
        fft.forward(v, gy, gx, spectrum, work);
        spectrum.par_iter_mut().zip(kernel.par_iter()).for_each(|(s, k)| *s *= *k);
        fft.inverse(spectrum, out, gy, gx, work);
    }

    /// Make x admissible at the current separation: gap ≥ 0 on the window, and the mean gap
    /// imposed (periodic).
    fn admit(&mut self) {
        self.update(|s| &mut s.x, |s, i, v| if s.in_window(i) { v.max(s.floor_at(i)) } else { v });
        if self.boundary == Boundary::Periodic {
            self.impose_mean_gap();
        }
    }

    /// Scale the gap (≥ 0) to the imposed mean (periodic); the traction M x scales with it.
    fn impose_mean_gap(&mut self) {
        let n = (self.gy * self.gx) as f64;
        let mean = self.sum_rows(|s, i| [s.x[i], 0.0, 0.0, 0.0])[0] / n;
        if mean > 0.0 {
            let k = self.separation / mean;
            self.x.par_iter_mut().for_each(|v| *v *= k);
            self.mx.par_iter_mut().for_each(|v| *v *= k);
        } else {
            self.x.par_iter_mut().for_each(|v| *v = self.separation);
            self.mx.par_iter_mut().for_each(|v| *v = 0.0);
        }
    }

    /// A cold state at separation `s`: the undeformed surface, pressed through where it would
    /// penetrate (free), or its gap scaled to the mean `s` (periodic).
    fn cold_start(&mut self, s: f64) {
        self.separation = s;
        match self.boundary {
            Boundary::Free => self.x.iter_mut().for_each(|v| *v = 0.0),
            Boundary::Periodic => {
                let top = self.heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let extra = (s - self.touching).max(0.0);
                let h = &self.heights;
                self.x.iter_mut().zip(h).for_each(|(v, h)| *v = top - h + extra);
            }
        }
        self.admit();
        self.refresh_traction();
        self.warm = true;
    }

    /// Solve at imposed separation `s` \[m] (see [`AdhesiveReport::separation`]; periodic: the
    /// mean gap, positive), from the last state.
    pub fn solve_separation(&mut self, s: f64) -> Result<AdhesiveReport> {
        self.pressure_scale = 0.0;
        self.at_separation(s)
    }

    /// [`solve_separation`](Self::solve_separation) with the residual's scale as set.
    fn at_separation(&mut self, s: f64) -> Result<AdhesiveReport> {
        let start = Instant::now();
        if !s.is_finite() || (self.boundary == Boundary::Periodic && s <= 0.0) {
            let periodic = if self.boundary == Boundary::Periodic { " and positive (the mean gap)" } else { "" };
            return Err(Error::invalid("separation", format!("must be finite{periodic}, got {s} m")));
        }
        let (iterations, residual) = self.relax(s)?;
        Ok(AdhesiveReport { iterations, solves: 1, residual, seconds: start.elapsed().as_secs_f64(), ..self.forces() })
    }

    /// The forces of the current state, with the separation and the contact points.
    fn forces(&mut self) -> AdhesiveReport {
        let area = self.size.0 * self.size.1 / (self.ny * self.nx) as f64;
        // The adhesive force sums each point's tension: never negative, and zero where the
        // surfaces are apart beyond the law's reach. There the traction is zero only to its
        // rounding (of the periodic M x + M h), which a difference of the sums would keep.
        let [load, compressive, contact, adhesive] = self.sum_rows(|s, i| {
            if !s.in_window(i) {
                return [0.0; SUMS];
            }
            let gap = s.gap_at(i, s.x[i]);
            let (traction, compressive) = (s.traction_at(i), s.compressive_at(i));
            let tension = if gap > 0.0 && s.law.tension(gap) == 0.0 { 0.0 } else { (compressive - traction).max(0.0) };
            [traction, compressive, if gap <= 0.0 { 1.0 } else { 0.0 }, tension]
        });
        AdhesiveReport {
            load: load * area,
            compressive_force: compressive * area,
            adhesive_force: adhesive * area,
            separation: self.separation,
            contact_points: contact as usize,
            iterations: 0,
            solves: 0,
            residual: 0.0,
            seconds: 0.0,
        }
    }

    /// The projected conjugate gradient at separation `s`: (iterations, residual).
    fn relax(&mut self, s: f64) -> Result<(usize, f64)> {
        // Its fields, made on first use: load control from an equilibrium without adhesion
        // (a study's solves) never needs them.
        let n = self.gy * self.gx;
        for field in [&mut self.direction, &mut self.m_direction, &mut self.change, &mut self.cohesive] {
            if field.len() != n {
                *field = vec![0.0; n];
            }
        }
        if !self.warm {
            self.cold_start(s);
        } else {
            self.separation = s;
            self.admit();
            self.refresh_traction();
        }
        // A failed solve is no warm start, and load control's state is no longer this one.
        self.lose_state();
        let periodic = self.boundary == Boundary::Periodic;
        let n_window = (self.ny * self.nx) as f64;
        let floor = self.law.strength().max(self.pressure_scale) * n_window.sqrt();
        let mut counter = Iterations::new("adhesive contact solver", self.convergence, STALL);
        let mut previous = f64::NAN;
        let mut fresh = true;
        loop {
            self.evaluate_cohesion();
            // The mean traction: the mean of −(M(g + h) + t) over the points apart (periodic).
            let mean = if periodic {
                let [sum, count, _, _] = self.sum_rows(|s, i| {
                    let g = s.x[i];
                    if g > 0.0 {
                        [-(s.mx[i] + s.mh[i] + s.cohesive[i]), 1.0, 0.0, 0.0]
                    } else {
                        [0.0; SUMS]
                    }
                });
                if count > 0.0 {
                    sum / count
                } else {
                    0.0
                }
            } else {
                0.0
            };
            self.mean_traction = mean;
            let [norm, opening, traction, _] = self.sum_rows(|s, i| {
                let (r, free) = s.residual_at(i);
                let sigma = if s.in_window(i) { s.traction_at(i) } else { 0.0 };
                let open = free && s.in_window(i) && s.gap_at(i, s.x[i]) <= 0.0;
                [if free { r * r } else { 0.0 }, if open { 1.0 } else { 0.0 }, sigma * sigma, 0.0]
            });
            let residual = norm.sqrt() / (traction.sqrt() + floor);
            if residual <= self.convergence.tolerance {
                if fresh {
                    self.warm = true;
                    return Ok((counter.done(), residual));
                }
                // Accept only on a traction recomputed from scratch.
                self.refresh_traction();
                fresh = true;
                counter.forget_best();
                continue;
            }
            let restart = counter.next(residual)?;
            if restart {
                self.refresh_traction();
                previous = f64::NAN;
                continue;
            }
            fresh = false;
            // Conjugation (Fletcher–Reeves), restarted when points were pulled open.
            let beta = if opening > 0.0 || previous.is_nan() { 0.0 } else { norm / previous };
            previous = norm;
            self.update_direction(|r, t| r + beta * t);
            if periodic {
                // The direction keeps the mean gap: its mean over the free points removed.
                let [sum, count, _, _] =
                    self.sum_rows(
                        |s, i| {
                            if s.residual_at(i).1 {
                                [s.direction[i], 1.0, 0.0, 0.0]
                            } else {
                                [0.0; SUMS]
                            }
                        },
                    );
                let shift = if count > 0.0 { sum / count } else { 0.0 };
                self.update_direction(|_, t| t - shift);
            }
            let t = std::mem::take(&mut self.direction);
            let mut mt = std::mem::take(&mut self.m_direction);
            self.apply(&t, &mut mt);
            (self.direction, self.m_direction) = (t, mt);
            let [along, curvature, _, _] = self.sum_rows(|s, i| {
                let t = s.direction[i];
                if t == 0.0 {
                    return [0.0; SUMS];
                }
                [s.residual_at(i).0 * t, t * s.m_direction[i], 0.0, 0.0]
            });
            if !(curvature > 0.0) {
                // A direction the elastic energy does not see (nothing left to move).
                self.refresh_traction();
                previous = f64::NAN;
                continue;
            }
            if self.step(along / curvature) {
                // The traction of the projection's change D; M t is no longer needed.
                let change = std::mem::take(&mut self.change);
                let mut md = std::mem::take(&mut self.m_direction);
                self.apply(&change, &mut md);
                self.mx.par_iter_mut().zip(md.par_iter()).for_each(|(m, d)| *m += d);
                (self.change, self.m_direction) = (change, md);
            }
            if periodic {
                self.impose_mean_gap();
            }
        }
    }

    /// t ← f(r, t) at the free points (r the residual), 0 elsewhere.
    fn update_direction(&mut self, f: impl Fn(f64, f64) -> f64 + Sync) {
        self.update(
            |s| &mut s.direction,
            |s, i, t| {
                let (r, free) = s.residual_at(i);
                if free {
                    f(r, t)
                } else {
                    0.0
                }
            },
        );
    }

    /// x ← max(x − τt, floor), M x ← M x − τ M t; the clipped part goes to `change`. Returns
    /// whether anything was clipped (M x then misses M·change).
    fn step(&mut self, step: f64) -> bool {
        let gx = self.gx;
        let mut x = std::mem::take(&mut self.x);
        let mut change = std::mem::take(&mut self.change);
        let mut sums = std::mem::take(&mut self.row_sums);
        {
            let this = &*self;
            x.par_chunks_mut(gx).zip(change.par_chunks_mut(gx)).zip(sums.par_iter_mut()).enumerate().for_each(
                |(y, ((xs, ds), sum))| {
                    let mut count = 0.0;
                    for (j, (x, d)) in xs.iter_mut().zip(ds.iter_mut()).enumerate() {
                        let i = y * gx + j;
                        let moved = *x - step * this.direction[i];
                        (*x, *d) = (moved, 0.0);
                        if this.in_window(i) {
                            let floor = this.floor_at(i);
                            if moved < floor {
                                (*x, *d) = (floor, floor - moved);
                                count += 1.0;
                            }
                        }
                    }
                    sum[0] = count;
                },
            );
        }
        let clipped = sums.iter().any(|s| s[0] > 0.0);
        (self.x, self.change, self.row_sums) = (x, change, sums);
        let (mt, mx) = (&self.m_direction, &mut self.mx);
        mx.par_iter_mut().zip(mt.par_iter()).for_each(|(m, t)| *m -= step * t);
        clipped
    }
}
