//! Line profiles: heights along one line (stylus profilometers, two-column exports), the kind of
//! topography beside the 2-D map ([`super::Topography`]), with statistics and a spectrum of its
//! own ([`super::stats`]). A profile is never reshaped into a map: what needs a map refuses it
//! ([`super::io::read`]).
//!
//! As SurfaceTopography's line scans: the positions start at 0 (the first point); a profile is
//! uniform when its positions lie on an equally spaced grid, and its length is then the number of
//! points times the step (each point stands for one step), otherwise the distance from the first
//! point to the last.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::map::{Provenance, MAX_LENGTH_M, MIN_SIZE_M};
use crate::error::Error;

/// How far each step may differ from the mean step for the positions to be uniform, in the
/// file's unit (before any conversion): SurfaceTopography's tolerance, the last digit of
/// positions printed with six decimals (a stylus export's steps of 0.000099 and 0.000100 are
/// one grid of 0.0000996 as printed).
const UNIFORM: f64 = 1e-6;
/// And as a fraction of the mean step, so that steps themselves near 1e-6 (positions in metres)
/// are not uniform for being small: printed positions round off far less than a step.
const UNIFORM_OF_STEP: f64 = 1e-2;

/// A grid step a file's header states, in the unit of its positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StatedStep {
    /// The step as printed.
    pub step: f64,
    /// Half a unit of its last printed digit: the true step lies within this of `step`.
    pub rounding: f64,
}

/// A line profile.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Positions [m] (as stored when `position_unit_known` is false), strictly increasing, the
    /// first 0.
    positions: Vec<f64>,
    /// Heights [m] (as stored when `height_unit_known` is false); `NaN` marks a missing point.
    heights: Vec<f64>,
    /// The grid step when the positions are equally spaced.
    step: Option<f64>,
    /// Where the first point lies, in the positions' unit: `positions` start at 0 for the
    /// statistics, and what the profile is written to keeps the file's positions.
    origin: f64,
    /// What became of a grid step the file's header states ([`Profile::adopt_stated_step`]):
    /// `None` when it states none, `Ok` when the positions were put on its grid, `Err` with why
    /// they were not (what refuses a non-uniform profile says it).
    pub stated_grid: Option<Result<(), String>>,
    /// Whether the positions are known to be metres (the file states their unit, or the user).
    pub position_unit_known: bool,
    /// Whether the heights are known to be metres.
    pub height_unit_known: bool,
    /// The positions' unit as the file states it, `None` when it states none.
    pub position_unit: Option<String>,
    /// Name of the column the heights come from.
    pub channel: String,
    /// Where the heights come from (`height_unit`: as the file states it).
    pub provenance: Provenance,
}

impl Profile {
    /// A profile of `heights` at `positions` (any origin; shifted to start at 0), both in
    /// unknown units until the caller says otherwise. The reason when there are fewer than two
    /// points, the lengths differ, or the positions are not finite and strictly increasing.
    pub fn new(mut positions: Vec<f64>, heights: Vec<f64>) -> Result<Profile, String> {
        if positions.len() != heights.len() {
            return Err(format!("{} positions for {} heights", positions.len(), heights.len()));
        }
        let n = positions.len();
        if n < 2 {
            return Err(format!("a line profile needs at least 2 points, not {n}"));
        }
        if let Some(i) = positions.iter().position(|x| !x.is_finite()) {
            return Err(format!("point {} has no position (x = {})", i + 1, positions[i]));
        }
        if let Some(i) = positions.windows(2).position(|w| w[1] <= w[0]) {
            return Err(format!(
                "point {} (x = {}) does not lie beyond point {} (x = {}): positions must increase",
                i + 2,
                positions[i + 1],
                i + 1,
                positions[i]
            ));
        }
        let origin = positions[0];
        positions.iter_mut().for_each(|x| *x -= origin);
        let end = positions[n - 1];
        let step = end / (n - 1) as f64;
        let tolerance = UNIFORM.min(UNIFORM_OF_STEP * step);
        let uniform = positions.windows(2).all(|w| ((w[1] - w[0]) - step).abs() < tolerance);
        Ok(Profile {
            positions,
            heights,
            step: uniform.then_some(step),
            origin,
            stated_grid: None,
            position_unit_known: false,
            height_unit_known: false,
            position_unit: None,
            channel: "default".into(),
            provenance: Provenance::default(),
        })
    }

    /// Put the positions on the grid of the step a file's header states (`stated`, in the
    /// positions' unit, before any [`Profile::scale`]) when they agree with it to their rounding
    /// (a stylus export prints 0.156 µm per sample and positions to 0.1 µm). The step is then
    /// the positions' mean step, (last − first)/(points − 1), which must lie within the stated
    /// step's rounding of it; each position must lie within one unit of its last printed decimal
    /// of that grid (half a unit its own rounding, half the mean step's, taken from rounded
    /// ends); and the positions become the grid. Otherwise the profile is left as it was.
    /// [`Profile::stated_grid`] records which.
    pub fn adopt_stated_step(&mut self, stated: StatedStep) {
        let n = self.points();
        let step = self.positions[n - 1] / (n - 1) as f64;
        let reason = if (step - stated.step).abs() > stated.rounding * (1.0 + 1e-9) {
            Some(format!("the header states a step of {}, the positions one of {step:.6} (in their unit)", stated.step))
        } else if let Some(quantum) = printed_quantum(self.origin, &self.positions) {
            let off = self.positions.iter().enumerate().map(|(i, &x)| (i, (x - i as f64 * step).abs()));
            let (worst, by) = off.fold((0, 0.0), |w, o| if o.1 > w.1 { o } else { w });
            (by > quantum * (1.0 + 1e-6)).then(|| {
                format!(
                    "point {} lies {by:.3e} off the grid of their mean step, more than the positions' rounding \
                     ({quantum:e}, in their unit)",
                    worst + 1
                )
            })
        } else {
            Some("the header states a step, but the positions are not printed to a fixed number of decimals".into())
        };
        if reason.is_none() {
            self.positions.iter_mut().enumerate().for_each(|(i, x)| *x = i as f64 * step);
            self.step = Some(step);
        }
        self.stated_grid = Some(reason.map_or(Ok(()), Err));
    }

    /// Number of points (at least 2).
    pub fn points(&self) -> usize {
        self.heights.len()
    }

    /// Positions [m, or as stored], the first 0.
    pub fn positions(&self) -> &[f64] {
        &self.positions
    }

    /// Heights [m, or as stored]; `NaN` marks a missing point.
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// The position of the first point as the file gives it [m, or as stored]: [`positions`]
    /// count from it.
    ///
    /// [`positions`]: Profile::positions
    pub fn origin(&self) -> f64 {
        self.origin
    }

    /// The grid step [m, or as stored] of a uniform profile; `None` when the positions are not
    /// equally spaced.
    pub fn step(&self) -> Option<f64> {
        self.step
    }

    /// The length [m, or as stored]: points × step when uniform, else last position − first.
    pub fn length(&self) -> f64 {
        match self.step {
            Some(step) => step * self.points() as f64,
            None => self.positions[self.points() - 1],
        }
    }

    /// Heights to level in place ([`super::detrend`]).
    pub(super) fn heights_mut(&mut self) -> &mut [f64] {
        &mut self.heights
    }

    /// Multiply the positions by `positions` and the heights by `heights` (a change of unit).
    pub fn scale(&mut self, positions: f64, heights: f64) {
        self.positions.iter_mut().for_each(|x| *x *= positions);
        self.origin *= positions;
        self.step = self.step.map(|s| s * positions);
        self.heights.iter_mut().for_each(|h| *h *= heights);
    }

    /// Refuse heights beyond ±[`MAX_LENGTH_M`] and a length outside [`MIN_SIZE_M`] …
    /// [`MAX_LENGTH_M`] (as for a map, [`super::Topography::require_representable`]): their
    /// squares and slopes would overflow, and no statistic reported may be non-finite.
    pub fn require_representable(&self) -> Result<(), String> {
        if let Some((i, h)) = self.heights.iter().enumerate().find(|(_, h)| h.abs() > MAX_LENGTH_M) {
            return Err(format!("point {} has height {h:e}, beyond ±{MAX_LENGTH_M:e} (m): not representable", i + 1));
        }
        let length = self.length();
        if !(MIN_SIZE_M..=MAX_LENGTH_M).contains(&length) {
            return Err(format!("the length {length:e} m is not between {MIN_SIZE_M:e} and {MAX_LENGTH_M:e} m"));
        }
        Ok(())
    }

    /// Number of missing (`NaN`) points.
    pub fn missing_points(&self) -> usize {
        self.heights.iter().filter(|h| h.is_nan()).count()
    }

    /// An error about this profile: names its file when it was read from one.
    pub fn error(&self, reason: impl Into<String>) -> Error {
        match &self.provenance.file {
            Some(path) => Error::file(path, reason),
            None => Error::invalid(format!("{} profile", self.provenance.format), reason),
        }
    }

    /// An error naming the file unless positions and heights are both known to be metres.
    pub fn require_metres(&self) -> crate::error::Result<()> {
        match (self.position_unit_known, self.height_unit_known) {
            (true, true) => Ok(()),
            (true, false) => {
                Err(self.error("the file states no unit for the heights: give it with --height-unit U, e.g. nm or µm"))
            }
            (false, true) => Err(self.error(
                "the file states no unit for the positions along the profile: give it with --position-unit U, \
                 e.g. µm or mm",
            )),
            (false, false) => Err(self.error(
                "the file states no length unit: give it with --height-unit U (of the heights, and of the \
                 positions unless --position-unit U gives theirs), e.g. nm or µm",
            )),
        }
    }
}

/// The unit of the last decimal the positions (`origin` + `positions`, as the file prints
/// them) are printed to, 10⁻ᵈ for the fewest decimals d ≤ 12 that hold them all; `None` when none
/// does.
fn printed_quantum(origin: f64, positions: &[f64]) -> Option<f64> {
    (0..=12).map(|d| 10f64.powi(-d)).find(|&q| {
        positions.iter().all(|&x| {
            let v = (origin + x) / q;
            (v - v.round()).abs() <= 1e-6 + 8.0 * f64::EPSILON * v.abs()
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_start_at_zero_and_uniformity_is_surface_topographys() {
        let p = Profile::new(vec![10.0, 11.0, 12.0, 13.0], vec![0.0; 4]).unwrap();
        assert_eq!(p.positions(), [0.0, 1.0, 2.0, 3.0]);
        assert_eq!((p.step(), p.length()), (Some(1.0), 4.0));
        // Printed to seven significant digits, a uniform grid stays uniform; steps of 97 and
        // 100 are not, in any unit.
        for unit in [1.0, 1e-3, 1e-6] {
            let x: Vec<f64> = (0..50).map(|i| format!("{:.6e}", unit * f64::from(i) / 7.0).parse().unwrap()).collect();
            assert!(Profile::new(x, vec![0.0; 50]).unwrap().step().is_some(), "unit {unit}");
            let x: Vec<f64> = (0..50).map(|i| unit * f64::from(100 * i - 3 * (i % 2))).collect();
            assert!(Profile::new(x, vec![0.0; 50]).unwrap().step().is_none(), "unit {unit}");
        }
        // A stylus export (container-2.zip's .txt): a grid of 0.29868 / 3000 printed with six
        // decimals, steps 0.000099 and 0.000100, is uniform, as SurfaceTopography reads it.
        let x: Vec<f64> =
            (0..3001).map(|i| format!("{:.6}", 0.298684 * f64::from(i) / 3000.0).parse().unwrap()).collect();
        let p = Profile::new(x, vec![0.0; 3001]).unwrap();
        assert!((p.length() - 0.298684 * 3001.0 / 3000.0).abs() < 1e-12, "{}", p.length());
        // Steps of 1e-8 and 1.3e-8 (metres): under 1e-6 apart, yet not one grid.
        let x: Vec<f64> = (0..50).map(|i| 1e-8 * (f64::from(i) + 0.3 * f64::from(i % 2))).collect();
        assert!(Profile::new(x, vec![0.0; 50]).unwrap().step().is_none());
        let p = Profile::new(vec![0.0, 1.0, 2.5, 3.0], vec![1.0; 4]).unwrap();
        assert_eq!((p.step(), p.length()), (None, 3.0));
        let mut p = Profile::new(vec![0.0, 1.0, 2.0], vec![1.0, 2.0, 3.0]).unwrap();
        p.scale(1e-6, 1e-9);
        assert_eq!((p.step(), p.heights()[2], p.length()), (Some(1e-6), 3.0 * 1e-9, 3e-6));
    }

    #[test]
    fn a_stated_step_puts_positions_rounded_off_it_on_its_grid() {
        // 0.15625 per sample printed to one decimal, the step stated as 0.156.
        let x: Vec<f64> = (0..1000).map(|i| format!("{:.1}", 0.15625 * f64::from(i)).parse().unwrap()).collect();
        let stated = StatedStep { step: 0.156, rounding: 0.0005 };
        let mut p = Profile::new(x.clone(), vec![0.0; 1000]).unwrap();
        assert_eq!((p.step(), printed_quantum(p.origin(), p.positions())), (None, Some(0.1)));
        p.adopt_stated_step(stated);
        let step = x[999] / 999.0;
        assert_eq!((p.step(), p.stated_grid.clone(), p.positions()[500]), (Some(step), Some(Ok(())), 500.0 * step));
        // A step stated otherwise, or a position a rounding further off: left as read.
        let mut p = Profile::new(x.clone(), vec![0.0; 1000]).unwrap();
        p.adopt_stated_step(StatedStep { step: 0.150, rounding: 0.0005 });
        assert!(p.step().is_none() && p.stated_grid.as_ref().unwrap().as_ref().unwrap_err().contains("0.15,"));
        // Point 8 at 1.2 where 7 × 0.15625 = 1.09375 printed is 1.1 (point 9 at 1.3, not 1.25 → 1.2).
        let mut moved = x;
        (moved[7], moved[8]) = (1.2, 1.3);
        let mut p = Profile::new(moved, vec![0.0; 1000]).unwrap();
        p.adopt_stated_step(stated);
        assert!(p.step().is_none() && p.stated_grid.unwrap().unwrap_err().starts_with("point 8 lies"));
    }

    #[test]
    fn positions_must_increase() {
        let e = Profile::new(vec![0.0, 2.0, 1.0], vec![0.0; 3]).unwrap_err();
        assert_eq!(e, "point 3 (x = 1) does not lie beyond point 2 (x = 2): positions must increase");
        assert!(Profile::new(vec![0.0, 0.0], vec![0.0; 2]).is_err());
        assert!(Profile::new(vec![0.0, f64::NAN], vec![0.0; 2]).is_err());
        assert!(Profile::new(vec![0.0, f64::INFINITY], vec![0.0; 2]).is_err());
        assert!(Profile::new(vec![0.0], vec![0.0]).unwrap_err().contains("at least 2 points"));
    }
}
