//! What an SHS analysis is asked and what it yields: the options ([`ShsOptions`]), each
//! restart ([`Cycle`]), the restarts grouped by hold time ([`Group`], [`group_by_hold`]), the
//! holds skipped, and the whole [`Analysis`]. Forces in newtons, lengths in metres, times in
//! seconds.
//!
//! Must not import the other files of shs (they build on it), nor topography, contact,
//! friction, study, plot or report.

use serde::{Serialize, Serializer};

use crate::error::{Error, Result};

/// How restarts are found and measured. Lengths in metres, times in seconds.
#[derive(Clone, Debug)]
pub struct ShsOptions {
    /// Sliding speed [m/s], for displacement derived from time when the trace has none.
    pub speed: f64,
    /// Sliding displacement after the peak over which F_D and N are averaged \[m].
    pub window: f64,
    /// Sliding displacement from the peak to the start of that window \[m] (0: at the peak),
    /// to leave out the fall from F_S to steady sliding.
    pub window_start: f64,
    /// Sliding displacement after the restart within which the peak F_S is sought \[m].
    pub peak_within: f64,
    /// Shortest hold and shortest slide \[s]: briefer stops, dips or bursts are noise; each hold
    /// so dropped is reported among the skipped.
    pub min_duration: f64,
    /// Friction below this fraction of the sliding level is near zero: a hold (without a
    /// displacement column).
    pub hold_fraction: f64,
    /// Friction above this fraction of the sliding level is sliding: a restart (without a
    /// displacement column).
    pub slide_fraction: f64,
    /// Hold times within this relative spread of a group's shortest join that group.
    pub group_tolerance: f64,
}

impl Default for ShsOptions {
    fn default() -> Self {
        ShsOptions {
            speed: 0.3e-6,
            window: 1e-6,
            window_start: 0.0,
            peak_within: 2e-6,
            min_duration: 1.0,
            hold_fraction: 0.2,
            slide_fraction: 0.5,
            group_tolerance: 0.25,
        }
    }
}

impl ShsOptions {
    /// Check every value; errors name the command-line option.
    pub fn validate(&self) -> Result<()> {
        let positive = [
            ("--speed", self.speed, "m/s"),
            ("--window", self.window, "m"),
            ("--peak-within", self.peak_within, "m"),
            ("--min-duration", self.min_duration, "s"),
        ];
        for (option, v, unit) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(option, format!("{v} {unit} must be positive")));
            }
        }
        if !(0.0 < self.hold_fraction && self.hold_fraction < self.slide_fraction && self.slide_fraction < 1.0) {
            return Err(Error::invalid(
                "--hold-fraction/--slide-fraction",
                format!("need 0 < {} < {} < 1", self.hold_fraction, self.slide_fraction),
            ));
        }
        if !(self.window_start.is_finite() && self.window_start >= 0.0) {
            return Err(Error::invalid("--window-start", format!("{} m must be ≥ 0", self.window_start)));
        }
        if !(self.group_tolerance.is_finite() && self.group_tolerance >= 0.0) {
            return Err(Error::invalid("--group-tolerance", format!("{} must be ≥ 0", self.group_tolerance)));
        }
        Ok(())
    }
}

/// One restart after a hold. Forces in newtons, times in seconds from the trace's clock.
#[derive(Clone, Debug, Serialize)]
pub struct Cycle {
    /// The hold before the restart \[s]: from the stage stopping to its moving again when the
    /// trace records displacement, else the time the friction spends near zero.
    pub hold_s: f64,
    /// F_S: the friction peak after the restart \[N].
    pub static_force_n: f64,
    /// F_D: mean friction over the window after the peak \[N].
    pub dynamic_force_n: f64,
    /// N: mean normal force over the same window \[N].
    pub normal_force_n: f64,
    /// mu_s = F_S / N.
    pub static_coefficient: f64,
    /// mu_d = F_D / N.
    pub dynamic_coefficient: f64,
    /// F_S / F_D (= mu_s / mu_d).
    pub friction_drop: f64,
    /// When the hold began \[s]: the stage stopped (between samples), or the friction had
    /// settled near zero.
    pub hold_start_s: f64,
    /// When the hold ended \[s]: the stage moved again (between samples), or half a sample after
    /// the last sample at the hold's friction level.
    pub restart_s: f64,
    /// The sample of the peak F_S \[s].
    pub peak_s: f64,
    /// The first sample of the dynamic window \[s] (the peak's when it starts there).
    pub window_start_s: f64,
    /// The last sample of the dynamic window \[s].
    pub window_end_s: f64,
}

/// Mean and sample standard deviation of one quantity over a group's restarts (`std` is
/// `None` for a single restart).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stat {
    /// Mean over the restarts, in the quantity's unit.
    pub mean: f64,
    /// Sample standard deviation (n − 1 in the denominator), in the quantity's unit.
    pub std: Option<f64>,
}

impl Stat {
    fn of(values: impl Iterator<Item = f64> + Clone) -> Stat {
        let n = values.clone().count() as f64;
        let mean = values.clone().sum::<f64>() / n;
        let std = (n > 1.0).then(|| (values.map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt());
        Stat { mean, std }
    }
}

/// Restarts after holds of similar length, summarised.
#[derive(Clone, Debug, Serialize)]
pub struct Group {
    /// Restarts in the group.
    pub n_restarts: usize,
    /// Hold time \[s].
    pub hold_s: Stat,
    /// F_S, the friction peak after the restart \[N].
    pub static_force_n: Stat,
    /// F_D, the mean friction over the window after the peak \[N].
    pub dynamic_force_n: Stat,
    /// N, the mean normal force over that window \[N].
    pub normal_force_n: Stat,
    /// mu_s = F_S / N.
    pub static_coefficient: Stat,
    /// mu_d = F_D / N.
    pub dynamic_coefficient: Stat,
    /// F_S / F_D.
    pub friction_drop: Stat,
}

/// What a trace yields: how many holds it has and what they were found on, its restarts in
/// time order, their groups by hold time (shortest first), and the holds that gave no
/// measurement, each with the reason (in time order).
#[derive(Clone, Debug, Serialize)]
pub struct Analysis {
    /// `"displacement"` (the stage stopped) or `"friction"` (the force near zero).
    pub holds_from: &'static str,
    /// Holds after a slide, those skipped included (one shorter than the minimum duration too).
    pub holds_found: usize,
    /// Every measured restart, in time order.
    pub cycles: Vec<Cycle>,
    /// The restarts grouped by hold time, shortest hold first.
    pub groups: Vec<Group>,
    /// The holds that gave no measurement, in time order.
    pub skipped: Vec<Skipped>,
}

/// A hold found but not measured: too short, or no complete restart after it. Serialised as
/// its reason alone.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    /// When the hold began \[s].
    pub start_s: f64,
    /// When the hold ended \[s] (the end of the trace for a hold it ends in).
    pub end_s: f64,
    /// Why it gave no measurement, starting with when it began ("hold from 12.50 s: …").
    pub reason: String,
}

impl Serialize for Skipped {
    fn serialize<S: Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.reason)
    }
}

/// Group restarts by hold time: sorted by hold, a restart joins the current group while its
/// hold is within `tolerance` (relative) of the group's shortest.
pub fn group_by_hold(cycles: &[Cycle], tolerance: f64) -> Vec<Group> {
    let mut sorted: Vec<&Cycle> = cycles.iter().collect();
    sorted.sort_by(|a, b| a.hold_s.total_cmp(&b.hold_s));
    let mut groups: Vec<Vec<&Cycle>> = Vec::new();
    for c in sorted {
        match groups.last_mut() {
            Some(g) if c.hold_s <= g[0].hold_s * (1.0 + tolerance) => g.push(c),
            _ => groups.push(vec![c]),
        }
    }
    groups
        .into_iter()
        .map(|g| {
            let stat = |q: fn(&Cycle) -> f64| Stat::of(g.iter().map(|c| q(c)));
            Group {
                n_restarts: g.len(),
                hold_s: stat(|c| c.hold_s),
                static_force_n: stat(|c| c.static_force_n),
                dynamic_force_n: stat(|c| c.dynamic_force_n),
                normal_force_n: stat(|c| c.normal_force_n),
                static_coefficient: stat(|c| c.static_coefficient),
                dynamic_coefficient: stat(|c| c.dynamic_coefficient),
                friction_drop: stat(|c| c.friction_drop),
            }
        })
        .collect()
}
