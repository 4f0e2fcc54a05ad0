//! The local law of the sliding onset under elastic sharing ([`SlipLaw`]): mu_s until a point
//! first slips, then falling to mu_d at once, linearly over a slip-weakening distance d_c, or
//! along a measured μ(slip) curve ([`Weakening`]); and the one check of a d_c given by a user.
//!
//! Must not import contact, study, shs, plot or report: a law is numbers only.

use crate::error::{Error, Result};

/// The slip-weakening distance d_c \[m] of elastic sharing when none is given (`slide`, the
/// study, Python): μ falls linearly from mu_s to mu_d over 2 nm of slip. With the instant drop
/// the onset under elastic sharing has no length of its own and its drop falls with the pixel;
/// with d_c = 2 nm the nucleation length G d_c / ((mu_s − mu_d) p) is resolved on the default
/// study's pixel and the drop converges (`tools/sharing-convergence.sh`; its figure in
/// docs/results.md). A d_c of 0 is the instant drop.
pub const DEFAULT_SLIP_DISTANCE_M: f64 = 2e-9;

/// How a point's friction coefficient falls from mu_s to mu_d as it slips.
#[derive(Debug, Clone, PartialEq)]
pub enum Weakening {
    /// At once on the first slip (the paper's law).
    Instant,
    /// Linearly over an accumulated slip d_c \[m].
    Linear(f64),
    /// A measured μ(slip): (slip \[m] from the onset of slip, μ) pairs, slip increasing from 0;
    /// beyond the last point μ stays at its last value.
    Curve(Vec<(f64, f64)>),
}

impl Weakening {
    /// The weakening of a slip-weakening distance `slip_distance` \[m] that a user gave (as
    /// `option`): 0 is the instant drop, a positive finite length the linear weakening over
    /// it; anything else is refused.
    pub fn of_slip_distance(slip_distance: f64, option: &str) -> Result<Weakening> {
        if slip_distance == 0.0 {
            Ok(Weakening::Instant)
        } else if slip_distance > 0.0 && slip_distance.is_finite() {
            Ok(Weakening::Linear(slip_distance))
        } else {
            Err(Error::invalid(
                option,
                format!("must be positive and finite, or 0 for the instant drop, got {slip_distance:e} m"),
            ))
        }
    }
}

/// The local law of the sliding onset.
#[derive(Debug, Clone, PartialEq)]
pub struct SlipLaw {
    /// Static coefficient mu_s: the bound of a point that has never slipped.
    pub mu_s: f64,
    /// Dynamic coefficient mu_d: the bound once weakened.
    pub mu_d: f64,
    /// How the bound falls from mu_s to mu_d once a point slips.
    pub weakening: Weakening,
}

impl SlipLaw {
    /// The slip-weakening distance d_c \[m]: 0 for the instant drop, none for a measured
    /// μ(slip) curve.
    pub fn slip_distance(&self) -> Option<f64> {
        match self.weakening {
            Weakening::Instant => Some(0.0),
            Weakening::Linear(dc) => Some(dc),
            Weakening::Curve(_) => None,
        }
    }

    /// The coefficient of a point that has slipped `slip` \[m] in all (path length), `slipped`
    /// whether it has slipped at all.
    pub fn mu(&self, slip: f64, slipped: bool) -> f64 {
        match &self.weakening {
            Weakening::Instant => {
                if slipped {
                    self.mu_d
                } else {
                    self.mu_s
                }
            }
            Weakening::Linear(dc) => self.mu_s - (self.mu_s - self.mu_d) * (slip / dc).min(1.0),
            Weakening::Curve(points) => {
                let i = points.partition_point(|(s, _)| *s <= slip);
                if i == 0 {
                    points[0].1
                } else if i == points.len() {
                    points[i - 1].1
                } else {
                    let ((s0, m0), (s1, m1)) = (points[i - 1], points[i]);
                    m0 + (m1 - m0) * (slip - s0) / (s1 - s0)
                }
            }
        }
    }

    /// The largest coefficient a point can have from now on, having slipped `slip` [m]
    /// (`slipped` whether at all): no later force exceeds the sum of these bounds.
    pub(super) fn ceiling(&self, slip: f64, slipped: bool) -> f64 {
        match &self.weakening {
            Weakening::Instant | Weakening::Linear(_) => self.mu(slip, slipped),
            Weakening::Curve(points) => {
                let later = points.iter().filter(|(s, _)| *s > slip).map(|p| p.1);
                later.fold(self.mu(slip, slipped), f64::max)
            }
        }
    }

    /// |dμ/ds| at an accumulated slip `slip` [1/m]: how fast the bound moves with the slip.
    pub(super) fn slope(&self, slip: f64) -> f64 {
        match &self.weakening {
            Weakening::Instant => 0.0,
            Weakening::Linear(dc) => {
                if slip < *dc {
                    (self.mu_s - self.mu_d) / dc
                } else {
                    0.0
                }
            }
            Weakening::Curve(points) => {
                let i = points.partition_point(|(s, _)| *s <= slip);
                if i == 0 || i == points.len() {
                    0.0
                } else {
                    let ((s0, m0), (s1, m1)) = (points[i - 1], points[i]);
                    ((m1 - m0) / (s1 - s0)).abs()
                }
            }
        }
    }

    /// The bound [Pa] that a point on its bound `bound` [Pa], under pressure `pressure` [Pa],
    /// settles at, having slipped `slip` [m] in all: lowering its bound by Δ lets it slip about
    /// `compliance` Δ more (its own compliance [m/Pa], K's diagonal; the others' response is
    /// left to the next solve), so the bound solves g = μ(slip + compliance (bound − g)) p.
    /// Taking μ(slip) p instead lowers a steep weakening's bounds a little at each solve.
    pub(super) fn settling_bound(&self, slip: f64, bound: f64, pressure: f64, compliance: f64) -> f64 {
        let after = |g: f64| self.mu(slip + compliance * (bound - g), true) * pressure;
        let first = after(bound);
        if first >= bound || self.weakening == Weakening::Instant {
            return first;
        }
        // after(g) − g is negative at the bound and not negative at the law's lowest μ.
        let (mut lo, mut hi) = (self.lowest() * pressure, bound);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if after(mid) >= mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The lowest coefficient a point can ever have: no path ends below Σ lowest · p a.
    pub(super) fn lowest(&self) -> f64 {
        match &self.weakening {
            Weakening::Curve(points) => points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min),
            _ => self.mu_d,
        }
    }

    /// Whether a point's coefficient never rises as it slips, so that a cascade only lowers the
    /// force (a measured μ(slip) may rise again).
    pub(super) fn only_falls(&self) -> bool {
        !matches!(self.weakening, Weakening::Curve(_))
    }

    /// Whether nothing changes once every point has slipped this far [m].
    pub(super) fn settled(&self, slip: f64) -> bool {
        match &self.weakening {
            Weakening::Instant => true,
            Weakening::Linear(dc) => slip >= *dc,
            Weakening::Curve(points) => slip >= points.last().map_or(0.0, |p| p.0),
        }
    }
}
