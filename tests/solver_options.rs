//! The solvers' options as the library checks them, for every caller (CLI, study, Python):
//! a tolerance that the starting guess passes is refused, and a cold start iterates.

use asperity::contact::{Boundary, ContactSolver, Convergence, ShearCompliance, SolverOptions, TangentialSolver};

const E_STAR: f64 = 1.5e11;

/// A tolerance of 1e-2 or more, or no iteration, is refused by the convergence check, and so
/// by the contact and the tangential solvers built with it (a tolerance the uniform start
/// passes would return that start after 0 iterations: with `contact --tolerance 1`, contact
/// fraction 1.0 where the solution's is 0.047).
#[test]
fn tolerances_the_start_passes_are_refused() {
    for tolerance in [1.0, 0.5, 1e-2, 0.0, -1e-6, f64::NAN, f64::INFINITY] {
        let e = Convergence { tolerance, max_iterations: 10 }.check().unwrap_err().to_string();
        assert!(e.starts_with("--tolerance: must lie in (0, 0.01)"), "{tolerance}: {e}");
    }
    assert!(Convergence { tolerance: 9e-3, max_iterations: 1 }.check().is_ok());
    let e = Convergence { tolerance: 1e-8, max_iterations: 0 }.check().unwrap_err().to_string();
    assert_eq!(e, "--max-iter: must be at least 1");
    let h = vec![0.0; 16];
    let convergence = Convergence { tolerance: 1.0, max_iterations: 100 };
    let options = SolverOptions { convergence, ..Default::default() };
    let e = ContactSolver::new(&h, (4, 4), (1e-6, 1e-6), E_STAR, Boundary::Periodic, options).err().unwrap();
    assert!(e.to_string().starts_with("--tolerance: must lie in (0, 0.01), got 1"), "{e}");
    let c = ShearCompliance { a: 1.0 / 50e9, b: 0.26 / 50e9 };
    let p = vec![1e9; 16];
    let e = TangentialSolver::new(&p, (4, 4), (1e-6, 1e-6), c, Boundary::Periodic, convergence).err().unwrap();
    assert!(e.to_string().starts_with("--tolerance: must lie in (0, 0.01), got 1"), "{e}");
}

/// A flat surface on a periodic window is in full contact at the uniform pressure: solved
/// exactly, without iterating.
#[test]
fn a_flat_surface_is_solved_exactly_at_once() {
    let h = vec![0.0; 64];
    let convergence = Convergence { tolerance: 1e-8, max_iterations: 100 };
    let options = SolverOptions { convergence, ..Default::default() };
    let mut s = ContactSolver::new(&h, (8, 8), (1e-6, 1e-6), E_STAR, Boundary::Periodic, options).unwrap();
    let report = s.solve(1e-3, |_, _| {}).unwrap();
    assert!(report.iterations == 0 && report.residual == 0.0, "{report:?}");
    let p_mean = 1e-3 / 1e-12;
    assert!(s.pressure().iter().all(|p| (p / p_mean - 1.0).abs() < 1e-12));
}

/// A build without the `gpu` feature refuses the GPU in one line that says how to get it, and
/// `--version` says which build it is.
#[cfg(not(feature = "gpu"))]
#[test]
fn a_build_without_the_gpu_backend_says_so() {
    use asperity::contact::Device;
    let h = vec![0.0; 16];
    let options = SolverOptions { device: Device::Gpu, ..Default::default() };
    let e = ContactSolver::new(&h, (4, 4), (1e-6, 1e-6), E_STAR, Boundary::Periodic, options).err().unwrap();
    assert_eq!(
        e.to_string(),
        "--device: this asperity was built without the GPU backend: build it with `cargo build --release --features gpu`"
    );
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_asperity")).arg("--version").output().unwrap();
    assert_eq!(
        String::from_utf8(o.stdout).unwrap(),
        format!(
            "asperity {} (commit {}; GPU backend: not built; build with --features gpu)\n",
            asperity::VERSION,
            asperity::COMMIT
        )
    );
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["contact", "s.npy", "--load", "1mN", "--device", "gpu", "--out", "o"])
        .output()
        .unwrap();
    let e = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success() && e.lines().count() == 1 && e.contains("built without the GPU backend"), "{e}");
}
