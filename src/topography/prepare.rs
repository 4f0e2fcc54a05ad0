//! Preparing a measured topography for the contact solver: the one sequence that the study
//! (`[[topography]]` with a `file`) and `asperity contact` both apply.
//!
//! In order: the heights must be known to be metres and the window's size known; then crop,
//! missing points (filled or refused), levelling, resampling (to a pixel size, then to a grid),
//! and a spherical cap added last, for a ball scanned after its curvature was levelled away.
//! The counter-surface, when there is one, is prepared the same way and compounded
//! (h = h_ball − h_wafer) on the ball's grid by [`compound_with`].
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::detrend::Detrend;
use super::map::Topography;
use super::missing::{fill_missing, refuse_missing};
use super::resample::{compound, crop, resample, CropWindow};
use super::synth::Cap;
use crate::error::Result;
use crate::limits::Limits;

/// How to prepare a measured topography. The default leaves it as read.
#[derive(Debug, Clone, PartialEq)]
pub struct Preparation {
    /// Window to keep.
    pub crop: Option<CropWindow>,
    /// Fill missing points harmonically rather than refuse them.
    pub fill_missing: bool,
    /// Levelling.
    pub detrend: Detrend,
    /// Pixel size to resample to \[m].
    pub pixel_size: Option<f64>,
    /// Grid (nx, ny) to resample to over the same window.
    pub grid: Option<(usize, usize)>,
    /// Spherical cap added to the levelled heights, apex at the window's centre.
    pub cap: Option<Cap>,
    /// How large a resampled grid may be.
    pub limits: Limits,
}

impl Default for Preparation {
    fn default() -> Self {
        Preparation {
            crop: None,
            fill_missing: false,
            detrend: Detrend::None,
            pixel_size: None,
            grid: None,
            cap: None,
            limits: Limits::default(),
        }
    }
}

impl Preparation {
    /// `topo` prepared for contact: heights in metres, a physical size, no missing point, at
    /// least 2 × 2 points.
    pub fn apply(&self, mut topo: Topography) -> Result<Topography> {
        topo.require_metres()?;
        if topo.physical_size.is_none() {
            return Err(topo.error("the file states no physical size: give it with --size LX[,LY] (study: size)"));
        }
        topo.require_plausible_heights()?;
        if let Some(window) = &self.crop {
            topo = crop(&topo, window)?;
        }
        let infinite = topo.heights.iter().filter(|h| h.is_infinite()).count();
        if infinite > 0 {
            return Err(topo.error(format!("{infinite} heights are infinite: crop them away")));
        }
        if self.fill_missing {
            fill_missing(&mut topo)?;
        } else {
            refuse_missing(&topo)?;
        }
        self.detrend.apply(&mut topo)?;
        if let Some(p) = self.pixel_size {
            topo = resample(&topo, p, &self.limits)?;
        }
        if let Some((nx, ny)) = self.grid {
            if (topo.nx(), topo.ny()) != (nx, ny) {
                let lx = topo.physical_size.expect("checked above").0;
                topo = resample(&topo, lx / nx as f64, &self.limits)?;
            }
        }
        if topo.nx() < 2 || topo.ny() < 2 {
            return Err(topo.error(format!(
                "a {}×{} grid is too small for contact: at least 2×2 points",
                topo.ny(),
                topo.nx()
            )));
        }
        if let Some(cap) = &self.cap {
            let size = topo.physical_size.expect("checked above");
            topo.heights += &cap.heights(size, (topo.nx(), topo.ny()))?;
            topo.periodic = false;
        }
        Ok(topo)
    }
}

/// The compound roughness h = h_ball − h_wafer on the ball's grid when there is a wafer (see
/// [`compound`]), the ball as it is otherwise.
pub fn compound_with(ball: Topography, wafer: Option<Topography>) -> Result<Topography> {
    match wafer {
        Some(w) => compound(&ball, &w),
        None => Ok(ball),
    }
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::*;
    use crate::topography::map::Provenance;
    use crate::topography::synth::CapShape;

    fn tilted(known: bool) -> Topography {
        Topography {
            heights: Array2::from_shape_fn((8, 10), |(j, i)| 1e-9 * i as f64 + 2e-9 * j as f64),
            physical_size: Some((10e-6, 8e-6)),
            periodic: false,
            height_unit_known: known,
            channel: "Height".into(),
            provenance: Provenance { file: Some("scan.txt".into()), format: "matrix".into(), height_unit: None },
        }
    }

    #[test]
    fn refuses_unknown_units_and_missing_sizes() {
        let e = Preparation::default().apply(tilted(false)).unwrap_err().to_string();
        assert!(e.contains("scan.txt") && e.contains("--height-unit"), "{e}");
        let e = Preparation::default().apply(Topography { physical_size: None, ..tilted(true) }).unwrap_err();
        assert!(e.to_string().contains("--size"), "{e}");
    }

    #[test]
    fn levels_then_adds_the_cap() {
        let cap = Cap { radius: 1e-3, shape: CapShape::Paraboloid };
        let prep = Preparation { detrend: Detrend::Polynomial(1), cap: Some(cap), ..Preparation::default() };
        let t = prep.apply(tilted(true)).unwrap();
        // The plane is gone; what remains is the paraboloid −ρ²/(2R), apex 0 at the centre.
        let (dx, dy) = (1e-6, 1e-6);
        for ((j, i), h) in t.heights.indexed_iter() {
            let rho2 = (i as f64 * dx - 5e-6).powi(2) + (j as f64 * dy - 4e-6).powi(2);
            assert!((h + rho2 / 2e-3).abs() < 1e-20, "({i}, {j}): {h:e}");
        }
        assert!(!t.periodic);
    }

    #[test]
    fn crops_and_resamples_to_a_grid() {
        let prep = Preparation {
            crop: Some(CropWindow::Pixels { x: 2..8, y: 0..6 }),
            grid: Some((3, 3)),
            ..Preparation::default()
        };
        let t = prep.apply(tilted(true)).unwrap();
        assert_eq!(t.heights.dim(), (3, 3));
        let (lx, ly) = t.physical_size.unwrap();
        assert!((lx / 6e-6 - 1.0).abs() < 1e-15 && (ly / 6e-6 - 1.0).abs() < 1e-15);
        // A plane survives cubic resampling exactly: column 0 is the cropped column 2.
        assert!((t.heights[[0, 0]] - 2e-9).abs() < 1e-21);
    }
}
