//! The contact solver against closed-form solutions (Hertz, Westergaard) and against Tamaas.

use std::f64::consts::PI;
use std::path::Path;

use asperity::contact::{full_contact_load, Boundary, ContactSolver, Convergence, SolverOptions};
use ndarray::Array2;
use ndarray_npy::read_npy;

const E_STAR: f64 = 1.0e11;

fn solver(h: &[f64], shape: (usize, usize), size: (f64, f64), boundary: Boundary) -> ContactSolver {
    ContactSolver::new(h, shape, size, E_STAR, boundary, SolverOptions::default()).unwrap()
}

/// Σ p·ΔxΔy against the imposed load.
fn force_error(s: &ContactSolver, load: f64) -> f64 {
    let (ny, nx) = s.shape();
    let (lx, ly) = s.size();
    let force: f64 = s.pressure().iter().sum::<f64>() * lx * ly / (nx * ny) as f64;
    (force / load - 1.0).abs()
}

/// A sphere of radius R on a free half-space: Hertz's contact radius a = (3NR/4E*)^⅓ and peak
/// pressure 3N/(2πa²), on square and on rectangular pixels.
#[test]
fn hertz_free_boundary() {
    let r = 1e-3;
    // (ny, nx, ly, lx): the contact spans 64 px on square pixels; 80 × 50 px on rectangular ones.
    for &(ny, nx, ly, lx) in &[(128, 128, 40e-6, 40e-6), (96, 160, 38.4e-6, 40e-6)] {
        let (dx, dy) = (lx / nx as f64, ly / ny as f64);
        let h: Vec<f64> = (0..ny * nx)
            .map(|i| {
                let x = ((i % nx) as f64 + 0.5) * dx - lx / 2.0;
                let y = ((i / nx) as f64 + 0.5) * dy - ly / 2.0;
                -(x * x + y * y) / (2.0 * r)
            })
            .collect();
        let a_hertz: f64 = 10e-6;
        let load = 4.0 * E_STAR * a_hertz.powi(3) / (3.0 * r);
        let mut s = solver(&h, (ny, nx), (lx, ly), Boundary::Free);
        s.solve(load, |_, _| {}).unwrap();
        let p = s.pressure();
        let area = p.iter().filter(|v| **v > 0.0).count() as f64 * dx * dy;
        let a = (area / PI).sqrt();
        let p_max = p.iter().copied().fold(0.0, f64::max);
        let p_hertz = 3.0 * load / (2.0 * PI * a_hertz * a_hertz);
        assert!((a / a_hertz - 1.0).abs() < 0.02, "{ny}×{nx}: contact radius {a:e} vs Hertz {a_hertz:e}");
        assert!((p_max / p_hertz - 1.0).abs() < 0.02, "{ny}×{nx}: peak pressure {p_max:e} vs Hertz {p_hertz:e}");
        assert!(force_error(&s, load) < 1e-10);
    }
}

/// h = h0 cos(2πx/λ) on a periodic window of one wavelength.
fn sinusoid(nx: usize, h0: f64) -> Vec<f64> {
    let row: Vec<f64> = (0..nx).map(|i| h0 * (2.0 * PI * i as f64 / nx as f64).cos()).collect();
    [row.clone(), row].concat()
}

/// Full contact (p̄ > p* = πE*h0/λ): p(x) = p̄ + p* cos(2πx/λ) exactly.
#[test]
fn westergaard_full_contact() {
    let (nx, lambda, h0) = (256, 10e-6, 20e-9);
    let p_star = PI * E_STAR * h0 / lambda;
    let ly = 2.0 * lambda / nx as f64;
    let mut s = solver(&sinusoid(nx, h0), (2, nx), (lambda, ly), Boundary::Periodic);
    let p_mean = 1.5 * p_star;
    let load = p_mean * lambda * ly;
    s.solve(load, |_, _| {}).unwrap();
    for (i, p) in s.pressure().iter().enumerate() {
        let want = p_mean + p_star * (2.0 * PI * (i % nx) as f64 / nx as f64).cos();
        assert!((p - want).abs() < 1e-8 * p_star, "pixel {i}: {p} vs {want}");
    }
    assert!(force_error(&s, load) < 1e-10);
}

/// The load of full contact, known before any solve, is Westergaard's p* = πE*h0/λ times the
/// area; on a rough window the solve just above it touches everywhere, just below it not.
#[test]
fn full_contact_load_is_westergaards_and_the_solvers() {
    let (nx, lambda, h0) = (256, 10e-6, 20e-9);
    let ly = 2.0 * lambda / nx as f64;
    let want = PI * E_STAR * h0 / lambda * lambda * ly;
    let got = full_contact_load(&sinusoid(nx, h0), (2, nx), (lambda, ly), E_STAR);
    assert!((got / want - 1.0).abs() < 1e-12, "{got:e} vs {want:e}");

    let h: Array2<f64> =
        read_npy(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas/heights.npy")).unwrap();
    let (ny, nx) = h.dim();
    let size = (8e-6, 6e-6);
    let h = h.as_standard_layout();
    let h = h.as_slice().unwrap();
    let full = full_contact_load(h, (ny, nx), size, E_STAR);
    for (factor, touches_everywhere) in [(1.02, true), (0.98, false)] {
        let mut s = solver(h, (ny, nx), size, Boundary::Periodic);
        s.solve(factor * full, |_, _| {}).unwrap();
        assert_eq!(s.pressure().iter().all(|p| *p > 0.0), touches_everywhere, "at {factor} × the full-contact load");
    }
}

/// Partial contact (Johnson): p̄/p* = sin²(πa/λ) for contact half-width a, and the peak
/// pressure 2p̄ / sin(πa/λ).
#[test]
fn westergaard_partial_contact() {
    let (nx, lambda, h0) = (1024, 10e-6, 20e-9);
    let dx = lambda / nx as f64;
    let p_star = PI * E_STAR * h0 / lambda;
    let ly = 2.0 * dx;
    let mut s = solver(&sinusoid(nx, h0), (2, nx), (lambda, ly), Boundary::Periodic);
    for ratio in [0.05, 0.2, 0.5, 0.8] {
        let p_mean = ratio * p_star;
        let load = p_mean * lambda * ly;
        s.solve(load, |_, _| {}).unwrap();
        let row = &s.pressure()[..nx];
        let width = row.iter().filter(|p| **p > 0.0).count() as f64 * dx;
        let a = lambda / PI * ratio.sqrt().asin();
        assert!((width - 2.0 * a).abs() <= 2.0 * dx, "p̄/p* = {ratio}: contact width {width:e} vs {:e}", 2.0 * a);
        let peak = 2.0 * p_mean / (PI * a / lambda).sin();
        assert!((row[0] / peak - 1.0).abs() < 5e-3, "p̄/p* = {ratio}: peak {} vs {peak}", row[0]);
        assert!(force_error(&s, load) < 1e-10);
    }
}

/// Tamaas 2.9 (PolonskyKeerRey, basic_2d, tolerance 1e-14) on a self-affine + sphere surface:
/// the same pressure maps within 1e-6 relative L2 and the same contact points. The fixture is
/// made by tools/make_tamaas_fixture.py.
#[test]
fn agrees_with_tamaas() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    let h: Array2<f64> = read_npy(dir.join("heights.npy")).unwrap();
    let size = (meta["physical_size_m"][0].as_f64().unwrap(), meta["physical_size_m"][1].as_f64().unwrap());
    let (e, nu) = (meta["youngs_pa"].as_f64().unwrap(), meta["poisson"].as_f64().unwrap());
    let mut s = ContactSolver::new(
        h.as_slice().unwrap(),
        h.dim(),
        size,
        e / (1.0 - nu * nu),
        Boundary::Periodic,
        SolverOptions::default(),
    )
    .unwrap();
    for entry in meta["loads"].as_array().unwrap() {
        let load = entry["load_n"].as_f64().unwrap();
        let reference: Array2<f64> = read_npy(dir.join(entry["pressure_file"].as_str().unwrap())).unwrap();
        s.solve(load, |_, _| {}).unwrap();
        let diff: f64 = s.pressure().iter().zip(reference.iter()).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
        let norm: f64 = reference.iter().map(|b| b * b).sum::<f64>().sqrt();
        assert!(diff / norm < 1e-6, "load {load} N: relative L2 difference {:e}", diff / norm);
        let differing = s.pressure().iter().zip(reference.iter()).filter(|(a, b)| (**a > 0.0) != (**b > 0.0)).count();
        assert_eq!(differing, 0, "load {load} N: contact points differ");
        assert_eq!(s.pressure().iter().filter(|p| **p > 0.0).count() as u64, entry["contact_points"].as_u64().unwrap());
        assert!(force_error(&s, load) < 1e-10);
    }
}

/// A sweep warm-started from the previous load gives the same answer as a cold solve.
#[test]
fn warm_start_gives_the_cold_answer() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas");
    let h: Array2<f64> = read_npy(dir.join("heights.npy")).unwrap();
    let size = (8e-6, 6e-6);
    let mut warm = solver(h.as_slice().unwrap(), h.dim(), size, Boundary::Periodic);
    warm.solve(2e-3, |_, _| {}).unwrap();
    warm.solve(4e-3, |_, _| {}).unwrap();
    let mut cold = solver(h.as_slice().unwrap(), h.dim(), size, Boundary::Periodic);
    cold.solve(4e-3, |_, _| {}).unwrap();
    let diff: f64 = warm.pressure().iter().zip(cold.pressure()).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
    let norm: f64 = cold.pressure().iter().map(|b| b * b).sum::<f64>().sqrt();
    assert!(diff / norm < 1e-7, "warm and cold differ by {:e}", diff / norm);
}

/// An iteration limit that is too small is an error, not a silent result.
#[test]
fn non_convergence_is_an_error() {
    let h = sinusoid(64, 20e-9);
    let convergence = Convergence { tolerance: 1e-12, max_iterations: 2 };
    let options = SolverOptions { convergence, ..Default::default() };
    let mut s = ContactSolver::new(&h, (2, 64), (10e-6, 0.3e-6), E_STAR, Boundary::Periodic, options).unwrap();
    let err = s.solve(1e-9, |_, _| {}).unwrap_err().to_string();
    assert!(err.contains("did not converge") && err.contains("2 iterations"), "{err}");
    assert!(!err.contains('\n'));
}

/// A progress callback that answers `Break` stops the solve at that iteration; the solver is
/// then as good as new: the next solve starts cold and gives the uninterrupted answer.
#[test]
fn a_solve_stops_when_its_callback_says_so() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas");
    let h: Array2<f64> = read_npy(dir.join("heights.npy")).unwrap();
    let size = (8e-6, 6e-6);
    let mut s = solver(h.as_slice().unwrap(), h.dim(), size, Boundary::Periodic);
    let mut calls = 0;
    let stop = |it: usize, _| {
        calls += 1;
        if it >= 3 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    };
    let err = s.solve(4e-3, stop).unwrap_err();
    assert!(matches!(err, asperity::Error::Interrupted { .. }), "{err}");
    assert_eq!(calls, 3);
    assert_eq!(err.to_string(), "contact solve at 0.004 N: interrupted");
    s.solve(4e-3, |_, _| {}).unwrap();
    let mut cold = solver(h.as_slice().unwrap(), h.dim(), size, Boundary::Periodic);
    cold.solve(4e-3, |_, _| {}).unwrap();
    assert_eq!(s.pressure(), cold.pressure());
}
