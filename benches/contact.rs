//! Contact solver timings on one surface, as JSON on stdout: the FFT pair, cold solves at each
//! load, and the warm-started sweep. `benches/compare_tamaas.py` runs it beside Tamaas.
//!
//! ```text
//! cargo bench --bench contact -- SURFACE.npy SIZE_M OUT_DIR LOAD_N...
//! ```
//!
//! Writes each cold solve's pressure map to OUT_DIR/asperity-NNN.npy (float64, Pa).

use std::path::PathBuf;
use std::time::Instant;

use asperity::contact::{Boundary, ContactSolver, Convergence, Material, SolverOptions};
use asperity::fft::Fft2;
use ndarray::Array2;
use ndarray_npy::{read_npy, write_npy};
use serde_json::json;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    if args.len() < 4 {
        eprintln!("usage: cargo bench --bench contact -- SURFACE.npy SIZE_M OUT_DIR LOAD_N...");
        std::process::exit(2);
    }
    let surface: Array2<f64> = read_npy(&args[0]).expect("a float64 .npy surface");
    let size: f64 = args[1].parse().expect("size in metres");
    let out = PathBuf::from(&args[2]);
    let loads: Vec<f64> = args[3..].iter().map(|a| a.parse().expect("load in newtons")).collect();
    let tolerance: f64 = std::env::var("TOLERANCE").ok().map(|t| t.parse().expect("a tolerance")).unwrap_or(1e-10);
    let (ny, nx) = surface.dim();
    let heights = surface.as_slice().expect("standard layout");
    let e_star = Material::SILICON.plane_strain_modulus();
    let convergence = Convergence { tolerance, max_iterations: 100_000 };
    let options = SolverOptions { convergence, ..Default::default() };
    let solver = || ContactSolver::new(heights, (ny, nx), (size, size), e_star, Boundary::Periodic, options).unwrap();

    // The FFT pair of the grid: forward and inverse of one field, median of 21.
    let plan = Fft2::new(ny, nx);
    let (mut work, mut spectrum) = (plan.make_work(), plan.make_spectrum());
    let mut field = heights.to_vec();
    let mut pair = Vec::new();
    for _ in 0..21 {
        let t = Instant::now();
        plan.forward(&field.clone(), ny, nx, &mut spectrum, &mut work);
        plan.inverse(&mut spectrum, &mut field, ny, nx, &mut work);
        pair.push(t.elapsed().as_secs_f64());
        field.iter_mut().for_each(|v| *v /= (ny * nx) as f64);
    }
    pair.sort_by(f64::total_cmp);
    let pair = pair[pair.len() / 2];

    let mut cold = Vec::new();
    for (k, &load) in loads.iter().enumerate() {
        let mut s = solver();
        let r = s.solve(load, |_, _| {}).unwrap();
        write_npy(
            out.join(format!("asperity-{k:03}.npy")),
            &Array2::from_shape_vec((ny, nx), s.pressure().to_vec()).unwrap(),
        )
        .unwrap();
        cold.push(json!({
            "load_n": load, "seconds": r.seconds, "iterations": r.iterations,
            "operator_applications": r.operator_applications, "residual": r.residual,
            "seconds_per_iteration": r.seconds / r.iterations as f64,
            "contact_points": s.pressure().iter().filter(|p| **p > 0.0).count(),
        }));
    }
    let mut s = solver();
    let start = Instant::now();
    let mut sweep = Vec::new();
    for &load in &loads {
        let r = s.solve(load, |_, _| {}).unwrap();
        sweep.push(json!({"load_n": load, "seconds": r.seconds, "iterations": r.iterations}));
    }
    let sweep_seconds = start.elapsed().as_secs_f64();
    let report = json!({
        "grid": [ny, nx], "threads": rayon::current_num_threads(), "tolerance": tolerance,
        "fft_pair_seconds": pair, "cold": cold, "sweep": sweep, "sweep_seconds": sweep_seconds,
    });
    println!("{}", serde_json::to_string_pretty(&report).unwrap());
}
