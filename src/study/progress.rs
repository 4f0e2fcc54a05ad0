//! What a run reports as it goes: the [`Progress`] events its callback receives, what its
//! workers count ([`Tally`]), and the error of a run the callback stopped.
//!
//! Of the runner's rooms it imports the [plan](super::plan) only; it must not import `plot`,
//! `report`, `cli` or `python`.

use std::sync::atomic::AtomicUsize;

use super::plan::Study;
use crate::error::Error;
use crate::friction::SlideStage;

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

/// What the workers of a run count.
#[derive(Default)]
pub(super) struct Tally {
    /// Solves finished now.
    pub(super) solved: AtomicUsize,
    /// Elastic onsets run now, and those found recorded by an earlier run.
    pub(super) onsets: AtomicUsize,
    pub(super) onsets_resumed: AtomicUsize,
}

impl Study {
    pub(super) fn interrupted(&self) -> Error {
        Error::Interrupted { what: format!("study {}", self.origin) }
    }
}
