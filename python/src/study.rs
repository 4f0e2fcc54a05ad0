//! Studies in Python: a study file or dict run as `asperity run` runs it, its progress reported
//! to a callback and Ctrl-C heard, its rows as JSON for the package's `asperity.run_study`.
//!
//! Must not import topography, contact, friction or shs of this crate.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use asperity::friction::SlideStage;
use asperity::study::config::StudyConfig;
use asperity::study::run::{Progress, Study};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{error, invalid, warn, SIGNAL_INTERVAL};

/// A study file's content from a dict given as JSON: the same keys and values as the TOML.
fn study_from_json(json: &str) -> asperity::Result<StudyConfig> {
    let origin = "study dict";
    let value: toml::Value =
        serde_json::from_str(json).map_err(|e| asperity::Error::invalid(origin, format!("not a study: {e}")))?;
    let text = toml::to_string(&value).map_err(|e| asperity::Error::invalid(origin, format!("not a study: {e}")))?;
    let base = std::env::current_dir().map_err(|e| asperity::Error::io(".", e))?;
    Ok(StudyConfig::parse(&text, origin)?.with_paths_from(&base))
}

/// A study event, owned, for the thread that reports it.
enum Event {
    Start {
        total: usize,
        done: usize,
        work: u64,
        work_done: u64,
        onsets: usize,
        onsets_done: usize,
    },
    Sliding {
        topography: String,
        load_n: f64,
        law: String,
        stage: &'static str,
        steps: usize,
        largest_drop: f64,
        seconds: f64,
    },
    Slid {
        topography: String,
        load_n: f64,
        law: String,
        iterations: usize,
        seconds: f64,
    },
    Solved {
        topography: String,
        load_n: f64,
        iterations: usize,
        seconds: f64,
        work: u64,
    },
}

/// An onset under way reports to a callback once it has taken this long, and at most this
/// often.
const SLIDING_INTERVAL: Duration = Duration::from_secs(1);

/// Run a study and return its rows as JSON; see ``asperity.run_study``. ``progress``: None,
/// or a callable taking one dict per event.
#[pyfunction]
#[pyo3(signature = (study_file, study_json, out, quick, fresh, progress))]
pub(crate) fn _run_study(
    py: Python<'_>,
    study_file: Option<PathBuf>,
    study_json: Option<String>,
    out: PathBuf,
    quick: bool,
    fresh: bool,
    progress: Option<Bound<'_, PyAny>>,
) -> PyResult<String> {
    let (config, origin) = py
        .detach(|| match (&study_file, &study_json) {
            (Some(path), _) => Ok((StudyConfig::from_file(path)?, path.display().to_string())),
            (None, Some(json)) => Ok((study_from_json(json)?, "study dict".to_string())),
            (None, None) => Ok((StudyConfig::default_study(), "the default study".to_string())),
        })
        .map_err(error)?;
    // The study's own words (its keys), as the command line warns.
    for w in config.warnings() {
        warn(py, &format!("{origin}: {w}"), 2)?;
    }
    let config = if quick { config.quick() } else { config };
    let study = py.detach(|| Study::prepare(config, &origin)).map_err(error)?;
    for w in study.warnings() {
        warn(py, &format!("{origin}: {w}"), 2)?;
    }
    // Read before any solve, as the command line does: a bad experiments file costs nothing.
    let experiments = asperity::report::experiments(&study).map_err(error)?;

    // The study runs on its own thread; this one (Python's, where signal handlers run) reports
    // its progress and looks for Ctrl-C, which stops the run after the solves under way (an
    // elastic onset at its next step).
    let stop = AtomicBool::new(false);
    let (events, mut received) = mpsc::channel::<Event>();
    let last_sliding = std::sync::Mutex::new(Instant::now());
    let outcome = std::thread::scope(|scope| -> PyResult<asperity::Result<asperity::study::run::Outcome>> {
        let runner = scope.spawn(|| {
            let events = events;
            study.run(&out, fresh, &|event| {
                let _ = events.send(match event {
                    // An onset under way, at most every second; Ctrl-C stops it at its next step.
                    Progress::Sliding { .. } if stop.load(Ordering::Relaxed) => return ControlFlow::Break(()),
                    Progress::Sliding { topography, load_n, law, stage, steps, largest_drop, seconds, .. } => {
                        let mut last = last_sliding.lock().unwrap_or_else(|e| e.into_inner());
                        if seconds < SLIDING_INTERVAL.as_secs_f64() || last.elapsed() < SLIDING_INTERVAL {
                            return ControlFlow::Continue(());
                        }
                        *last = Instant::now();
                        let stage = match stage {
                            SlideStage::March => "march",
                            SlideStage::Search => "search",
                        };
                        let (topography, law) = (topography.to_string(), law.to_string());
                        Event::Sliding { topography, load_n, law, stage, steps, largest_drop, seconds }
                    }
                    Progress::Start { total, done, work, work_done, onsets, onsets_done } => {
                        Event::Start { total, done, work, work_done, onsets, onsets_done }
                    }
                    Progress::Slid { topography, load_n, law, iterations, seconds } => Event::Slid {
                        topography: topography.to_string(),
                        load_n,
                        law: law.to_string(),
                        iterations,
                        seconds,
                    },
                    Progress::Solved { topography, load_n, iterations, seconds, work } => {
                        Event::Solved { topography: topography.to_string(), load_n, iterations, seconds, work }
                    }
                });
                if stop.load(Ordering::Relaxed) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
        });
        let mut raised: Option<PyErr> = None;
        loop {
            let waiting = &mut received;
            match py.detach(move || waiting.recv_timeout(SIGNAL_INTERVAL)) {
                Ok(event) => {
                    if let (Some(callback), None) = (&progress, &raised) {
                        let dict = PyDict::new(py);
                        match event {
                            Event::Start { total, done, work, work_done, onsets, onsets_done } => {
                                dict.set_item("event", "start")?;
                                dict.set_item("total", total)?;
                                dict.set_item("done", done)?;
                                dict.set_item("work", work)?;
                                dict.set_item("work_done", work_done)?;
                                dict.set_item("onsets", onsets)?;
                                dict.set_item("onsets_done", onsets_done)?;
                            }
                            Event::Sliding { topography, load_n, law, stage, steps, largest_drop, seconds } => {
                                dict.set_item("event", "sliding")?;
                                dict.set_item("topography", topography)?;
                                dict.set_item("load_n", load_n)?;
                                dict.set_item("law", law)?;
                                dict.set_item("stage", stage)?;
                                dict.set_item("steps", steps)?;
                                dict.set_item("largest_drop", largest_drop)?;
                                dict.set_item("seconds", seconds)?;
                            }
                            Event::Slid { topography, load_n, law, iterations, seconds } => {
                                dict.set_item("event", "slid")?;
                                dict.set_item("topography", topography)?;
                                dict.set_item("load_n", load_n)?;
                                dict.set_item("law", law)?;
                                dict.set_item("iterations", iterations)?;
                                dict.set_item("seconds", seconds)?;
                            }
                            Event::Solved { topography, load_n, iterations, seconds, work } => {
                                dict.set_item("event", "solved")?;
                                dict.set_item("topography", topography)?;
                                dict.set_item("load_n", load_n)?;
                                dict.set_item("iterations", iterations)?;
                                dict.set_item("seconds", seconds)?;
                                dict.set_item("work", work)?;
                            }
                        }
                        if let Err(e) = callback.call1((dict,)) {
                            raised = Some(e);
                            stop.store(true, Ordering::Relaxed);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    raised = Some(e);
                    stop.store(true, Ordering::Relaxed);
                }
            }
        }
        let result = py.detach(|| runner.join()).expect("the study thread does not panic");
        match (result, raised) {
            (Err(asperity::Error::Interrupted { .. }), Some(e)) | (Ok(_), Some(e)) => Err(e),
            (result, _) => Ok(result),
        }
    })?;
    let outcome = outcome.map_err(error)?;
    for w in &outcome.warnings {
        warn(py, w, 2)?;
    }
    py.detach(|| asperity::report::write(&out, &outcome, &experiments)).map_err(error)?;
    serde_json::to_string(&outcome.rows).map_err(|e| invalid("study", e.to_string()))
}
