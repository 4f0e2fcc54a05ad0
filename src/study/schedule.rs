//! The work of a run over the threads: each sweep's chain of loads solved in order on its own
//! worker ([`Study::sweep`]), the elastic onsets of the solves queued, the largest first, for
//! every thread ([`Work`], [`OnsetJob`]), and each solve recorded in load order once its onsets
//! are done ([`Study::flush`]).
//!
//! It reads the [plan](super::plan), writes and reads the [records](super::records) and
//! reports [progress](super::progress); it must not import `plot`, `report`, `cli` or
//! `python`.

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};
use std::ops::{ControlFlow, Range};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use ndarray::Array2;

use super::plan::Study;
use super::progress::{Progress, Tally};
use super::records::{
    normal_name, onset_name, read_map, read_normal, read_onset, record_name, remove_if_present, warm_name, KeyedRow,
    NormalRecord, SolveRecord,
};
use super::{MapSnapshot, Row, Sharing, SolveFacts, FIGURE_LOADS_N, NEAR_DECADES};
use crate::contact::{
    self, AdhesiveSolver, ContactSolver, Convergence, Proceed, ShearCompliance, SolverOptions, TangentialOptions,
    TangentialSolver,
};
use crate::error::{Error, Result};
use crate::friction::{
    elastic_onset, element_stiffness, spring_slider_onset, stuck_stiffness, ElementLoads, Onset, SlipLaw,
    PEAK_TOLERANCE,
};
use crate::output;
use crate::quantity::{show, LENGTH};

/// Pixels kept around the contact points in a [`MapSnapshot`].
const SNAPSHOT_MARGIN: usize = 8;

/// What the workers of a run share: its tallies, its progress callback, and the queue of the
/// elastic onsets whose solves are done. Each onset depends only on its solve's pressure, so
/// they run in any order, over all threads together with the sweeps' normal solves, the
/// largest first; the first error stops the run.
pub(super) struct Work<'s, R> {
    pub(super) dir: &'s Path,
    pub(super) progress: &'s (dyn Fn(Progress) -> R + Sync),
    pub(super) tally: Tally,
    pub(super) queue: Mutex<Queue>,
    /// Whether a worker failed or was stopped: no new solve or onset starts.
    pub(super) stopped: AtomicBool,
    /// The first error.
    pub(super) error: Mutex<Option<Error>>,
}

impl<R> Work<'_, R> {
    pub(super) fn stopped(&self) -> bool {
        self.stopped.load(Ordering::Relaxed)
    }

    /// Stop the run with `e`, unless an earlier error stopped it.
    pub(super) fn fail(&self, e: Error) {
        self.error.lock().expect("no panic holding it").get_or_insert(e);
        self.stopped.store(true, Ordering::Relaxed);
    }
}

/// The elastic onsets waiting for a thread, and how many workers take them.
#[derive(Default)]
pub(super) struct Queue {
    jobs: BinaryHeap<OnsetJob>,
    workers: usize,
}

/// One elastic onset to run: law `l` on load `k`'s solve of a sweep under the local law `slip`,
/// its row going to `slot` of the solve's rows.
struct OnsetJob {
    /// The solve's contact points: the larger contact set first (its onset takes longest).
    cost: usize,
    chain: Arc<Chain>,
    k: usize,
    l: usize,
    slip: SlipLaw,
    /// The key of its elastic row ([`Study::slot_key`]), which names its record.
    key: String,
    /// The places of its rows in the solve's: the elastic one, and equal sharing's under the
    /// same slip weakening (a law with a slip-weakening distance).
    slot: usize,
    weakening_slot: Option<usize>,
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

/// A unit's chain of loads in a sweep, as its solves' onsets and records need it.
struct Chain {
    /// The sweep's unit, its label in progress reports and errors, and its rows' name.
    u: usize,
    label: String,
    name: String,
    /// Its folder of solve records, the names of its solves by load ([`Study::stem`]), its
    /// loads, and which of them were done before this run ([`Study::done`]).
    solves: PathBuf,
    stems: Vec<String>,
    loads: Range<usize>,
    recorded: Vec<bool>,
    /// Grid (ny, nx) and physical size (lx, ly) [m].
    shape: (usize, usize),
    size: (f64, f64),
    state: Mutex<ChainState>,
}

impl Chain {
    /// Whether load `k`'s solve was done before this run.
    fn is_recorded(&self, k: usize) -> bool {
        self.loads.contains(&k) && self.recorded[k - self.loads.start]
    }
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
    /// Its rows, sharing-major, and their slots' keys; the elastic ones as their onsets end.
    rows: Vec<Option<Row>>,
    keys: Vec<String>,
    /// The rows of its earlier record that the study does not ask for, kept in the new one.
    kept: Vec<KeyedRow>,
    /// Its onsets not done yet.
    left: usize,
}

impl Study {
    /// Solve the loads `loads` of sweep `u` (elastic or plastic) that are not done yet
    /// ([`Study::done`]), in increasing order, each from the solution of the load before it
    /// (warm start). The piece's first load starts cold; a gap in its records goes on from the
    /// map of the load before it when one is kept (by a killed run, or at the end of another
    /// run's piece), and starts cold otherwise: a load added between two recorded ones, whose
    /// maps the records do not keep (a grid of float64 each), converges from no pressure to
    /// the same contact within the solver's tolerance. Each record says whether its solve
    /// started cold. The map of the piece's last load stays for whoever goes on from it.
    ///
    /// With adhesion, the sweep of a topography solves its adhesive unit too: at each load, the
    /// adhesive solve starts from the solve without adhesion at that load (solved again, and not
    /// recorded twice, where that one is recorded already), and hands the friction model, and
    /// elastic sharing's tangential solver, the compressive part of the traction.
    ///
    /// A solve recorded without a row the study asks for (a law added) is solved again; the
    /// rows of its elastic onsets recorded already are kept, and so are the rows of its
    /// record that the study does not ask for (another study's laws).
    ///
    /// With elastic sharing a solve's parts are recorded as they finish, for a run stopped
    /// before its record to go on from: the normal solve (`<stem>-normal.json`, with its map
    /// `<stem>-warm.npy`) and each law's onset (`<stem>-elastic-<key>.json`, keyed by its
    /// slot). The onsets go to the run's queue ([`Work`]) and the sweep goes on to its next
    /// load; the solves are recorded in load order as their onsets finish ([`Study::flush`]),
    /// each record replacing its parts.
    pub(super) fn sweep<'s, R: Proceed>(
        &'s self,
        scope: &rayon::Scope<'s>,
        work: &'s Work<'s, R>,
        u: usize,
        plastic: bool,
        loads: Range<usize>,
    ) -> Result<()> {
        let dir = work.dir;
        let chain = self.chain(dir, u, plastic, loads.clone())?;
        let adhesive = self.adhesive_unit(u).map(|a| self.chain(dir, a, plastic, loads.clone())).transpose()?;
        let chains = || std::iter::once(&chain).chain(adhesive.as_ref());
        if chains().all(|c| c.recorded.iter().all(|&r| r)) {
            return chains().try_for_each(|c| self.tidy(&c.solves, c.u, &c.stems, loads.clone()));
        }
        let (label, _, topo, _) = self.unit(u);
        let (shape, size) = (chain.shape, chain.size);
        let c = &self.config.contact;
        let heights = topo.heights.as_standard_layout();
        let options = SolverOptions {
            convergence: Convergence { tolerance: c.tolerance, max_iterations: c.max_iterations },
            device: c.device,
        };
        let heights = heights.as_slice().expect("standard layout");
        let e_star = self.config.effective_modulus();
        let mut solver = ContactSolver::new(heights, shape, size, e_star, c.boundary, options)?;
        solver.set_hardness(if plastic { self.config.material.hardness.map(|h| h.0) } else { None })?;
        let mut adhesive_solver = match (&adhesive, self.cohesive_law()) {
            (Some(_), Some(law)) => {
                Some(AdhesiveSolver::new(heights, shape, size, e_star, c.boundary, law, options.convergence)?)
            }
            _ => None,
        };
        let elastic = self.sharings(u).contains(&Sharing::Elastic);
        let warm = |k: usize| chain.solves.join(warm_name(&chain.stems[k]));
        // A normal solve an earlier run finished, its elastic onsets not all.
        let kept = |c: &Chain, k: usize| {
            elastic
                && c.solves.join(normal_name(&c.stems[k])).is_file()
                && c.solves.join(warm_name(&c.stems[k])).is_file()
        };
        let todo: Vec<usize> = loads.clone().filter(|&k| chains().any(|c| !c.is_recorded(k))).collect();
        // The load whose solution the solver holds.
        let mut held = None;
        for k in todo {
            if work.stopped() {
                break;
            }
            let load = self.loads[k];
            let context = |e: Error| Error::invalid(format!("topography \"{label}\" at {load} N"), e.to_string());
            // The gap of the solve without adhesion, where an adhesive solve starts from it.
            let mut gap = None;
            let (pressure, cold, facts) = if kept(&chain, k) {
                // Kept only with elastic sharing, whose next load starts cold.
                let (normal, pressure) = read_normal(&chain.solves, &chain.stems[k], load)?;
                (pressure, normal.cold, normal.solve)
            } else {
                // An elastic onset follows its solve's pressure to the last bit, and a warm
                // start leaves the solution dependent on where a chain was cut (by shards, by a
                // killed run) within the tolerance: with elastic sharing every solve starts
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
                gap = adhesive.as_ref().is_some_and(|a| !a.is_recorded(k)).then(|| solver.gap());
                let summary = contact::summarize(solver.pressure(), shape, size, c.boundary, self.config.hardness());
                let facts = SolveFacts::new(&summary, &report);
                if elastic && !chain.is_recorded(k) {
                    self.record_normal(&chain, k, &pressure, cold, facts).map_err(context)?;
                }
                (pressure, cold, facts)
            };
            held = Some(k);
            // The map the next load goes on from, should this run stop before it (or this piece
            // end there); with elastic sharing it is written already.
            if !chain.is_recorded(k) && k + 1 < self.loads.len() && !chain.is_recorded(k + 1) && !elastic {
                output::write_npy(&warm(k), &pressure)?;
            }
            // The adhesive solve goes before the record of the solve it starts from: a run stopped
            // between them solves that one again from the same start (the map of the load before
            // it stays until that record), so that its adhesive rows are an uninterrupted run's.
            if let (Some(a), Some(adhesive_solver)) = (&adhesive, adhesive_solver.as_mut()) {
                if !a.is_recorded(k) {
                    let (pressure, facts) = if kept(a, k) {
                        let (normal, pressure) = read_normal(&a.solves, &a.stems[k], load)?;
                        (pressure, normal.solve)
                    } else {
                        // From the equilibrium without adhesion at the load (a loading, as the
                        // ball pressed onto the wafer): where several equilibria carry one load,
                        // the one reached depends on the load alone, not on where a chain was
                        // cut. The friction model sees the compressive pressure: the tension
                        // outside the contact carries none.
                        let gap = match gap.take() {
                            Some(gap) => gap,
                            None => {
                                // Read from a kept normal solve's map (elastic sharing, whose
                                // solves start cold): solved again cold, to the same bits.
                                solver.reset();
                                solver.solve(load, |_, _| ()).map_err(context)?;
                                solver.gap()
                            }
                        };
                        let report = adhesive_solver
                            .solve_from(load, pressure.as_slice().expect("row-major"), &gap)
                            .map_err(context)?;
                        let compressive = adhesive_solver.compressive_pressure();
                        let summary = contact::summarize(&compressive, shape, size, c.boundary, self.config.hardness());
                        let pressure = Array2::from_shape_vec(shape, compressive).expect("the grid's shape");
                        let facts = SolveFacts::adhesive(&summary, &report);
                        if elastic {
                            self.record_normal(a, k, &pressure, true, facts).map_err(context)?;
                        }
                        (pressure, facts)
                    };
                    self.settle(scope, work, a, plastic, k, &pressure, true, facts)?;
                }
            }
            if !chain.is_recorded(k) {
                self.settle(scope, work, &chain, plastic, k, &pressure, cold, facts)?;
            }
        }
        chains().try_for_each(|c| {
            c.state.lock().expect("no panic holding it").complete = true;
            self.flush(c, work)
        })
    }

    /// The chain of unit `u`'s loads `loads`, elastic or `plastic`, with its folder of records
    /// made and the loads recorded before this run.
    fn chain(&self, dir: &Path, u: usize, plastic: bool, loads: Range<usize>) -> Result<Arc<Chain>> {
        let solves = self.solves_dir(dir, u, plastic);
        let recorded: Vec<bool> = loads.clone().map(|k| self.done(dir, u, plastic, k)).collect::<Result<_>>()?;
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        let (label, _, topo, name) = self.unit(u);
        let shape = topo.heights.dim();
        let size = topo.physical_size.expect("built with a physical size");
        Ok(Arc::new(Chain {
            u,
            label,
            name: name.to_string(),
            solves,
            stems: (0..self.loads.len()).map(|k| self.stem(u, plastic, k)).collect(),
            loads,
            recorded,
            shape,
            size,
            state: Mutex::new(ChainState::default()),
        }))
    }

    /// Record the normal solve of `chain` at load `k` for its elastic onsets, which read it from
    /// its map, and for a run stopped before its record to go on from: the map first, then the
    /// record that names it.
    fn record_normal(
        &self,
        chain: &Chain,
        k: usize,
        pressure: &Array2<f64>,
        cold: bool,
        facts: SolveFacts,
    ) -> Result<()> {
        facts.require_finite()?;
        output::write_npy(&chain.solves.join(warm_name(&chain.stems[k])), pressure)?;
        output::write_json(
            &chain.solves.join(normal_name(&chain.stems[k])),
            &NormalRecord { load_n: self.loads[k], cold, solve: facts },
        )
    }

    /// The rest of `chain`'s solve at load `k` once its normal solve is known (`pressure` \[Pa],
    /// compressive): the rows of its layout (the paper's at once, the elastic ones as the onsets
    /// that give them end, or from an earlier run's record of them), its map and snapshot when
    /// the study keeps them, and its record once its onsets are done.
    #[allow(clippy::too_many_arguments)]
    fn settle<'s, R: Proceed>(
        &'s self,
        scope: &rayon::Scope<'s>,
        work: &'s Work<'s, R>,
        chain: &Arc<Chain>,
        plastic: bool,
        k: usize,
        pressure: &Array2<f64>,
        cold: bool,
        facts: SolveFacts,
    ) -> Result<()> {
        let (u, name, load, stem) = (chain.u, chain.name.as_str(), self.loads[k], &chain.stems[k]);
        let label = &chain.label;
        let context = |e: Error| Error::invalid(format!("topography \"{label}\" at {load} N"), e.to_string());
        let (shape, pixel) = (chain.shape, (chain.size.0 / chain.shape.1 as f64, chain.size.1 / chain.shape.0 as f64));
        let c = &self.config.contact;
        let layout = self.layout(u);
        let keys: Vec<String> = layout.iter().map(|s| self.slot_key(s)).collect();
        // The solve's record from an earlier study, whose elastic onsets stay good.
        let earlier = self.read_solve(&chain.solves, stem, load)?;
        let elements = ElementLoads::from_pressure(pressure, pixel.0 * pixel.1).map_err(context)?;
        // The rows of the solve's layout: the paper's at once, the others as the elastic
        // onsets that give them end (or from an earlier run's record of them).
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
                    // Equal sharing's row under the same weakening (at the same d_c).
                    let weakening_slot = layout.iter().position(|s| {
                        s.sharing == Sharing::Equal
                            && s.law == l
                            && s.slip_distance != Some(0.0)
                            && s.slip_distance == row.slip_distance
                    });
                    // Recorded with the solve by an earlier study: both of its rows.
                    let from_record = earlier.as_ref().and_then(|r| {
                        let weakening = match weakening_slot {
                            Some(w) => Some(r.row(&keys[w])?.clone()),
                            None => None,
                        };
                        Some((r.row(&keys[slot])?.clone(), weakening))
                    });
                    let path = chain.solves.join(onset_name(stem, &keys[slot]));
                    if let Some((row, weakening)) = from_record {
                        rows[slot] = Some(row);
                        if let Some(w) = weakening_slot {
                            rows[w] = weakening;
                        }
                        work.tally.onsets_resumed.fetch_add(1, Ordering::Relaxed);
                    } else if path.is_file() {
                        let mut kept =
                            read_onset(&path, name, load, &super::law_name(&self.laws[l]), weakening_slot.is_some())?
                                .into_iter();
                        rows[slot] = kept.next();
                        if let Some(w) = weakening_slot {
                            rows[w] = kept.next();
                        }
                        work.tally.onsets_resumed.fetch_add(1, Ordering::Relaxed);
                    } else {
                        onsets.push((slot, weakening_slot, l, self.slip_law(row)));
                    }
                }
            }
        }

        // Everything of this solve first, its record last: a record means the solve is done.
        if self.keeps_maps(u) {
            let maps = self.maps_dir(work.dir, u, plastic);
            std::fs::create_dir_all(&maps).map_err(|e| Error::io(&maps, e))?;
            output::write_npy(&maps.join(format!("{stem}.npy")), pressure)?;
        }
        if self.shows(u, plastic) && self.snapshot_indices().contains(&k) {
            let mut snap =
                MapSnapshot::crop(name, load, pressure, pixel, SNAPSHOT_MARGIN).expect("a load makes contact");
            if (load / FIGURE_LOADS_N[0]).log10().abs() <= NEAR_DECADES {
                // The friction curve's: its elements' k_t, from the stuck contact.
                let compliance = ShearCompliance::of(&self.config.bodies());
                let mut solver = TangentialSolver::new(
                    pressure.as_slice().expect("row-major"),
                    shape,
                    chain.size,
                    compliance,
                    c.boundary,
                    TangentialOptions::default(),
                )
                .map_err(context)?;
                snap.stuck_stiffness = Some(stuck_stiffness(&mut solver).map_err(context)?.0);
            }
            let dir = work.dir.join("snapshots");
            std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
            snap.save(&dir, &self.snapshot_stem(k))?;
        }
        let kept_rows =
            earlier.map_or_else(Vec::new, |r| r.rows.into_iter().filter(|r| !keys.contains(&r.key)).collect());
        let pending = Pending { load, cold, facts, rows, keys: keys.clone(), kept: kept_rows, left: onsets.len() };
        chain.state.lock().expect("no panic holding it").pending.insert(k, pending);
        for (slot, weakening_slot, l, slip) in onsets {
            let key = keys[slot].clone();
            let chain = Arc::clone(chain);
            let job = OnsetJob { cost: facts.contact_points, chain, k, l, slip, key, slot, weakening_slot };
            self.enqueue(scope, work, job);
        }
        self.flush(chain, work)
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

    /// Run the elastic onset `job`, record it (`<stem>-elastic-<key>.json`) and report it to the
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
        let slip = &job.slip;
        // A band's onset names its d_c.
        let dc = match slip.slip_distance() {
            Some(d) if d > 0.0 && d != self.config.model.slip_distance.0 => format!(", d_c {}", show(d, &LENGTH)),
            _ => String::new(),
        };
        let failed = |e: Error| {
            Error::invalid(
                format!("topography \"{}\" at {load} N: elastic sharing{dc}, law \"{law_label}\"", chain.label),
                e.to_string(),
            )
        };
        let pressure = read_map(&chain.solves.join(warm_name(&chain.stems[k])))?;
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
        let normal = solver.normal_force();
        let onset = elastic_onset(&mut solver, slip, PEAK_TOLERANCE, |p| {
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
        let mut rows = vec![Row::elastic(&chain.name, load, &facts, law, slip, &onset, seconds)];
        if job.weakening_slot.is_some() {
            // Equal sharing under the same weakening: each element a spring–slider of the
            // contact's stuck stiffness shared equally.
            let area = chain.size.0 * chain.size.1 / (chain.shape.0 * chain.shape.1) as f64;
            let elements = ElementLoads::from_pressure(&pressure, area).map_err(failed)?;
            let stiffness = element_stiffness(onset.stuck_stiffness, elements.len());
            let equal = spring_slider_onset(&elements, slip, stiffness).map_err(failed)?;
            rows.push(Row::equal_weakening(&chain.name, load, &facts, law, slip, &equal));
        }
        rows.iter().try_for_each(Row::require_finite)?;
        output::write_json(&chain.solves.join(onset_name(&chain.stems[k], &job.key)), &rows)?;
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
                None => return self.tidy(&chain.solves, chain.u, &chain.stems, chain.loads.clone()),
            }
        })();
        lock().flushing = false;
        flushed
    }

    /// Write load `k`'s record (its rows all known), remove its parts and the maps no load
    /// goes on from, and report it to the progress callback, whose `Break` stops the run with
    /// [`Error::Interrupted`] (no later record is written).
    fn record<R: Proceed>(&self, chain: &Chain, k: usize, pending: Pending, work: &Work<'_, R>) -> Result<()> {
        let Pending { load, cold, facts, rows, keys, kept, .. } = pending;
        let rows: Vec<KeyedRow> = keys
            .into_iter()
            .zip(rows)
            .map(|(key, r)| KeyedRow { key, row: r.expect("every onset done") })
            .chain(kept)
            .collect();
        let warm = |k: usize| chain.solves.join(warm_name(&chain.stems[k]));
        // Never a NaN in a record (written as null): no later run could read it back.
        rows.iter().try_for_each(|r| r.row.require_finite())?;
        let stem = &chain.stems[k];
        output::write_json(
            &chain.solves.join(record_name(stem)),
            &SolveRecord { load_n: load, cold, solve: facts, rows },
        )?;
        self.remove_parts(&chain.solves, chain.u, stem)?;
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
}
