//! The friction-drop band over Young's modulus rests on linear elasticity: the pressure for a
//! modulus E* at load N is E*/E*₀ times the pressure for E*₀ at N·E*₀/E*, so the drop (a ratio
//! of forces) is drop(N; E*) = drop(N·E*₀/E*; E*₀). Checked here against direct solves.

use asperity::contact::{Boundary, ContactSolver, Convergence, Material, SolverOptions};
use asperity::friction::{ElementLoads, FrictionLaw, Onset};
use asperity::topography::synth::SyntheticSurface;
use ndarray::Array2;

fn solve(heights: &[f64], size: (f64, f64), e_star: f64, load: f64) -> Array2<f64> {
    let convergence = Convergence { tolerance: 1e-12, max_iterations: 20_000 };
    let options = SolverOptions { convergence, ..Default::default() };
    let mut solver = ContactSolver::new(heights, (128, 128), size, e_star, Boundary::Periodic, options).unwrap();
    solver.solve(load, |_, _| ()).unwrap();
    Array2::from_shape_vec((128, 128), solver.pressure().to_vec()).unwrap()
}

#[test]
fn the_drop_at_another_modulus_is_the_drop_at_a_scaled_load() {
    let surface = SyntheticSurface { grid: (128, 128), seed: 5, ..Default::default() };
    let topo = surface.generate().unwrap();
    let heights: Vec<f64> = topo.heights.iter().copied().collect();
    let area = (surface.size.0 / 128.0).powi(2);
    let law = FrictionLaw::preset("hold 100 s").unwrap();
    let drop = |p: &Array2<f64>| Onset::new(&ElementLoads::from_pressure(p, area).unwrap(), &law).friction_drop();
    let e0 = Material::SILICON.plane_strain_modulus();
    for youngs in [127e9, 133e9] {
        let e = Material { youngs, poisson: 0.26 }.plane_strain_modulus();
        for load in [3e-3, 3e-2] {
            let direct = solve(&heights, surface.size, e, load);
            let scaled = solve(&heights, surface.size, e0, load * e0 / e);
            let elements = direct.iter().filter(|p| **p > 0.0).count();
            assert!(elements > 10, "a multi-element contact: {elements}");
            assert_eq!(elements, scaled.iter().filter(|p| **p > 0.0).count(), "E = {youngs}, N = {load}");
            let (a, b) = (drop(&direct), drop(&scaled));
            assert!((a - b).abs() < 1e-9, "E = {youngs} Pa, N = {load} N: drop {a} directly, {b} scaled");
            // The pressures themselves scale by E*/E*₀.
            let worst = direct.iter().zip(&scaled).map(|(p, q)| (p - q * e / e0).abs()).fold(0.0, f64::max);
            let peak = direct.iter().copied().fold(0.0, f64::max);
            assert!(worst < 1e-7 * peak, "E = {youngs}, N = {load}: pressures differ by {worst} Pa");
        }
    }
}
