//! The stuck tangential stiffness K_t of one round patch against Mindlin's 8 a / Σ (2 − ν_i)/G_i
//! (a stuck circle of radius a on the half-space), for patch radii from 1.5 to 32 pixels: how
//! far the pixelated patch's stiffness lies from the continuum's, a taken from the patch's pixel
//! area πa². Silicon (E = 130 GPa, ν = 0.26) on a rigid flat, the study's default, free boundary, 1 GPa on each pixel of
//! the patch (K_t does not depend on the pressure). Prints CSV:
//! `radius_px,points,equivalent_radius_px,kt_n_per_m,mindlin_n_per_m,ratio`.
//!
//! `cargo run --release --example stiffness_mindlin` (tools/accuracy.py runs it).

use asperity::contact::{Boundary, Material, ShearCompliance, TangentialOptions, TangentialSolver};
use asperity::friction::stuck_stiffness;

fn main() -> asperity::Result<()> {
    let compliance = ShearCompliance::of(&[Material::SILICON]);
    let dx = 20.75e-9;
    println!("radius_px,points,equivalent_radius_px,kt_n_per_m,mindlin_n_per_m,ratio");
    for radius in [1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0] {
        // A free window four patch diameters wide, so that its edge does not stiffen the patch.
        let n = ((8.0 * radius) as usize).max(32);
        let centre = (n as f64 - 1.0) / 2.0;
        let pressure: Vec<f64> = (0..n * n)
            .map(|i| {
                let (y, x) = ((i / n) as f64 - centre, (i % n) as f64 - centre);
                if x.hypot(y) < radius {
                    1e9
                } else {
                    0.0
                }
            })
            .collect();
        let size = (n as f64 * dx, n as f64 * dx);
        let mut solver =
            TangentialSolver::new(&pressure, (n, n), size, compliance, Boundary::Free, TangentialOptions::default())?;
        let (k, _) = stuck_stiffness(&mut solver)?;
        let points = solver.points().len();
        let a = (points as f64 / std::f64::consts::PI).sqrt();
        let mindlin = 8.0 * a * dx / (2.0 * compliance.a - compliance.b);
        println!("{radius},{points},{a:.4},{k:.6e},{mindlin:.6e},{:.5}", k / mindlin);
    }
    Ok(())
}
