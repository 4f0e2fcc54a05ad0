//! The study runner: every topography at every load (elastic contact), every friction law on
//! every solve (the stick-slip model), the results table and the maps behind the figures; the
//! figures and the report are drawn from its [`Records`] by the layer above (`crate::report`).
//!
//! [`Study::prepare`] reads every file and builds every topography and law before anything is
//! solved, so a bad input fails at once. [`Study::run`] then solves the topographies in
//! parallel, each sweeping its loads in increasing order from the previous solution (warm
//! start). It writes into DIR:
//!
//! - `study.toml`: the study as run (paths absolute, loads explicit);
//! - `results.csv`, `results.json`: one [`Row`] per topography × solve (elastic, plastic, as
//!   `contact.plastic` lists them) × sharing (as `model.sharing` lists them) × law × load, in
//!   that order;
//! - `resolution.csv`: with the resolution figure, the friction drop of every topography × law
//!   × load at the study's pixel size and [`COARSENING`] times coarser ([`ResolutionRow`]);
//! - `snapshots/<topography>-NN.npy|json`: [`MapSnapshot`]s of the first topography at the
//!   swept loads nearest to [`FIGURE_LOADS_N`] (NN: the load's index in increasing order),
//!   the one the friction curve draws with its contact's stuck tangential stiffness K_t;
//! - `pressure/<topography>/NN.npy`: every full pressure map \[Pa], when asked for (a plastic
//!   sweep's in `pressure/<topography>/plastic/`, and its solve records likewise);
//! - `figures/`, `index.html`: the figures and their report, written by `crate::report` while
//!   the run's results lock is held (see [`Outcome::records`]);
//! - `solves/`: what makes a run resumable — the study's `fingerprint.json`, the ledger
//!   `written.jsonl` of every file the runs wrote in DIR ([`output::Ledger`]; `fresh` removes
//!   those and nothing else), and below
//!   `solves/topographies/<topography>/` one record `NN.json` per finished (topography, load)
//!   solve (its rows for every sharing and law, elastic sharing's onsets included, and whether
//!   the solve started cold) and the last pressure
//!   map `warm-NN.npy` of an unfinished chain (float64, lossless). With elastic sharing, a
//!   solve's parts are recorded as they finish until its record replaces them: its normal
//!   solve `NN-normal.json` (with its map `warm-NN.npy`) and each law's onset
//!   `NN-elastic-LL.json` (LL the law's index; a row of results.json). A killed run, run again
//!   into the same DIR, picks up at the first missing record from that map, or from the parts
//!   of its solve: the solver depends only on the pressure it starts from, and an onset only
//!   on its solve's pressure, so the results equal an uninterrupted run's (apart from the
//!   timings) and no finished part is computed again. Topography names appear only as folder
//!   names there (and under `pressure/`), so no name collides with the run's own files.
//!
//! Units of work are pieces of a sweep's chain of loads: a whole chain, or with a
//! [shard] its share of the chains. A piece starts cold at its first load. A
//! shard writes its solves only (records, snapshots, maps); a run without a shard solves what
//! is missing, going on from the map a piece that ended before a gap kept, and writes the
//! table and figures.
//!
//! One writer per unit of work: a piece is locked by
//! `solves/topographies/<topography>/loads-AA-BB.lock` (AA, BB its first and last load; a
//! plastic sweep's in its `plastic/`) while it is solved, and taken only when no other
//! process holds an overlapping piece. Every process
//! working in DIR holds `solves/study.lock` shared; claiming DIR (checking or writing the
//! fingerprint, taking the pieces' locks, `fresh` discarding the earlier solves, which needs
//! the study's lock exclusive) happens under `solves/claim.lock`, and the results, figures
//! and report are written under `solves/results.lock`. The locks are advisory (`flock`) and
//! released by the kernel when a process ends, so a killed run never leaves a stale one.
//!
//! Every file is written atomically. The library prints nothing: progress goes to a callback.

use std::cmp::Reverse;
use std::collections::hash_map::DefaultHasher;
use std::collections::{BTreeMap, BinaryHeap};
use std::hash::{Hash, Hasher};
use std::ops::{ControlFlow, Range};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::config::{Counterface, Force, LawSpec, LoadsSpec, StudyConfig, SurfaceSpec};
use super::shard::{self, Piece, Shard};
use super::{
    FigureKind, MapSnapshot, Records, ResolutionRow, Row, Sharing, SolveFacts, COARSENING, FIGURE_LOADS_N, NEAR_DECADES,
};
use crate::contact::{
    self, ContactSolver, Convergence, Proceed, ShearCompliance, SolverOptions, TangentialOptions, TangentialSolver,
};
use crate::error::{Error, Result};
use crate::friction::{
    elastic_onset, element_stiffness, spring_slider_onset, stuck_stiffness, ElementLoads, FrictionLaw, Onset,
    SlideStage, SlipLaw, Weakening, PEAK_TOLERANCE,
};
use crate::limits::Limits;
use crate::output::{self, Access, Ledger, Lock};
use crate::plausible::{self, Spelling};
use crate::quantity::{show, PRESSURE};
use crate::topography::io::{self, ReadOptions};
use crate::topography::prepare::compound_with;
use crate::topography::resample::resample;
use crate::topography::Topography;

/// Pixels kept around the contact points in a [`MapSnapshot`].
const SNAPSHOT_MARGIN: usize = 8;

// The run's own names in `DIR/solves/`; topographies have theirs below `topographies/`.
const SOLVES: &str = "solves";
const FINGERPRINT: &str = "fingerprint.json";
const CLAIM_LOCK: &str = "claim.lock";
const STUDY_LOCK: &str = "study.lock";
const RESULTS_LOCK: &str = "results.lock";
const TOPOGRAPHIES: &str = "topographies";
/// The ledger of what runs wrote in DIR.
const LEDGER: &str = "written.jsonl";
/// The files of `solves/` that stay for good: `fresh` keeps them (the claim replaces the
/// fingerprint, and a lock file is never removed while a process may open it).
const KEPT: [&str; 5] = [FINGERPRINT, CLAIM_LOCK, STUDY_LOCK, RESULTS_LOCK, LEDGER];

/// Every name the runs write at the top of DIR (files, and folders with all below them): what
/// a user put there is never written over, so it is refused before anything is solved.
const DIR_OUTPUTS: [&str; 9] = [
    "study.toml",
    "results.csv",
    "results.json",
    "resolution.csv",
    "index.html",
    "figures",
    "pressure",
    "snapshots",
    SOLVES,
];

/// A study ready to run: every topography built, every law resolved.
pub struct Study {
    /// Names the study in errors (its file, or "default study").
    origin: String,
    /// The study as run.
    config: StudyConfig,
    topographies: Vec<(String, Topography)>,
    /// (topography index, coarsening, the topography resampled) for the resolution figure.
    coarse: Vec<(usize, usize, Topography)>,
    laws: Vec<FrictionLaw>,
    /// Each law's slip weakening under elastic sharing ([`super::config::ModelSpec::weakening`]).
    weakenings: Vec<Weakening>,
    /// The hold time [s] of each law, where known.
    hold_times: Vec<Option<f64>>,
    /// Loads [N], ascending.
    loads: Vec<f64>,
    /// Wait for work another process holds, instead of refusing it.
    wait: bool,
    /// Solve only this shard's share, and write no table or figures.
    shard: Option<Shard>,
    /// Loads that press a read topography's window unusually hard ([`Study::warnings`]).
    warnings: Vec<String>,
}

/// The locks a run holds while it works in DIR, and its ledger (none in a DIR an asperity
/// without ledgers started).
#[derive(Debug)]
struct Claim {
    _study: Lock,
    _units: Vec<Lock>,
    _ledger: Option<Ledger>,
    /// What `fresh` left in DIR, not having written it.
    left: Vec<PathBuf>,
}

/// What the runner reports as it goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress<'a> {
    /// Before the first solve: `done` of the `total` solves were finished by an earlier run,
    /// and `onsets_done` of the `onsets` elastic-sharing onsets those solves run (one per law
    /// and solve of the study's own grid; they take most of such a run's time). A solve's
    /// `work` sums the estimated work of the share's solves ([`Study::solve_work`]),
    /// `work_done` that of the solves done.
    Start {
        /// Solves of the run's share.
        total: usize,
        /// Of those, solves an earlier run finished.
        done: usize,
        /// The estimated work of the share's solves, summed.
        work: u64,
        /// Of it, the solves' an earlier run finished.
        work_done: u64,
        /// Elastic-sharing onsets of the run's share.
        onsets: usize,
        /// Of those, onsets an earlier run recorded.
        onsets_done: usize,
    },
    /// The elastic-sharing onset of one law on a (topography, load) solve finished and was
    /// recorded (before that solve's `Solved`): its tangential solver iterations and seconds.
    /// Onsets an earlier run recorded are not run again, nor reported.
    Slid {
        /// Topography name.
        topography: &'a str,
        /// Normal load N \[N].
        load_n: f64,
        /// Friction law name.
        law: &'a str,
        /// Tangential solver iterations, summed over the path to sliding.
        iterations: usize,
        /// Wall-clock time of the onset \[s].
        seconds: f64,
    },
    /// An elastic-sharing onset under way settled a state (one may take minutes: a log shows it
    /// is alive): its `stage` (the march from δ = 0 or the search for the peak), its `steps`
    /// and tangential `solves` so far, the
    /// largest force so far over mu_d N, and its `seconds`. A `Break` stops the onset there
    /// and the run with [`Error::Interrupted`]; the onset is not recorded (the onsets finished
    /// are).
    Sliding {
        /// Topography name.
        topography: &'a str,
        /// Normal load N \[N].
        load_n: f64,
        /// Friction law name.
        law: &'a str,
        /// The march from δ = 0 or the search for the peak.
        stage: SlideStage,
        /// Displacement steps so far.
        steps: usize,
        /// Tangential solves so far.
        solves: usize,
        /// The largest tangential force so far over mu_d N.
        largest_drop: f64,
        /// Wall-clock time of the onset so far \[s].
        seconds: f64,
    },
    /// One (topography, load) solve finished.
    Solved {
        /// Topography name.
        topography: &'a str,
        /// Normal load N \[N].
        load_n: f64,
        /// Normal contact solver iterations.
        iterations: usize,
        /// Wall-clock time of the solve \[s].
        seconds: f64,
        /// The solve's estimated work ([`Study::solve_work`]).
        work: u64,
    },
}

/// What a run did.
#[derive(Debug)]
pub struct Outcome {
    /// Every row; none for a shard, which writes its solves only.
    pub rows: Vec<Row>,
    /// The solves of this run's share: all of the study's, or a shard's.
    pub share: usize,
    /// Of those, solves run now.
    pub solved: usize,
    /// Of those, solves found finished by an earlier run.
    pub resumed: usize,
    /// Elastic onsets run now.
    pub onsets: usize,
    /// Elastic onsets of the solves run now that an earlier run had finished (and recorded)
    /// before it stopped.
    pub onsets_resumed: usize,
    /// What the figures and the report are drawn from; none for a shard.
    pub records: Option<Records>,
    /// Plausibility warnings ([`super::warnings`]), also in the report.
    pub warnings: Vec<String>,
    /// With `fresh`: the files DIR held that no run wrote (put there by hand), kept; relative
    /// to DIR.
    pub left: Vec<PathBuf>,
    /// The results lock, held until the outcome is dropped: the figures drawn from `records`
    /// are written under it, as the table is.
    _results: Option<Lock>,
    /// The run's locks and its ledger, held until the outcome is dropped: the figures and the
    /// report written from `records` are recorded for `--fresh`, and never written through a
    /// link in DIR, as the table is not.
    _claim: Claim,
}

/// What the workers of a run count.
#[derive(Default)]
struct Tally {
    /// Solves finished now.
    solved: AtomicUsize,
    /// Elastic onsets run now, and those found recorded by an earlier run.
    onsets: AtomicUsize,
    onsets_resumed: AtomicUsize,
}

/// What the workers of a run share: its tallies, its progress callback, and the queue of the
/// elastic onsets whose solves are done. Each onset depends only on its solve's pressure, so
/// they run in any order, over all threads together with the sweeps' normal solves, the
/// largest first; the first error stops the run.
struct Work<'s, R> {
    dir: &'s Path,
    progress: &'s (dyn Fn(Progress) -> R + Sync),
    tally: Tally,
    queue: Mutex<Queue>,
    /// Whether a worker failed or was stopped: no new solve or onset starts.
    stopped: AtomicBool,
    /// The first error.
    error: Mutex<Option<Error>>,
}

impl<R> Work<'_, R> {
    fn stopped(&self) -> bool {
        self.stopped.load(Ordering::Relaxed)
    }

    /// Stop the run with `e`, unless an earlier error stopped it.
    fn fail(&self, e: Error) {
        self.error.lock().expect("no panic holding it").get_or_insert(e);
        self.stopped.store(true, Ordering::Relaxed);
    }
}

/// The elastic onsets waiting for a thread, and how many workers take them.
#[derive(Default)]
struct Queue {
    jobs: BinaryHeap<OnsetJob>,
    workers: usize,
}

/// One elastic onset to run: law `l` on load `k`'s solve of a sweep, its row going to `slot`
/// of the solve's rows.
struct OnsetJob {
    /// The solve's contact points: the larger contact set first (its onset takes longest).
    cost: usize,
    chain: Arc<Chain>,
    k: usize,
    l: usize,
    /// The places of its rows in the solve's: the elastic one, and equal sharing's under the
    /// same slip weakening (a law with a slip-weakening distance).
    slot: usize,
    weakening_slot: Option<usize>,
}

/// One row of each solve: its sharing, the index of its law, and its slip-weakening distance
/// d_c [m] (0: the instant drop; none: the law's measured curve).
#[derive(Clone, Copy, PartialEq)]
struct Slot {
    sharing: Sharing,
    law: usize,
    slip_distance: Option<f64>,
}

impl OnsetJob {
    /// The queue's order: the most contact points first, then (in a fixed order) the earlier
    /// sweep, the heavier load, the earlier law.
    fn key(&self) -> (usize, Reverse<usize>, usize, Reverse<usize>) {
        (self.cost, Reverse(self.chain.u), self.k, Reverse(self.l))
    }
}

impl PartialEq for OnsetJob {
    fn eq(&self, other: &Self) -> bool {
        self.key() == other.key()
    }
}

impl Eq for OnsetJob {}

impl PartialOrd for OnsetJob {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OnsetJob {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.key().cmp(&other.key())
    }
}

/// A sweep as its solves' onsets and records need it.
struct Chain {
    /// The sweep's unit, its label in progress reports and errors, and its rows' name.
    u: usize,
    label: String,
    name: String,
    /// Its folder of solve records, its loads, and which of them an earlier run recorded.
    solves: PathBuf,
    loads: Range<usize>,
    recorded: Vec<bool>,
    /// Grid (ny, nx) and physical size (lx, ly) [m].
    shape: (usize, usize),
    size: (f64, f64),
    state: Mutex<ChainState>,
}

/// The solves of a sweep waiting for their record.
#[derive(Default)]
struct ChainState {
    /// By load index: the sweep's solves not recorded yet.
    pending: BTreeMap<usize, Pending>,
    /// Whether the sweep has solved its last load (or stopped).
    complete: bool,
    /// Whether a thread is writing records ([`Study::flush`]).
    flushing: bool,
}

/// A solve waiting for its elastic onsets, and then its record.
struct Pending {
    /// Normal load [N].
    load: f64,
    cold: bool,
    facts: SolveFacts,
    /// Its rows, sharing-major; the elastic ones as their onsets end.
    rows: Vec<Option<Row>>,
    /// Its onsets not done yet.
    left: usize,
}

/// The record of one finished solve, `solves/<topography>/NN.json`.
#[derive(Serialize, Deserialize)]
struct SolveRecord {
    load_n: f64,
    /// Whether the solve started from no pressure (the first of its piece of the load
    /// chain), not from the solution of the load before it.
    #[serde(default)]
    cold: bool,
    solve: SolveFacts,
    /// One row per sharing and law (sharing-major), in the study's order; the coarser copies
    /// of the resolution figure under equal sharing only.
    rows: Vec<Row>,
}

/// The normal solve of a load whose elastic onsets are not all done, `NN-normal.json` beside
/// its pressure map `warm-NN.npy`; the solve's record replaces it.
#[derive(Serialize, Deserialize)]
struct NormalRecord {
    load_n: f64,
    cold: bool,
    solve: SolveFacts,
}

/// What a DIR's solves were computed for, `solves/fingerprint.json`.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Fingerprint {
    asperity: String,
    /// The resolved study, without the output options that do not change the solves.
    study: serde_json::Value,
    /// A digest of each topography's heights, grid and size as built.
    heights: Vec<String>,
}

impl Study {
    /// Read every file and build every topography and law of `config` (checked, with paths
    /// resolved); errors name `origin` and the topography or law.
    pub fn prepare(config: StudyConfig, origin: &str) -> Result<Study> {
        let at = |what: &str, e: Error| Error::invalid(format!("{origin}: {what}"), e.to_string());
        let grid = config.contact.grid;
        let limits = config.limits.limits();
        let boundary = config.contact.boundary;
        if let Some((nx, ny)) = grid {
            limits
                .check_grid(nx, ny)
                .and_then(|()| contact::check_solves_memory((ny, nx), boundary))
                .map_err(|r| at("contact.grid", Error::invalid("grid", r)))?;
        }
        let mut topographies = Vec::with_capacity(config.topographies.len());
        for spec in &config.topographies {
            let name = spec.name.clone().expect("checked: every topography has a name");
            let here = |e| at(&format!("topography \"{name}\""), e);
            // A synthetic surface's grid is known before it is generated: refuse it before.
            if let Some(s) = spec.synthetic.as_ref().filter(|_| grid.is_none()) {
                contact::check_solves_memory((s.grid.1, s.grid.0), boundary)
                    .map_err(|r| here(Error::invalid("synthetic.grid", r)))?;
            }
            let topo = build_topography(spec, grid, &limits).map_err(here)?;
            contact::check_solves_memory((topo.ny(), topo.nx()), boundary)
                .map_err(|r| here(Error::invalid("grid", r)))?;
            topographies.push((name, topo));
        }
        let (mut laws, mut hold_times, mut weakenings) = (Vec::new(), Vec::new(), Vec::new());
        for spec in &config.laws {
            let name = spec.name();
            let here = |e| at(&format!("law \"{name}\""), e);
            let weakening = config.model.weakening(spec).map_err(here)?;
            for (law, hold) in resolve_law(spec).map_err(here)? {
                laws.push(law);
                hold_times.push(hold);
                weakenings.push(weakening.clone());
            }
        }
        let mut coarse = Vec::new();
        if config.output.figures.contains(&FigureKind::Resolution) {
            for (t, (name, topo)) in topographies.iter().enumerate() {
                let (lx, _) = topo.physical_size.expect("built with a physical size");
                for factor in COARSENING {
                    let pixel = lx / topo.nx() as f64 * factor as f64;
                    let coarser =
                        resample(topo, pixel, &limits).map_err(|e| at(&format!("topography \"{name}\""), e))?;
                    coarse.push((t, factor, coarser));
                }
            }
        }
        let loads = config.load_values();
        let mut warnings = Vec::new();
        for ((name, topo), spec) in topographies.iter().zip(&config.topographies) {
            let size = topo.physical_size.expect("a built topography has a size");
            let here = format!("topography \"{name}\": loads");
            for &load in [loads[0], loads[loads.len() - 1]].iter() {
                contact::check_load(load, size, config.effective_modulus()).map_err(|e| at(&here, e))?;
            }
            // A file's window is known only now (a synthetic one's was judged with the file).
            match plausible::load(loads[loads.len() - 1], size, config.effective_modulus(), Spelling::StudyFile) {
                Err(reason) => return Err(Error::invalid(format!("{origin}: {here}"), reason)),
                Ok(Some(w)) if spec.synthetic.is_none() => warnings.push(format!("{here}: {w}")),
                Ok(_) => {}
            }
        }
        let mut config = config;
        config.loads =
            LoadsSpec { values: Some(loads.iter().map(|&l| Force(l)).collect()), min: None, max: None, count: None };
        Ok(Study {
            origin: origin.to_string(),
            config,
            topographies,
            coarse,
            laws,
            weakenings,
            hold_times,
            loads,
            wait: false,
            shard: None,
            warnings,
        })
    }

    /// What the prepared study found unusual once its files were read, in the study file's
    /// words: its heaviest load pressing a file's window unusually hard (a bare `1` meant in mN).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// When another process works in DIR on the same units, wait for it (`true`) instead of
    /// refusing (the default).
    pub fn waiting(self, wait: bool) -> Study {
        Study { wait, ..self }
    }

    /// Solve only `shard`'s share of the work ([`shard::assign`]): its solve records, and no
    /// table, figures or report (a run without a shard writes them, solving only what is
    /// missing).
    pub fn sharded(self, shard: Option<Shard>) -> Study {
        Study { shard, ..self }
    }

    /// Make `dir` this study's without solving anything, as a run does first (for scripts
    /// that run it later): new, or holding this study's solves; anything else is refused.
    pub fn claim_dir(&self, dir: &Path) -> Result<()> {
        self.claim(dir, false, &[]).map(drop)
    }

    /// Names the study in errors: its file, or "default study".
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The study as it runs: paths absolute, loads explicit.
    pub fn config(&self) -> &StudyConfig {
        &self.config
    }

    /// The loads \[N], ascending.
    pub fn loads(&self) -> &[f64] {
        &self.loads
    }

    /// The topographies as built, with their names.
    pub fn topographies(&self) -> &[(String, Topography)] {
        &self.topographies
    }

    /// How many coarser copies of the topographies the resolution figure solves at every load
    /// ([`COARSENING`] per topography, or none without that figure).
    pub fn coarse_copies(&self) -> usize {
        self.coarse.len()
    }

    /// The contact solves of the study, the units shards divide: every load of every sweep (a
    /// topography or a coarser copy, elastic or plastic).
    pub fn solves(&self) -> usize {
        self.sweeps().len() * self.loads.len()
    }

    /// The friction laws, one per law of the study file or per hold time of an aging law.
    pub fn laws(&self) -> &[FrictionLaw] {
        &self.laws
    }

    /// How many sweeps the study runs: one per topography, and for the resolution figure one
    /// per topography and coarsening.
    fn units(&self) -> usize {
        self.topographies.len() + self.coarse.len()
    }

    /// Sweep `u`'s name in progress reports, folder under `solves/`, topography, and the name
    /// of its rows.
    fn unit(&self, u: usize) -> (String, String, &Topography, &str) {
        match u.checked_sub(self.topographies.len()) {
            None => {
                let (name, topo) = &self.topographies[u];
                (name.clone(), name.clone(), topo, name)
            }
            Some(c) => {
                let (t, factor, topo) = &self.coarse[c];
                let name = &self.topographies[*t].0;
                (format!("{name} ({factor}× coarser)"), format!("{name}@{factor}x"), topo, name)
            }
        }
    }

    /// Run the study into `dir`, resuming the solves an earlier run of the same study left
    /// there; `fresh` discards them (and only them: files put in `dir` by hand stay). A `dir`
    /// holding another study, or anything that is not a study's output, is refused before
    /// anything is solved; so is a `dir` where another process works on the same units, unless
    /// [waiting](Study::waiting). `progress` answers each event with `()`, or with a
    /// `ControlFlow` whose `Break` stops the run with [`Error::Interrupted`] once the solves
    /// under way are recorded (the run resumes from there); a `Break` answering an elastic
    /// onset ([`Progress::Slid`]) stops at once, and resuming goes on from that solve's
    /// recorded parts (its normal solve and the onsets finished).
    pub fn run<R: Proceed>(
        &self,
        dir: &Path,
        fresh: bool,
        progress: &(dyn Fn(Progress) -> R + Sync),
    ) -> Result<Outcome> {
        let sweeps = self.sweeps();
        let pieces = self.pieces();
        let mut claim = self.claim(dir, fresh, &pieces)?;
        let left = std::mem::take(&mut claim.left);

        let share: usize = pieces.iter().map(|p| p.loads.len()).sum();
        let per_solve = |p: &Piece| self.onsets_per_solve(sweeps[p.sweep].0);
        let onsets: usize = pieces.iter().map(|p| p.loads.len() * per_solve(p)).sum();
        // The solves, and the onsets, an earlier run recorded: a recorded solve's own and those
        // of a solve it stopped in.
        let (mut resumed, mut onsets_done, mut work, mut work_done) = (0, 0, 0, 0);
        for p in &pieces {
            let (u, plastic) = sweeps[p.sweep];
            let solves = self.solves_dir(dir, u, plastic);
            for k in p.loads.clone() {
                work += self.solve_work(u, k);
                if solves.join(record_name(k)).is_file() {
                    resumed += 1;
                    onsets_done += per_solve(p);
                    work_done += self.solve_work(u, k);
                } else {
                    onsets_done += (0..per_solve(p)).filter(|&l| solves.join(onset_name(k, l)).is_file()).count();
                }
            }
        }
        let start = Progress::Start { total: share, done: resumed, work, work_done, onsets, onsets_done };
        if !progress(start).proceed() {
            return Err(self.interrupted());
        }
        let work = Work {
            dir,
            progress,
            tally: Tally::default(),
            queue: Mutex::new(Queue::default()),
            stopped: AtomicBool::new(false),
            error: Mutex::new(None),
        };
        // Each sweep's worker takes the next piece in order: the study's own sweeps first, the
        // cheap coarse ones filling in at the end. Their elastic onsets go to the queue, whose
        // workers start as onsets come ([`Study::enqueue`]); the scope ends when all are done.
        let next = AtomicUsize::new(0);
        let workers = rayon::current_num_threads().min(pieces.len()).max(1);
        rayon::scope(|scope| {
            for _ in 0..workers {
                scope.spawn(|scope| loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= pieces.len() || work.stopped() {
                        return;
                    }
                    let (u, plastic) = sweeps[pieces[k].sweep];
                    if let Err(e) = self.sweep(scope, &work, u, plastic, pieces[k].loads.clone()) {
                        return work.fail(e);
                    }
                });
            }
        });
        if let Some(e) = work.error.into_inner().expect("no panic holding it") {
            return Err(e);
        }
        let tally = work.tally;
        let solved = tally.solved.into_inner();
        let (onsets, onsets_resumed) = (tally.onsets.into_inner(), tally.onsets_resumed.into_inner());
        if self.shard.is_some() {
            return Ok(Outcome {
                rows: Vec::new(),
                share,
                solved,
                resumed,
                onsets,
                onsets_resumed,
                records: None,
                warnings: Vec::new(),
                left,
                _results: None,
                _claim: claim,
            });
        }

        let results = Lock::acquire(&dir.join(SOLVES).join(RESULTS_LOCK), Access::Exclusive, true)?;
        output::remove_stale_temporaries(dir)?;
        output::remove_stale_temporaries(&dir.join("figures"))?;
        let rows = self.rows(dir, 0..self.topographies.len())?;
        let resolution = self.resolution_rows(dir, &rows)?;
        if !resolution.is_empty() {
            output::write_atomic(&dir.join("resolution.csv"), |w| {
                let mut csv = csv::Writer::from_writer(w);
                for row in &resolution {
                    csv.serialize(row).map_err(std::io::Error::other)?;
                }
                csv.flush()
            })?;
        }
        output::write_atomic(&dir.join("results.csv"), |w| {
            let mut csv = csv::Writer::from_writer(w);
            for row in &rows {
                csv.serialize(row).map_err(std::io::Error::other)?;
            }
            csv.flush()
        })?;
        output::write_json(&dir.join("results.json"), &super::Results::new(rows.clone()))?;

        let snapshots = dir.join("snapshots");
        let maps = self
            .snapshot_indices()
            .into_iter()
            .map(|k| MapSnapshot::load(&snapshots, &self.snapshot_stem(k)))
            .collect::<Result<Vec<_>>>()?;
        let names: Vec<String> = self.topographies.iter().map(|(n, _)| n.clone()).collect();
        let parameters = self.study_file()?;
        let hold_time_loads: Vec<f64> = self.config.output.hold_time_loads.iter().map(|f| f.0).collect();
        // The figures show the first kind of solve listed; the table has them all. Every figure
        // but the sharing comparison draws the equal-sharing rows.
        let first = self.config.contact.plastic.modes()[0];
        let shown = |which: &dyn Fn(&Row) -> bool| -> Vec<Row> {
            rows.iter().filter(|r| r.plastic == first && which(r)).cloned().collect()
        };
        let records = Records {
            rows: shown(&Row::papers),
            weakening_rows: shown(&|r| r.sharing == Sharing::Equal && !r.papers()),
            elastic_rows: shown(&|r| r.sharing == Sharing::Elastic),
            topographies: names,
            laws: self.laws.clone(),
            hold_times: self.hold_times.clone(),
            modulus_ratios: self.modulus_ratios(),
            counterface: self.other_counterface(),
            resolution,
            hold_time_loads,
            log_density: self.config.output.log_density,
            hardness_pa: self.config.hardness(),
            slip_distance_m: self.config.model.slip_distance.0,
            grid: self.config.contact.grid,
            maps,
            figures: self.config.output.figures.clone(),
            snapshot_fractions: self.config.output.snapshot_fractions.clone(),
            parameters,
        };
        let warnings = super::study_warnings(&rows, &self.config);
        Ok(Outcome {
            rows,
            share,
            solved,
            resumed,
            onsets,
            onsets_resumed,
            records: Some(records),
            warnings,
            left,
            _results: results,
            _claim: claim,
        })
    }

    /// The study as run, as a study file.
    fn study_file(&self) -> Result<String> {
        let text = toml::to_string(&self.config).map_err(|e| Error::invalid("study", e.to_string()))?;
        Ok(format!("# The study as run by asperity {}.\n\n{text}", env!("CARGO_PKG_VERSION")))
    }

    /// E*₀/E* for E − ΔE and E + ΔE of `material.youngs_uncertainty` (none without it).
    fn modulus_ratios(&self) -> Vec<f64> {
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

    /// The estimated work of sweep `u`'s solve at load `k`, for the time left: its grid points
    /// times 1 + the decades its load lies above the study's lowest. A solve's time grows with
    /// its grid, and its iterations with its load (on the default study, 20–40 from 1 to
    /// 100 µN, 99 at 100 mN, warm-started).
    fn solve_work(&self, u: usize, k: usize) -> u64 {
        let lowest = self.loads.iter().copied().fold(f64::INFINITY, f64::min);
        let decades = (self.loads[k] / lowest).log10().max(0.0);
        (self.unit(u).2.heights.len() as f64 * (1.0 + decades)).round() as u64
    }

    /// The other counterface of the friction-drop figure: the same material when the study's
    /// is the paper's rigid flat, the rigid flat when it is the same material; its
    /// description and E*₀/E*.
    fn other_counterface(&self) -> Option<(String, f64)> {
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

    /// Make `dir` this study's: new, holding this study's solves (kept, or discarded when
    /// `fresh`), or what a start killed before its fingerprint leaves. Anything else is
    /// refused, and so is `fresh` in a DIR whose runs kept no ledger. Returns the locks of the
    /// run (the study's, shared, and every piece's of `pieces`) and its open ledger.
    fn claim(&self, dir: &Path, fresh: bool, pieces: &[Piece]) -> Result<Claim> {
        let fingerprint = self.fingerprint()?;
        // Before anything is created in it.
        self.check_dir(dir)?;
        let solves = dir.join(SOLVES);
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        let _claiming = Lock::acquire(&solves.join(CLAIM_LOCK), Access::Exclusive, true)?;
        self.check_dir(dir)?;
        // Only claims write here, and this one holds the claim lock.
        output::remove_stale_temporaries(&solves)?;
        let stored_path = solves.join(FINGERPRINT);
        let stored = match std::fs::read_to_string(&stored_path) {
            Ok(text) => Some(serde_json::from_str::<Fingerprint>(&text).ok()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(Error::io(&stored_path, e)),
        };
        let ledger_path = solves.join(LEDGER);
        let recorded = Ledger::read(&ledger_path)?;
        if let Some(recorded) = &recorded {
            self.check_outputs(dir, recorded)?;
        }
        // A DIR an asperity without ledgers wrote stays without one: a ledger begun now would
        // miss the earlier files, which a later `fresh` must not keep as this study's.
        let ledger = match (&stored, &recorded) {
            (Some(_), None) if fresh => {
                return Err(Error::invalid(
                    "--fresh",
                    format!(
                        "{} was written by an asperity that kept no record of its files, so --fresh cannot tell them \
                         from yours: move your own files out of it and remove it, or choose another --out",
                        dir.display()
                    ),
                ))
            }
            (Some(_), None) => None,
            _ => Some(Ledger::open(dir, &ledger_path)),
        };
        let mut left = Vec::new();
        let study_lock = solves.join(STUDY_LOCK);
        let study = match stored {
            Some(Some(f)) if f == fingerprint && !fresh => self.lock(&study_lock, Access::Shared, dir, "this study")?,
            Some(_) if !fresh => {
                return Err(Error::invalid(
                    "--out",
                    format!(
                        "{} holds the results of a different study than {}: rerun with --fresh to start over, or \
                         choose another --out",
                        dir.display(),
                        self.origin
                    ),
                ))
            }
            stored => {
                let lock = self.lock(&study_lock, Access::Exclusive, dir, "its study")?;
                if stored.is_some() {
                    left = discard(dir, recorded.unwrap_or_default())?;
                }
                output::write_json(&stored_path, &fingerprint)?;
                // Safe to share by release and retake: the claim lock keeps other claims out.
                lock.share()?
            }
        };
        let sweeps = self.sweeps();
        let first_mode = self.config.contact.plastic.modes()[0];
        let units = pieces
            .iter()
            .map(|piece| {
                let (u, plastic) = sweeps[piece.sweep];
                let unit = self.solves_dir(dir, u, plastic);
                std::fs::create_dir_all(&unit).map_err(|e| Error::io(&unit, e))?;
                let (label, folder, ..) = self.unit(u);
                let what = format!("topography \"{label}\"{}", if plastic { " (plastic)" } else { "" });
                let lock = self.lock_loads(&unit, piece.loads.clone(), dir, &what)?;
                // A whole chain's folders are this run's alone now: what a killed run left
                // there goes (a piece shares them with the other pieces' writers).
                if piece.loads.len() == self.loads.len() {
                    let pressure = plastic_dir(dir.join("pressure").join(folder), plastic);
                    output::remove_stale_temporaries(&unit)?;
                    output::remove_stale_temporaries(&pressure)?;
                    if u == 0 && plastic == first_mode {
                        output::remove_stale_temporaries(&dir.join("snapshots"))?;
                    }
                }
                Ok(lock)
            })
            .collect::<Result<Vec<_>>>()?;
        let text = self.study_file()?;
        output::write_atomic(&dir.join("study.toml"), |w| w.write_all(text.as_bytes()))?;
        Ok(Claim { _study: study, _units: units, _ledger: ledger, left })
    }

    /// Refuse, before anything in `dir` changes, a file where the runs write their outputs
    /// ([`DIR_OUTPUTS`]) that the ledger `recorded` does not hold as written by a run (a user's
    /// file, or one changed since), and an input of the study there (which a run would replace
    /// or `fresh` remove), compared as `cp` does, by device and inode.
    fn check_outputs(&self, dir: &Path, recorded: &[output::Written]) -> Result<()> {
        use std::os::unix::fs::MetadataExt;
        let inputs: Vec<(&Path, (u64, u64))> = self
            .config
            .input_files()
            .into_iter()
            .filter_map(|p| std::fs::metadata(p).ok().map(|m| (p, (m.dev(), m.ino()))))
            .collect();
        let by_path: std::collections::HashMap<&Path, &output::Written> =
            recorded.iter().map(|w| (w.path.as_path(), w)).collect();
        let mut found = Vec::new();
        files_below(dir, Path::new(""), &mut found)?;
        found.sort();
        // A lock file is opened, never written over, and may be another process's to record.
        let lock = |p: &Path| p.starts_with(SOLVES) && p.extension().is_some_and(|e| e == "lock");
        for path in found {
            let first = path.components().next().map(|c| c.as_os_str().to_owned()).unwrap_or_default();
            if !DIR_OUTPUTS.iter().any(|o| first == *o) || is_kept(&path) || lock(&path) {
                continue;
            }
            let full = dir.join(&path);
            if std::fs::symlink_metadata(&full).is_ok_and(|m| m.file_type().is_symlink()) {
                return Err(Error::file(
                    &full,
                    "a symbolic link in a folder asperity writes: it never writes through one (it would replace what \
                     the link points to); remove the link, or choose another --out",
                ));
            }
            let Ok(meta) = std::fs::metadata(&full) else { continue };
            if let Some((input, _)) = inputs.iter().find(|(_, id)| *id == (meta.dev(), meta.ino())) {
                return Err(Error::file(
                    &full,
                    format!(
                        "is an input of the study ({}) where the study writes its results: keep inputs out of \
                         DIR's {}, or choose another --out",
                        input.display(),
                        DIR_OUTPUTS.join(", ")
                    ),
                ));
            }
            let ours = reached_without_links(dir, &path)
                .is_some_and(|m| by_path.get(path.as_path()).is_some_and(|w| w.is(&m)));
            if !ours {
                return Err(Error::file(
                    &full,
                    "is a file asperity did not write (or one changed since), where the study writes its results: \
                     asperity never writes over one; move it away, or choose another --out",
                ));
            }
        }
        Ok(())
    }

    /// Take a lock of the run in `dir`, waiting for it or refusing when another process holds
    /// it (working on `what`).
    fn lock(&self, path: &Path, access: Access, dir: &Path, what: &str) -> Result<Lock> {
        Lock::acquire(path, access, self.wait)?.ok_or_else(|| {
            Error::invalid(
                "--out",
                format!(
                    "{} is busy: another asperity run works on {what} there; wait for it with --wait, or choose \
                     another --out",
                    dir.display()
                ),
            )
        })
    }

    /// Lock loads `loads` of the sweep whose records are in `folder`: by its own lock file
    /// `loads-AA-BB.lock` (AA, BB its first and last load), once no other process holds the
    /// lock of a piece that overlaps it. Only claims take these locks, under the claim lock, so
    /// no new one appears meanwhile.
    fn lock_loads(&self, folder: &Path, loads: Range<usize>, dir: &Path, what: &str) -> Result<Lock> {
        let own = format!("loads-{:02}-{:02}.lock", loads.start, loads.end - 1);
        let lock = self.lock(&folder.join(&own), Access::Exclusive, dir, what)?;
        let entries = std::fs::read_dir(folder).map_err(|e| Error::io(folder, e))?;
        for entry in entries {
            let name = entry.map_err(|e| Error::io(folder, e))?.file_name();
            let Some(name) = name.to_str() else { continue };
            if let Some((first, last)) = lock_range(name) {
                if name != own && first < loads.end && last >= loads.start {
                    drop(self.lock(&folder.join(name), Access::Exclusive, dir, what)?);
                }
            }
        }
        Ok(lock)
    }

    /// Refuse a `dir` that is an empty path, a file, or holds neither a study's solves nor only
    /// what a start killed before its fingerprint leaves (the solves folder, its locks,
    /// temporaries): the rules of every caller (`asperity run`, `slurm`, Python's `run_study`).
    fn check_dir(&self, dir: &Path) -> Result<()> {
        // An empty path names no folder: its files would land beside the user's own.
        if dir.as_os_str().is_empty() {
            return Err(Error::invalid("--out", "an empty path names no folder: choose a new or empty folder"));
        }
        match std::fs::metadata(dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(e) => return Err(Error::io(dir, e)),
            Ok(m) if !m.is_dir() => {
                return Err(Error::invalid("--out", format!("{} is a file, not a directory", dir.display())))
            }
            Ok(_) => {}
        }
        let solves = dir.join(SOLVES);
        if solves.join(FINGERPRINT).is_file() {
            return Ok(());
        }
        let only = |d: &Path, names: &[&str]| -> Result<bool> {
            let entries = match std::fs::read_dir(d) {
                Ok(entries) => entries,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(true),
                Err(e) => return Err(Error::io(d, e)),
            };
            for entry in entries {
                let name = entry.map_err(|e| Error::io(d, e))?.file_name();
                if !(output::is_temporary(&name) || names.iter().any(|n| name == *n)) {
                    return Ok(false);
                }
            }
            Ok(true)
        };
        // A claim writes the fingerprint before anything else and never removes it: what it
        // wrote while this looked is a study's.
        if (only(dir, &[SOLVES])? && only(&solves, &[CLAIM_LOCK, STUDY_LOCK, LEDGER])?)
            || solves.join(FINGERPRINT).is_file()
        {
            return Ok(());
        }
        Err(Error::invalid("--out", format!("{} is not empty and holds no study: choose another --out", dir.display())))
    }

    fn fingerprint(&self) -> Result<Fingerprint> {
        let mut study = self.config.clone();
        let defaults = StudyConfig::default_study().output;
        // Figures, their snapshots' fractions and the measured points do not change a solve.
        study.output.figures = defaults.figures;
        study.output.snapshot_fractions = defaults.snapshot_fractions;
        study.output.experiments = None;
        // Nor do the input limits.
        study.limits = Default::default();
        let heights = self
            .topographies
            .iter()
            .map(|(_, t)| {
                let mut h = DefaultHasher::new();
                t.heights.dim().hash(&mut h);
                t.physical_size.map(|(lx, ly)| (lx.to_bits(), ly.to_bits())).hash(&mut h);
                t.heights.iter().for_each(|v| v.to_bits().hash(&mut h));
                format!("{:016x}", h.finish())
            })
            .collect();
        Ok(Fingerprint {
            asperity: env!("CARGO_PKG_VERSION").to_string(),
            study: serde_json::to_value(&study).map_err(|e| Error::invalid("study", e.to_string()))?,
            heights,
        })
    }

    /// This run's pieces of work ([`shard::assign`]): every sweep's whole chain, or a shard's
    /// share. Indices into [`Study::sweeps`].
    fn pieces(&self) -> Vec<Piece> {
        let points: Vec<usize> = self.sweeps().iter().map(|&(u, _)| self.unit(u).2.heights.len()).collect();
        let shard = self.shard.unwrap_or(Shard { index: 1, count: 1 });
        shard::assign(&points, self.loads.len(), shard.count).swap_remove(shard.index - 1)
    }

    /// The sweeps of the run, (unit, plastic): every topography in each kind of solve listed,
    /// the coarser copies of the resolution figure in the first kind only.
    fn sweeps(&self) -> Vec<(usize, bool)> {
        let modes = self.config.contact.plastic.modes();
        let main =
            (0..self.topographies.len()).flat_map(|t| modes.clone().into_iter().map(move |plastic| (t, plastic)));
        main.chain((self.topographies.len()..self.units()).map(|u| (u, modes[0]))).collect()
    }

    /// The sharings of sweep `u`'s rows: the study's, or for a coarser copy of the resolution
    /// figure equal sharing only.
    fn sharings(&self, u: usize) -> &[Sharing] {
        if u < self.topographies.len() {
            &self.config.model.sharing
        } else {
            &[Sharing::Equal]
        }
    }

    /// The elastic-sharing onsets of each solve of sweep `u`: one per law, or none.
    fn onsets_per_solve(&self, u: usize) -> usize {
        if self.sharings(u).contains(&Sharing::Elastic) {
            self.laws.len()
        } else {
            0
        }
    }

    /// Rows of a solve of the study's own grid ([`Study::layout`]).
    fn rows_per_solve(&self) -> usize {
        self.layout(0).len()
    }

    /// The rows of each solve of sweep `u`, in order: per sharing listed, one per law; before
    /// the elastic ones, per law with a slip-weakening distance, equal sharing under the same
    /// weakening, so that the interaction and the weakening show apart.
    fn layout(&self, u: usize) -> Vec<Slot> {
        let laws = 0..self.laws.len();
        let mut slots = Vec::new();
        for &sharing in self.sharings(u) {
            if sharing == Sharing::Elastic {
                let weakening = laws.clone().filter_map(|l| match self.weakenings[l] {
                    Weakening::Linear(dc) => Some(Slot { sharing: Sharing::Equal, law: l, slip_distance: Some(dc) }),
                    _ => None,
                });
                slots.extend(weakening);
            }
            let slip_distance = |l: usize| match sharing {
                Sharing::Equal => Some(0.0),
                Sharing::Elastic => self.slip_law(l).slip_distance(),
            };
            slots.extend(laws.clone().map(|l| Slot { sharing, law: l, slip_distance: slip_distance(l) }));
        }
        slots
    }

    /// The local law of elastic sharing for law `l`: mu_s to mu_d over the model's
    /// slip-weakening distance, or along the law's measured curve.
    fn slip_law(&self, l: usize) -> SlipLaw {
        let law = &self.laws[l];
        SlipLaw { mu_s: law.mu_s, mu_d: law.mu_d, weakening: self.weakenings[l].clone() }
    }

    /// The folder of sweep `u`'s solve records, elastic or plastic.
    fn solves_dir(&self, dir: &Path, u: usize, plastic: bool) -> PathBuf {
        plastic_dir(dir.join(SOLVES).join(TOPOGRAPHIES).join(self.unit(u).1), plastic)
    }

    /// Solve the loads `loads` of sweep `u` (elastic or plastic) that have no record yet, in
    /// increasing order, each from the solution of the load before it (warm start). The
    /// piece's first load starts cold; a gap in its records goes on from the map of the load
    /// before it (kept by a killed run, or at the end of another run's piece), and when that
    /// map is gone (a `--fresh` cut short) the piece starts over. Each record says whether its
    /// solve started cold. The map of the piece's last load stays for whoever goes on from it.
    ///
    /// With elastic sharing a solve's parts are recorded as they finish, for a run stopped
    /// before its record to go on from: the normal solve (`NN-normal.json`, with its map
    /// `warm-NN.npy`) and each law's onset (`NN-elastic-LL.json`, LL the law's index). The
    /// onsets go to the run's queue ([`Work`]) and the sweep goes on to its next load; the
    /// solves are recorded in load order as their onsets finish ([`Study::flush`]), each
    /// record replacing its parts.
    fn sweep<'s, R: Proceed>(
        &'s self,
        scope: &rayon::Scope<'s>,
        work: &'s Work<'s, R>,
        u: usize,
        plastic: bool,
        loads: Range<usize>,
    ) -> Result<()> {
        let dir = work.dir;
        let solves = self.solves_dir(dir, u, plastic);
        let warm = |k: usize| solves.join(warm_name(k));
        let recorded: Vec<bool> = loads.clone().map(|k| solves.join(record_name(k)).is_file()).collect();
        let is_recorded = |k: usize| loads.contains(&k) && recorded[k - loads.start];
        if recorded.iter().all(|&r| r) {
            return self.tidy(&solves, loads);
        }
        let (label, _, topo, name) = self.unit(u);
        let main = u < self.topographies.len();
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        let shape = topo.heights.dim();
        let size = topo.physical_size.expect("built with a physical size");
        let pixel = (size.0 / shape.1 as f64, size.1 / shape.0 as f64);
        let c = &self.config.contact;
        let heights = topo.heights.as_standard_layout();
        let options = SolverOptions {
            convergence: Convergence { tolerance: c.tolerance, max_iterations: c.max_iterations },
            device: c.device,
        };
        let mut solver = ContactSolver::new(
            heights.as_slice().expect("standard layout"),
            shape,
            size,
            self.config.effective_modulus(),
            c.boundary,
            options,
        )?;
        solver.set_hardness(if plastic { self.config.material.hardness.map(|h| h.0) } else { None })?;
        let maps = plastic_dir(dir.join("pressure").join(name), plastic);
        let keep_maps = self.config.output.pressure_maps && main;
        if keep_maps {
            std::fs::create_dir_all(&maps).map_err(|e| Error::io(&maps, e))?;
        }
        let shown = u == 0 && plastic == self.config.contact.plastic.modes()[0];
        let snapshots = if shown { self.snapshot_indices() } else { Vec::new() };
        let elastic = self.sharings(u).contains(&Sharing::Elastic);
        // A normal solve an earlier run finished, its elastic onsets not all.
        let kept = |k: usize| elastic && solves.join(normal_name(k)).is_file() && warm(k).is_file();
        let mut todo: Vec<usize> = loads.clone().filter(|&k| !is_recorded(k)).collect();
        if todo.iter().any(|&k| k > loads.start && is_recorded(k - 1) && !warm(k - 1).is_file() && !kept(k)) {
            todo = loads.clone().collect();
        }
        let chain = Arc::new(Chain {
            u,
            label: label.clone(),
            name: name.to_string(),
            solves: solves.clone(),
            loads: loads.clone(),
            recorded: recorded.clone(),
            shape,
            size,
            state: Mutex::new(ChainState::default()),
        });
        // The load whose solution the solver holds.
        let mut held = None;
        for k in todo {
            if work.stopped() {
                break;
            }
            let load = self.loads[k];
            let context = |e: Error| Error::invalid(format!("topography \"{label}\" at {load} N"), e.to_string());
            let (pressure, cold, facts) = if kept(k) {
                let (normal, pressure) = read_normal(&solves, k, load)?;
                // The next load goes on from it as from the solver's own solution.
                solver.warm_start(pressure.as_slice().expect("row-major"))?;
                (pressure, normal.cold, normal.solve)
            } else {
                // An elastic onset follows its solve's pressure to the last bit, and a warm
                // start leaves the solution dependent on where a chain was cut (by shards, by
                // a killed run) within the tolerance: with elastic sharing every solve starts
                // cold, so that its rows are the same however the study was run.
                let cold = if elastic {
                    solver.reset();
                    true
                } else if k > 0 && held == Some(k - 1) {
                    false
                } else if k > loads.start && warm(k - 1).is_file() {
                    solver.warm_start(read_map(&warm(k - 1))?.as_slice().expect("row-major"))?;
                    false
                } else {
                    solver.reset();
                    true
                };
                let report = solver.solve(load, |_, _| ()).map_err(context)?;
                let pressure = Array2::from_shape_vec(shape, solver.pressure().to_vec()).expect("the grid's shape");
                let summary = contact::summarize(solver.pressure(), shape, size, c.boundary, self.config.hardness());
                let facts = SolveFacts::new(&summary, &report);
                if elastic {
                    // The onsets read the solve from its map, and a run stopped before its
                    // record goes on from it: the map first, then the record that names it.
                    facts.require_finite().map_err(context)?;
                    output::write_npy(&warm(k), &pressure)?;
                    output::write_json(
                        &solves.join(normal_name(k)),
                        &NormalRecord { load_n: load, cold, solve: facts },
                    )?;
                }
                (pressure, cold, facts)
            };
            let elements = ElementLoads::from_pressure(&pressure, pixel.0 * pixel.1).map_err(context)?;
            // The rows of the solve's layout: the paper's at once, the others as the elastic
            // onsets that give them end (or from an earlier run's record of them).
            let layout = self.layout(u);
            let mut rows: Vec<Option<Row>> = vec![None; layout.len()];
            let mut onsets = Vec::new();
            for (slot, row) in layout.iter().enumerate() {
                match row.sharing {
                    Sharing::Equal if row.slip_distance == Some(0.0) => {
                        rows[slot] = Some(Row::new(name, load, &facts, &Onset::new(&elements, &self.laws[row.law])));
                    }
                    Sharing::Equal => {}
                    Sharing::Elastic => {
                        let l = row.law;
                        let weakening_slot = layout
                            .iter()
                            .position(|s| s.sharing == Sharing::Equal && s.law == l && s.slip_distance != Some(0.0));
                        let path = solves.join(onset_name(k, l));
                        if path.is_file() {
                            let mut kept = read_onset(
                                &path,
                                name,
                                load,
                                &super::law_name(&self.laws[l]),
                                weakening_slot.is_some(),
                            )?
                            .into_iter();
                            rows[slot] = kept.next();
                            if let Some(w) = weakening_slot {
                                rows[w] = kept.next();
                            }
                            work.tally.onsets_resumed.fetch_add(1, Ordering::Relaxed);
                        } else {
                            onsets.push((slot, weakening_slot, l));
                        }
                    }
                }
            }

            // Everything of this solve first, its record last: a record means the solve is done.
            if keep_maps {
                output::write_npy(&maps.join(format!("{k:02}.npy")), &pressure)?;
            }
            if snapshots.contains(&k) {
                let mut snap =
                    MapSnapshot::crop(name, load, &pressure, pixel, SNAPSHOT_MARGIN).expect("a load makes contact");
                if (load / FIGURE_LOADS_N[0]).log10().abs() <= NEAR_DECADES {
                    // The friction curve's: its elements' k_t, from the stuck contact.
                    let compliance = ShearCompliance::of(&self.config.bodies());
                    let mut solver = TangentialSolver::new(
                        pressure.as_slice().expect("row-major"),
                        shape,
                        size,
                        compliance,
                        c.boundary,
                        TangentialOptions::default(),
                    )
                    .map_err(context)?;
                    snap.stuck_stiffness = Some(stuck_stiffness(&mut solver).map_err(context)?.0);
                }
                let dir = dir.join("snapshots");
                std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
                snap.save(&dir, &self.snapshot_stem(k))?;
            }
            // The map the next load goes on from, should this run stop before it (or this piece
            // end there); with elastic sharing it is written already.
            if k + 1 < self.loads.len() && !is_recorded(k + 1) && !elastic {
                output::write_npy(&warm(k), &pressure)?;
            }
            let pending = Pending { load, cold, facts, rows, left: onsets.len() };
            chain.state.lock().expect("no panic holding it").pending.insert(k, pending);
            for (slot, weakening_slot, l) in onsets {
                let job =
                    OnsetJob { cost: facts.contact_points, chain: Arc::clone(&chain), k, l, slot, weakening_slot };
                self.enqueue(scope, work, job);
            }
            self.flush(&chain, work)?;
            held = Some(k);
        }
        chain.state.lock().expect("no panic holding it").complete = true;
        self.flush(&chain, work)
    }

    /// Queue an elastic onset, and start a worker for it unless every thread has one: the
    /// workers take the largest onset queued first ([`OnsetJob`]'s order). Never more
    /// workers than threads, so that no more onsets are under way at once (each holds its
    /// solver's memory) when a thread waiting inside an onset's transforms takes up other work.
    fn enqueue<'s, R: Proceed>(&'s self, scope: &rayon::Scope<'s>, work: &'s Work<'s, R>, job: OnsetJob) {
        let mut queue = work.queue.lock().expect("no panic holding it");
        queue.jobs.push(job);
        if queue.workers < rayon::current_num_threads() {
            queue.workers += 1;
            scope.spawn(move |_| self.onsets(work));
        }
    }

    /// A worker of the onsets' queue: the largest first, until the queue is empty or the run
    /// stops.
    fn onsets<R: Proceed>(&self, work: &Work<'_, R>) {
        loop {
            let job = {
                let mut queue = work.queue.lock().expect("no panic holding it");
                match queue.jobs.pop() {
                    Some(job) if !work.stopped() => job,
                    _ => {
                        queue.workers -= 1;
                        return;
                    }
                }
            };
            if let Err(e) = self.onset(&job, work) {
                work.fail(e);
            }
        }
    }

    /// Run the elastic onset `job`, record it (`NN-elastic-LL.json`) and report it to the
    /// progress callback, whose `Break` stops the run at once with [`Error::Interrupted`] (the
    /// onsets finished stay recorded, no solve's record is written); then record the sweep's
    /// solves whose onsets are all done. Errors name the topography, the load and the law.
    fn onset<R: Proceed>(&self, job: &OnsetJob, work: &Work<'_, R>) -> Result<()> {
        let chain = &job.chain;
        let (k, l) = (job.k, job.l);
        let (load, facts) = {
            let state = chain.state.lock().expect("no panic holding it");
            let pending = &state.pending[&k];
            (pending.load, pending.facts)
        };
        let law = &self.laws[l];
        let law_label = super::law_name(law);
        let failed = |e: Error| {
            Error::invalid(
                format!("topography \"{}\" at {load} N: elastic sharing, law \"{law_label}\"", chain.label),
                e.to_string(),
            )
        };
        let pressure = read_map(&chain.solves.join(warm_name(k)))?;
        let start = std::time::Instant::now();
        let compliance = ShearCompliance::of(&self.config.bodies());
        let options = TangentialOptions::default();
        let mut solver = TangentialSolver::new(
            pressure.as_slice().expect("row-major"),
            chain.shape,
            chain.size,
            compliance,
            self.config.contact.boundary,
            options,
        )
        .map_err(failed)?;
        let slip = self.slip_law(l);
        let normal = solver.normal_force();
        let onset = elastic_onset(&mut solver, &slip, PEAK_TOLERANCE, |p| {
            let answer = (work.progress)(Progress::Sliding {
                topography: &chain.label,
                load_n: load,
                law: &law_label,
                stage: p.stage,
                steps: p.work.steps,
                solves: p.work.solves,
                largest_drop: p.largest_force_n / (law.mu_d * normal),
                seconds: start.elapsed().as_secs_f64(),
            });
            // A Break, or a run another worker stopped, ends the onset at this step.
            if answer.proceed() && !work.stopped() {
                ControlFlow::Continue(())
            } else {
                ControlFlow::Break(())
            }
        });
        let onset = match onset {
            Err(Error::Interrupted { .. }) => {
                work.fail(self.interrupted());
                return Ok(());
            }
            onset => onset.map_err(failed)?,
        };
        drop(solver);
        let seconds = start.elapsed().as_secs_f64();
        let mut rows = vec![Row::elastic(&chain.name, load, &facts, law, &slip, &onset, seconds)];
        if job.weakening_slot.is_some() {
            // Equal sharing under the same weakening: each element a spring–slider of the
            // contact's stuck stiffness shared equally.
            let area = chain.size.0 * chain.size.1 / (chain.shape.0 * chain.shape.1) as f64;
            let elements = ElementLoads::from_pressure(&pressure, area).map_err(failed)?;
            let stiffness = element_stiffness(onset.stuck_stiffness, elements.len());
            let equal = spring_slider_onset(&elements, &slip, stiffness).map_err(failed)?;
            rows.push(Row::equal_weakening(&chain.name, load, &facts, law, &slip, &equal));
        }
        rows.iter().try_for_each(Row::require_finite)?;
        output::write_json(&chain.solves.join(onset_name(k, l)), &rows)?;
        work.tally.onsets.fetch_add(1, Ordering::Relaxed);
        let answer = (work.progress)(Progress::Slid {
            topography: &chain.label,
            load_n: load,
            law: &law_label,
            iterations: onset.work.iterations,
            seconds,
        });
        if !answer.proceed() {
            // Stopped before the row reaches its solve: no record is written without it.
            work.fail(self.interrupted());
            return Ok(());
        }
        {
            let mut state = chain.state.lock().expect("no panic holding it");
            let pending = state.pending.get_mut(&k).expect("pending until its onsets end");
            let mut rows = rows.into_iter();
            pending.rows[job.slot] = rows.next();
            if let Some(w) = job.weakening_slot {
                pending.rows[w] = rows.next();
            }
            pending.left -= 1;
        }
        self.flush(chain, work)
    }

    /// Record `chain`'s solves whose onsets are all done, in load order (one thread at a
    /// time: the others leave theirs to it), unless the run stopped; and once the sweep has
    /// run its last load and recorded it, remove what no solve needs any more
    /// ([`Study::tidy`]).
    fn flush<R: Proceed>(&self, chain: &Chain, work: &Work<'_, R>) -> Result<()> {
        let lock = || chain.state.lock().expect("no panic holding it");
        {
            let mut state = lock();
            if state.flushing {
                return Ok(());
            }
            state.flushing = true;
        }
        let flushed = (|| loop {
            // Once stopped, the solves stay in their parts, as a stop leaves them.
            if work.stopped() {
                return Ok(());
            }
            let ready = {
                let mut state = lock();
                match state.pending.first_key_value() {
                    Some((_, first)) if first.left == 0 => state.pending.pop_first(),
                    None if state.complete => None,
                    _ => return Ok(()),
                }
            };
            match ready {
                Some((k, pending)) => self.record(chain, k, pending, work)?,
                None => return self.tidy(&chain.solves, chain.loads.clone()),
            }
        })();
        lock().flushing = false;
        flushed
    }

    /// Write load `k`'s record (its rows all known), remove its parts and the maps no load
    /// goes on from, and report it to the progress callback, whose `Break` stops the run with
    /// [`Error::Interrupted`] (no later record is written).
    fn record<R: Proceed>(&self, chain: &Chain, k: usize, pending: Pending, work: &Work<'_, R>) -> Result<()> {
        let Pending { load, cold, facts, rows, .. } = pending;
        let rows: Vec<Row> = rows.into_iter().map(|r| r.expect("every onset done")).collect();
        let warm = |k: usize| chain.solves.join(warm_name(k));
        // Never a NaN in a record (written as null): no later run could read it back.
        rows.iter().try_for_each(Row::require_finite)?;
        output::write_json(
            &chain.solves.join(record_name(k)),
            &SolveRecord { load_n: load, cold, solve: facts, rows },
        )?;
        self.remove_parts(&chain.solves, k)?;
        let next_recorded = chain.loads.contains(&(k + 1)) && chain.recorded[k + 1 - chain.loads.start];
        if k + 1 >= self.loads.len() || next_recorded {
            remove_if_present(&warm(k))?;
        }
        if k > chain.loads.start {
            remove_if_present(&warm(k - 1))?;
        }
        work.tally.solved.fetch_add(1, Ordering::Relaxed);
        let answer = (work.progress)(Progress::Solved {
            topography: &chain.label,
            load_n: load,
            iterations: facts.iterations,
            seconds: facts.seconds,
            work: self.solve_work(chain.u, k),
        });
        if !answer.proceed() {
            work.fail(self.interrupted());
        }
        Ok(())
    }

    /// Remove the parts of load `k`'s solve in `solves` ([`Study::sweep`]), once it is
    /// recorded.
    fn remove_parts(&self, solves: &Path, k: usize) -> Result<()> {
        remove_if_present(&solves.join(normal_name(k)))?;
        (0..self.laws.len()).try_for_each(|l| remove_if_present(&solves.join(onset_name(k, l))))
    }

    /// Remove what no solve of `loads` in `solves` needs any more (a run killed between a
    /// record and these removals leaves them): the maps of loads whose next load is
    /// recorded, and of the chain's last load once recorded; the parts of recorded solves.
    fn tidy(&self, solves: &Path, loads: Range<usize>) -> Result<()> {
        let last = self.loads.len() - 1;
        for k in loads.clone() {
            let next_recorded = k + 1 < loads.end && solves.join(record_name(k + 1)).is_file();
            let recorded = solves.join(record_name(k)).is_file();
            if next_recorded || (k == last && recorded) {
                remove_if_present(&solves.join(warm_name(k)))?;
            }
            if recorded {
                self.remove_parts(solves, k)?;
            }
        }
        Ok(())
    }

    fn interrupted(&self) -> Error {
        Error::Interrupted { what: format!("study {}", self.origin) }
    }

    /// Every row from the solve records of `units`: topography × solve × law × load.
    fn rows(&self, dir: &Path, units: std::ops::Range<usize>) -> Result<Vec<Row>> {
        let mut rows = Vec::with_capacity(units.len() * self.rows_per_solve() * self.loads.len());
        for (u, plastic) in self.sweeps().into_iter().filter(|(u, _)| units.contains(u)) {
            let solves = self.solves_dir(dir, u, plastic);
            let records = (0..self.loads.len())
                .map(|k| {
                    let path = solves.join(record_name(k));
                    let record: SolveRecord = read_record(&path)?;
                    let layout = self.layout(u);
                    let matches = record.rows.len() == layout.len()
                        && record.rows.iter().zip(&layout).all(|(r, s)| {
                            r.sharing == s.sharing
                                && r.law == super::law_name(&self.laws[s.law])
                                && r.slip_distance_m == s.slip_distance
                        });
                    if record.load_n != self.loads[k] || !matches {
                        return Err(foreign(&path));
                    }
                    Ok(record)
                })
                .collect::<Result<Vec<_>>>()?;
            for l in 0..self.layout(u).len() {
                rows.extend(records.iter().map(|r| r.rows[l].clone()));
            }
        }
        Ok(rows)
    }

    /// The resolution study's rows: the study's `rows` and those of the coarse sweeps, by
    /// coarsening (none without coarse sweeps).
    fn resolution_rows(&self, dir: &Path, rows: &[Row]) -> Result<Vec<ResolutionRow>> {
        if self.coarse.is_empty() {
            return Ok(Vec::new());
        }
        let pixel = |t: &Topography| t.physical_size.expect("built with a physical size").0 / t.nx() as f64;
        let own = |name: &str| &self.topographies.iter().find(|(n, _)| n == name).expect("a row's topography").1;
        // The coarser copies are solved under equal sharing only.
        let mut out: Vec<ResolutionRow> =
            rows.iter().filter(|r| r.papers()).map(|r| ResolutionRow::new(1, pixel(own(&r.topography)), r)).collect();
        for factor in COARSENING {
            for (c, (_, f, topo)) in self.coarse.iter().enumerate() {
                if *f == factor {
                    let u = self.topographies.len() + c;
                    out.extend(self.rows(dir, u..u + 1)?.iter().map(|r| ResolutionRow::new(factor, pixel(topo), r)));
                }
            }
        }
        Ok(out)
    }

    /// Indices of the swept loads nearest (in log scale) to [`FIGURE_LOADS_N`], ascending.
    fn snapshot_indices(&self) -> Vec<usize> {
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

    fn snapshot_stem(&self, k: usize) -> String {
        format!("{}-{k:02}", self.topographies[0].0)
    }
}

/// Whether `path` (relative to DIR) is one of the files of `solves/` kept for good ([`KEPT`]).
fn is_kept(path: &Path) -> bool {
    path.parent() == Some(Path::new(SOLVES)) && KEPT.iter().any(|k| path.ends_with(k))
}

/// Remove what runs wrote into `dir`, for `--fresh`: the files of its ledger, `recorded`, that
/// are still the very files written (the identity recorded; never a folder, nor what a link
/// points to, nor a user's file named by a hand-edited line or put in an output's place), then
/// the folders that held them once empty; files put in DIR by hand stay, and so do the folders
/// holding them. Returns those files, relative to `dir`. The fingerprint stays for the claim to
/// replace in one rename, so that a discard cut short still leaves a study's DIR (its ledger
/// whole until the end, for the next `fresh` to go on); the solve records go first, so that
/// what such a DIR resumes is solved again.
fn discard(dir: &Path, mut recorded: Vec<output::Written>) -> Result<Vec<PathBuf>> {
    let index = |s: &str| s.len() >= 2 && s.bytes().all(|b| b.is_ascii_digit());
    let is_record = |p: &Path| {
        p.starts_with(Path::new(SOLVES).join(TOPOGRAPHIES))
            && p.file_name().and_then(|n| n.to_str()?.strip_suffix(".json")).is_some_and(index)
    };
    recorded.retain(|w| !is_kept(&w.path));
    recorded.sort_by_key(|w| !is_record(&w.path));
    for written in &recorded {
        if reached_without_links(dir, &written.path).is_some_and(|m| written.is(&m)) {
            let full = dir.join(&written.path);
            std::fs::remove_file(&full).map_err(|e| Error::io(&full, e))?;
        }
    }
    // The emptied folders, deepest first; one still holding a file stays.
    let mut folders: Vec<&Path> = recorded.iter().flat_map(|w| w.path.ancestors().skip(1)).collect();
    folders.retain(|f| !f.as_os_str().is_empty() && *f != Path::new(SOLVES));
    folders.sort_by_key(|f| std::cmp::Reverse(f.components().count()));
    folders.dedup();
    for folder in folders {
        if reached_without_links(dir, folder).is_some_and(|m| m.is_dir()) {
            let _ = std::fs::remove_dir(dir.join(folder));
        }
    }
    // The ledger keeps what stays: the files of `solves/` kept for good.
    Ledger::retain(&dir.join(SOLVES).join(LEDGER), is_kept)?;
    let mut left = Vec::new();
    files_below(dir, Path::new(""), &mut left)?;
    left.retain(|p| !is_kept(p));
    left.sort();
    Ok(left)
}

/// What is at `path` (relative, below `dir`), if it is reached through folders only, no link
/// (the last component's own metadata, a link not followed).
fn reached_without_links(dir: &Path, path: &Path) -> Option<std::fs::Metadata> {
    let mut at = dir.to_path_buf();
    let mut meta = None;
    for part in path.components() {
        if meta.as_ref().is_some_and(|m: &std::fs::Metadata| !m.is_dir()) {
            return None;
        }
        at.push(part);
        meta = Some(std::fs::symlink_metadata(&at).ok()?);
    }
    meta
}

/// Push onto `found` every entry below `dir.join(at)` that is not a folder (links not followed,
/// temporaries skipped), relative to `dir`.
fn files_below(dir: &Path, at: &Path, found: &mut Vec<PathBuf>) -> Result<()> {
    let folder = dir.join(at);
    let entries = match std::fs::read_dir(&folder) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(&folder, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(&folder, e))?;
        if output::is_temporary(&entry.file_name()) {
            continue;
        }
        let path = at.join(entry.file_name());
        if entry.file_type().map_err(|e| Error::io(entry.path(), e))?.is_dir() {
            files_below(dir, &path, found)?;
        } else {
            found.push(path);
        }
    }
    Ok(())
}

/// The name of load `k`'s solve record in its sweep's folder.
fn record_name(k: usize) -> String {
    format!("{k:02}.json")
}

/// The name of the pressure map of load `k` that a solve goes on from.
fn warm_name(k: usize) -> String {
    format!("warm-{k:02}.npy")
}

/// The name of load `k`'s normal solve while its elastic onsets are under way.
fn normal_name(k: usize) -> String {
    format!("{k:02}-normal.json")
}

/// The name of load `k`'s elastic onset under the study's law `l`, until the solve's record.
fn onset_name(k: usize, l: usize) -> String {
    format!("{k:02}-elastic-{l:02}.json")
}

/// The error of a record in `path` that is not this study's.
fn foreign(path: &Path) -> Error {
    Error::file(path, "not a record of this study's solve: rerun with --fresh")
}

/// Read a JSON record.
fn read_record<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::file(path, e.to_string()))
}

/// The normal solve of load `k` (`load` [N]) recorded in `solves`, with its pressure map
/// [Pa] (row-major).
fn read_normal(solves: &Path, k: usize, load: f64) -> Result<(NormalRecord, Array2<f64>)> {
    let path = solves.join(normal_name(k));
    let normal: NormalRecord = read_record(&path)?;
    if normal.load_n != load {
        return Err(foreign(&path));
    }
    Ok((normal, read_map(&solves.join(warm_name(k)))?))
}

/// A pressure map [Pa] a run kept (`warm-NN.npy`), row-major.
fn read_map(path: &Path) -> Result<Array2<f64>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let pressure = io::npy::read_f64(&bytes).map_err(|r| Error::file(path, r))?;
    if !pressure.is_standard_layout() {
        return Err(Error::file(path, "not a row-major array"));
    }
    Ok(pressure)
}

/// The rows an elastic onset recorded in `path` for the solve of the rows named `name` at
/// `load` [N] under the law named `law`: the elastic one, then, `weakening` when the law has a
/// slip-weakening distance, equal sharing's under the same weakening.
fn read_onset(path: &Path, name: &str, load: f64, law: &str, weakening: bool) -> Result<Vec<Row>> {
    let rows: Vec<Row> = read_record(path)?;
    let same = |r: &Row| r.law == law && r.topography == name && r.load_n == load;
    let ours = rows.len() == 1 + usize::from(weakening)
        && rows.iter().all(same)
        && rows[0].sharing == Sharing::Elastic
        && rows[1..].iter().all(|r| r.sharing == Sharing::Equal && r.slip_distance_m == rows[0].slip_distance_m);
    if ours {
        Ok(rows)
    } else {
        Err(foreign(path))
    }
}

/// The first and last load of a piece's lock file `loads-AA-BB.lock`.
fn lock_range(name: &str) -> Option<(usize, usize)> {
    let (first, last) = name.strip_prefix("loads-")?.strip_suffix(".lock")?.split_once('-')?;
    Some((first.parse().ok()?, last.parse().ok()?))
}

/// Remove the file `path`; a missing one is no error.
fn remove_if_present(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io(path, e)),
        _ => Ok(()),
    }
}

/// `path`, or its `plastic` subfolder for a plastic sweep.
fn plastic_dir(path: PathBuf, plastic: bool) -> PathBuf {
    if plastic {
        path.join("plastic")
    } else {
        path
    }
}

/// A topography as the study solves it: read or generated, prepared, compounded with its
/// wafer, on the `grid` override if any.
fn build_topography(spec: &SurfaceSpec, grid: Option<(usize, usize)>, limits: &Limits) -> Result<Topography> {
    let ball = build_surface(spec, grid, limits)?;
    // A measured wafer is interpolated onto the ball's grid by the compounding as it is.
    let wafer =
        spec.wafer.as_ref().map(|w| build_surface(w, grid.filter(|_| w.synthetic.is_some()), limits)).transpose()?;
    let topo = compound_with(ball, wafer)?;
    // What `contact` refuses a study refuses: a synthetic surface's heights are checked
    // nowhere else (rms_slope = 1e6 gave ±1.7 m on a 10 µm window, solved).
    contact::contact_size(&topo)?;
    Ok(topo)
}

/// One surface: generated, or read and prepared ([`crate::topography::prepare::Preparation`]).
fn build_surface(spec: &SurfaceSpec, grid: Option<(usize, usize)>, limits: &Limits) -> Result<Topography> {
    if let Some(s) = &spec.synthetic {
        let mut s = s.clone();
        if let Some(g) = grid {
            s.grid = g;
        }
        limits.check_grid(s.grid.0, s.grid.1).map_err(|r| Error::invalid("synthetic.grid", r))?;
        return s.generate_within(limits);
    }
    let path = spec.file.as_ref().expect("checked: a surface is synthetic or a file");
    let options = ReadOptions {
        format: spec.format.clone(),
        channel: spec.channel.clone(),
        physical_size: spec.size.map(|s| (s.0 .0, s.1 .0)),
        height_unit: spec.height_unit.clone(),
        position_unit: None,
        limits: *limits,
    };
    spec.preparation(grid, *limits).apply(io::read(path, &options)?)
}

/// The laws a checked spec describes, named, each with its hold time [s] where known: one,
/// or one per hold time of an aging law.
fn resolve_law(spec: &LawSpec) -> Result<Vec<(FrictionLaw, Option<f64>)>> {
    if let (Some(mu_s), Some(mu_d), Some(t0), Some(beta), Some(times)) =
        (spec.mu_s, spec.mu_d, spec.hold_time, spec.aging, &spec.hold_times)
    {
        return times
            .iter()
            .zip(spec.names())
            .map(|(t, name)| Ok((FrictionLaw::aged(mu_s, mu_d, t0.0, beta, t.0)?.named(name), Some(t.0))))
            .collect();
    }
    let law = match (spec.mu_s, spec.mu_d, &spec.preset, &spec.curve) {
        (Some(mu_s), Some(mu_d), ..) => FrictionLaw::new(mu_s, mu_d),
        (_, _, Some(preset), _) => FrictionLaw::preset(preset),
        (_, _, _, Some(curve)) => FrictionLaw::from_curve_file(curve, spec.window),
        _ => unreachable!("checked: a law is a pair, a preset or a curve"),
    }?;
    Ok(vec![(law.named(spec.name()), spec.stated_hold_time())])
}
