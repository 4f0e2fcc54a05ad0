//! `[[law]]`: the local (element-scale) friction laws — a pair of coefficients, a preset, a
//! measured curve, or an aging law over hold times — their names and checks.
//!
//! Of the study file it may import only `defaults`, `quantities` and `places`; it must not
//! import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`, `report`,
//! `cli` or `python`.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::places::{at, key, reason_of, Checked, Segment};
use super::quantities::{Length, Time};
use crate::friction::FrictionLaw;
use crate::plausible;

/// A local friction law: `name` + `mu_s` + `mu_d`, a `preset`, or a measured `curve`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "a [[law]] table: { mu_s, mu_d }, a preset or a curve")]
pub struct LawSpec {
    /// The law's label in the results (relabels a preset; a curve's default is its file name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Local static coefficient mu_s (≥ mu_d).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_s: Option<f64>,
    /// Local dynamic coefficient mu_d (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_d: Option<f64>,
    /// A named (mu_s, mu_d) pair, such as `"hold 100 s"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// A measured nanoscale friction curve (CSV of displacement, friction coefficient): mu_s is
    /// its peak, mu_d its mean past the peak.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<PathBuf>,
    /// (start, end) past the curve's peak over which mu_d is averaged, in the curve's
    /// displacement unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<(f64, f64)>,
    /// The displacement unit of `curve` as a length \[m]: with it, elastic sharing follows the
    /// curve past its peak as μ(slip) (the curve's own slip weakening) instead of
    /// `[model] slip_distance`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve_unit: Option<Length>,
    /// The AFM hold time the law was measured at \[s] (t₀ of an aging law).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold_time: Option<Time>,
    /// β of an aging law, mu_s(t) = mu_s(t₀) + β·log10(t/t₀) with mu_d fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aging: Option<f64>,
    /// The hold times \[s] an aging law is evaluated at: one law of the study each.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hold_times: Option<Vec<Time>>,
}

impl LawSpec {
    /// The law's name: its `name`, else its preset's, else its curve file's as written, else
    /// its coefficients ("mu_s 0.6, mu_d 0.4").
    pub fn name(&self) -> String {
        match (&self.name, &self.preset, &self.curve) {
            (Some(n), ..) => n.clone(),
            (None, Some(p), _) => p.clone(),
            (None, None, Some(c)) => c.display().to_string(),
            (None, None, None) => match (self.mu_s, self.mu_d) {
                (Some(mu_s), Some(mu_d)) => format!("mu_s {mu_s}, mu_d {mu_d}"),
                _ => String::new(),
            },
        }
    }

    /// The names of the laws this spec gives the study: its name, or for an aging law one
    /// per hold time ("hold 10 s", or "NAME, hold 10 s" when it has a name).
    pub fn names(&self) -> Vec<String> {
        match &self.hold_times {
            Some(times) => times
                .iter()
                .map(|t| match &self.name {
                    Some(n) => format!("{n}, hold {} s", t.0),
                    None => format!("hold {} s", t.0),
                })
                .collect(),
            None => vec![self.name()],
        }
    }

    /// The hold time of a law given by this spec: its `hold_time`, or the one a preset's name
    /// states ("hold 100 s").
    pub fn stated_hold_time(&self) -> Option<f64> {
        self.hold_time.map(|t| t.0).or_else(|| {
            let preset = self.preset.as_deref()?;
            preset.strip_prefix("hold ")?.strip_suffix(" s")?.parse().ok()
        })
    }

    fn check(&self) -> std::result::Result<(), String> {
        for (key, mu) in [("mu_s", self.mu_s), ("mu_d", self.mu_d)] {
            if let Some(mu) = mu {
                plausible::friction_coefficient(mu).map_err(|r| format!("{key}: {r}"))?;
            }
        }
        if let Some(t) = self.hold_time {
            if t.0.is_nan() || t.0 <= 0.0 {
                return Err(format!("hold_time: {} s is not positive", t.0));
            }
        }
        if self.curve_unit.is_some() && self.curve.is_none() {
            return Err("`curve_unit` applies to a `curve` only".into());
        }
        if self.aging.is_some() || self.hold_times.is_some() {
            return self.check_aging();
        }
        match (self.mu_s, self.mu_d, &self.preset, &self.curve) {
            (Some(mu_s), Some(mu_d), None, None) => {
                if self.window.is_some() {
                    return Err("`window` applies to a `curve` only".into());
                }
                FrictionLaw::new(mu_s, mu_d).map(drop).map_err(reason_of)
            }
            (None, None, Some(preset), None) => {
                if self.window.is_some() {
                    return Err("`window` applies to a `curve` only".into());
                }
                FrictionLaw::preset(preset).map(drop).map_err(reason_of)
            }
            (None, None, None, Some(_)) if self.curve_unit.is_some_and(|u| !(u.0 > 0.0 && u.0.is_finite())) => {
                Err(format!("curve_unit: {} m is not a positive length", self.curve_unit.map_or(0.0, |u| u.0)))
            }
            (None, None, None, Some(_)) => match self.window {
                Some((start, end)) if !(start >= 0.0 && start < end && end.is_finite()) => {
                    Err(format!("window must be [start, end] with 0 ≤ start < end, got [{start}, {end}]"))
                }
                _ => Ok(()),
            },
            _ => Err("give exactly one of `mu_s` and `mu_d` (with `name`), `preset` or `curve`".into()),
        }
    }

    /// An aging law: mu_s at `hold_time`, mu_d, `aging` and `hold_times`, nothing else.
    fn check_aging(&self) -> std::result::Result<(), String> {
        let (Some(mu_s), Some(mu_d), Some(t0), Some(beta), Some(times)) =
            (self.mu_s, self.mu_d, self.hold_time, self.aging, &self.hold_times)
        else {
            return Err("an aging law needs mu_s (at hold_time), mu_d, hold_time, aging and hold_times".into());
        };
        if self.preset.is_some() || self.curve.is_some() || self.window.is_some() {
            return Err("an aging law is given by mu_s, mu_d, hold_time, aging and hold_times only".into());
        }
        if times.is_empty() {
            return Err("hold_times is empty".into());
        }
        for (i, t) in times.iter().enumerate() {
            if t.0.is_nan() || t.0 <= 0.0 {
                return Err(format!("hold_times: {} s is not positive", t.0));
            }
            if times[..i].contains(t) {
                return Err(format!("hold_times: {} s is listed twice", t.0));
            }
            FrictionLaw::aged(mu_s, mu_d, t0.0, beta, t.0).map(drop).map_err(reason_of)?;
        }
        Ok(())
    }
}

/// The `[[law]]` tables: at least one, each checked, every law they give named once.
pub(super) fn check_laws(laws: &[LawSpec]) -> Checked {
    if laws.is_empty() {
        return at(&[key("law")], "no friction law: give at least one [[law]]".into());
    }
    for (i, law) in laws.iter().enumerate() {
        let here = [key("law"), Segment::Index(i)];
        law.check().or_else(|r| at(&here, r))?;
        let (earlier, mine): (Vec<String>, Vec<String>) =
            (laws[..i].iter().flat_map(|o| o.names()).collect(), law.names());
        for (k, name) in mine.iter().enumerate() {
            if earlier.contains(name) || mine[..k].contains(name) {
                return at(&here, format!("the name \"{name}\" is used twice"));
            }
        }
    }
    Ok(())
}
