//! The numerical study of the paper: elastic contact and the stick-slip transition model over
//! loads × topographies × friction laws, with the results as a table and the data behind the
//! figures.
//!
//! This file holds the data that the study's runner produces and its figures consume:
//! [`Row`] (one line of `results.csv`) and [`MapSnapshot`] (the contact region of one solve,
//! kept for the maps, distributions, curves and movies). It imports, of the study, the study
//! file (`config`) only, never the runner's rooms, nor `plot`, `report`, `cli` or `python`.

pub mod adhesion;
pub mod config;
mod plan;
mod progress;
mod records;
pub mod run;
mod schedule;
pub mod shard;
pub mod slurm;

use std::path::Path;

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use crate::contact::{AdhesiveReport, ContactSummary, SolveReport};
use crate::error::{Error, Result};
use crate::friction::{ClassShare, ElasticOnset, FrictionLaw, Onset, SlipLaw, WeakeningOnset};

pub use config::{FigureKind, Sharing};

/// What `results.json` holds: the rows, and which asperity computed them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// The version of asperity that wrote the file ([`crate::VERSION`]).
    pub asperity_version: String,
    /// The commit it was built from ([`crate::COMMIT`]).
    pub commit: String,
    /// One row per topography × sharing × law × load.
    pub rows: Vec<Row>,
}

impl Results {
    /// `rows` as computed by this asperity.
    pub fn new(rows: Vec<Row>) -> Results {
        Results { asperity_version: crate::VERSION.to_string(), commit: crate::COMMIT.to_string(), rows }
    }
}

/// Records of earlier runs hold the paper's equal sharing only: the instant drop.
fn instant() -> Option<f64> {
    Some(0.0)
}

/// One result: one topography × friction law × load, with one sharing of the tangential force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Normal load N \[N].
    pub load_n: f64,
    /// Topography name.
    pub topography: String,
    /// Friction law name.
    pub law: String,
    /// Whether the solve capped the pressure at the hardness (elastic–perfectly-plastic).
    pub plastic: bool,
    /// How the tangential force is shared among the elements (records of earlier runs: equal).
    #[serde(default)]
    pub sharing: Sharing,
    /// The slip-weakening distance d_c \[m] of the local law: 0 for the instant drop (the
    /// paper's equal sharing), d_c for elastic sharing and for equal sharing with the same
    /// weakening, empty for a law that follows a measured μ(slip) curve.
    #[serde(default = "instant")]
    pub slip_distance_m: Option<f64>,
    /// Local static friction coefficient mu_s of the law.
    pub mu_s: f64,
    /// Local dynamic friction coefficient mu_d of the law.
    pub mu_d: f64,
    /// Contact elements (pixels with p > 0).
    pub contact_points: usize,
    /// Contact patches (4-connected clusters).
    pub patches: usize,
    /// Fraction of the window in contact.
    pub contact_fraction: f64,
    /// Largest local pressure \[Pa].
    pub max_pressure_pa: f64,
    /// Fraction of the load carried within 2 % of the window's edges (at least 2 pixels).
    pub edge_load_fraction: f64,
    /// Fraction of the load carried at p ≥ the material's hardness (empty when none is given).
    pub load_above_hardness_fraction: Option<f64>,
    /// F_S / N.
    pub static_coefficient: f64,
    /// mu_d.
    pub dynamic_coefficient: f64,
    /// F_S / (mu_d N).
    pub friction_drop: f64,
    /// Element classes at the critical state (the peak of the friction force): count, fraction
    /// of N, fraction of F_S. Under elastic sharing ([`SlideClass`](crate::friction::SlideClass)):
    /// critical = not slipped before, on its bound μ_s p; pre-sliding = slipped before the peak
    /// and fully weakened (slip ≥ d_c, at μ_d); subcritical = stuck below its bound; the
    /// `weakening_` columns hold the rest, slipped and partly weakened.
    ///
    /// Critical elements (stuck at the stress ratio mu_s): their number.
    pub critical_count: usize,
    /// Fraction of N the critical elements carry.
    pub critical_normal_fraction: f64,
    /// Fraction of F_S the critical elements carry.
    pub critical_friction_fraction: f64,
    /// Pre-sliding elements (slipped before the peak, at mu_d): their number.
    pub pre_sliding_count: usize,
    /// Fraction of N the pre-sliding elements carry.
    pub pre_sliding_normal_fraction: f64,
    /// Fraction of F_S the pre-sliding elements carry.
    pub pre_sliding_friction_fraction: f64,
    /// Subcritical elements (stuck below mu_s): their number.
    pub subcritical_count: usize,
    /// Fraction of N the subcritical elements carry.
    pub subcritical_normal_fraction: f64,
    /// Fraction of F_S the subcritical elements carry.
    pub subcritical_friction_fraction: f64,
    /// Elastic sharing only: elements slipped before the peak and still weakening (0 < slip <
    /// d_c, between μ_s and μ_d), their number; none under the instant drop.
    #[serde(default)]
    pub weakening_count: Option<usize>,
    /// Elastic sharing only: fraction of N the weakening elements carry.
    #[serde(default)]
    pub weakening_normal_fraction: Option<f64>,
    /// Elastic sharing only: fraction of F_S the weakening elements carry.
    #[serde(default)]
    pub weakening_friction_fraction: Option<f64>,
    /// Contact solver iterations of the solve this row comes from.
    pub iterations: usize,
    /// Wall-clock time \[s] of that solve.
    pub seconds: f64,
    /// Elastic sharing only: the tangential solver's iterations, summed over the path to
    /// sliding.
    #[serde(default)]
    pub slide_iterations: Option<usize>,
    /// Elastic sharing only: the path's wall-clock time \[s].
    #[serde(default)]
    pub slide_seconds: Option<f64>,
    /// With adhesion only: the adhesive force N_a = N_c − N \[N] of the solve, N_c the
    /// compressive force the friction model's elements carry. Then `friction_drop` and
    /// `static_coefficient` are over the applied load N, and the class fractions of N are
    /// fractions of N_c.
    #[serde(default)]
    pub adhesive_force_n: Option<f64>,
    /// With adhesion only: the paper's AFM definition F_S/(μ_d (N + N_a)), over the total
    /// normal force (applied load and adhesion force).
    #[serde(default)]
    pub friction_drop_total_load: Option<f64>,
}

impl Row {
    /// The row for `onset`, computed on a solve of `topography` at `load_n`.
    pub fn new(topography: &str, load_n: f64, solve: &SolveFacts, onset: &Onset) -> Row {
        let model = (onset.static_coefficient(), onset.dynamic_coefficient(), onset.friction_drop());
        let shares = [&onset.critical, &onset.pre_sliding, &onset.subcritical];
        Row::of(topography, load_n, solve, &onset.law, (Sharing::Equal, Some(0.0)), model, shares)
    }

    /// The row for equal sharing under the slip weakening `slip` (each element a
    /// spring–slider of the contact's stuck stiffness), on the same solve.
    pub fn equal_weakening(
        topography: &str,
        load_n: f64,
        solve: &SolveFacts,
        law: &FrictionLaw,
        slip: &SlipLaw,
        onset: &WeakeningOnset,
    ) -> Row {
        let model = (onset.static_coefficient(), onset.mu_d, onset.friction_drop());
        let shares = [&onset.critical, &onset.pre_sliding, &onset.subcritical];
        Row::of(topography, load_n, solve, law, (Sharing::Equal, slip.slip_distance()), model, shares)
    }

    /// Whether the row comes from an adhesive solve.
    pub fn adhesive(&self) -> bool {
        self.adhesive_force_n.is_some()
    }

    /// Whether the row is the paper's model: equal sharing with the instant drop.
    pub fn papers(&self) -> bool {
        self.sharing == Sharing::Equal && self.slip_distance_m == Some(0.0)
    }

    /// The row's model as a label: its sharing, unless instant its weakening, and adhesion
    /// ("equal sharing", "elastic sharing, d_c 2 nm", "equal sharing, adhesive").
    pub fn model(&self) -> String {
        let sharing = self.sharing.name();
        let adhesion = if self.adhesive() { ", adhesive" } else { "" };
        match self.slip_distance_m {
            Some(d) if d == 0.0 => format!("{sharing} sharing{adhesion}"),
            Some(d) => {
                format!("{sharing} sharing, d_c {}{adhesion}", crate::quantity::show(d, &crate::quantity::LENGTH))
            }
            None => format!("{sharing} sharing, measured curve{adhesion}"),
        }
    }

    /// The row for the elastic-sharing `onset` under `law`, on the same solve, its path taking
    /// `seconds`.
    pub fn elastic(
        topography: &str,
        load_n: f64,
        solve: &SolveFacts,
        law: &FrictionLaw,
        slip: &SlipLaw,
        onset: &ElasticOnset,
        seconds: f64,
    ) -> Row {
        let model = (onset.static_coefficient(), onset.mu_d, onset.friction_drop());
        let c = &onset.classes;
        Row {
            weakening_count: Some(c.weakening.count),
            weakening_normal_fraction: Some(c.weakening.normal_fraction),
            weakening_friction_fraction: Some(c.weakening.friction_fraction),
            slide_iterations: Some(onset.work.iterations),
            slide_seconds: Some(seconds),
            ..Row::of(
                topography,
                load_n,
                solve,
                law,
                (Sharing::Elastic, slip.slip_distance()),
                model,
                [&c.critical, &c.weakened, &c.stuck],
            )
        }
    }

    /// A row from the solve's facts, the model's (static coefficient, dynamic coefficient,
    /// friction drop) over the normal force its elements carry, and its critical, pre-sliding
    /// and subcritical shares. With adhesion the elements carry N_c = N + N_a: the model's drop
    /// is the paper's AFM definition, and the drop and static coefficient over the applied
    /// load N are it times N_c/N.
    fn of(
        topography: &str,
        load_n: f64,
        solve: &SolveFacts,
        law: &FrictionLaw,
        (sharing, slip_distance_m): (Sharing, Option<f64>),
        (static_coefficient, dynamic_coefficient, friction_drop): (f64, f64, f64),
        [critical, pre_sliding, subcritical]: [&ClassShare; 3],
    ) -> Row {
        let total = solve.adhesive_force_n.map(|a| (load_n + a) / load_n).unwrap_or(1.0);
        Row {
            load_n,
            topography: topography.to_string(),
            law: law_name(law),
            plastic: solve.plastic,
            sharing,
            slip_distance_m,
            mu_s: law.mu_s,
            mu_d: law.mu_d,
            contact_points: solve.contact_points,
            patches: solve.patches,
            contact_fraction: solve.contact_fraction,
            max_pressure_pa: solve.max_pressure_pa,
            edge_load_fraction: solve.edge_load_fraction,
            load_above_hardness_fraction: solve.load_above_hardness_fraction,
            static_coefficient: static_coefficient * total,
            dynamic_coefficient,
            friction_drop: friction_drop * total,
            critical_count: critical.count,
            critical_normal_fraction: critical.normal_fraction,
            critical_friction_fraction: critical.friction_fraction,
            pre_sliding_count: pre_sliding.count,
            pre_sliding_normal_fraction: pre_sliding.normal_fraction,
            pre_sliding_friction_fraction: pre_sliding.friction_fraction,
            subcritical_count: subcritical.count,
            subcritical_normal_fraction: subcritical.normal_fraction,
            subcritical_friction_fraction: subcritical.friction_fraction,
            weakening_count: None,
            weakening_normal_fraction: None,
            weakening_friction_fraction: None,
            iterations: solve.iterations,
            seconds: solve.seconds,
            slide_iterations: None,
            slide_seconds: None,
            adhesive_force_n: solve.adhesive_force_n,
            friction_drop_total_load: solve.adhesive_force_n.map(|_| friction_drop),
        }
    }

    /// An error naming the row's topography, load and law unless every number it holds is
    /// finite: a solve record holding NaN (written as null) is read back by no later run.
    pub fn require_finite(&self) -> Result<()> {
        let numbers = [
            ("load_n", self.load_n),
            ("mu_s", self.mu_s),
            ("mu_d", self.mu_d),
            ("static_coefficient", self.static_coefficient),
            ("dynamic_coefficient", self.dynamic_coefficient),
            ("friction_drop", self.friction_drop),
            ("critical_normal_fraction", self.critical_normal_fraction),
            ("critical_friction_fraction", self.critical_friction_fraction),
            ("pre_sliding_normal_fraction", self.pre_sliding_normal_fraction),
            ("pre_sliding_friction_fraction", self.pre_sliding_friction_fraction),
            ("subcritical_normal_fraction", self.subcritical_normal_fraction),
            ("subcritical_friction_fraction", self.subcritical_friction_fraction),
            ("weakening_normal_fraction", self.weakening_normal_fraction.unwrap_or(0.0)),
            ("weakening_friction_fraction", self.weakening_friction_fraction.unwrap_or(0.0)),
            ("contact_fraction", self.contact_fraction),
            ("max_pressure_pa", self.max_pressure_pa),
            ("edge_load_fraction", self.edge_load_fraction),
            ("load_above_hardness_fraction", self.load_above_hardness_fraction.unwrap_or(0.0)),
            ("seconds", self.seconds),
            ("slide_seconds", self.slide_seconds.unwrap_or(0.0)),
            ("adhesive_force_n", self.adhesive_force_n.unwrap_or(0.0)),
            ("friction_drop_total_load", self.friction_drop_total_load.unwrap_or(0.0)),
        ];
        let at = format!("topography \"{}\" at {:e} N, law \"{}\"", self.topography, self.load_n, self.law);
        match numbers.iter().find(|(_, v)| !v.is_finite()) {
            Some((name, v)) => Err(Error::invalid(at, format!("{name} is {v}: not recorded"))),
            None => Ok(()),
        }
    }
}

/// The plausibility warnings of a study's solves, one line each, naming the topography and the
/// load ([`crate::contact::plausibility_warnings`]).
/// Without the remedies (the report's list; see [`study_warnings`]).
pub fn warnings(rows: &[Row]) -> Vec<String> {
    warnings_with(rows, |_| Vec::new())
}

/// [`warnings`] with the remedies the study file can still take, in its own words, leaving out
/// what `config` already does ([`config::StudyConfig::edge_remedies`]).
pub fn study_warnings(rows: &[Row], config: &config::StudyConfig) -> Vec<String> {
    warnings_with(rows, |topography| config.edge_remedies(topography))
}

fn warnings_with(rows: &[Row], remedies: impl Fn(&str) -> Vec<String>) -> Vec<String> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    // Every law of a solve repeats its contact figures: one warning per solve.
    for r in rows.iter().filter(|r| seen.insert((r.topography.clone(), r.load_n.to_bits()))) {
        let found = crate::contact::plausibility_warnings(
            r.edge_load_fraction,
            r.load_above_hardness_fraction,
            r.max_pressure_pa,
            &remedies(&r.topography),
        );
        let load = crate::quantity::show(r.load_n, &crate::quantity::FORCE);
        out.extend(found.into_iter().map(|w| format!("topography \"{}\" at {load}: {w}", r.topography)));
    }
    out
}

/// The name of `law` in the rows: its label, or its two coefficients when it has none.
pub fn law_name(law: &FrictionLaw) -> String {
    law.name.clone().unwrap_or_else(|| format!("mu_s={} mu_d={}", law.mu_s, law.mu_d))
}

/// What a row needs to know of the contact solve behind it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolveFacts {
    /// Whether the solve capped the pressure at the hardness.
    #[serde(default)]
    pub plastic: bool,
    /// Contact elements (pixels with p > 0).
    pub contact_points: usize,
    /// Contact patches (4-connected clusters).
    pub patches: usize,
    /// Fraction of the window in contact.
    pub contact_fraction: f64,
    /// Largest local pressure \[Pa].
    pub max_pressure_pa: f64,
    /// Fraction of the load carried within 2 % of the window's edges (at least 2 pixels).
    pub edge_load_fraction: f64,
    /// Fraction of the load carried at p ≥ the material's hardness (none when none is given).
    pub load_above_hardness_fraction: Option<f64>,
    /// Solver iterations.
    pub iterations: usize,
    /// Wall-clock time of the solve \[s].
    pub seconds: f64,
    /// With adhesion: the adhesive force N_a = N_c − N \[N] (absent without).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adhesive_force_n: Option<f64>,
}

impl SolveFacts {
    /// An error unless every number of the solve is finite (see [`Row::require_finite`]).
    pub fn require_finite(&self) -> Result<()> {
        let numbers = [
            ("contact_fraction", self.contact_fraction),
            ("max_pressure_pa", self.max_pressure_pa),
            ("edge_load_fraction", self.edge_load_fraction),
            ("load_above_hardness_fraction", self.load_above_hardness_fraction.unwrap_or(0.0)),
            ("seconds", self.seconds),
            ("adhesive_force_n", self.adhesive_force_n.unwrap_or(0.0)),
        ];
        match numbers.iter().find(|(_, v)| !v.is_finite()) {
            Some((name, v)) => Err(Error::invalid("contact solve", format!("{name} is {v}: not recorded"))),
            None => Ok(()),
        }
    }

    /// The facts of a solve from its contact statistics and the solver's report.
    pub fn new(summary: &ContactSummary, report: &SolveReport) -> SolveFacts {
        SolveFacts { plastic: report.hardness.is_some(), ..SolveFacts::of(summary, report.iterations, report.seconds) }
    }

    /// The facts of an adhesive solve from the statistics of its compressive pressure and the
    /// solver's report.
    pub fn adhesive(summary: &ContactSummary, report: &AdhesiveReport) -> SolveFacts {
        SolveFacts {
            adhesive_force_n: Some(report.adhesive_force),
            ..SolveFacts::of(summary, report.iterations, report.seconds)
        }
    }

    /// The facts of an elastic solve without adhesion from its statistics, its iterations and
    /// its time \[s].
    fn of(summary: &ContactSummary, iterations: usize, seconds: f64) -> SolveFacts {
        SolveFacts {
            plastic: false,
            contact_points: summary.contact_points,
            patches: summary.patch_sizes.len(),
            contact_fraction: summary.contact_fraction,
            max_pressure_pa: summary.max_pressure,
            edge_load_fraction: summary.edge_load_fraction,
            load_above_hardness_fraction: summary.load_above_hardness_fraction,
            iterations,
            seconds,
            adhesive_force_n: None,
        }
    }
}

/// The contact region of one solve, kept for the figures: the pressure inside the bounding box
/// of the contact points (all of them: the stick-slip model sees the same elements as on the
/// whole window), with where that box sits in the window.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSnapshot {
    /// Topography name.
    pub topography: String,
    /// Normal load N \[N].
    pub load_n: f64,
    /// Pressure \[Pa] on the box, shape (rows, columns).
    pub pressure: Array2<f64>,
    /// (row, column) of the box's first pixel in the window.
    pub origin: (usize, usize),
    /// The window's grid (ny, nx).
    pub grid: (usize, usize),
    /// Pixel size (dx, dy) \[m].
    pub pixel_size: (f64, f64),
    /// The contact's stuck tangential stiffness K_t [N/m] ([`crate::friction::stuck_stiffness`]
    /// on the solve's contact set), which gives the elements k_t = K_t / n and δ in metres:
    /// recorded for the snapshot the friction curve (Fig. 4a) draws, the one within
    /// [`NEAR_DECADES`] of 0.1 mN; `None` for the others and in an earlier run's snapshots.
    pub stuck_stiffness: Option<f64>,
}

/// `MapSnapshot` without its array, as stored beside it.
#[derive(Serialize, Deserialize)]
struct SnapshotMeta {
    topography: String,
    load_n: f64,
    origin: (usize, usize),
    grid: (usize, usize),
    pixel_size_m: (f64, f64),
    /// Absent in the snapshots of runs before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stuck_stiffness_n_per_m: Option<f64>,
}

impl MapSnapshot {
    /// The box around the contact points of `pressure` (shape `grid`), with `margin` pixels
    /// around it where the window allows. `None` when nothing is in contact.
    pub fn crop(
        topography: &str,
        load_n: f64,
        pressure: &Array2<f64>,
        pixel_size: (f64, f64),
        margin: usize,
    ) -> Option<MapSnapshot> {
        let (ny, nx) = pressure.dim();
        let (mut r0, mut r1, mut c0, mut c1) = (usize::MAX, 0, usize::MAX, 0);
        for ((r, c), p) in pressure.indexed_iter() {
            if *p > 0.0 {
                (r0, r1, c0, c1) = (r0.min(r), r1.max(r), c0.min(c), c1.max(c));
            }
        }
        if r0 == usize::MAX {
            return None;
        }
        let (r0, c0) = (r0.saturating_sub(margin), c0.saturating_sub(margin));
        let (r1, c1) = ((r1 + margin + 1).min(ny), (c1 + margin + 1).min(nx));
        Some(MapSnapshot {
            topography: topography.to_string(),
            load_n,
            pressure: pressure.slice(ndarray::s![r0..r1, c0..c1]).to_owned(),
            origin: (r0, c0),
            grid: (ny, nx),
            pixel_size,
            stuck_stiffness: None,
        })
    }

    /// Area of one pixel \[m²].
    pub fn pixel_area(&self) -> f64 {
        self.pixel_size.0 * self.pixel_size.1
    }

    /// Write as `<stem>.npy` (pressure, float64, Pa) and `<stem>.json`, atomically.
    pub fn save(&self, dir: &Path, stem: &str) -> Result<()> {
        crate::output::write_npy(&dir.join(format!("{stem}.npy")), &self.pressure)?;
        let meta = SnapshotMeta {
            topography: self.topography.clone(),
            load_n: self.load_n,
            origin: self.origin,
            grid: self.grid,
            pixel_size_m: self.pixel_size,
            stuck_stiffness_n_per_m: self.stuck_stiffness,
        };
        crate::output::write_json(&dir.join(format!("{stem}.json")), &meta)
    }

    /// Read what [`MapSnapshot::save`] wrote.
    pub fn load(dir: &Path, stem: &str) -> Result<MapSnapshot> {
        let json = dir.join(format!("{stem}.json"));
        let text = std::fs::read_to_string(&json).map_err(|e| Error::io(&json, e))?;
        let meta: SnapshotMeta = serde_json::from_str(&text).map_err(|e| Error::file(&json, e.to_string()))?;
        let npy = dir.join(format!("{stem}.npy"));
        let bytes = std::fs::read(&npy).map_err(|e| Error::io(&npy, e))?;
        let pressure = crate::topography::io::npy::read_f64(&bytes).map_err(|r| Error::file(&npy, r))?;
        Ok(MapSnapshot {
            topography: meta.topography,
            load_n: meta.load_n,
            pressure,
            origin: meta.origin,
            grid: meta.grid,
            pixel_size: meta.pixel_size_m,
            stuck_stiffness: meta.stuck_stiffness_n_per_m,
        })
    }
}

/// The pixel sizes of the resolution figure, as multiples of the study's.
pub const COARSENING: [usize; 2] = [2, 4];

/// One result of the resolution study (`resolution.csv`): a topography × law × load on a grid
/// `coarsening` times coarser than the study's (1: the study's own).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResolutionRow {
    /// Pixel size as a multiple of the study's (1: the study's own grid).
    pub coarsening: usize,
    /// Pixel size along x \[m].
    pub pixel_size_m: f64,
    /// Normal load N \[N].
    pub load_n: f64,
    /// Topography name.
    pub topography: String,
    /// Friction law name.
    pub law: String,
    /// Contact elements (pixels with p > 0) on this grid.
    pub contact_points: usize,
    /// F_S / (mu_d N) on this grid.
    pub friction_drop: f64,
}

impl ResolutionRow {
    /// The resolution row of `row`, solved on a grid `coarsening` times coarser, of pixel size
    /// `pixel_size_m` \[m].
    pub fn new(coarsening: usize, pixel_size_m: f64, row: &Row) -> ResolutionRow {
        ResolutionRow {
            coarsening,
            pixel_size_m,
            load_n: row.load_n,
            topography: row.topography.clone(),
            law: row.law.clone(),
            contact_points: row.contact_points,
            friction_drop: row.friction_drop,
        }
    }
}

/// The loads \[N] at which the paper shows maps, distributions, curves and movies; a study keeps
/// a [`MapSnapshot`] of its first topography at the swept load nearest to each (in log scale).
pub const FIGURE_LOADS_N: [f64; 4] = [1e-4, 1e-3, 1e-2, 1e-1];

/// A snapshot stands for a figure load when it lies within half a decade of it.
pub const NEAR_DECADES: f64 = 0.5;

/// What a study records for its figures and report: its rows, maps and parameters as run. The
/// study writes them and stops; the layer above it draws from them (see [`crate::report`]).
#[derive(Debug)]
pub struct Records {
    /// The result rows under equal sharing (the paper's model), which every figure but the
    /// sharing comparison draws.
    pub rows: Vec<Row>,
    /// The result rows under equal sharing with elastic sharing's slip weakening (empty
    /// without elastic sharing, or when its laws drop at once).
    pub weakening_rows: Vec<Row>,
    /// The result rows under elastic sharing (empty unless the study asks for them).
    pub elastic_rows: Vec<Row>,
    /// The rows at the ends of the band of d_c: equal sharing under the weakening and elastic
    /// sharing (empty without a band).
    pub band_rows: Vec<Row>,
    /// The result rows of the adhesive solves under equal sharing (the paper's model; empty
    /// without `contact.adhesion`); the rows above are the solves without adhesion.
    pub adhesive_rows: Vec<Row>,
    /// The cohesive law of the adhesive solves, if any.
    pub cohesive_law: Option<crate::contact::CohesiveLaw>,
    /// Topography names, in the study's order.
    pub topographies: Vec<String>,
    /// Friction laws, in the study's order; maps, curves and movies use the first.
    pub laws: Vec<FrictionLaw>,
    /// The hold time \[s] of each law, where known (matches measured points to laws).
    pub hold_times: Vec<Option<f64>>,
    /// E*₀/E* for the moduli the friction-drop band also covers (empty: the study's only).
    pub modulus_ratios: Vec<f64>,
    /// The other counterface the friction-drop figure shows (the same material against the
    /// paper's rigid flat, or the rigid flat against the same material): its description and
    /// E*₀/E*, by the same scaling; none for another body.
    pub counterface: Option<(String, f64)>,
    /// Where a single summit's DMT pull-off is no longer small beside the load (none when no
    /// topography has a curvature).
    pub adhesion: Option<adhesion::AdhesionLimit>,
    /// The resolution study's rows (empty when it was not asked for).
    pub resolution: Vec<ResolutionRow>,
    /// Loads \[N] of the hold-time figure.
    pub hold_time_loads: Vec<f64>,
    /// p(σ) on a logarithmic density axis.
    pub log_density: bool,
    /// The hardness \[Pa] marked on p(σ), when the study sets one.
    pub hardness_pa: Option<f64>,
    /// Elastic sharing's slip-weakening distance d_c \[m] (0: the instant drop); a law given by
    /// a measured curve follows its own.
    pub slip_distance_m: f64,
    /// The ends of the band of d_c \[m], low then high (empty without a band).
    pub slip_distance_band: Vec<f64>,
    /// The contact grid (nx, ny) every topography was resampled to, when the study sets one.
    pub grid: Option<(usize, usize)>,
    /// Snapshots of the first topography at the loads nearest to [`FIGURE_LOADS_N`].
    pub maps: Vec<MapSnapshot>,
    /// Which figures to draw.
    pub figures: Vec<FigureKind>,
    /// δ/δ_peak of the stress-ratio snapshots.
    pub snapshot_fractions: Vec<f64>,
    /// The study's parameters as run (the study file written beside the results).
    pub parameters: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No record holds a NaN (JSON would write it as null, which no later run could read back).
    #[test]
    fn a_non_finite_row_is_refused() {
        let law = FrictionLaw::new(0.6, 0.4).unwrap();
        let onset = Onset::new(&crate::friction::ElementLoads::from_forces(&[1.0, 2.0]).unwrap(), &law);
        let facts = SolveFacts {
            plastic: false,
            contact_points: 2,
            patches: 1,
            contact_fraction: 0.5,
            max_pressure_pa: 1e9,
            edge_load_fraction: 0.0,
            load_above_hardness_fraction: None,
            iterations: 3,
            seconds: 0.1,
            adhesive_force_n: None,
        };
        let row = Row::new("ball", 1e-3, &facts, &onset);
        assert!(row.require_finite().is_ok() && facts.require_finite().is_ok());
        let bad = Row { critical_friction_fraction: f64::NAN, ..row.clone() };
        let e = bad.require_finite().unwrap_err().to_string();
        assert_eq!(
            e,
            "topography \"ball\" at 1e-3 N, law \"mu_s=0.6 mu_d=0.4\": critical_friction_fraction is NaN: not recorded"
        );
        let bad = Row { slide_seconds: Some(f64::INFINITY), ..row };
        assert!(bad.require_finite().unwrap_err().to_string().contains("slide_seconds is inf"));
        let e = SolveFacts { max_pressure_pa: f64::NAN, ..facts }.require_finite().unwrap_err().to_string();
        assert_eq!(e, "contact solve: max_pressure_pa is NaN: not recorded");
    }

    #[test]
    fn crop_keeps_every_contact_point_and_round_trips() {
        let mut p = Array2::zeros((20, 30));
        p[[5, 7]] = 1.0;
        p[[9, 12]] = 2.0;
        let snap = MapSnapshot::crop("t", 1e-3, &p, (1e-8, 2e-8), 2).unwrap();
        assert_eq!(snap.origin, (3, 5));
        assert_eq!(snap.pressure.dim(), (9, 10));
        assert_eq!(snap.pressure.sum(), 3.0);
        let dir = tempfile::tempdir().unwrap();
        snap.save(dir.path(), "m").unwrap();
        assert_eq!(MapSnapshot::load(dir.path(), "m").unwrap(), snap);
        // A snapshot without K_t is written as before it was recorded, and such a one loads.
        let json = std::fs::read_to_string(dir.path().join("m.json")).unwrap();
        assert!(!json.contains("stuck_stiffness") && json.contains("pixel_size_m"), "{json}");
        let snap = MapSnapshot { stuck_stiffness: Some(6.2e4), ..snap };
        snap.save(dir.path(), "k").unwrap();
        assert_eq!(MapSnapshot::load(dir.path(), "k").unwrap(), snap);
        assert!(MapSnapshot::crop("t", 1.0, &Array2::zeros((3, 3)), (1.0, 1.0), 0).is_none());
    }
}
