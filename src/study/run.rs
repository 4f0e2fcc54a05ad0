//! The study runner: every topography at every load (elastic contact), every friction law on
//! every solve (the stick-slip model), the results table, the maps behind the figures, and the
//! figures.
//!
//! [`Study::prepare`] reads every file and builds every topography and law before anything is
//! solved, so a bad input fails at once. [`Study::run`] then solves the topographies in
//! parallel, each sweeping its loads in increasing order from the previous solution (warm
//! start). It writes into DIR:
//!
//! - `study.toml`: the study as run (paths absolute, loads explicit);
//! - `results.csv`, `results.json`: one [`Row`] per topography × law × load, in that order;
//! - `resolution.csv`: with the resolution figure, the friction drop of every topography × law
//!   × load at the study's pixel size and [`COARSENING`] times coarser ([`ResolutionRow`]);
//! - `snapshots/<topography>-NN.npy|json`: [`MapSnapshot`]s of the first topography at the
//!   swept loads nearest to [`FIGURE_LOADS_N`] (NN: the load's index in increasing order);
//! - `pressure/<topography>/NN.npy`: every full pressure map [Pa], when asked for;
//! - `figures/`, `index.html`: the figures and their report;
//! - `solves/`: what makes a run resumable — the study's fingerprint, one record per finished
//!   (topography, load) solve (its rows for every law), and the last pressure map of each
//!   unfinished sweep (float64, lossless). A killed run, run again into the same DIR, picks up
//!   at the first missing record from that map: the solver depends only on the pressure it
//!   starts from, so the results equal an uninterrupted run's (apart from the timings).
//!
//! Every file is written atomically. The library prints nothing: progress goes to a callback.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use ndarray::Array2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::config::{CropSpec, Force, LawSpec, LoadsSpec, StudyConfig, SurfaceSpec};
use super::{FigureInput, FigureKind, MapSnapshot, ResolutionRow, Row, SolveFacts, COARSENING, FIGURE_LOADS_N};
use crate::contact::{self, ContactSolver, SolverOptions};
use crate::error::{Error, Result};
use crate::friction::{ElementLoads, FrictionLaw, Onset};
use crate::output;
use crate::shs::{read_points, ShsPoint};
use crate::topography::io::{self, ReadOptions};
use crate::topography::missing::{fill_missing, refuse_missing};
use crate::topography::resample::{compound, crop, resample, CropWindow};
use crate::topography::Topography;

/// Pixels kept around the contact points in a [`MapSnapshot`].
const SNAPSHOT_MARGIN: usize = 8;

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
    /// The hold time [s] of each law, where known.
    hold_times: Vec<Option<f64>>,
    /// Loads [N], ascending.
    loads: Vec<f64>,
    experiments: Vec<ShsPoint>,
}

/// What the runner reports as it goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress<'a> {
    /// Before the first solve: `done` of the `total` solves were finished by an earlier run.
    Start { total: usize, done: usize },
    /// One (topography, load) solve finished.
    Solved { topography: &'a str, load_n: f64, iterations: usize, seconds: f64 },
}

/// What a run did.
#[derive(Debug)]
pub struct Outcome {
    pub rows: Vec<Row>,
    /// Solves run now, and solves found finished by an earlier run.
    pub solved: usize,
    pub resumed: usize,
    /// Figures and report written.
    pub figures: Vec<PathBuf>,
}

/// The record of one finished solve, `solves/<topography>/NN.json`.
#[derive(Serialize, Deserialize)]
struct SolveRecord {
    load_n: f64,
    solve: SolveFacts,
    /// One row per law, in the study's order.
    rows: Vec<Row>,
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
        let mut topographies = Vec::with_capacity(config.topographies.len());
        for spec in &config.topographies {
            let name = spec.name.clone().expect("checked: every topography has a name");
            let topo = build_topography(spec, grid).map_err(|e| at(&format!("topography \"{name}\""), e))?;
            topographies.push((name, topo));
        }
        let (mut laws, mut hold_times) = (Vec::new(), Vec::new());
        for spec in &config.laws {
            let name = spec.name();
            for (law, hold) in resolve_law(spec).map_err(|e| at(&format!("law \"{name}\""), e))? {
                laws.push(law);
                hold_times.push(hold);
            }
        }
        let mut coarse = Vec::new();
        if config.output.figures.contains(&FigureKind::Resolution) {
            for (t, (name, topo)) in topographies.iter().enumerate() {
                let (lx, _) = topo.physical_size.expect("built with a physical size");
                for factor in COARSENING {
                    let pixel = lx / topo.nx() as f64 * factor as f64;
                    let coarser = resample(topo, pixel).map_err(|e| at(&format!("topography \"{name}\""), e))?;
                    coarse.push((t, factor, coarser));
                }
            }
        }
        let experiments = match &config.output.experiments {
            Some(path) => read_points(path).map_err(|e| at("output.experiments", e))?,
            None => Vec::new(),
        };
        let loads = config.load_values();
        let mut config = config;
        config.loads =
            LoadsSpec { values: Some(loads.iter().map(|&l| Force(l)).collect()), min: None, max: None, count: None };
        Ok(Study { origin: origin.to_string(), config, topographies, coarse, laws, hold_times, loads, experiments })
    }

    /// The study as it runs: paths absolute, loads explicit.
    pub fn config(&self) -> &StudyConfig {
        &self.config
    }

    /// The loads [N], ascending.
    pub fn loads(&self) -> &[f64] {
        &self.loads
    }

    /// The topographies as built, with their names.
    pub fn topographies(&self) -> &[(String, Topography)] {
        &self.topographies
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
    /// there; `fresh` discards them. A `dir` holding another study, or anything that is not a
    /// study's output, is refused before anything is solved.
    pub fn run(&self, dir: &Path, fresh: bool, progress: &(dyn Fn(Progress) + Sync)) -> Result<Outcome> {
        self.claim(dir, fresh)?;
        let text = self.study_file()?;
        output::write_atomic(&dir.join("study.toml"), |w| w.write_all(text.as_bytes()))?;

        let total = self.units() * self.loads.len();
        let finished: Vec<usize> = (0..self.units()).map(|u| self.finished(dir, u)).collect();
        let resumed: usize = finished.iter().sum();
        progress(Progress::Start { total, done: resumed });
        let solved = AtomicUsize::new(0);
        // Each worker takes the next sweep in order: the study's own first, the cheap coarse
        // ones filling in at the end.
        let next = AtomicUsize::new(0);
        let workers = rayon::current_num_threads().min(self.units()).max(1);
        (0..workers).into_par_iter().try_for_each(|_| loop {
            let u = next.fetch_add(1, Ordering::Relaxed);
            if u >= self.units() {
                return Ok(());
            }
            self.sweep(dir, u, finished[u], progress, &solved)?;
        })?;

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
        output::write_json(&dir.join("results.json"), &rows)?;

        let snapshots = dir.join("snapshots");
        let maps = self
            .snapshot_indices()
            .into_iter()
            .map(|k| MapSnapshot::load(&snapshots, &self.snapshot_stem(k)))
            .collect::<Result<Vec<_>>>()?;
        let names: Vec<String> = self.topographies.iter().map(|(n, _)| n.clone()).collect();
        let parameters = self.study_file()?;
        let hold_time_loads: Vec<f64> = self.config.output.hold_time_loads.iter().map(|f| f.0).collect();
        let input = FigureInput {
            rows: &rows,
            topographies: &names,
            laws: &self.laws,
            hold_times: &self.hold_times,
            modulus_ratios: &self.modulus_ratios(),
            resolution: &resolution,
            hold_time_loads: &hold_time_loads,
            log_density: self.config.output.log_density,
            maps: &maps,
            experiments: &self.experiments,
            figures: &self.config.output.figures,
            snapshot_fractions: &self.config.output.snapshot_fractions,
            parameters: &parameters,
        };
        let figures = crate::plot::study::render(dir, &input)?;
        Ok(Outcome { rows, solved: solved.into_inner(), resumed, figures })
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

    /// Make `dir` this study's: new, or holding this study's solves (kept, or discarded when
    /// `fresh`). Anything else is refused.
    fn claim(&self, dir: &Path, fresh: bool) -> Result<()> {
        let fingerprint = self.fingerprint()?;
        let solves = dir.join("solves");
        let stored = solves.join("fingerprint.json");
        if dir.exists() {
            if !dir.is_dir() {
                return Err(Error::invalid("--out", format!("{} is a file, not a directory", dir.display())));
            }
            if stored.is_file() {
                if fresh {
                    std::fs::remove_dir_all(dir).map_err(|e| Error::io(dir, e))?;
                } else {
                    let text = std::fs::read_to_string(&stored).map_err(|e| Error::io(&stored, e))?;
                    if serde_json::from_str::<Fingerprint>(&text).ok() != Some(fingerprint) {
                        return Err(Error::invalid(
                            "--out",
                            format!(
                                "{} holds the results of a different study than {}: rerun with --fresh to start \
                                 over, or choose another --out",
                                dir.display(),
                                self.origin
                            ),
                        ));
                    }
                    return Ok(());
                }
            } else if std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?.next().is_some() {
                return Err(Error::invalid(
                    "--out",
                    format!("{} is not empty and holds no study: choose another --out", dir.display()),
                ));
            }
        }
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        output::write_json(&stored, &fingerprint)
    }

    fn fingerprint(&self) -> Result<Fingerprint> {
        let mut study = self.config.clone();
        let defaults = StudyConfig::default_study().output;
        // Figures, their snapshots' fractions and the measured points do not change a solve.
        study.output.figures = defaults.figures;
        study.output.snapshot_fractions = defaults.snapshot_fractions;
        study.output.experiments = None;
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

    /// The folder of sweep `u`'s solve records.
    fn solves_dir(&self, dir: &Path, u: usize) -> PathBuf {
        dir.join("solves").join(self.unit(u).1)
    }

    /// How many of sweep `u`'s loads have their record: the sweep resumes after them.
    fn finished(&self, dir: &Path, u: usize) -> usize {
        let solves = self.solves_dir(dir, u);
        (0..self.loads.len()).take_while(|k| solves.join(format!("{k:02}.json")).is_file()).count()
    }

    /// Sweep `u` over the loads from index `first` on.
    fn sweep(
        &self,
        dir: &Path,
        u: usize,
        first: usize,
        progress: &(dyn Fn(Progress) + Sync),
        solved: &AtomicUsize,
    ) -> Result<()> {
        let n = self.loads.len();
        if first == n {
            return Ok(());
        }
        let (label, _, topo, name) = self.unit(u);
        let main = u < self.topographies.len();
        let solves = self.solves_dir(dir, u);
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        let warm = |k: usize| solves.join(format!("warm-{k:02}.npy"));
        let shape = topo.heights.dim();
        let size = topo.physical_size.expect("built with a physical size");
        let pixel = (size.0 / shape.1 as f64, size.1 / shape.0 as f64);
        let c = &self.config.contact;
        let heights = topo.heights.as_standard_layout();
        let options = SolverOptions { tolerance: c.tolerance, max_iterations: c.max_iterations };
        let mut solver = ContactSolver::new(
            heights.as_slice().expect("standard layout"),
            shape,
            size,
            self.config.effective_modulus(),
            c.boundary,
            options,
        )?;
        if first > 0 {
            let path = warm(first - 1);
            let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
            let pressure = io::npy::read_f64(&bytes).map_err(|r| Error::file(&path, r))?;
            solver.warm_start(pressure.as_slice().ok_or_else(|| Error::file(&path, "not a row-major array"))?)?;
        }
        let maps = dir.join("pressure").join(name);
        let keep_maps = self.config.output.pressure_maps && main;
        if keep_maps {
            std::fs::create_dir_all(&maps).map_err(|e| Error::io(&maps, e))?;
        }
        let snapshots = if u == 0 { self.snapshot_indices() } else { Vec::new() };
        for (k, &load) in self.loads.iter().enumerate().skip(first) {
            let context = |e: Error| Error::invalid(format!("topography \"{label}\" at {load} N"), e.to_string());
            let report = solver.solve(load, |_, _| ()).map_err(context)?;
            let pressure = Array2::from_shape_vec(shape, solver.pressure().to_vec()).expect("the grid's shape");
            let summary = contact::summarize(solver.pressure(), shape, size, c.boundary);
            let facts = SolveFacts::new(&summary, &report);
            let elements = ElementLoads::from_pressure(&pressure, pixel.0 * pixel.1).map_err(context)?;
            let rows = self.laws.iter().map(|law| Row::new(name, load, &facts, &Onset::new(&elements, law))).collect();

            // Everything of this solve first, its record last: a record means the solve is done.
            if keep_maps {
                output::write_npy(&maps.join(format!("{k:02}.npy")), &pressure)?;
            }
            if snapshots.contains(&k) {
                let snap =
                    MapSnapshot::crop(name, load, &pressure, pixel, SNAPSHOT_MARGIN).expect("a load makes contact");
                let dir = dir.join("snapshots");
                std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
                snap.save(&dir, &self.snapshot_stem(k))?;
            }
            if k + 1 < n {
                output::write_npy(&warm(k), &pressure)?;
            }
            output::write_json(
                &solves.join(format!("{k:02}.json")),
                &SolveRecord { load_n: load, solve: facts, rows },
            )?;
            if k > 0 {
                let old = warm(k - 1);
                std::fs::remove_file(&old).or_else(|e| if old.exists() { Err(Error::io(&old, e)) } else { Ok(()) })?;
            }
            solved.fetch_add(1, Ordering::Relaxed);
            progress(Progress::Solved {
                topography: &label,
                load_n: load,
                iterations: report.iterations,
                seconds: report.seconds,
            });
        }
        Ok(())
    }

    /// Every row from the solve records of `units`: topography × law × load.
    fn rows(&self, dir: &Path, units: std::ops::Range<usize>) -> Result<Vec<Row>> {
        let mut rows = Vec::with_capacity(units.len() * self.laws.len() * self.loads.len());
        for t in units {
            let solves = self.solves_dir(dir, t);
            let records = (0..self.loads.len())
                .map(|k| {
                    let path = solves.join(format!("{k:02}.json"));
                    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
                    let record: SolveRecord =
                        serde_json::from_str(&text).map_err(|e| Error::file(&path, e.to_string()))?;
                    if record.load_n != self.loads[k] || record.rows.len() != self.laws.len() {
                        return Err(Error::file(&path, "not a record of this study's solve: rerun with --fresh"));
                    }
                    Ok(record)
                })
                .collect::<Result<Vec<_>>>()?;
            for l in 0..self.laws.len() {
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
        let mut out: Vec<ResolutionRow> =
            rows.iter().map(|r| ResolutionRow::new(1, pixel(own(&r.topography)), r)).collect();
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

/// A topography as the study solves it: read or generated, prepared, compounded with its
/// wafer, on the `grid` override if any.
fn build_topography(spec: &SurfaceSpec, grid: Option<(usize, usize)>) -> Result<Topography> {
    let ball = build_surface(spec, grid)?;
    match &spec.wafer {
        // A measured wafer is interpolated onto the ball's grid by `compound` as it is.
        Some(w) => compound(&ball, &build_surface(w, grid.filter(|_| w.synthetic.is_some()))?),
        None => Ok(ball),
    }
}

/// One surface: generated, or read, cropped, filled, levelled and resampled, in that order.
fn build_surface(spec: &SurfaceSpec, grid: Option<(usize, usize)>) -> Result<Topography> {
    if let Some(s) = &spec.synthetic {
        let mut s = s.clone();
        if let Some(g) = grid {
            s.grid = g;
        }
        return s.generate();
    }
    let path = spec.file.as_ref().expect("checked: a surface is synthetic or a file");
    let options = ReadOptions {
        format: spec.format.clone(),
        channel: spec.channel.clone(),
        physical_size: spec.size.map(|s| (s.0 .0, s.1 .0)),
        height_unit: spec.height_unit.clone(),
    };
    let mut topo = io::read(path, &options)?;
    if topo.physical_size.is_none() {
        return Err(Error::file(path, "the file states no physical size: give it with `size`"));
    }
    if let Some(c) = &spec.crop {
        topo = crop(&topo, &crop_window(c))?;
    }
    if spec.fill_missing {
        fill_missing(&mut topo)?;
    } else {
        refuse_missing(&topo)?;
    }
    spec.detrend().apply(&mut topo)?;
    if let Some(p) = spec.pixel_size {
        topo = resample(&topo, p.0)?;
    }
    if let Some((nx, ny)) = grid {
        if (topo.nx(), topo.ny()) != (nx, ny) {
            let lx = topo.physical_size.expect("checked above").0;
            topo = resample(&topo, lx / nx as f64)?;
        }
    }
    if topo.nx() < 2 || topo.ny() < 2 {
        return Err(topo.error(format!("a {}×{} grid is too small for contact", topo.ny(), topo.nx())));
    }
    Ok(topo)
}

fn crop_window(c: &CropSpec) -> CropWindow {
    match (c.x, c.y, c.columns, c.rows) {
        (Some(x), Some(y), ..) => CropWindow::Physical { x: (x[0].0, x[1].0), y: (y[0].0, y[1].0) },
        (_, _, Some(cols), Some(rows)) => CropWindow::Pixels { x: cols[0]..cols[1], y: rows[0]..rows[1] },
        _ => unreachable!("checked: a crop is physical or in pixels"),
    }
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
