//! The CPU engine of the normal solve (the problem and its residual: see [`super::solver`]).
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
//!
//! The iteration is in `elastic`, its capped variant in `saturated`; here the engine's state
//! and its dispatch between them.
//!
//! Imports `options` and `influence` inside `contact`, never `solver`, `gpu` or the other solves;
//! must not import friction, study, report, plot, shs, cli.

use rustfft::num_complex::Complex64;

use super::influence::{Boundary, Influence};
use super::options::{Engine, SolveReport, SolverOptions};
use crate::error::{Error, Result};
use crate::fft::large_buffer;

mod elastic;
mod saturated;

/// Partial sums kept per grid row.
const SUMS: usize = 10;

/// Up to this many grid rows with changes, their transform is summed directly inside the
/// column passes (a few axpys per spectrum row) rather than computed by FFT.
const DIRECT_ROWS: usize = 8;

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

/// The CPU engine of [`super::ContactSolver`].
pub(super) struct CpuSolver {
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
    /// Whether the displacement is K p of the stored pressure, as an exact check left it at the
    /// end of a solve, and whether a warm solve may start from it, scaled to its load.
    displaced: bool,
    rescaled_start: bool,
    /// The cap on the pressure (elastic–perfectly-plastic contact) [Pa], if any.
    hardness: Option<f64>,
}

impl CpuSolver {
    /// The problem [`super::ContactSolver::new`] has checked, with the RMS height `h_rms` [m].
    pub(super) fn new(
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
        let flat_spread = flat_spread(heights, (ny, nx), (lx, ly), e_star);
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
            displaced: false,
            rescaled_start: false,
            hardness: None,
        })
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

    /// The error of a solve stopped by its caller.
    fn interrupted(load: f64) -> Error {
        Error::Interrupted { what: format!("contact solve at {load} N") }
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
}

impl Engine for CpuSolver {
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
        self.displaced = false;
    }

    fn warm_start(&mut self, pressure: &[f64]) -> Result<()> {
        self.pressure_field.copy_from_slice(pressure);
        self.adopt_pressure_field();
        self.warm = true;
        self.displaced = false;
        Ok(())
    }

    fn set_hardness(&mut self, hardness: Option<f64>) {
        self.hardness = hardness;
    }

    fn set_tolerance(&mut self, tolerance: f64) {
        self.options.convergence.tolerance = tolerance;
    }

    fn set_rescaled_start(&mut self, on: bool) {
        self.rescaled_start = on;
    }

    fn set_heights(&mut self, heights: &[f64], h_rms: f64) -> Result<()> {
        self.heights.copy_from_slice(heights);
        self.h_rms = h_rms;
        self.flat_spread = flat_spread(heights, (self.ny, self.nx), self.size, self.e_star);
        Ok(())
    }

    fn solve(&mut self, load: f64, proceed: &mut dyn FnMut(usize, f64) -> bool) -> Result<SolveReport> {
        // The dense pressure is rebuilt at the end: the iteration needs only the contact set.
        self.pressure_field = Vec::new();
        // Whether the start may scale the displacement: only the elastic iteration asks.
        let displaced = std::mem::take(&mut self.displaced) && self.rescaled_start;
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
            _ => self.solve_elastic(load, displaced, proceed),
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
}

/// The bound `flat_spread` of [`CpuSolver`] for `heights` [m].
fn flat_spread(heights: &[f64], (ny, nx): (usize, usize), (lx, ly): (f64, f64), e_star: f64) -> f64 {
    // |F⁻¹[|q| ĥ]| ≤ q_max Σ|ĥ(q)|/n ≤ q_max √n h_rms (Parseval), and h_rms ≤ max − min.
    let q_max = std::f64::consts::PI * ((nx as f64 / lx).powi(2) + (ny as f64 / ly).powi(2)).sqrt();
    0.5 * e_star * q_max * ((ny * nx) as f64).sqrt() * height_range(heights)
}

/// The range of `heights`, max − min [m].
fn height_range(heights: &[f64]) -> f64 {
    let (low, high) = heights.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &z| (l.min(z), h.max(z)));
    high - low
}

/// Sum per-row partial sums in row order (deterministic).
fn sum_rows<const K: usize>(rows: &[[f64; K]]) -> [f64; K] {
    rows.iter().fold([0.0; K], |mut a, b| {
        a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        a
    })
}
