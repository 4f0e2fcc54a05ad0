//! The Python module `asperity._asperity`: a thin PyO3 layer over the library's public API.
//!
//! It imports only its own modules and the library's public API (`asperity::…`); its modules
//! import one way, in the pipeline's order (topography ← contact ← friction), over `errors` and
//! `units`.
//!
//! It converts arguments and results (numpy float64 arrays of shape (ny, nx), SI units) and
//! adds no physics. Long work runs with the GIL released and stops on Ctrl-C: the solver's
//! per-iteration callback checks for signals. Every library error becomes `asperity.Error`
//! (a `ValueError`) with the command line's one-line message in Python's words: the arguments'
//! names, not the options'; memory that is not there (an estimate over what is available, an
//! allocation that failed) is a `MemoryError` with the same line. The plausibility checks of the command line ([`asperity::plausible`])
//! refuse a value no contact problem has and warn (`warnings.warn`, a `UserWarning`) about an
//! unusual one.
//!
//! One module per area: [`topography`], [`contact`], [`friction`], [`shs`], [`study`], over
//! [`errors`] (messages in Python's words) and [`units`] (arguments as the library's values).
//!
//! Must not hold the work of an area (that is its module's) nor physics (the library's): it only
//! registers the modules' classes and functions.

mod contact;
mod errors;
mod friction;
mod shs;
mod study;
mod topography;
mod units;

use pyo3::prelude::*;

use crate::errors::{error, Error};

/// asperity: the static friction coefficient of rough interfaces from their measured
/// topography (Peng, Roch, Bonn & Weber, PRL 134, 176202, 2025).
#[pymodule]
fn _asperity(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    // The worker threads, as the command line starts them: a bad RAYON_NUM_THREADS is refused
    // here rather than panicking in the first solve.
    asperity::limits::start_threads().map_err(error)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PRESETS", asperity::friction::PRESETS.iter().map(|(n, s, d)| (*n, *s, *d)).collect::<Vec<_>>())?;
    m.add_class::<topography::Topography>()?;
    m.add_class::<topography::Profile>()?;
    m.add_class::<contact::ContactSolution>()?;
    m.add_class::<friction::Onset>()?;
    m.add_class::<friction::ClassShare>()?;
    m.add_class::<friction::Slide>()?;
    m.add_class::<friction::PartialSlip>()?;
    m.add_function(wrap_pyfunction!(topography::read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(topography::compound, m)?)?;
    m.add_function(wrap_pyfunction!(topography::generate, m)?)?;
    m.add_function(wrap_pyfunction!(topography::psd, m)?)?;
    m.add_function(wrap_pyfunction!(contact::contact, m)?)?;
    m.add_function(wrap_pyfunction!(friction::onset, m)?)?;
    m.add_function(wrap_pyfunction!(friction::slide, m)?)?;
    m.add_function(wrap_pyfunction!(shs::_analyse_shs, m)?)?;
    m.add_function(wrap_pyfunction!(study::_run_study, m)?)?;
    Ok(())
}
