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
//!   that order, the rows at the ends of `model.slip_distance_band` last; then with
//!   `contact.adhesion` the same for the adhesive solves (their `adhesive_force_n` set; records
//!   in `solves/topographies/<topography>/adhesive/`);
//! - `resolution.csv`: with the resolution figure, the friction drop of every topography × law
//!   × load at the study's pixel size and [`COARSENING`] times coarser ([`ResolutionRow`]);
//! - `snapshots/<topography>-<stem>.npy|json`: [`MapSnapshot`]s of the first topography at
//!   the swept loads nearest to [`FIGURE_LOADS_N`] (the stem names the solve, see below), the
//!   one the friction curve draws with its contact's stuck tangential stiffness K_t;
//! - `pressure/<topography>/<stem>.npy`: every full pressure map \[Pa], when asked for (a
//!   plastic sweep's in `pressure/<topography>/plastic/`, and its solve records likewise);
//! - `figures/`, `index.html`: the figures and their report, written by `crate::report` while
//!   the run's results lock is held (see [`Outcome::records`]);
//! - `solves/`: what makes a run resumable and a DIR grow — `fingerprint.json` (how the
//!   records are named), the ledger `written.jsonl` of every file the runs wrote in DIR
//!   ([`output::Ledger`]; `fresh` removes those and nothing else), and below
//!   `solves/topographies/<topography>/` one record `<stem>.json` per finished solve, its stem
//!   `<load>N-<digest>` naming the solve's load and identity ([`Study::stem`]: topography as
//!   built, material, contact settings, kind of solve, load). A record holds the solve's rows
//!   each under its slot's key ([`Study::slot_key`]: sharing, law, slip weakening), elastic
//!   sharing's onsets included, those of every study that recorded the solve, and whether
//!   the solve started cold. So a run finds what any earlier study computed with the same
//!   inputs, solves what is new, and leaves out of its table what it does not ask for (kept
//!   until `fresh`). Beside them, the last pressure map `<stem>-warm.npy` of an unfinished
//!   chain (float64, lossless). With elastic sharing, a solve's parts are recorded as they
//!   finish until its record replaces them: its normal solve `<stem>-normal.json` (with its
//!   map `<stem>-warm.npy`) and each law's onset `<stem>-elastic-<key>.json` (a row of
//!   results.json). A killed run, run again into the same DIR, picks up at the first missing
//!   record from that map, or from the parts of its solve: the solver depends only on the
//!   pressure it starts from, and an onset only on its solve's pressure, so the results equal
//!   an uninterrupted run's (apart from the timings) and no finished part is computed again.
//!   Topography names appear only as folder names there (and under `pressure/`), so no name
//!   collides with the run's own files.
//!
//! Units of work are pieces of a sweep's chain of loads: a whole chain, or with a
//! [shard](super::shard) its share of the chains. A piece starts cold at its first load. A
//! shard writes its solves only (records, snapshots, maps); a run without a shard solves what
//! is missing, going on from the map a piece that ended before a gap kept (or cold), and
//! writes the table and figures.
//!
//! One writer per solve: a run locks every solve of its pieces by
//! `solves/topographies/<topography>/<stem>.lock` (a plastic sweep's in its `plastic/`), so
//! no two processes, of one study or two, write the same record. Every process
//! working in DIR holds `solves/study.lock` shared; claiming DIR (checking or writing the
//! fingerprint, taking the solves' locks, `fresh` discarding the earlier solves, which needs
//! that lock exclusive) happens under `solves/claim.lock`, and the results, figures
//! and report are written under `solves/results.lock`. The locks are advisory (`flock`) and
//! released by the kernel when a process ends, so a killed run never leaves a stale one.
//!
//! Every file is written atomically. The library prints nothing: progress goes to a callback.
//!
//! The runner is in rooms, each importing only those before it: `plan.rs` holds the prepared
//! [`Study`] and what it computes, `progress.rs` the reports, `records.rs` what a run keeps in
//! DIR and resumes from, `schedule.rs` the solves and onsets over the threads; this file tells
//! the story ([`Study::prepare`], [`Study::run`]) and imports them all. None of them imports
//! `plot`, `report`, `cli` or `python`: the figures and the report are drawn by the layer above.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use super::adhesion::AdhesionLimit;
use super::config::{Force, LawSpec, LoadsSpec, StudyConfig, SurfaceSpec};
pub use super::plan::Study;
pub use super::progress::Progress;
use super::progress::Tally;
use super::records::{heights_digest, onset_name, Claim, RESULTS_LOCK, SOLVES};
use super::schedule::{Queue, Work};
use super::shard::{Piece, Shard};
use super::{FigureKind, MapSnapshot, Records, Row, Sharing, COARSENING};
use crate::contact::{self, Proceed};
use crate::error::{Error, Result};
use crate::friction::FrictionLaw;
use crate::limits::Limits;
use crate::output::{self, Access, Lock};
use crate::plausible::{self, Spelling};
use crate::topography::io::{self, ReadOptions};
use crate::topography::prepare::compound_with;
use crate::topography::resample::resample;
use crate::topography::Topography;

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
    /// Elastic onsets of the solves run now that an earlier run had recorded: one stopped
    /// before the solve's record, or one that recorded the solve without a row this study
    /// asks for (another law).
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
        let digests =
            topographies.iter().map(|(_, t)| t).chain(coarse.iter().map(|(_, _, t)| t)).map(heights_digest).collect();
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
            digests,
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

    /// When another process works in DIR on the same solves, wait for it (`true`) instead of
    /// refusing (the default).
    pub fn waiting(self, wait: bool) -> Study {
        Study { wait, ..self }
    }

    /// Solve only `shard`'s share of the work ([`shard::assign`](super::shard::assign)): its solve records, and no
    /// table, figures or report (a run without a shard writes them, solving only what is
    /// missing).
    pub fn sharded(self, shard: Option<Shard>) -> Study {
        Study { shard, ..self }
    }

    /// Make `dir` this study's without solving anything, as a run does first (for scripts
    /// that run it later): new, or holding studies' solves; anything else is refused.
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

    /// The loads of the study's sweeps, the units shards divide: every load of every sweep (a
    /// topography or a coarser copy, elastic or plastic; with adhesion, a topography's load is
    /// its solve and its adhesive solve together).
    pub fn solves(&self) -> usize {
        self.sweeps().len() * self.loads.len()
    }

    /// The friction laws, one per law of the study file or per hold time of an aging law.
    pub fn laws(&self) -> &[FrictionLaw] {
        &self.laws
    }

    /// Run the study into `dir`, reusing the solves earlier runs left there that were computed
    /// with the same inputs ([`Study::stem`]), of this study or another; `fresh` discards them
    /// (and only them: files put in `dir` by hand stay). A `dir` holding anything that is not
    /// a study's output is refused before anything is solved; so is a `dir` where another
    /// process works on the same solves, unless
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

        // A piece's units: its sweep's, and the adhesive one its sweep solves beside it.
        let units = |p: &Piece| {
            let (u, plastic) = sweeps[p.sweep];
            std::iter::once((u, plastic)).chain(self.adhesive_unit(u).map(|a| (a, plastic)))
        };
        let share: usize = pieces.iter().map(|p| p.loads.len() * units(p).count()).sum();
        let onsets: usize =
            pieces.iter().flat_map(|p| units(p).map(|(u, _)| p.loads.len() * self.onsets_per_solve(u))).sum();
        // The solves, and the onsets, an earlier run recorded: a recorded solve's own and those
        // of a solve it stopped in.
        let (mut resumed, mut onsets_done, mut work, mut work_done) = (0, 0, 0, 0);
        for (p, (u, plastic)) in pieces.iter().flat_map(|p| units(p).map(move |unit| (p, unit))) {
            let solves = self.solves_dir(dir, u, plastic);
            let elastic: Vec<String> =
                self.layout(u).iter().filter(|s| s.sharing == Sharing::Elastic).map(|s| self.slot_key(s)).collect();
            for k in p.loads.clone() {
                work += self.solve_work(u, k);
                if self.done(dir, u, plastic, k)? {
                    resumed += 1;
                    onsets_done += self.onsets_per_solve(u);
                    work_done += self.solve_work(u, k);
                } else {
                    let stem = self.stem(u, plastic, k);
                    let record = self.read_solve(&solves, &stem, self.loads[k])?;
                    let kept = |key: &&String| {
                        solves.join(onset_name(&stem, key)).is_file()
                            || record.as_ref().is_some_and(|r| r.row(key).is_some())
                    };
                    onsets_done += elastic.iter().filter(kept).count();
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
        let mut rows = self.rows(dir, 0..self.topographies.len())?;
        let resolution = self.resolution_rows(dir, &rows)?;
        // The adhesive solves' rows after the others (their units follow the coarser copies).
        rows.extend(self.rows(dir, self.topographies.len() + self.coarse.len()..self.units())?);
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
        let shown = |adhesive: bool, which: &dyn Fn(&Row) -> bool| -> Vec<Row> {
            rows.iter().filter(|r| r.plastic == first && r.adhesive() == adhesive && which(r)).cloned().collect()
        };
        let band = self.config.model.band();
        let in_band = |r: &Row| r.slip_distance_m.is_some_and(|d| band.contains(&d));
        let records = Records {
            rows: shown(false, &Row::papers),
            weakening_rows: shown(false, &|r| r.sharing == Sharing::Equal && !r.papers() && !in_band(r)),
            elastic_rows: shown(false, &|r| r.sharing == Sharing::Elastic && !in_band(r)),
            band_rows: shown(false, &in_band),
            adhesive_rows: shown(true, &Row::papers),
            cohesive_law: self.cohesive_law(),
            topographies: names,
            laws: self.laws.clone(),
            hold_times: self.hold_times.clone(),
            modulus_ratios: self.modulus_ratios(),
            counterface: self.other_counterface(),
            adhesion: AdhesionLimit::of(&self.topographies.iter().map(|(_, t)| t).collect::<Vec<_>>())?,
            resolution,
            hold_time_loads,
            log_density: self.config.output.log_density,
            hardness_pa: self.config.hardness(),
            slip_distance_m: self.config.model.slip_distance.0,
            slip_distance_band: band.clone(),
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
