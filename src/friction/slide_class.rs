//! The classes of the contact points in a state of the elastic onset's path ([`SlideClass`]),
//! for any local law: a slip-weakening law splits the points that slipped into those still
//! weakening and those fully weakened, so that the classes at the peak stay informative when
//! hardly any point is on its bound at μ_s (with d_c > 0 the peak lies inside a smooth stretch
//! of the path, and the points slipping for the first time there are few).
//!
//! The paper's three classes (`friction::onset`) map as: critical ↔ critical, and with a
//! weakening law also the weakening points (on their bound above μ_d: more slip lowers the
//! force they carry); pre-sliding ↔ weakened (at μ_d); subcritical ↔ stuck. Under the instant
//! drop no point is weakening and the classes are those of equal sharing's definitions.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use serde::Serialize;

use super::onset::ClassShare;
use super::slip_law::SlipLaw;

/// What a contact point is in a state of the path, with its code in `classes.npy`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[repr(i8)]
pub enum SlideClass {
    /// Slipped before the increment that reached this state, fully weakened: its coefficient
    /// is the law's last (mu_d once the slip reaches d_c; under the instant drop every slipped
    /// point).
    Weakened = 1,
    /// Not slipped before, on its bound now: slipping for the first time.
    Critical = 2,
    /// Not slipped before, below its bound.
    Stuck = 3,
    /// Slipped before, not yet fully weakened: 0 < s < d_c, its coefficient between mu_s and
    /// mu_d (a measured μ(slip): short of the curve's last point).
    Weakening = 4,
}

impl SlideClass {
    /// The class of a point that `before` had slipped before the increment that reached the
    /// state, is `on_bound` now, and has slipped `slip` \[m] in all (path length).
    pub(super) fn of(law: &SlipLaw, before: bool, on_bound: bool, slip: f64) -> SlideClass {
        match (before, on_bound) {
            (true, _) if law.settled(slip) => SlideClass::Weakened,
            (true, _) => SlideClass::Weakening,
            (false, true) => SlideClass::Critical,
            (false, false) => SlideClass::Stuck,
        }
    }
}

/// Count and shares of N and F_S of each class at the peak.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlideClasses {
    /// Never slipped, below the bound.
    pub stuck: ClassShare,
    /// Never slipped before the peak's increment, on the bound μ_s p.
    pub critical: ClassShare,
    /// Slipped, partly weakened (0 < s < d_c).
    pub weakening: ClassShare,
    /// Slipped, fully weakened (s ≥ d_c, at mu_d p; every slipped point under the instant drop).
    pub weakened: ClassShare,
}

impl SlideClasses {
    /// The shares of `elements` (class, normal force \[N], friction force \[N]) of the normal
    /// force and the friction force `totals` \[N].
    pub fn tally(elements: impl Iterator<Item = (SlideClass, f64, f64)> + Clone, totals: (f64, f64)) -> Self {
        let share = |class| ClassShare::tally(elements.clone(), class, totals);
        SlideClasses {
            stuck: share(SlideClass::Stuck),
            critical: share(SlideClass::Critical),
            weakening: share(SlideClass::Weakening),
            weakened: share(SlideClass::Weakened),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::friction::slip_law::Weakening;

    /// Under the instant drop the classes are the three of a law without a slip scale, with
    /// their codes: every point slipped before is weakened (1) whatever its slip, one on its
    /// bound for the first time critical (2), the rest stuck (3); none is weakening.
    #[test]
    fn the_instant_drop_keeps_three_classes() {
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Instant };
        for slip in [0.0, 1e-12, 1e-9, 1.0] {
            for on_bound in [true, false] {
                assert_eq!(SlideClass::of(&law, true, on_bound, slip), SlideClass::Weakened);
            }
            assert_eq!(SlideClass::of(&law, false, true, slip), SlideClass::Critical);
            assert_eq!(SlideClass::of(&law, false, false, slip), SlideClass::Stuck);
        }
        let codes = [SlideClass::Weakened, SlideClass::Critical, SlideClass::Stuck, SlideClass::Weakening];
        assert_eq!(codes.map(|c| c as i8), [1, 2, 3, 4]);
    }

    /// A linear weakening over d_c: a slipped point weakens until its slip reaches d_c, then it
    /// is at mu_d; one slipped as far that had not slipped before is critical.
    #[test]
    fn a_linear_weakening_splits_the_slipped_at_its_distance() {
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(2e-9) };
        assert_eq!(SlideClass::of(&law, true, true, 1e-12), SlideClass::Weakening);
        assert_eq!(SlideClass::of(&law, true, false, 1.999e-9), SlideClass::Weakening);
        assert_eq!(SlideClass::of(&law, true, true, 2e-9), SlideClass::Weakened);
        assert_eq!(SlideClass::of(&law, false, true, 3e-9), SlideClass::Critical);
        let curve = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Curve(vec![(0.0, 0.6), (5e-9, 0.4)]) };
        assert_eq!(SlideClass::of(&curve, true, true, 4e-9), SlideClass::Weakening);
        assert_eq!(SlideClass::of(&curve, true, true, 5e-9), SlideClass::Weakened);
    }
}
