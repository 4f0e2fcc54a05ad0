//! Where the study's non-adhesive model stops holding: the loads at which the pull-off force
//! of a single contacting summit is no longer small beside the load. The figures and the report
//! mark this range for the solves without adhesion, whether or not `[contact] adhesion` solves
//! the adhesive contact beside them.
//!
//! Must not import plot, report, cli or python.

use serde::Serialize;

use crate::error::Result;
use crate::topography::stats::slope_curvature;
use crate::topography::Topography;

/// The work of adhesion w \[J/m²] of the estimate: of the order of the capillary bound
/// 2γ cos θ ≤ 0.14 J/m² of a wetting water film on a hydrophilic oxide (γ = 0.072 J/m², as
/// docs/adhesion.md gives it); an assumed value, not a measured one.
pub const WORK_OF_ADHESION: f64 = 0.1;

/// Below the load at which one summit's pull-off is this fraction of it, adhesion changes the
/// load by more than a tenth: outside what a non-adhesive model describes.
pub const ADHESION_SHARE: f64 = 0.1;

/// The DMT estimate of where adhesion matters, from the study's topographies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AdhesionLimit {
    /// The summit radius R = 1/κ \[m], κ the RMS mean curvature √⟨(∇²h/2)²⟩ of the topography
    /// (half the Laplacian: exactly 1/R on a sphere of radius R); the largest over the study's
    /// topographies, whose pull-off is the largest.
    pub summit_radius_m: f64,
    /// The work of adhesion w \[J/m²] ([`WORK_OF_ADHESION`]).
    pub work_of_adhesion: f64,
    /// The DMT pull-off force 2πRw of one summit \[N] (Derjaguin, Muller & Toporov 1975).
    pub pull_off_n: f64,
    /// The load below which one summit's pull-off exceeds [`ADHESION_SHARE`] of it \[N].
    pub load_n: f64,
}

impl AdhesionLimit {
    /// The limit for summits of radius `summit_radius_m` \[m] and the work [`WORK_OF_ADHESION`].
    pub fn new(summit_radius_m: f64) -> AdhesionLimit {
        let pull_off_n = 2.0 * std::f64::consts::PI * summit_radius_m * WORK_OF_ADHESION;
        AdhesionLimit {
            summit_radius_m,
            work_of_adhesion: WORK_OF_ADHESION,
            pull_off_n,
            load_n: pull_off_n / ADHESION_SHARE,
        }
    }

    /// The limit of the topographies `maps` (their largest summit radius); `None` when none has
    /// a curvature (a flat map).
    pub fn of(maps: &[&Topography]) -> Result<Option<AdhesionLimit>> {
        let mut largest: Option<f64> = None;
        for map in maps {
            let curvature = slope_curvature(map)?.rms_curvature_from_area_per_m;
            if curvature > 0.0 && curvature.is_finite() {
                largest = Some(largest.map_or(1.0 / curvature, |r| r.max(1.0 / curvature)));
            }
        }
        Ok(largest.map(AdhesionLimit::new))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::Provenance;
    use ndarray::Array2;

    fn paraboloid(radius: f64, n: usize, size: f64) -> Topography {
        let dx = size / n as f64;
        let heights = Array2::from_shape_fn((n, n), |(j, i)| {
            let (x, y) = (i as f64 * dx - size / 2.0, j as f64 * dx - size / 2.0);
            -(x * x + y * y) / (2.0 * radius)
        });
        Topography {
            heights,
            physical_size: Some((size, size)),
            periodic: false,
            height_unit_known: true,
            channel: "test".into(),
            provenance: Provenance { format: "test".into(), ..Default::default() },
        }
    }

    /// On paraboloids of 2 and 3 µm the summit radius is theirs (the finite differences of a
    /// quadratic are exact), the larger one sets the limit: 2π · 3 µm · 0.1 J/m² = 1.885 µN
    /// of pull-off, the limit at ten times that.
    #[test]
    fn the_limit_of_paraboloids_is_their_dmt_pull_off() {
        let (small, large) = (paraboloid(2e-6, 64, 1e-6), paraboloid(3e-6, 64, 1e-6));
        let limit = AdhesionLimit::of(&[&small, &large]).unwrap().unwrap();
        assert!((limit.summit_radius_m / 3e-6 - 1.0).abs() < 1e-9, "{limit:?}");
        assert!((limit.pull_off_n / 1.884_955_592e-6 - 1.0).abs() < 1e-9, "{limit:?}");
        assert!((limit.load_n / 1.884_955_592e-5 - 1.0).abs() < 1e-9, "{limit:?}");
        let flat = Topography { heights: Array2::zeros((8, 8)), ..small };
        assert_eq!(AdhesionLimit::of(&[&flat]).unwrap(), None);
    }
}
