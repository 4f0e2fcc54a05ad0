//! `asperity run`: the paper's numerical study, end to end.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use clap::Args;

use asperity::error::escaped;
use asperity::friction::SlideStage;
use asperity::quantity::{show, FORCE};
use asperity::study::config::{StudyConfig, DEFAULT_STUDY};
use asperity::study::run::{Progress, Study};
use asperity::study::shard::Shard;
use asperity::Result;

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// Run a study: elastic contact of every topography at every load, the stick-slip model with
/// every local friction law, the results table and the figures.
///
/// Without STUDY, runs the default study: three synthetic silicon balls (31.13 µm square,
/// 1500 × 1500 points, ≈ 40 nm RMS on a 1.5 mm-radius sphere), each against a synthetic wafer
/// (0.2 nm RMS), E = 130 ± 3 GPa, ν = 0.26, 25 loads from 0.1 µN (one contact element) to
/// 100 mN, and the local laws "hold 100 s" and "hold 10 s" of one aging law — ILLUSTRATIVE
/// PLACEHOLDERS for measured (mu_s, mu_d) pairs.
/// `--print-default` shows it as a commented study file to start from.
///
/// Writes into DIR: results.csv and results.json (one row per topography × sharing × law ×
/// load, with contact points, patches, contact fraction, static and dynamic coefficients,
/// friction drop, element classes with their fractions of N and F_S, solver iterations and
/// seconds; a band of d_c and adhesion, where the study asks for them, add rows), study.toml
/// (the study as run), snapshots/ (pressure maps [Pa] of the first topography near 0.1, 1, 10
/// and 100 mN, the 0.1 mN one with its contact's stuck tangential stiffness K_t [N/m], which
/// gives the friction curve δ in metres), pressure/ (every map, if the study asks), figures/ and
/// index.html.
///
/// Resumable, and a DIR grows with its study: finished solves (with elastic sharing, each
/// finished onset too) are kept in DIR/solves, each found by what it was computed from (the
/// topography, material, contact settings and load; an onset also by its law and slip
/// weakening). Running the same study again continues where an interrupted run stopped, with
/// the same results (all but the `seconds` columns, the time each solve took); a changed study (a load, law or topography added, an output option
/// changed) solves only what is new. Solves it no longer asks for stay in DIR/solves, out of
/// the table and figures, until --fresh. One writer per solve: a second run into a DIR where
/// another works on the same solves is refused (or waits, with --wait).
#[derive(Args)]
pub struct RunArgs {
    /// Study file (TOML; see --print-default) [default: the embedded default study].
    study: Option<PathBuf>,
    /// Output directory.
    #[arg(long, value_name = "DIR", default_value = "results")]
    out: PathBuf,
    /// A smoke run: the same study on a coarse grid, fast — every topography on 256 × 256
    /// points over the same window, 7 loads over the same range. The pixel is the model's
    /// element, so its numbers are not the study's.
    #[arg(long)]
    quick: bool,
    /// Print the default study as a commented study file (every key and unit explained) and
    /// exit.
    #[arg(long, conflicts_with_all = ["study", "quick", "fresh"])]
    print_default: bool,
    /// Discard what earlier runs wrote in DIR (every study's solves) and start over. Files put
    /// there by hand stay; one where runs write (results, figures/, pressure/, snapshots/,
    /// solves/) is refused first.
    #[arg(long)]
    fresh: bool,
    /// When another run works in DIR on the same solves, wait for it instead of refusing.
    #[arg(long, conflicts_with = "print_default")]
    wait: bool,
    /// Solve only shard I of N (I from 1 to N): its share of the loads of every topography,
    /// balanced by grid points × loads, each piece of a load chain starting cold. Shards run at
    /// once into one DIR (also on several machines over a shared filesystem) and write only
    /// their solves; a run without --shard afterwards writes the table and figures, solving
    /// nothing twice.
    #[arg(long, value_name = "I/N", value_parser = shard, conflicts_with_all = ["print_default", "fresh"])]
    shard: Option<Shard>,
    #[command(flatten)]
    limits: super::LimitArgs,
}

pub fn run(args: RunArgs) -> Result<()> {
    if args.print_default {
        return super::print(DEFAULT_STUDY);
    }
    super::stop_resumes();
    let start = Instant::now();
    let study = prepare(args.study.as_deref(), args.quick, &args.limits)?.waiting(args.wait).sharded(args.shard);
    let experiments = asperity::report::experiments(&study)?;

    let bar = super::progress_bar(0, "solving", false);
    // A batch log (stderr not a terminal) gets a plain line every few seconds instead of the bar.
    let batch = !std::io::stderr().is_terminal();
    let last_line = Mutex::new(Instant::now());
    // Without elastic onsets the bar measures the solves' estimated work (grid points, more at
    // higher loads) and tells the time left from it; an onset's cost grows steeply with its contact points, unknown
    // until its solve is done, so with onsets it counts solves and onsets and tells none.
    let by_work = Mutex::new(None::<Pace>);
    let (solved, solves) = (AtomicUsize::new(0), AtomicUsize::new(0));
    // A batch log's line: "solving: DONE/ALL … after T s (WHAT)", at most every few seconds
    // unless `always`.
    let batch_line = |what: &str, always: bool| {
        if !batch {
            return;
        }
        let mut last = last_line.lock().unwrap_or_else(|e| e.into_inner());
        if always || last.elapsed() >= super::BATCH_PROGRESS {
            *last = Instant::now();
            let pace = by_work.lock().unwrap_or_else(|e| e.into_inner());
            let done = match pace.as_ref() {
                Some(pace) => format!(
                    "{}/{} solves{}",
                    solved.load(Ordering::Relaxed),
                    solves.load(Ordering::Relaxed),
                    pace.left(bar.position()).map_or(String::new(), |t| format!(", about {} left", duration(t)))
                ),
                None => format!("{}/{} solves and elastic onsets", bar.position(), bar.length().unwrap_or(0)),
            };
            super::message(&format!("solving: {done} after {:.0} s ({what})", start.elapsed().as_secs_f64()));
        }
    };
    let outcome = study.run(&args.out, args.fresh, &|event| match event {
        Progress::Start { total, done, work, work_done, onsets, onsets_done } => {
            solved.store(done, Ordering::Relaxed);
            solves.store(total, Ordering::Relaxed);
            if onsets == 0 {
                bar.set_style(super::bar_style("solving", "{percent}%", true));
                bar.set_length(work);
                bar.set_position(work_done);
                *by_work.lock().unwrap_or_else(|e| e.into_inner()) =
                    Some(Pace { start: Instant::now(), from: work_done, total: work });
            } else {
                bar.set_length((total + onsets) as u64);
                bar.set_position((done + onsets_done) as u64);
            }
            if batch {
                let onsets = match onsets {
                    0 => String::new(),
                    n => format!(
                        " and {n} elastic onsets ({onsets_done} done by an earlier run), counted together, \
                         without an estimate of the time left (an onset's cost grows with its contact points)"
                    ),
                };
                super::message(&format!("solving: {total} solves ({done} done by an earlier run){onsets}"));
            }
        }
        Progress::Slid { topography, load_n, law, iterations, seconds } => {
            // The bar shows the study's names: escaped, as every message.
            let what =
                format!("{} at {}: elastic onset of \"{}\"", escaped(topography), show(load_n, &FORCE), escaped(law));
            bar.set_message(format!("{what} ({iterations} iterations, {seconds:.1} s)"));
            bar.inc(1);
            batch_line(&format!("{what} in {seconds:.1} s"), false);
        }
        // An onset under way, once it has taken a second: on the bar as it goes, in a batch log
        // with the other lines.
        Progress::Sliding { topography, load_n, law, stage, steps, solves, largest_drop, seconds }
            if seconds >= 1.0 =>
        {
            let stage = match stage {
                SlideStage::March => "marching",
                SlideStage::Search => "searching for the peak",
            };
            let line = format!(
                "{} at {}: elastic onset of \"{}\" under way, {stage}, {steps} steps, \
                 {solves} solves, largest force {largest_drop:.4} mu_d N, {seconds:.0} s",
                escaped(topography),
                show(load_n, &FORCE),
                escaped(law)
            );
            batch_line(&line, false);
            if !batch {
                bar.set_message(line);
            }
        }
        Progress::Sliding { .. } => {}
        Progress::Solved { topography, load_n, iterations, work, .. } => {
            let topography = escaped(topography);
            let count = solved.fetch_add(1, Ordering::Relaxed) + 1;
            let at = format!("{topography} at {} ({iterations} iterations)", show(load_n, &FORCE));
            if by_work.lock().unwrap_or_else(|e| e.into_inner()).is_some() {
                bar.set_message(format!("{count}/{} solves, {at}", solves.load(Ordering::Relaxed)));
                bar.inc(work);
            } else {
                bar.set_message(at);
                bar.inc(1);
            }
            let finished = bar.length().is_some_and(|l| bar.position() == l);
            batch_line(&format!("{topography} at {}", show(load_n, &FORCE)), finished);
        }
    })?;
    let figures = asperity::report::write(&args.out, &outcome, &experiments)?;
    bar.finish_and_clear();
    if !outcome.left.is_empty() {
        let names: Vec<String> = outcome.left.iter().map(|p| format!("{:?}", p.display().to_string())).collect();
        super::message(&format!(
            "--fresh: left {} file(s) in {} that asperity did not write: {}",
            names.len(),
            args.out.display(),
            names.join(", ")
        ));
    }
    for w in &outcome.warnings {
        super::message(&format!("warning: {w}"));
    }

    let dir = args.out.display();
    let grid = study.config().contact.grid.map_or(String::new(), |(nx, ny)| format!(" on {nx}×{ny}"));
    let seconds = start.elapsed().as_secs_f64();
    let (topographies, loads) = (study.topographies().len(), study.loads().len());
    // What the solves are: the topographies, in each kind of solve, and their coarser copies.
    let kinds = match (study.config().contact.plastic.modes().len() > 1, study.config().contact.adhesion.is_some()) {
        (true, _) => ", each elastic and plastic,",
        (false, true) => ", each with and without adhesion,",
        (false, false) => "",
    };
    let topographies = match topographies {
        1 => "1 topography".to_string(),
        n => format!("{n} topographies"),
    };
    let solved = match study.coarse_copies() {
        0 => format!("{topographies}{grid}{kinds} × {loads} loads"),
        n => format!("({topographies}{grid}{kinds} and {n} coarser copies for the resolution figure) × {loads} loads"),
    };
    // The elastic onsets run now, and those of the solves run now that were recorded before
    // (by an interrupted solve, or with the solve by a study with other laws).
    let onsets = match (outcome.onsets, outcome.onsets_resumed) {
        (0, 0) => String::new(),
        (run, 0) => format!("; {run} elastic onsets run"),
        (run, n) => format!("; {run} elastic onsets run, {n} recorded before kept"),
    };
    if let Some(shard) = args.shard {
        let (resumed, share) = (outcome.resumed, outcome.share);
        super::message(&format!(
            "shard {shard} of {solved}: {share} solves, {} solved, {resumed} resumed{onsets}, in {seconds:.1} s",
            outcome.solved
        ));
        super::message(&format!(
            "wrote the solve records only: `asperity run` into {dir} without --shard writes the table and figures"
        ));
        return Ok(());
    }
    super::message(&format!(
        "{solved}: {} solved, {} resumed{onsets}, in {seconds:.1} s",
        outcome.solved, outcome.resumed
    ));
    super::message(&format!(
        "wrote {dir}/results.csv, {dir}/results.json ({} rows) and {dir}/study.toml",
        outcome.rows.len()
    ));
    if !figures.is_empty() {
        // A figure is its image (with its vector copy) or its movie.
        let drawn = figures.iter().filter(|f| f.extension().is_some_and(|e| e == "png" || e == "gif")).count();
        super::message(&format!("wrote {drawn} figures and {dir}/index.html"));
    }
    super::print(&drop_summary(&outcome.rows))
}

/// The pace of a run's solves: the grid points solved since `start` from `from` of `total`.
struct Pace {
    start: Instant,
    from: u64,
    total: u64,
}

impl Pace {
    /// The time left \[s] at `position` grid points, at the run's pace so far; none before
    /// its first solve.
    fn left(&self, position: u64) -> Option<f64> {
        let done = position.checked_sub(self.from).filter(|&d| d > 0)?;
        Some(self.start.elapsed().as_secs_f64() * self.total.saturating_sub(position) as f64 / done as f64)
    }
}

/// `seconds` as a log reads it: "40 s", "3 min", "1.5 h".
fn duration(seconds: f64) -> String {
    match seconds {
        s if s < 100.0 => format!("{s:.0} s"),
        s if s < 6000.0 => format!("{:.0} min", s / 60.0),
        s => format!("{:.1} h", s / 3600.0),
    }
}

/// The loads the run's closing summary shows \[N]: 0.1, 1, 10 and 100 mN, the paper's decades.
const SUMMARY_LOADS: [f64; 4] = [1e-4, 1e-3, 1e-2, 1e-1];

/// The results table in brief: per law (and sharing, and plastic solve where there is one),
/// the range of the friction drop over the topographies at each of [`SUMMARY_LOADS`] the study
/// solved ("–" for a load it did not).
fn drop_summary(rows: &[asperity::study::Row]) -> String {
    use std::fmt::Write;
    let mut groups: Vec<(String, String, bool)> = Vec::new();
    for r in rows {
        let key = (r.law.clone(), r.model(), r.plastic);
        if !groups.contains(&key) {
            groups.push(key);
        }
    }
    let plastic = rows.iter().any(|r| r.plastic);
    let label = |(law, model, p): &(String, String, bool)| {
        format!(
            "{law}, {model}{}",
            if plastic {
                if *p {
                    ", plastic"
                } else {
                    ", elastic"
                }
            } else {
                ""
            }
        )
    };
    let width = groups.iter().map(|g| label(g).chars().count()).max().unwrap_or(0).max(20);
    let mut s = format!("{:<width$}", "friction drop, min–max");
    for load in SUMMARY_LOADS {
        let _ = write!(s, " {:>15}", show(load, &FORCE));
    }
    s.push('\n');
    for group in &groups {
        let _ = write!(s, "{:<width$}", label(group));
        for load in SUMMARY_LOADS {
            let drops: Vec<f64> = rows
                .iter()
                .filter(|r| r.law == group.0 && r.model() == group.1 && r.plastic == group.2)
                .filter(|r| (r.load_n - load).abs() <= 1e-9 * load)
                .map(|r| r.friction_drop)
                .collect();
            let cell = match (drops.iter().copied().reduce(f64::min), drops.iter().copied().reduce(f64::max)) {
                (Some(lo), Some(hi)) => format!("{lo:.4}–{hi:.4}"),
                _ => "–".to_string(),
            };
            let _ = write!(s, " {cell:>15}");
        }
        s.push('\n');
    }
    s
}

/// The study of a study file (or the default), at the --quick scale if asked, with the
/// limits given; every input read and checked.
pub fn prepare(path: Option<&Path>, quick: bool, limits: &super::LimitArgs) -> Result<Study> {
    let (config, origin) = match path {
        Some(path) => (StudyConfig::from_file(path)?, path.display().to_string()),
        None => (StudyConfig::default_study(), "the default study".to_string()),
    };
    for w in config.warnings() {
        super::message(&format!("warning: {origin}: {w}"));
    }
    let mut config = if quick { config.quick() } else { config };
    if let Some(limits) = limits.given() {
        config.limits.max_points = limits.max_points;
    }
    let study = Study::prepare(config, &origin)?;
    for w in study.warnings() {
        super::message(&format!("warning: {origin}: {w}"));
    }
    Ok(study)
}

/// `--shard I/N`.
fn shard(s: &str) -> std::result::Result<Shard, String> {
    s.parse()
}
