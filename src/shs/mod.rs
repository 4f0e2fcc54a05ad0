//! Slide-hold-slide (SHS) experiments: from a raw friction trace to the static and dynamic
//! friction after each hold, as the paper measures them on its rheometer.
//!
//! In an SHS trace the interface slides at a constant speed (0.3 µm/s in the paper), is held
//! for a hold time, and slides again. Rheometers hold in one of two ways: the shear force is
//! released (it falls to about zero), or the stage stops with the force still loaded (it relaxes
//! by a few per cent). After each restart the static friction force F_S is the peak, and the
//! dynamic friction force F_D the mean over a window of steady sliding after the peak (≈ 1 µm);
//! the normal force N is averaged over the same window. The initial slide before the first hold
//! is not a restart, nor is the first slide of a trace that starts at rest.
//!
//! When the trace records the stage's displacement, holds are found on it (the stage stopped
//! for at least the minimum duration), whatever the force does, and each hold lasts from the
//! stage stopping to its restarting. Without it, displacement is derived from time and the
//! sliding speed, counted from each restart; holds are then seen in the friction signal only,
//! so the force must be released during them, and a hold is the time the friction spends near
//! zero (shorter than the stage's hold by the time the force takes to relax). The `detect`
//! module describes both.
//!
//! Must not import topography, contact, friction, study, plot or report: a trace is its own input.

mod analysis;
mod detect;
mod points;
mod trace;

pub use crate::quantity::seconds_per;
pub use analysis::{group_by_hold, Analysis, Cycle, Group, ShsOptions, Skipped, Stat};
pub use points::{read_points, write_points, ShsPoint};
pub use trace::{read_trace, Trace, TraceFormat, DISPLACEMENT_COLUMN};

use crate::error::Result;

/// Find every hold and restart in `trace` and measure each restart. An error, naming the
/// trace, when no hold or no complete restart is found.
pub fn analyse(trace: &Trace, options: &ShsOptions) -> Result<Analysis> {
    detect::analyse(trace, options)
}
