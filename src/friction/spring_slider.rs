//! Equal sharing with slip weakening: each element a spring–slider of the stuck stiffness
//! k_t = K_t / n ([`element_stiffness`](super::element_stiffness)), all driven by the common
//! displacement δ. An element carries k_t δ until it reaches mu_s n_i; then it slips by s_i
//! with k_t (δ − s_i) = μ(s_i) n_i. Under a linear weakening over d_c, with a_i = (mu_s − mu_d)
//! n_i / d_c, it slips stably when k_t > a_i, its force falling linearly in δ to mu_d n_i at
//! δ = d_c + mu_d n_i / k_t, and snaps at once to mu_d n_i otherwise (always, for the instant
//! drop, which is the paper's model). The total force is piecewise linear in δ, with downward
//! jumps at the snaps: its largest value is F_S, found exactly at the elements' breakpoints in
//! O(M log M). Beside elastic sharing with the same law, it separates what the elastic
//! interaction does from what the weakening does.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

use serde::Serialize;

use super::onset::{ClassShare, ElementLoads};
use super::slip_law::{SlipLaw, Weakening};
use crate::error::{Error, Result};

/// A stable weakening shorter than this fraction of its δ is taken as a snap.
const RESOLVED: f64 = 1e-6;

/// The onset of sliding under equal sharing with slip weakening.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WeakeningOnset {
    /// N = Σ n_i \[N].
    pub normal_force_n: f64,
    /// F_S: the largest total force along δ \[N] (at a snap, the force just before it).
    pub static_force_n: f64,
    /// δ at F_S \[m].
    pub peak_displacement_m: f64,
    /// The dynamic coefficient mu_d of the law.
    pub mu_d: f64,
    /// At the peak, the paper's classes (count, shares of N and of F_S): the critical
    /// elements, reaching mu_s n_i there;
    pub critical: ClassShare,
    /// the pre-sliding ones, slipped before it (weakening, or at mu_d n_i);
    pub pre_sliding: ClassShare,
    /// the subcritical ones, stuck below mu_s n_i.
    pub subcritical: ClassShare,
}

impl WeakeningOnset {
    /// F_S / N.
    pub fn static_coefficient(&self) -> f64 {
        self.static_force_n / self.normal_force_n
    }

    /// F_S / (mu_d N).
    pub fn friction_drop(&self) -> f64 {
        self.static_coefficient() / self.mu_d
    }
}

/// The onset of the elements `loads` under equal sharing, each element a spring–slider of
/// stiffness `stiffness` k_t \[N/m] with the local law `law` (the instant drop or a linear
/// weakening; a measured μ(slip) is refused).
pub fn spring_slider_onset(loads: &ElementLoads, law: &SlipLaw, stiffness: f64) -> Result<WeakeningOnset> {
    if !(stiffness > 0.0 && stiffness.is_finite()) {
        return Err(Error::invalid("element stiffness", format!("must be positive and finite, got {stiffness} N/m")));
    }
    let dc = match law.weakening {
        Weakening::Instant => 0.0,
        Weakening::Linear(dc) => dc,
        Weakening::Curve(_) => {
            return Err(Error::invalid(
                "equal sharing with slip weakening",
                "takes the instant drop or a slip-weakening distance, not a measured μ(slip)",
            ))
        }
    };
    let k = stiffness;
    let elements: Vec<Element> = loads.sorted().iter().map(|&n| Element::new(n, law, dc, k)).collect();
    // The total force is A + B δ between breakpoints; each event changes A and B at its δ.
    let mut events: Vec<(f64, f64, f64)> = Vec::with_capacity(2 * loads.len());
    for e in &elements {
        match e.stable {
            Some((intercept, slope, end)) => {
                events.push((e.onset, intercept, -k - slope));
                events.push((end, law.mu_d * e.n - intercept, slope));
            }
            None => events.push((e.onset, law.mu_d * e.n, -k)),
        }
    }
    events.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (mut intercept, mut slope) = (0.0, k * loads.len() as f64);
    let (mut best, mut at) = (0.0_f64, 0.0);
    let mut i = 0;
    while i < events.len() {
        let delta = events[i].0;
        // Just before the events at δ (the force before a snap), then just after them.
        let before = intercept + slope * delta;
        if before > best {
            (best, at) = (before, delta);
        }
        while i < events.len() && events[i].0 == delta {
            intercept += events[i].1;
            slope += events[i].2;
            i += 1;
        }
        let after = intercept + slope * delta;
        if after > best {
            (best, at) = (after, delta);
        }
    }
    // Sums of many terms may put the last bits outside [mu_d N, mu_s N], where F_S never is.
    let normal = loads.total();
    let static_force = best.clamp(law.mu_d * normal, law.mu_s * normal);
    // The classes just before the events at the peak's δ: an element whose onset is there
    // reaches mu_s n there (its δ is the same float), an earlier one has slipped.
    let class = |e: &Element| match e.onset.total_cmp(&at) {
        std::cmp::Ordering::Less => Class::PreSliding,
        std::cmp::Ordering::Equal => Class::Critical,
        std::cmp::Ordering::Greater => Class::Subcritical,
    };
    let tally = |which| {
        let each = elements.iter().map(|e| (class(e), e.n, e.force(at, law.mu_d, k)));
        ClassShare::tally(each, which, (normal, static_force))
    };
    Ok(WeakeningOnset {
        normal_force_n: normal,
        static_force_n: static_force,
        peak_displacement_m: at,
        mu_d: law.mu_d,
        critical: tally(Class::Critical),
        pre_sliding: tally(Class::PreSliding),
        subcritical: tally(Class::Subcritical),
    })
}

#[derive(Clone, Copy, PartialEq)]
enum Class {
    Critical,
    PreSliding,
    Subcritical,
}

/// One spring–slider: its normal force n \[N], the δ \[m] at which it reaches mu_s n, and,
/// when it weakens stably, its force A − B δ on the stable branch and the δ where that
/// reaches mu_d n.
struct Element {
    n: f64,
    onset: f64,
    stable: Option<(f64, f64, f64)>,
}

impl Element {
    fn new(n: f64, law: &SlipLaw, dc: f64, k: f64) -> Element {
        let onset = law.mu_s * n / k;
        // The stable weakening's span in δ, d_c (1 − a/k): an element that weakens over less
        // than [`RESOLVED`] of its δ is taken to snap (the others gain at most that fraction
        // of F meanwhile), which spares A and B the terms of order k/(k − a) that cancel.
        let span = dc - (law.mu_s - law.mu_d) * n / k;
        let stable = (span > RESOLVED * (onset + dc)).then(|| {
            // f = mu_s n k/(k − a) − a k/(k − a) δ until it reaches mu_d n at δ = onset +
            // span, with a = (mu_s − mu_d) n / d_c and k − a = k span / d_c.
            let a = (law.mu_s - law.mu_d) * n / dc;
            (law.mu_s * n * dc / span, a * dc / span, onset + span)
        });
        Element { n, onset, stable }
    }

    /// The element's force at δ \[N], just before its events there.
    fn force(&self, delta: f64, mu_d: f64, k: f64) -> f64 {
        match self.stable {
            _ if delta <= self.onset => k * delta,
            Some((intercept, slope, end)) if delta <= end => intercept - slope * delta,
            _ => mu_d * self.n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::friction::law::FrictionLaw;
    use crate::friction::onset::Onset;

    /// One element's force at δ, from its own law: stuck, slipping stably, or weakened.
    fn element_force(n: f64, law: &SlipLaw, k: f64, delta: f64) -> f64 {
        let dc = match law.weakening {
            Weakening::Linear(dc) => dc,
            _ => 0.0,
        };
        if k * delta < law.mu_s * n {
            return k * delta;
        }
        // k (δ − s) = μ(s) n on the stable branch, s < d_c.
        let a = if dc > 0.0 { (law.mu_s - law.mu_d) * n / dc } else { f64::INFINITY };
        let s = (k * delta - law.mu_s * n) / (k - a);
        if k > a && s < dc {
            k * (delta - s)
        } else {
            law.mu_d * n
        }
    }

    /// The largest total force on a grid of δ: approaches F_S from below as the grid refines.
    fn sampled(forces: &[f64], law: &SlipLaw, k: f64, until: f64, points: usize) -> f64 {
        (0..=points)
            .map(|j| until * j as f64 / points as f64)
            .map(|d| forces.iter().map(|&n| element_force(n, law, k, d)).sum::<f64>())
            .fold(0.0, f64::max)
    }

    fn linear(dc: f64) -> SlipLaw {
        SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Linear(dc) }
    }

    #[test]
    fn one_element_peaks_at_mu_s_n() {
        let loads = ElementLoads::from_forces(&[2e-3]).unwrap();
        for dc in [1e-12, 1e-9, 1e-6] {
            let onset = spring_slider_onset(&loads, &linear(dc), 1e4).unwrap();
            assert!((onset.static_force_n / (0.6 * 2e-3) - 1.0).abs() < 1e-14, "{onset:?}");
            assert!((onset.peak_displacement_m / (0.6 * 2e-3 / 1e4) - 1.0).abs() < 1e-14);
            assert!((onset.friction_drop() - 1.5).abs() < 1e-13);
        }
    }

    /// Two elements, n = 1 and 3 mN, k = 10⁴ N/m, d_c = 1 µm: the weaker one slips at δ =
    /// 60 nm and weakens stably (a = 0.2 mN/µm = 200 N/m < k) while the force still rises,
    /// at k − ak/(k − a) = 9 795.9 N/m, until the other reaches mu_s n at 180 nm: F_S =
    /// mu_s n₂ + f₁(180 nm) = 1.8 mN + (0.6·1 mN·k − a k δ)/(k − a) = 2.375510 mN. With
    /// d_c = 1 nm the weaker one snaps to mu_d n₁ at once: F_S = max(2 k δ₁, 0.4 + 1.8 mN) =
    /// 2.2 mN.
    #[test]
    fn two_elements_match_the_closed_form() {
        let loads = ElementLoads::from_forces(&[1e-3, 3e-3]).unwrap();
        let k = 1e4;
        let stable = spring_slider_onset(&loads, &linear(1e-6), k).unwrap();
        let a = 0.2e-3 / 1e-6;
        let expected = 1.8e-3 + (0.6e-3 * k - a * k * 180e-9) / (k - a);
        assert!((stable.static_force_n / expected - 1.0).abs() < 1e-13, "{stable:?} {expected}");
        assert!((stable.peak_displacement_m / 180e-9 - 1.0).abs() < 1e-12);
        // At the peak the stronger one is critical, the weaker one weakening: F_S − 1.8 mN.
        assert_eq!((stable.critical.count, stable.pre_sliding.count, stable.subcritical.count), (1, 1, 0));
        assert!((stable.critical.normal_fraction - 0.75).abs() < 1e-15);
        assert!((stable.critical.friction_fraction - 1.8e-3 / expected).abs() < 1e-12, "{stable:?}");
        assert!((stable.pre_sliding.friction_fraction - (expected - 1.8e-3) / expected).abs() < 1e-11);
        let snapping = spring_slider_onset(&loads, &linear(1e-9), k).unwrap();
        assert!((snapping.static_force_n / 2.2e-3 - 1.0).abs() < 1e-13, "{snapping:?}");
        // The weaker one at mu_d n₁ = 0.4 of 2.2 mN.
        assert_eq!((snapping.critical.count, snapping.pre_sliding.count), (1, 1));
        assert!((snapping.pre_sliding.friction_fraction - 0.4 / 2.2).abs() < 1e-12, "{snapping:?}");
    }

    /// The instant drop is the paper's equal sharing, to the last bits, for any stiffness.
    #[test]
    fn the_instant_drop_is_the_papers_model() {
        let forces: Vec<f64> = (0..500).map(|i| 1e-6 * (1.0 + ((i * 7919) % 997) as f64 / 97.0)).collect();
        let loads = ElementLoads::from_forces(&forces).unwrap();
        let paper = Onset::new(&loads, &FrictionLaw::new(0.6, 0.4).unwrap());
        for k in [1.0, 1e3, 1e6] {
            let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Instant };
            let onset = spring_slider_onset(&loads, &law, k).unwrap();
            assert!((onset.static_force_n / paper.static_force - 1.0).abs() < 1e-12, "{k}: {onset:?}");
            let pairs = [
                (onset.critical, paper.critical),
                (onset.pre_sliding, paper.pre_sliding),
                (onset.subcritical, paper.subcritical),
            ];
            for (ours, theirs) in pairs {
                assert_eq!(ours.count, theirs.count, "{k}: {onset:?} {paper:?}");
                assert!((ours.normal_fraction - theirs.normal_fraction).abs() < 1e-12, "{ours:?} {theirs:?}");
                assert!((ours.friction_fraction - theirs.friction_fraction).abs() < 1e-12, "{ours:?} {theirs:?}");
            }
        }
    }

    /// Many elements, stable and snapping ones mixed, against the force sampled on a fine grid
    /// of δ: F_S from the breakpoints is the sampled largest force to within the grid's
    /// resolution, k_t M Δδ, and never below it.
    #[test]
    fn many_elements_match_the_sampled_force() {
        let forces: Vec<f64> = (0..40).map(|i| 1e-4 * (1.0 + ((i * 37) % 23) as f64)).collect();
        let loads = ElementLoads::from_forces(&forces).unwrap();
        let k = 2e3;
        for dc in [1e-9, 3e-9, 1e-8, 1e-7] {
            let law = linear(dc);
            let onset = spring_slider_onset(&loads, &law, k).unwrap();
            let until = 2.0 * onset.peak_displacement_m + 2.0 * dc;
            let points = 400_000;
            let grid = sampled(&forces, &law, k, until, points);
            let resolution = k * forces.len() as f64 * until / points as f64;
            assert!(onset.static_force_n >= grid * (1.0 - 1e-12), "{dc}: {onset:?} {grid}");
            assert!(onset.static_force_n - grid <= resolution, "{dc}: {} {grid} {resolution}", onset.static_force_n);
        }
    }

    #[test]
    fn a_measured_curve_is_refused() {
        let loads = ElementLoads::from_forces(&[1e-3]).unwrap();
        let law = SlipLaw { mu_s: 0.6, mu_d: 0.4, weakening: Weakening::Curve(vec![(0.0, 0.6), (1e-9, 0.4)]) };
        let e = spring_slider_onset(&loads, &law, 1e4).unwrap_err().to_string();
        assert!(e.contains("not a measured μ(slip)"), "{e}");
    }
}
