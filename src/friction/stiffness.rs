//! The elements' shear stiffness k_t, which turns the model's element shear s into the
//! slider's displacement δ = s / k_t ([`displacement`](super::displacement)).
//!
//! The stick-slip model leaves k_t free (the curve is computed in s). The elastic contact
//! fixes it: with every contact point stuck, a rigid tangential displacement δ of the slider
//! meets the force F = K_t δ, the contact's stuck stiffness K_t [N/m] following from the
//! Cerruti operator on the contact set ([`stuck_stiffness`]). Shared equally by the n
//! elements, k_t = K_t / n ([`element_stiffness`]), so that while all are stuck the model's
//! force n s = K_t δ rises with the elastic contact's own slope, and δ_peak = n s* / K_t.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use crate::contact::{TangentialReport, TangentialSolver};
use crate::error::{Error, Result};

/// The stuck tangential stiffness K_t = dF/dδ [N/m] of the contact set of `solver`: the force
/// along x of the solve for a unit displacement along x at every contact point with unbounded
/// tractions (no point slips), with that solve's report (for a caller that counts its work).
/// The solver is left holding that traction.
pub fn stuck_stiffness(solver: &mut TangentialSolver) -> Result<(f64, TangentialReport)> {
    let m = solver.points().len();
    let report = solver.solve(&vec![[1.0, 0.0]; m], &vec![f64::INFINITY; m])?;
    let k = solver.force()[0];
    if !(k > 0.0 && k.is_finite()) {
        return Err(Error::invalid("sliding onset", format!("the stuck tangential stiffness is {k} N/m")));
    }
    Ok((k, report))
}

/// k_t = K_t / n [N/m]: the shear stiffness of each of `elements` elements sharing the
/// contact's stuck stiffness `contact` K_t [N/m] equally.
pub fn element_stiffness(contact: f64, elements: usize) -> f64 {
    contact / elements as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Boundary, Material, ShearCompliance, TangentialOptions};

    /// One round patch: K_t against Mindlin's 8 a / Σ (2 − ν_i)/G_i (a stuck circle of radius
    /// a on the half-space), a taken from the patch's pixel area πa².
    #[test]
    fn one_round_patch_has_mindlins_stiffness() {
        let si = Material { youngs: 130e9, poisson: 0.26 };
        let compliance = ShearCompliance::of(&[si, si]);
        let (n, l, radius) = (96, 9.6e-6, 12.0);
        let pressure: Vec<f64> = (0..n * n)
            .map(|i| {
                let (y, x) = ((i / n) as f64 - 47.5, (i % n) as f64 - 47.5);
                if x.hypot(y) < radius {
                    1e9
                } else {
                    0.0
                }
            })
            .collect();
        let mut solver =
            TangentialSolver::new(&pressure, (n, n), (l, l), compliance, Boundary::Free, TangentialOptions::default())
                .unwrap();
        let (k, _) = stuck_stiffness(&mut solver).unwrap();
        let dx = l / n as f64;
        let a = (solver.points().len() as f64 / std::f64::consts::PI).sqrt() * dx;
        let mindlin = 8.0 * a / (2.0 * compliance.a - compliance.b);
        eprintln!("K_t {k:.5e} N/m, Mindlin {mindlin:.5e} N/m, ratio {:.4}", k / mindlin);
        assert!((k / mindlin - 1.0).abs() < 0.02, "K_t {k} N/m against Mindlin's {mindlin} N/m");
        // Linear in the displacement: the same stiffness from a solver that starts stuck.
        assert!((stuck_stiffness(&mut solver).unwrap().0 / k - 1.0).abs() < 1e-5);
    }
}
