//! `[model]`: how the tangential force is shared among the contact elements ([`Sharing`]), and
//! elastic sharing's slip weakening with the band of slip-weakening distances around it.
//!
//! Of the study file it may import only `defaults`, `quantities`, `places` and `laws`; it must
//! not import `config/mod.rs`, which ties the sections, nor the study's runner, `plot`,
//! `report`, `cli` or `python`.

use serde::{Deserialize, Serialize};

use super::laws::LawSpec;
use super::places::{at, key, Checked, Segment};
use super::quantities::Length;
use crate::error::Result;
use crate::friction::{slip_curve_file, Weakening, DEFAULT_SLIP_DISTANCE_M};
use crate::plausible::{self, Spelling};
use crate::quantity;

/// How the tangential force is shared among the contact elements at the onset of sliding.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Sharing {
    /// Equally among the stuck elements: the paper's model ([`Onset`](crate::friction::Onset)).
    #[default]
    Equal,
    /// Through the elastic half-space, each element's shear following from the constrained
    /// tangential solve ([`crate::friction::elastic_onset`]).
    Elastic,
}

impl Sharing {
    /// The name of the sharing in the study file and the results.
    pub fn name(self) -> &'static str {
        match self {
            Sharing::Equal => "equal",
            Sharing::Elastic => "elastic",
        }
    }
}

/// The friction model's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[serde(expecting = "the [model] table")]
pub struct ModelSpec {
    /// How the tangential force is shared among the contact elements: each listed sharing
    /// gives its own rows (the `sharing` column), in this order.
    #[serde(default = "equal_sharing")]
    pub sharing: Vec<Sharing>,
    /// Elastic sharing's slip-weakening distance d_c \[m]: μ falls linearly from mu_s to mu_d
    /// over an accumulated slip d_c (0: at once on the first slip, the paper's law, whose
    /// onset depends on the pixel). A `curve` law with its `curve_unit` follows its curve.
    #[serde(default = "default_slip_distance")]
    pub slip_distance: Length,
    /// Two slip-weakening distances \[m], low < `slip_distance` < high: the models that weaken
    /// over d_c (elastic sharing, equal sharing with the same weakening) are computed at each
    /// end too, for laws without a measured curve. None: d_c alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_distance_band: Option<Vec<Length>>,
}

impl Default for ModelSpec {
    fn default() -> Self {
        ModelSpec { sharing: equal_sharing(), slip_distance: default_slip_distance(), slip_distance_band: None }
    }
}

impl ModelSpec {
    pub(super) fn is_default(&self) -> bool {
        *self == ModelSpec::default()
    }

    /// The slip weakening of elastic sharing for the law `spec` (checked, paths resolved): its
    /// measured curve past the peak when it gives a `curve_unit`, else a linear fall over
    /// `slip_distance`, or the instant drop for a `slip_distance` of 0. Reads the curve file.
    pub fn weakening(&self, spec: &LawSpec) -> Result<Weakening> {
        match (&spec.curve, spec.curve_unit) {
            (Some(path), Some(unit)) => Ok(Weakening::Curve(slip_curve_file(path, unit.0)?)),
            _ if self.slip_distance.0 == 0.0 => Ok(Weakening::Instant),
            _ => Ok(Weakening::Linear(self.slip_distance.0)),
        }
    }

    /// The sharings, each listed once, and the slip-weakening distance.
    pub(super) fn check(&self) -> Checked {
        let sharing = &self.sharing;
        let path = [key("model"), key("sharing")];
        if sharing.is_empty() {
            return at(&path, "the list is empty: give \"equal\", \"elastic\" or both".into());
        }
        if let Some(i) = (1..sharing.len()).find(|&i| sharing[..i].contains(&sharing[i])) {
            let mut path = path.to_vec();
            path.push(Segment::Index(i));
            return at(&path, format!("\"{}\" is listed twice", sharing[i].name()));
        }
        let dc = self.slip_distance.0;
        if !(dc >= 0.0 && dc.is_finite()) {
            return at(
                &[key("model"), key("slip_distance")],
                format!("{} is not a length ≥ 0 (0: instant drop)", quantity::show(dc, &quantity::LENGTH)),
            );
        }
        plausible::slip_distance(dc, Spelling::StudyFile)
            .map(drop)
            .or_else(|r| at(&[key("model"), key("slip_distance")], r))?;
        let Some(band) = &self.slip_distance_band else { return Ok(()) };
        let path = [key("model"), key("slip_distance_band")];
        if !sharing.contains(&Sharing::Elastic) {
            return at(&path, "a band of d_c needs elastic sharing: add \"elastic\" to [model] sharing".into());
        }
        if band.len() != 2 {
            return at(&path, format!("give two lengths, low and high, not {}", band.len()));
        }
        for (i, Length(d)) in band.iter().enumerate() {
            let mut path = path.to_vec();
            path.push(Segment::Index(i));
            if !(*d > 0.0 && d.is_finite()) {
                return at(&path, format!("{d} m is not a positive length"));
            }
            plausible::slip_distance(*d, Spelling::StudyFile).map(drop).or_else(|r| at(&path, r))?;
        }
        let (low, high) = (band[0].0, band[1].0);
        if !(low < dc && dc < high) {
            let show = |m: f64| quantity::show(m, &quantity::LENGTH);
            let reason = format!(
                "[{}, {}] does not bracket slip_distance = {}: give low < slip_distance < high",
                show(low),
                show(high),
                show(dc)
            );
            return at(&path, reason);
        }
        Ok(())
    }

    /// The slip-weakening distances \[m] the band adds, low then high (none without one).
    pub fn band(&self) -> Vec<f64> {
        self.slip_distance_band.iter().flatten().map(|l| l.0).collect()
    }
}

fn default_slip_distance() -> Length {
    Length(DEFAULT_SLIP_DISTANCE_M)
}

fn equal_sharing() -> Vec<Sharing> {
    vec![Sharing::Equal]
}
