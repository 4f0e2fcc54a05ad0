//! The paper's Fig. 2 trend on a real solve by the contact solver: the friction drop falls
//! with load, from the single-element value mu_s/mu_d to a plateau near 1.

use asperity::contact::{Boundary, ContactSolver, Material, SolverOptions};
use asperity::friction::{ElementLoads, FrictionLaw, Onset};
use ndarray::Array2;
use ndarray_npy::read_npy;

#[test]
fn friction_drop_falls_with_load_on_a_rough_sphere() {
    // The Tamaas fixture's surface: 96 × 128 pixels over 8 × 6 µm, a sphere of radius
    // 200 µm with 5 nm RMS self-affine roughness, silicon on a rigid flat.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas");
    let h: Array2<f64> = read_npy(dir.join("heights.npy")).unwrap();
    let (ny, nx) = h.dim();
    let (lx, ly) = (8e-6, 6e-6);
    let e_star = Material::SILICON.plane_strain_modulus();
    let heights: Vec<f64> = h.iter().copied().collect();
    let mut solver =
        ContactSolver::new(&heights, (ny, nx), (lx, ly), e_star, Boundary::Periodic, SolverOptions::default()).unwrap();
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    let area = lx / nx as f64 * (ly / ny as f64);

    // What the solve gives, load [N] → (elements, friction drop, critical fraction of N):
    // one element carries 0.2 µN and the drop is mu_s/mu_d = 1.5; two and three elements
    // give 1.300 and 1.332 (few elements: the drop depends on their particular pressures, as
    // the two-element cases show, and need not fall monotonically); from 40 elements on the
    // drop falls steadily, 1.096 → 1.066 → 1.058, while the critical elements' share of N
    // falls from 1 to 0.1 %.
    let expected = [
        (2e-7, 1, 1.5, 1.0),
        (2e-6, 2, 1.29967, 0.59933),
        (2e-5, 3, 1.33202, 0.35154),
        (2e-4, 40, 1.09559, 0.075648),
        (2e-3, 251, 1.06587, 0.0070655),
        (2e-2, 2132, 1.05779, 0.00090765),
    ];
    let mut drops = Vec::new();
    for (load, elements, drop, critical_share) in expected {
        solver.solve(load, |_, _| {}).unwrap();
        let p = Array2::from_shape_vec((ny, nx), solver.pressure().to_vec()).unwrap();
        let o = Onset::new(&ElementLoads::from_pressure(&p, area).unwrap(), &law);
        assert!((o.normal_force / load - 1.0).abs() < 1e-9, "the map carries the load");
        assert_eq!(o.elements, elements, "{load} N");
        assert!((o.friction_drop() / drop - 1.0).abs() < 1e-4, "{load} N: drop {}", o.friction_drop());
        assert!((o.critical.normal_fraction / critical_share - 1.0).abs() < 1e-3, "{load} N: {:?}", o.critical);
        drops.push(o.friction_drop());
    }
    assert!((drops[0] - law.drop()).abs() < 1e-15);
    // The trend of Fig. 2: every multi-asperity drop lies below every few-element one, and
    // falls with load.
    assert!(drops[3..].windows(2).all(|w| w[1] < w[0]));
    assert!(drops[3] < drops[..3].iter().copied().fold(f64::INFINITY, f64::min));
}
