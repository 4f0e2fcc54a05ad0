//! The GPU backend (`--features gpu`) against the CPU solver on the same problems: pressures
//! within 1e-9 relative L2 at the same tolerance, 1e-12, and the same contact points. (At the
//! default 1e-10 the two iterations, each within its tolerance, differ by 1e-9 to 3e-9 on
//! these grids and up to 2.3e-8 at 16384², with the same contact points: the benchmark of
//! `tools/gpu-check.sh`.) The capped solve is the CPU's iteration, equal to rounding. Where no GPU
//! can be used (no driver, no device, no CUDA libraries) each test prints one line saying so
//! and passes; `tools/gpu-check.sh` runs them where there is one.
#![cfg(feature = "gpu")]

use asperity::contact::{Boundary, ContactSolver, Convergence, Device, SolverOptions};
use asperity::topography::synth::SyntheticSurface;

const E_STAR: f64 = 1.394e11;

/// The default rough ball (roughness on a 1.5 mm sphere, 31.13 µm window) on an nx × ny grid.
fn ball(nx: usize, ny: usize, seed: u64) -> (Vec<f64>, (f64, f64)) {
    let s = SyntheticSurface { grid: (nx, ny), seed, ..Default::default() };
    (s.generate().unwrap().heights.iter().copied().collect(), s.size)
}

/// A GPU solver, or None (with a one-line note) where this machine has no usable GPU.
fn gpu(
    heights: &[f64],
    shape: (usize, usize),
    size: (f64, f64),
    boundary: Boundary,
    tolerance: f64,
) -> Option<ContactSolver> {
    let convergence = Convergence { tolerance, ..SolverOptions::default().convergence };
    let options = SolverOptions { convergence, device: Device::Gpu };
    match ContactSolver::new(heights, shape, size, E_STAR, boundary, options) {
        Ok(s) => Some(s),
        Err(e) if e.to_string().contains("was not found") || e.to_string().contains("no CUDA device") => {
            eprintln!("skipped: no GPU here ({e})");
            None
        }
        Err(e) => panic!("{e}"),
    }
}

fn cpu(heights: &[f64], shape: (usize, usize), size: (f64, f64), boundary: Boundary, tolerance: f64) -> ContactSolver {
    let convergence = Convergence { tolerance, ..SolverOptions::default().convergence };
    let options = SolverOptions { convergence, ..Default::default() };
    ContactSolver::new(heights, shape, size, E_STAR, boundary, options).unwrap()
}

/// ‖a − b‖ / ‖b‖.
fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    (d / b.iter().map(|y| y * y).sum::<f64>()).sqrt()
}

/// A warm load sweep on both devices, compared load by load.
fn sweep(shape: (usize, usize), boundary: Boundary, hardness: Option<f64>, loads: &[f64]) {
    let (heights, size) = ball(shape.1, shape.0, 1);
    let tolerance = 1e-12;
    let Some(mut g) = gpu(&heights, shape, size, boundary, tolerance) else { return };
    let mut c = cpu(&heights, shape, size, boundary, tolerance);
    g.set_hardness(hardness).unwrap();
    c.set_hardness(hardness).unwrap();
    for &load in loads {
        let rc = c.solve(load, |_, _| ()).unwrap();
        let rg = g.solve(load, |_, _| ()).unwrap();
        let (pc, pg) = (c.pressure(), g.pressure());
        let error = relative_l2(pg, pc);
        let contact = |p: &[f64]| p.iter().map(|q| *q > 0.0).collect::<Vec<_>>();
        let differ = contact(pc).iter().zip(contact(pg)).filter(|(a, b)| **a != *b).count();
        eprintln!(
            "{shape:?} {boundary:?} H={hardness:?} {load:e} N: CPU {} it, GPU {} it ({:.3} s), relative L2 {error:.2e}, \
             {differ} contact points differ",
            rc.iterations, rg.iterations, rg.seconds
        );
        assert!(rg.residual <= tolerance, "{rg:?}");
        assert!(error <= 1e-9, "{load} N: relative L2 {error:e}");
        assert_eq!(differ, 0, "{load} N");
        // The load is carried, and the displacement is the CPU's.
        let area = size.0 * size.1 / (shape.0 * shape.1) as f64;
        assert!((pg.iter().sum::<f64>() * area / load - 1.0).abs() < 1e-12);
        assert!(relative_l2(&g.displacement(), &c.displacement()) < 1e-8);
    }
}

#[test]
fn a_periodic_sweep_is_the_cpus() {
    sweep((256, 256), Boundary::Periodic, None, &[1e-5, 1e-4, 1e-3, 1e-2]);
}

/// ny ≠ nx, odd: the window's indexing and the half spectrum's rows.
#[test]
fn a_rectangular_odd_grid_is_the_cpus() {
    sweep((97, 160), Boundary::Periodic, None, &[1e-4, 1e-2]);
}

#[test]
fn a_free_boundary_sweep_is_the_cpus() {
    sweep((128, 96), Boundary::Free, None, &[1e-4, 1e-3, 1e-2]);
}

/// The cap: points saturate at H and the load restoration's Newton steps run on the GPU.
#[test]
fn a_capped_sweep_is_the_cpus() {
    sweep((128, 128), Boundary::Periodic, Some(8e9), &[1e-3, 1e-2, 5e-2]);
}

/// A solve resumed from a saved pressure continues as the CPU's does.
#[test]
fn a_warm_start_from_a_pressure_map_is_the_cpus() {
    let shape = (128, 128);
    let (heights, size) = ball(128, 128, 2);
    let Some(mut g) = gpu(&heights, shape, size, Boundary::Periodic, 1e-12) else { return };
    let mut c = cpu(&heights, shape, size, Boundary::Periodic, 1e-12);
    c.solve(1e-3, |_, _| ()).unwrap();
    let saved = c.pressure().to_vec();
    g.warm_start(&saved).unwrap();
    c.solve(3e-3, |_, _| ()).unwrap();
    g.solve(3e-3, |_, _| ()).unwrap();
    assert!(relative_l2(g.pressure(), c.pressure()) <= 1e-9);
}

/// `contact --device gpu` writes what `--device cpu` writes, to the solver's precision.
#[test]
fn the_cli_solves_on_the_gpu() {
    let dir = tempfile::tempdir().unwrap();
    let (heights, _) = ball(128, 128, 3);
    let array = ndarray::Array2::from_shape_vec((128, 128), heights).unwrap();
    ndarray_npy::write_npy(dir.path().join("s.npy"), &array).unwrap();
    let run = |device: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_asperity"))
            .current_dir(dir.path())
            .args(["contact", "s.npy", "--size", "31.13um", "--load", "1mN,10mN", "--tolerance", "1e-12"])
            .args(["--device", device, "--out", device])
            .output()
            .unwrap()
    };
    let o = run("gpu");
    let e = String::from_utf8_lossy(&o.stderr);
    if e.contains("was not found") || e.contains("no CUDA device") {
        eprintln!("skipped: no GPU here ({})", e.trim());
        return;
    }
    assert!(o.status.success(), "{e}");
    assert!(run("cpu").status.success());
    for k in ["000", "001"] {
        let read = |d: &str| -> ndarray::Array2<f64> {
            ndarray_npy::read_npy(dir.path().join(format!("{d}/pressure-{k}.npy"))).unwrap()
        };
        let (g, c) = (read("gpu"), read("cpu"));
        assert!(relative_l2(g.as_slice().unwrap(), c.as_slice().unwrap()) <= 1e-9);
    }
}
