//! A study's figures and report, drawn from what the study recorded: the layer above `study`
//! and `plot` (cli → report → plot → study). The study computes and records ([`Study::run`]);
//! this module reads the measured points the study names, before anything is solved, and draws
//! the figures and writes `index.html` from the study's [`Records`](crate::study::Records).
//!
//! Must not import topography, contact or friction: it joins what study recorded with plot, and
//! nothing in the library imports it.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::plot::FigureInput;
use crate::shs::{read_points, ShsPoint};
use crate::study::run::{Outcome, Study};

/// The measured points of `study`'s `output.experiments` (none when it names no file), read
/// and checked; an error names the study and the option.
pub fn experiments(study: &Study) -> Result<Vec<ShsPoint>> {
    match &study.config().output.experiments {
        Some(path) => read_points(path)
            .map_err(|e| Error::invalid(format!("{}: output.experiments", study.origin()), e.to_string())),
        None => Ok(Vec::new()),
    }
}

/// Draw the figures and write the report of a finished run into `dir` (under the run's results
/// lock, which `outcome` holds), with the measured points `experiments`. Returns every file
/// written; none for a shard's outcome, which records no results.
pub fn write(dir: &Path, outcome: &Outcome, experiments: &[ShsPoint]) -> Result<Vec<PathBuf>> {
    match &outcome.records {
        Some(records) => crate::plot::study::render(dir, &FigureInput::new(records, experiments)),
        None => Ok(Vec::new()),
    }
}
