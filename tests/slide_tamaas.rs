//! The tangential solve against Tamaas 2.9's PolonskyKeerTan (fixture made by
//! tools/make_tamaas_tangential_fixture.py).
//!
//! Tamaas solves normal and tangential tractions together with the coupled Boussinesq–Cerruti
//! operator, the mean traction imposed, in one shot. asperity's solve takes the pressure as
//! given, is uncoupled and displacement-controlled. Here it gets Tamaas' pressure, and the
//! rigid displacement δ is chosen so that the tangential force is Tamaas' (one solve from an
//! unloaded state per δ, as Tamaas does): the problems then differ only by the coupling, whose
//! terms carry (1 − 2ν). At ν = 0.5 they are the same problem; below, the difference is the
//! coupling's, and it shrinks as ν approaches 0.5.

use std::path::Path;

use asperity::contact::{Boundary, ShearCompliance, TangentialOptions, TangentialSolver};
use asperity::topography::io::npy;

fn fixture() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/tamaas_tangential"))
}

fn read(name: &str) -> Vec<f64> {
    let bytes = std::fs::read(fixture().join(name)).unwrap();
    npy::read_f64(&bytes).unwrap().iter().copied().collect()
}

/// Relative L2 difference between asperity's shear and Tamaas' for one fixture case.
fn difference(case: &serde_json::Value, meta: &serde_json::Value) -> f64 {
    let n = meta["grid"][0].as_u64().unwrap() as usize;
    let l = meta["physical_size_m"][0].as_f64().unwrap();
    let (e, mu) = (meta["youngs_pa"].as_f64().unwrap(), meta["mu"].as_f64().unwrap());
    let nu = case["poisson"].as_f64().unwrap();
    let g = e / (2.0 * (1.0 + nu));
    let pressure = read(case["pressure"].as_str().unwrap());
    let (tx, ty) = (read(case["shear_x"].as_str().unwrap()), read(case["shear_y"].as_str().unwrap()));
    let force = meta["mean_traction_pa"][0].as_f64().unwrap() * l * l;
    let compliance = ShearCompliance { a: 1.0 / g, b: nu / g };
    let options = TangentialOptions { tolerance: 1e-12, max_iterations: 50_000 };
    let mut solver = TangentialSolver::new(&pressure, (n, n), (l, l), compliance, Boundary::Periodic, options).unwrap();
    let m = solver.points().len();
    let bound: Vec<f64> = solver.pressure().iter().map(|p| mu * p).collect();
    let mut force_at = |delta: f64| {
        solver.solve(&vec![[delta, 0.0]; m], &bound).unwrap();
        solver.force()[0]
    };
    // Regula falsi on δ, bracketed from δ = 0 up.
    let d0 = 1e-9;
    let guess = force / (force_at(d0) / d0);
    let mut lo = (0.0, 0.0);
    let mut hi = (guess, force_at(guess));
    while hi.1 < force {
        lo = hi;
        hi = (2.0 * hi.0, force_at(2.0 * hi.0));
    }
    for round in 0..200 {
        let mut d = lo.0 + (force - lo.1) / (hi.1 - lo.1) * (hi.0 - lo.0);
        if round % 3 == 2 {
            d = 0.5 * (lo.0 + hi.0);
        }
        let f = force_at(d);
        if (f - force).abs() <= 1e-12 * force {
            break;
        }
        if f < force {
            lo = (d, f);
        } else {
            hi = (d, f);
        }
    }
    let mut diff = 0.0;
    let mut norm = 0.0;
    let q = solver.traction();
    let mut mine = vec![[0.0; 2]; n * n];
    for (&i, q) in solver.points().iter().zip(q) {
        mine[i] = *q;
    }
    for i in 0..n * n {
        diff += (mine[i][0] - tx[i]).powi(2) + (mine[i][1] - ty[i]).powi(2);
        norm += tx[i] * tx[i] + ty[i] * ty[i];
    }
    (diff / norm).sqrt()
}

#[test]
#[ignore = "does not hold yet: measured relative L2 0.86, 0.72, 0.16 at ν = 0.26, 0.4, 0.5; the \
            difference shrinks towards ν = 0.5 but stays far above 1e-4 there, cause not found"]
fn shear_matches_tamaas_where_the_problems_coincide() {
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture().join("meta.json")).unwrap()).unwrap();
    let cases = meta["cases"].as_array().unwrap();
    let diffs: Vec<(f64, f64)> = cases.iter().map(|c| (c["poisson"].as_f64().unwrap(), difference(c, &meta))).collect();
    eprintln!("relative L2 shear difference against Tamaas, by Poisson's ratio: {diffs:?}");
    let (last_nu, last) = *diffs.last().unwrap();
    assert_eq!(last_nu, 0.5);
    assert!(last < 1e-4, "ν = 0.5 (uncoupled in both): {last:.3e}");
    // The coupling's share falls as ν → 0.5.
    for w in diffs.windows(2) {
        assert!(w[1].1 < w[0].1, "{diffs:?}");
    }
    assert!(diffs[0].1 > 1e-3, "ν = 0.26 should show the coupling: {diffs:?}");
}
