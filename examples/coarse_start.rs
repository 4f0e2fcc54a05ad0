//! Does a coarse-grid start lower the cost of a cold contact solve? The measurement behind
//! the solver's cold start from a uniform pressure: the iterations a coarse start saves on the
//! fine grid are spent on the coarse one, so the solver does not start from one.
//!
//! For a periodic surface saved as `.npy` (square, even side, heights in metres, the paper's
//! 31.13 µm window) and a load [N], each round solves it three ways, interleaved so that the
//! shared machine's drift falls on all three: `cold` (uniform start), `coarse` (the solve on
//! the half-resolution grid, heights averaged over 2×2 pixels, its pressure interpolated
//! bilinearly and periodically, rescaled to the load by the solver, as warm start) and `multi`
//! (the same, recursively down to 128²). It prints the total wall and CPU time and per level the
//! iterations, FFT pairs and the solver's seconds, the work in FFT pairs of the fine grid, and the converged maps' relative L2 difference to the
//! cold one. `cargo run --release --example coarse_start -- SURFACE.npy LOAD ROUNDS`

use std::time::Instant;

use asperity::contact::{Boundary, ContactSolver, Material, SolverOptions};

const SIZE: f64 = 31.13e-6;

/// The heights averaged over 2×2 pixels: (n/2)².
fn coarsen(h: &[f64], n: usize) -> Vec<f64> {
    let m = n / 2;
    let at = |y: usize, x: usize| h[y * n + x];
    (0..m * m)
        .map(|k| {
            let (y, x) = (2 * (k / m), 2 * (k % m));
            0.25 * (at(y, x) + at(y, x + 1) + at(y + 1, x) + at(y + 1, x + 1))
        })
        .collect()
}

/// The coarse pressure (m², pixel I centred on fine coordinate 2I + 1/2) interpolated
/// bilinearly and periodically onto the fine grid (n = 2m).
fn refine(p: &[f64], m: usize) -> Vec<f64> {
    let n = 2 * m;
    let weights = |x: usize| {
        let c = (x as f64 - 0.5) / 2.0;
        let f = c.floor();
        let i = (f as i64).rem_euclid(m as i64) as usize;
        (i, (i + 1) % m, c - f)
    };
    let mut out = vec![0.0; n * n];
    for y in 0..n {
        let (a, b, wy) = weights(y);
        for x in 0..n {
            let (c, d, wx) = weights(x);
            out[y * n + x] = (1.0 - wy) * ((1.0 - wx) * p[a * m + c] + wx * p[a * m + d])
                + wy * ((1.0 - wx) * p[b * m + c] + wx * p[b * m + d]);
        }
    }
    out
}

/// One level's solve: grid side, iterations, FFT pairs, solver seconds.
type Level = (usize, usize, f64, f64);

/// Solve on the n² grid, started from `levels` coarser solves (down to 128²). Returns the
/// pressure and, per level, (grid, iterations, FFT pairs, solver seconds).
fn solve(h: &[f64], n: usize, load: f64, levels: usize) -> (Vec<f64>, Vec<Level>) {
    let e_star = Material::SILICON.plane_strain_modulus();
    let options = SolverOptions::default();
    let mut solver = ContactSolver::new(h, (n, n), (SIZE, SIZE), e_star, Boundary::Periodic, options).expect("solver");
    let mut log = Vec::new();
    if levels > 0 && n.is_multiple_of(2) && n / 2 >= 128 {
        let (coarse, coarse_log) = solve(&coarsen(h, n), n / 2, load, levels - 1);
        log = coarse_log;
        solver.warm_start(&refine(&coarse, n / 2)).expect("warm start");
    }
    let report = solver.solve(load, |_, _| ()).expect("solve");
    log.push((n, report.iterations, report.operator_applications, report.seconds));
    (solver.pressure().to_vec(), log)
}

/// CPU time of this process so far (user + system, all threads) [s]: on a shared machine it
/// moves less than the wall time.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage fills the struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut usage);
        usage
    };
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    seconds(usage.ru_utime) + seconds(usage.ru_stime)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let heights: ndarray::Array2<f64> = ndarray_npy::read_npy(&args[0]).expect("a .npy of heights");
    let load: f64 = args[1].parse().expect("load [N]");
    let rounds: usize = args[2].parse().expect("rounds");
    let n = heights.nrows();
    assert_eq!(n, heights.ncols(), "a square grid");
    let h: Vec<f64> = heights.iter().copied().collect();
    for round in 0..rounds {
        let mut cold = Vec::new();
        for (name, levels) in [("cold", 0), ("coarse", 1), ("multi", usize::MAX)] {
            let (start, cpu) = (Instant::now(), cpu_seconds());
            let (p, log) = solve(&h, n, load, levels);
            let (total, cpu) = (start.elapsed().as_secs_f64(), cpu_seconds() - cpu);
            if levels == 0 {
                cold = p.clone();
            }
            let norm = cold.iter().map(|c| c * c).sum::<f64>().sqrt();
            let diff = p.iter().zip(&cold).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt() / norm;
            // The work in FFT pairs of the fine grid (a pair on (n/2)² costs about a quarter).
            let pairs: f64 = log.iter().map(|(g, _, a, _)| a * (g * g) as f64 / (n * n) as f64).sum();
            let levels: Vec<String> =
                log.iter().map(|(g, it, a, s)| format!("{g}²: {it} it {a} pairs {s:.2} s")).collect();
            println!(
                "{n}² round {round} {name:6} total {total:7.2} s (CPU {cpu:7.2} s), {pairs:.1} fine pairs; vs cold {diff:.1e}; {}",
                levels.join(", ")
            );
        }
    }
}
