//! Python arguments as the library's values: lengths and windows in metres, whole numbers,
//! ranges, the input limits, 2-D float64 arrays (heights checked against the limits and the
//! memory), and read-only views of the arrays a result keeps.
//!
//! Must not import topography, contact, friction, shs or study of this crate: they build on it
//! (it builds on errors only).

use asperity::limits::{self as core_limits, Limits};
use asperity::plausible::{self, Spelling};
use ndarray::Array2;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{error, invalid, judge, python_words};

/// A whole number ≥ 0 (a seed, a count), refused as the command line refuses `--seed -1`.
pub(crate) fn whole(value: &Bound<'_, PyAny>, name: &str) -> PyResult<u64> {
    value.extract::<u64>().map_err(|_| {
        let shown = value.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
        invalid(name, format!("{} is not a whole number ≥ 0", asperity::quantity::quoted(&shown)))
    })
}

/// The input limits: `max_points`, the largest grid, as the command line's `--max-points`
/// (default 2^28).
pub(crate) fn limits(max_points: Option<&Bound<'_, PyAny>>) -> PyResult<Limits> {
    match max_points {
        None => Ok(Limits::default()),
        Some(n) => {
            let n = usize::try_from(whole(n, "max_points")?).unwrap_or(usize::MAX);
            Limits::new(n, "max_points").map_err(error)
        }
    }
}

/// Bytes per point of taking an array of heights: numpy's float64 conversion of another type,
/// then the copy a topography keeps.
const HEIGHTS_BYTES_PER_POINT: u64 = 16;

/// An owned float64 copy of the 2-D array-like `value` of heights, its grid checked against
/// `limits` and its memory against what is available before anything is converted or copied
/// (an array's shape is known beforehand; a nested list is already as large as its copy).
pub(crate) fn heights_within(value: &Bound<'_, PyAny>, limits: &Limits) -> PyResult<Array2<f64>> {
    let check = |ny: usize, nx: usize| -> PyResult<()> {
        limits.check_grid(nx, ny).map_err(|reason| invalid("heights", python_words(&reason, &[])))?;
        let memory = core_limits::grid_memory(nx, ny, HEIGHTS_BYTES_PER_POINT);
        core_limits::check_memory(memory, &format!("a {nx} × {ny} map of heights"))
            .map_err(|reason| PyMemoryError::new_err(asperity::error::one_line(&format!("heights: {reason}"))))
    };
    if let Ok([ny, nx]) = value.getattr("shape").and_then(|s| s.extract::<[usize; 2]>()) {
        check(ny, nx)?;
    }
    let map = float_map(value, "heights")?;
    let view = map.as_array();
    let (ny, nx) = view.dim();
    check(ny, nx)?;
    let mut copy = Vec::new();
    core_limits::reserve(&mut copy, ny * nx, "the heights")
        .map_err(|reason| PyMemoryError::new_err(asperity::error::one_line(&format!("heights: {reason}"))))?;
    copy.extend(view.iter().copied());
    Ok(Array2::from_shape_vec((ny, nx), copy).expect("ny × nx heights"))
}

/// A 2-D float64 array from any array-like (no copy when it already is one).
pub(crate) fn float_map<'py>(value: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
    if let Ok(array) = value.extract::<PyReadonlyArray2<f64>>() {
        return Ok(array);
    }
    let py = value.py();
    let converted = py
        .import("numpy")?
        .call_method1("asarray", (value, "float64"))
        .map_err(|e| invalid(name, format!("not an array of numbers ({})", e.value(py))))?;
    let ndim: usize = converted.getattr("ndim")?.extract()?;
    if ndim != 2 {
        return Err(invalid(name, format!("a 2-D array of shape (ny, nx) is needed, got {ndim} dimension(s)")));
    }
    converted.extract::<PyReadonlyArray2<f64>>()
}

/// `(lx, ly)` from a length or a pair of lengths [m] of a measured window, each positive and
/// finite and judged plausible ([`plausible::window`]).
pub(crate) fn window(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    let (x, y) = lengths(value, name)?;
    judge(value.py(), name, x, plausible::window(x, Spelling::Python))?;
    if y != x {
        judge(value.py(), name, y, plausible::window(y, Spelling::Python))?;
    }
    Ok((x, y))
}

/// `(lx, ly)` from a length or a pair of lengths [m], each positive and finite.
pub(crate) fn lengths(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    let (x, y) = match value.extract::<f64>() {
        Ok(l) => (l, l),
        Err(_) => {
            value.extract::<(f64, f64)>().map_err(|_| invalid(name, "expected a length or (lx, ly) in metres"))?
        }
    };
    if !(x > 0.0 && x.is_finite() && y > 0.0 && y.is_finite()) {
        return Err(invalid(name, format!("lengths must be positive and finite, got ({x}, {y}) m")));
    }
    Ok((x, y))
}

/// A number range `(start, end)` (checked where it is used).
pub(crate) fn range(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    value.extract::<(f64, f64)>().map_err(|_| invalid(name, "expected a pair (start, end)"))
}

/// A pixel range `(start, end)`: indices ≥ 0.
pub(crate) fn pixels(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(usize, usize)> {
    value.extract::<(usize, usize)>().map_err(|_| invalid(name, "expected a pair (start, end) of pixel indices ≥ 0"))
}

/// A read-only view of `array`, whose data `owner` holds and never changes.
pub(crate) fn view_of<'py>(array: &Array2<f64>, owner: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    // SAFETY: `owner` is a frozen pyclass that owns `array` and never mutates or moves its
    // buffer; the view keeps `owner` alive and is made read-only.
    let view = unsafe { PyArray2::borrow_from_array(array, owner) };
    let kwargs = PyDict::new(view.py());
    kwargs.set_item("write", false)?;
    view.call_method("setflags", (), Some(&kwargs))?;
    Ok(view)
}
