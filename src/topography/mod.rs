//! Topographies: measured or synthetic height maps in metres ([`Topography`], in `map`), ready for
//! the contact solver, and line profiles ([`profile`]), the other kind of topography a file may
//! hold ([`AnyTopography`], in [`io`]). This file only declares and re-exports its files.
//!
//! Reading instrument files lives in [`io`], one module per format behind one registry;
//! preparing them in [`detrend`], [`missing`] and [`resample`] (crop, resample, compound), in
//! the one order [`prepare`] applies for contact;
//! synthetic surfaces in [`synth`]; statistics and the power spectrum in [`stats`].
//!
//! Imports the base row (error, fft, limits, output, plausible, quantity); must not import contact,
//! friction, study, report, plot, shs, cli.

pub mod detrend;
pub mod io;
mod map;
pub mod missing;
pub mod prepare;
pub mod profile;
pub mod resample;
pub mod stats;
pub mod synth;

pub use io::AnyTopography;
pub use map::{Provenance, Topography, MAX_LENGTH_M, MIN_SIZE_M};
