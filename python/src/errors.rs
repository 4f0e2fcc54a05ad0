//! Errors and warnings in Python's words: `asperity.Error` (a `ValueError`) with the command
//! line's one-line message, its options written as the arguments of the same meaning; a
//! `MemoryError` for memory that is not there; the plausibility verdicts of [`asperity::plausible`]
//! as errors or `UserWarning`s; Ctrl-C while long work runs with the GIL released.
//!
//! Must not import the other modules of this crate: they all build on it.

use std::ffi::CString;
use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use asperity::plausible::Verdict;
use asperity::quantity::human;
use pyo3::exceptions::{PyMemoryError, PyUserWarning, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    asperity,
    Error,
    PyValueError,
    "Bad input or a computation that failed: the one-line message of the asperity command line."
);

/// A library error as `asperity.Error` (a `MemoryError` when memory is short): its one line as
/// the command line prints it, in Python's words ([`python_words`]), control characters escaped.
pub(crate) fn error(e: asperity::Error) -> PyErr {
    error_naming(e, &[])
}

/// [`error`], with some options named otherwise than [`python_words`] would (`--load` is
/// `loads` in `contact`).
pub(crate) fn error_naming(e: asperity::Error, names: &[(&str, &str)]) -> PyErr {
    use asperity::Error as E;
    let line = match e {
        E::Invalid { option, reason } => format!("{}: {}", python_words(&option, names), python_words(&reason, names)),
        E::File { path, reason } => E::File { path, reason: python_words(&reason, names) }.to_string(),
        e @ E::NotConverged { .. } => python_words(&e.to_string(), names),
        other => other.to_string(),
    };
    let line = asperity::error::one_line(&line);
    if asperity::limits::is_out_of_memory(&line) {
        PyMemoryError::new_err(line)
    } else {
        Error::new_err(line)
    }
}

/// Phrases of the library's messages that point at a command line, and what Python calls them.
const PHRASES: &[(&str, &str)] = &[
    ("asperity topo convert --fill-missing", "Topography.fill_missing()"),
    ("(displacement_m, or --displacement-column)", "(the displacement_m argument)"),
];

/// `text` with each command-line option (`--max-iter`, `--height-unit U`) written as the
/// argument of the same meaning in Python (`max_iter`, `height_unit`): its name with `_` for
/// `-`, or as `names` says, its value's placeholder dropped.
pub(crate) fn python_words(text: &str, names: &[(&str, &str)]) -> String {
    let mut text = text.to_string();
    for (phrase, python) in PHRASES {
        text = text.replace(phrase, python);
    }
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let len =
            after.find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')).unwrap_or(after.len());
        if len == 0 || !after.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.push_str("--");
            rest = after;
            continue;
        }
        let flag = &rest[at..at + 2 + len];
        match names.iter().find(|(f, _)| *f == flag) {
            Some((_, name)) => out.push_str(name),
            None => out.push_str(&after[..len].replace('-', "_")),
        }
        rest = &after[len..];
        // The value's placeholder (`--height-unit U`, `--size LX[,LY]`) is no part of a keyword.
        if let Some(placeholder) = rest.strip_prefix(' ') {
            let end = placeholder
                .find(|c: char| !(c.is_ascii_uppercase() || c.is_ascii_digit() || "[],_".contains(c)))
                .unwrap_or(placeholder.len());
            if end > 0 && placeholder.starts_with(|c: char| c.is_ascii_uppercase()) {
                rest = &placeholder[end..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// The argument `name` = `value` [SI] as [`plausible`] judges it: refused as `asperity.Error`
/// ("youngs=130: 130 Pa is not a solid's Young's modulus …; did you mean 1.3e11 (130 GPa)?"), or
/// taken with a `UserWarning` of the same form when merely unusual. The warning points at the
/// caller's line.
pub(crate) fn judge(py: Python<'_>, name: &str, value: f64, verdict: Verdict) -> PyResult<Option<String>> {
    let said = format!("{name}={}", human(value));
    match verdict {
        Ok(None) => Ok(None),
        Ok(Some(warning)) => {
            let line = format!("{said}: {warning}");
            warn(py, &line, 1)?;
            Ok(Some(line))
        }
        Err(reason) => Err(Error::new_err(asperity::error::one_line(&format!("{said}: {reason}")))),
    }
}

/// `line` as a `UserWarning` (an error when warnings are errors), from the line of the
/// caller `stacklevel` frames up: 1 for a function of this module called from Python.
pub(crate) fn warn(py: Python<'_>, line: &str, stacklevel: i32) -> PyResult<()> {
    let message = CString::new(asperity::error::one_line(line)).expect("an escaped line has no NUL");
    PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, stacklevel)
}

/// An `asperity.Error` about the argument `name`.
pub(crate) fn invalid(name: &str, reason: impl Into<String>) -> PyErr {
    Error::new_err(asperity::error::one_line(&format!("{name}: {}", reason.into())))
}

/// How often long work looks for signals while the GIL is released: often enough for Ctrl-C
/// to feel immediate, seldom enough that waiting for the GIL (held by another Python thread for
/// up to its 5 ms switch interval) costs little.
pub(crate) const SIGNAL_INTERVAL: Duration = Duration::from_millis(100);

/// Ctrl-C while the GIL is released: looks for signals at most every [`SIGNAL_INTERVAL`], and
/// keeps the exception a handler raised. Python runs signal handlers in its main thread only,
/// so work started from another thread never takes the GIL for them.
pub(crate) struct Signals {
    main_thread: bool,
    last: Instant,
    raised: Option<PyErr>,
}

impl Signals {
    pub(crate) fn new(py: Python<'_>) -> PyResult<Self> {
        let threading = py.import("threading")?;
        let main_thread = threading.call_method0("current_thread")?.is(&threading.call_method0("main_thread")?);
        Ok(Signals { main_thread, last: Instant::now(), raised: None })
    }

    /// `Break` once a signal handler has raised.
    pub(crate) fn check(&mut self) -> ControlFlow<()> {
        if self.main_thread && self.raised.is_none() && self.last.elapsed() >= SIGNAL_INTERVAL {
            self.last = Instant::now();
            self.raised = Python::attach(|py| py.check_signals()).err();
        }
        if self.raised.is_some() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }

    /// The exception to raise for `e`: the handler's (KeyboardInterrupt) when it stopped the work.
    pub(crate) fn error(&mut self, e: asperity::Error) -> PyErr {
        match (e, self.raised.take()) {
            (asperity::Error::Interrupted { .. }, Some(raised)) => raised,
            (e, _) => error(e),
        }
    }
}
