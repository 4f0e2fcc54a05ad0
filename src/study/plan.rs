//! The prepared study, [`Study`] (every topography built, every law resolved), and what it
//! computes from its config alone: its sweeps (a topography or a coarser copy, elastic or
//! plastic) and the pieces of their load chains a run takes, the rows of each solve
//! (sharings × laws, and the band of d_c: [`Slot`]), the elastic onsets each solve runs, the estimated work of a
//! solve, the loads whose maps the figures keep, and the figures' other counterface.
//!
//! Nothing here touches the disk. The runner's other rooms build on it; it must import none of
//! them, nor `plot`, `report`, `cli` or `python`.

use super::config::{Counterface, StudyConfig};
use super::shard::{self, Piece, Shard};
use super::{Sharing, FIGURE_LOADS_N};
use crate::contact::CohesiveLaw;
use crate::friction::{FrictionLaw, SlipLaw, Weakening};
use crate::quantity::{show, PRESSURE};
use crate::topography::Topography;

/// A study ready to run: every topography built, every law resolved.
pub struct Study {
    /// Names the study in errors (its file, or "default study").
    pub(super) origin: String,
    /// The study as run.
    pub(super) config: StudyConfig,
    pub(super) topographies: Vec<(String, Topography)>,
    /// (topography index, coarsening, the topography resampled) for the resolution figure.
    pub(super) coarse: Vec<(usize, usize, Topography)>,
    /// The digest of each sweep unit's topography as built (the topographies, then the
    /// coarser copies), part of its solves' identity ([`Study::stem`]).
    pub(super) digests: Vec<String>,
    pub(super) laws: Vec<FrictionLaw>,
    /// Each law's slip weakening under elastic sharing ([`super::config::ModelSpec::weakening`]).
    pub(super) weakenings: Vec<Weakening>,
    /// The hold time [s] of each law, where known.
    pub(super) hold_times: Vec<Option<f64>>,
    /// Loads [N], ascending.
    pub(super) loads: Vec<f64>,
    /// Wait for work another process holds, instead of refusing it.
    pub(super) wait: bool,
    /// Solve only this shard's share, and write no table or figures.
    pub(super) shard: Option<Shard>,
    /// Loads that press a read topography's window unusually hard ([`Study::warnings`]).
    pub(super) warnings: Vec<String>,
}

/// One row of each solve: its sharing, the index of its law, and its slip-weakening distance
/// d_c [m] (0: the instant drop; none: the law's measured curve).
#[derive(Clone, Copy, PartialEq)]
pub(super) struct Slot {
    pub(super) sharing: Sharing,
    pub(super) law: usize,
    pub(super) slip_distance: Option<f64>,
}

impl Study {
    /// How many units of solves the study records: one per topography, for the resolution
    /// figure one per topography and coarsening, and with adhesion one more per topography
    /// (the adhesive solves, after the coarser copies, solved by their topography's sweep).
    pub(super) fn units(&self) -> usize {
        let adhesive = if self.config.contact.adhesion.is_some() { self.topographies.len() } else { 0 };
        self.topographies.len() + self.coarse.len() + adhesive
    }

    /// Whether unit `u` solves with adhesion.
    pub(super) fn adhesive(&self, u: usize) -> bool {
        u >= self.topographies.len() + self.coarse.len()
    }

    /// The adhesive unit that topography `u`'s sweep solves beside its own, load by load, each
    /// adhesive solve starting from the solve without adhesion at its load; none without
    /// adhesion (nor for a coarser copy).
    pub(super) fn adhesive_unit(&self, u: usize) -> Option<usize> {
        (self.config.contact.adhesion.is_some() && u < self.topographies.len())
            .then(|| u + self.topographies.len() + self.coarse.len())
    }

    /// The index of sweep `u`'s topography as built among [`Study::digests`]'s: an adhesive
    /// sweep solves its topography's.
    pub(super) fn built(&self, u: usize) -> usize {
        if self.adhesive(u) {
            u - self.topographies.len() - self.coarse.len()
        } else {
            u
        }
    }

    /// The cohesive law of the adhesive units, if the study has them.
    pub(super) fn cohesive_law(&self) -> Option<CohesiveLaw> {
        self.config.contact.adhesion.as_ref().map(|a| a.cohesive_law().expect("checked with the study file"))
    }

    /// Unit `u`'s grid points: the weight of a solve in the time left and in the shards'
    /// shares, an adhesive one as one without (started from it, it costs about as much:
    /// docs/adhesion.md, "Cost").
    fn weighted_points(&self, u: usize) -> usize {
        self.unit(u).2.heights.len()
    }

    /// Sweep `u`'s grid points, weighted by the cost of its solves at one load: its own and its
    /// adhesive unit's.
    fn sweep_points(&self, u: usize) -> usize {
        self.weighted_points(u) + self.adhesive_unit(u).map_or(0, |a| self.weighted_points(a))
    }

    /// Sweep `u`'s name in progress reports, folder under `solves/`, topography, and the name
    /// of its rows.
    pub(super) fn unit(&self, u: usize) -> (String, String, &Topography, &str) {
        match u.checked_sub(self.topographies.len()) {
            None => {
                let (name, topo) = &self.topographies[u];
                (name.clone(), name.clone(), topo, name)
            }
            Some(_) if self.adhesive(u) => {
                let (name, topo) = &self.topographies[self.built(u)];
                (format!("{name} (adhesive)"), format!("{name}/adhesive"), topo, name)
            }
            Some(c) => {
                let (t, factor, topo) = &self.coarse[c];
                let name = &self.topographies[*t].0;
                (format!("{name} ({factor}× coarser)"), format!("{name}@{factor}x"), topo, name)
            }
        }
    }

    /// E*₀/E* for E − ΔE and E + ΔE of `material.youngs_uncertainty` (none without it).
    pub(super) fn modulus_ratios(&self) -> Vec<f64> {
        let Some(delta) = self.config.material.youngs_uncertainty else { return Vec::new() };
        let e0 = self.config.effective_modulus();
        [-1.0, 1.0]
            .iter()
            .filter_map(|sign| {
                let mut config = self.config.clone();
                config.material.youngs.0 += sign * delta.0;
                (config.material.youngs.0 > 0.0).then(|| e0 / config.effective_modulus())
            })
            .collect()
    }

    /// The estimated work of unit `u`'s solve at load `k`, for the time left: its grid points
    /// times 1 + the decades its load lies above the study's lowest. A solve's time grows with
    /// its grid, and its iterations with its load (on the default study, 20–40 from 1 to
    /// 100 µN, 99 at 100 mN, warm-started).
    pub(super) fn solve_work(&self, u: usize, k: usize) -> u64 {
        let lowest = self.loads.iter().copied().fold(f64::INFINITY, f64::min);
        let decades = (self.loads[k] / lowest).log10().max(0.0);
        (self.weighted_points(u) as f64 * (1.0 + decades)).round() as u64
    }

    /// The other counterface of the friction-drop figure: the same material when the study's
    /// is the paper's rigid flat, the rigid flat when it is the same material; its
    /// description and E*₀/E*.
    pub(super) fn other_counterface(&self) -> Option<(String, f64)> {
        let mut other = self.config.clone();
        let name = match self.config.material.counterface {
            Counterface::Rigid => {
                other.material.counterface = Counterface::Same;
                "the same material"
            }
            Counterface::Same => {
                other.material.counterface = Counterface::Rigid;
                "a rigid flat"
            }
            Counterface::Body { .. } => return None,
        };
        let e = other.effective_modulus();
        Some((format!("{name}, E* = {}", show(e, &PRESSURE)), self.config.effective_modulus() / e))
    }

    /// This run's pieces of work ([`shard::assign`]): every sweep's whole chain, or a shard's
    /// share. Indices into [`Study::sweeps`].
    pub(super) fn pieces(&self) -> Vec<Piece> {
        let points: Vec<usize> = self.sweeps().iter().map(|&(u, _)| self.sweep_points(u)).collect();
        let shard = self.shard.unwrap_or(Shard { index: 1, count: 1 });
        shard::assign(&points, self.loads.len(), shard.count).swap_remove(shard.index - 1)
    }

    /// The sweeps of the run, (unit, plastic): every topography in each kind of solve listed
    /// (with its adhesive unit, elastic: the study file refuses adhesion with a plastic solve),
    /// then the coarser copies of the resolution figure in the first kind only: the costly
    /// sweeps first, the cheap ones filling in at the end.
    pub(super) fn sweeps(&self) -> Vec<(usize, bool)> {
        let modes = self.config.contact.plastic.modes();
        let main =
            (0..self.topographies.len()).flat_map(|t| modes.clone().into_iter().map(move |plastic| (t, plastic)));
        let coarse = self.topographies.len()..self.topographies.len() + self.coarse.len();
        main.chain(coarse.map(|u| (u, modes[0]))).collect()
    }

    /// The units whose solves the study records, (unit, plastic), in the order of its rows:
    /// the sweeps', the adhesive units after the coarser copies.
    pub(super) fn recorded_units(&self) -> Vec<(usize, bool)> {
        let modes = self.config.contact.plastic.modes();
        let adhesive = (0..self.topographies.len()).filter_map(|u| self.adhesive_unit(u)).map(|a| (a, modes[0]));
        self.sweeps().into_iter().chain(adhesive).collect()
    }

    /// The sharings of sweep `u`'s rows: the study's, or for a coarser copy of the resolution
    /// figure equal sharing only.
    pub(super) fn sharings(&self, u: usize) -> &[Sharing] {
        if u < self.topographies.len() || self.adhesive(u) {
            &self.config.model.sharing
        } else {
            &[Sharing::Equal]
        }
    }

    /// The elastic-sharing onsets of each solve of sweep `u`: one per elastic row of its layout.
    pub(super) fn onsets_per_solve(&self, u: usize) -> usize {
        self.layout(u).iter().filter(|s| s.sharing == Sharing::Elastic).count()
    }

    /// Rows of a solve of the study's own grid ([`Study::layout`]).
    pub(super) fn rows_per_solve(&self) -> usize {
        self.layout(0).len()
    }

    /// The rows of each solve of sweep `u`, in order: per sharing listed, one per law; before
    /// the elastic ones, per law with a slip-weakening distance, equal sharing under the same
    /// weakening, so that the interaction and the weakening show apart; last, at each end of
    /// the band of d_c, equal then elastic sharing for those laws.
    pub(super) fn layout(&self, u: usize) -> Vec<Slot> {
        let laws = 0..self.laws.len();
        let linear = |l: &usize| matches!(self.weakenings[*l], Weakening::Linear(_));
        let at = |sharing, d: f64| move |l| Slot { sharing, law: l, slip_distance: Some(d) };
        let dc = self.config.model.slip_distance.0;
        let mut slots = Vec::new();
        for &sharing in self.sharings(u) {
            if sharing == Sharing::Elastic {
                slots.extend(laws.clone().filter(linear).map(at(Sharing::Equal, dc)));
            }
            let slip_distance = |l: usize| match (sharing, &self.weakenings[l]) {
                (Sharing::Equal, _) | (_, Weakening::Instant) => Some(0.0),
                (_, Weakening::Linear(d)) => Some(*d),
                (_, Weakening::Curve(_)) => None,
            };
            slots.extend(laws.clone().map(|l| Slot { sharing, law: l, slip_distance: slip_distance(l) }));
        }
        if self.sharings(u).contains(&Sharing::Elastic) {
            for d in self.config.model.band() {
                for sharing in [Sharing::Equal, Sharing::Elastic] {
                    slots.extend(laws.clone().filter(linear).map(at(sharing, d)));
                }
            }
        }
        slots
    }

    /// The local law of `slot`'s weakening models: mu_s to mu_d over the slot's slip-weakening
    /// distance, or along the law's measured curve, or at once.
    pub(super) fn slip_law(&self, slot: &Slot) -> SlipLaw {
        let law = &self.laws[slot.law];
        let weakening = match (&self.weakenings[slot.law], slot.slip_distance) {
            (Weakening::Linear(_), Some(d)) => Weakening::Linear(d),
            (w, _) => w.clone(),
        };
        SlipLaw { mu_s: law.mu_s, mu_d: law.mu_d, weakening }
    }

    /// Indices of the swept loads nearest (in log scale) to [`FIGURE_LOADS_N`], ascending.
    pub(super) fn snapshot_indices(&self) -> Vec<usize> {
        let mut indices: Vec<usize> = FIGURE_LOADS_N
            .iter()
            .map(|target| {
                let distance = |l: f64| (l / target).ln().abs();
                (0..self.loads.len()).min_by(|&a, &b| distance(self.loads[a]).total_cmp(&distance(self.loads[b])))
            })
            .map(|k| k.expect("at least one load"))
            .collect();
        indices.dedup();
        indices
    }

    /// Whether the study keeps every full pressure map of sweep `u`'s solves: a topography's,
    /// adhesive or not, when `output.pressure_maps` asks.
    pub(super) fn keeps_maps(&self, u: usize) -> bool {
        self.config.output.pressure_maps && (u < self.topographies.len() || self.adhesive(u))
    }

    /// Whether the figures' snapshots come from sweep `u`, elastic or `plastic`: the first
    /// topography in the first kind of solve listed.
    pub(super) fn shows(&self, u: usize, plastic: bool) -> bool {
        u == 0 && plastic == self.config.contact.plastic.modes()[0]
    }

    /// The stem of the names of the snapshot of load `k` in `snapshots/`: the first
    /// topography's name and its solve's ([`Study::stem`]).
    pub(super) fn snapshot_stem(&self, k: usize) -> String {
        format!("{}-{}", self.topographies[0].0, self.stem(0, self.config.contact.plastic.modes()[0], k))
    }
}
