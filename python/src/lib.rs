//! The Python module `asperity._asperity`: a thin PyO3 layer over the library's public API.
//!
//! It converts arguments and results (numpy float64 arrays of shape (ny, nx), SI units) and
//! adds no physics. Long work runs with the GIL released and stops on Ctrl-C: the solver's
//! per-iteration callback checks for signals. Every library error becomes `asperity.Error`
//! (a `ValueError`) with the command line's one-line message in Python's words: the arguments'
//! names, not the options'; memory that is not there (an estimate over what is available, an
//! allocation that failed) is a `MemoryError` with the same line. The plausibility checks of the command line ([`asperity::plausible`])
//! refuse a value no contact problem has and warn (`warnings.warn`, a `UserWarning`) about an
//! unusual one.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use std::ffi::CString;

use asperity::contact::{
    self as core_contact, AdhesiveSolver, Boundary, CohesiveLaw, ContactSolver, Convergence, Device, Material,
    ShearCompliance, SolverOptions, TangentialOptions, TangentialSolver,
};
use asperity::friction::{
    elastic_onset, element_stiffness, ramp_force, slip_curve_file, spring_slider_onset, ClassShare as CoreShare, Curve,
    ElementLoads, FrictionLaw, Loading, Onset as CoreOnset, SlidePoint, SlideStage, SlipLaw, Snapshot, Weakening,
    DEFAULT_SLIP_DISTANCE_M, PEAK_TOLERANCE,
};
use asperity::limits::{self as core_limits, Limits};
use asperity::plausible::{self, Spelling, Verdict};
use asperity::quantity::human;
use asperity::shs::{self, ShsOptions, Trace};
use asperity::study::config::StudyConfig;
use asperity::study::run::{Progress, Study};
use asperity::topography::detrend::Detrend;
use asperity::topography::missing::fill_missing;
use asperity::topography::prepare::Preparation;
use asperity::topography::profile::Profile as CoreProfile;
use asperity::topography::resample::{self, CropWindow};
use asperity::topography::stats::{self, Window};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};
use asperity::topography::{io, AnyTopography, Provenance, Topography as CoreTopography};
use ndarray::{Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

pyo3::create_exception!(
    asperity,
    Error,
    PyValueError,
    "Bad input or a computation that failed: the one-line message of the asperity command line."
);

/// A library error as `asperity.Error` (a `MemoryError` when memory is short): its one line as
/// the command line prints it, in Python's words ([`python_words`]), control characters escaped.
fn error(e: asperity::Error) -> PyErr {
    error_naming(e, &[])
}

/// [`error`], with some options named otherwise than [`python_words`] would (`--load` is
/// `loads` in `contact`).
fn error_naming(e: asperity::Error, names: &[(&str, &str)]) -> PyErr {
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
fn python_words(text: &str, names: &[(&str, &str)]) -> String {
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
fn judge(py: Python<'_>, name: &str, value: f64, verdict: Verdict) -> PyResult<Option<String>> {
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
fn warn(py: Python<'_>, line: &str, stacklevel: i32) -> PyResult<()> {
    let message = CString::new(asperity::error::one_line(line)).expect("an escaped line has no NUL");
    PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, stacklevel)
}

/// A whole number ≥ 0 (a seed, a count), refused as the command line refuses `--seed -1`.
fn whole(value: &Bound<'_, PyAny>, name: &str) -> PyResult<u64> {
    value.extract::<u64>().map_err(|_| {
        let shown = value.repr().map_or_else(|_| "?".to_string(), |r| r.to_string());
        invalid(name, format!("{} is not a whole number ≥ 0", asperity::quantity::quoted(&shown)))
    })
}

/// The input limits: `max_points`, the largest grid, as the command line's `--max-points`
/// (default 2^28).
fn limits(max_points: Option<&Bound<'_, PyAny>>) -> PyResult<Limits> {
    match max_points {
        None => Ok(Limits::default()),
        Some(n) => {
            let n = usize::try_from(whole(n, "max_points")?).unwrap_or(usize::MAX);
            Limits::new(n, "max_points").map_err(error)
        }
    }
}

/// An `asperity.Error` about the argument `name`.
fn invalid(name: &str, reason: impl Into<String>) -> PyErr {
    Error::new_err(asperity::error::one_line(&format!("{name}: {}", reason.into())))
}

/// How often long work looks for signals while the GIL is released: often enough for Ctrl-C
/// to feel immediate, seldom enough that waiting for the GIL (held by another Python thread for
/// up to its 5 ms switch interval) costs little.
const SIGNAL_INTERVAL: Duration = Duration::from_millis(100);

/// Ctrl-C while the GIL is released: looks for signals at most every [`SIGNAL_INTERVAL`], and
/// keeps the exception a handler raised. Python runs signal handlers in its main thread only,
/// so work started from another thread never takes the GIL for them.
struct Signals {
    main_thread: bool,
    last: Instant,
    raised: Option<PyErr>,
}

impl Signals {
    fn new(py: Python<'_>) -> PyResult<Self> {
        let threading = py.import("threading")?;
        let main_thread = threading.call_method0("current_thread")?.is(&threading.call_method0("main_thread")?);
        Ok(Signals { main_thread, last: Instant::now(), raised: None })
    }

    /// `Break` once a signal handler has raised.
    fn check(&mut self) -> ControlFlow<()> {
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
    fn error(&mut self, e: asperity::Error) -> PyErr {
        match (e, self.raised.take()) {
            (asperity::Error::Interrupted { .. }, Some(raised)) => raised,
            (e, _) => error(e),
        }
    }
}

/// Bytes per point of taking an array of heights: numpy's float64 conversion of another type,
/// then the copy a topography keeps.
const HEIGHTS_BYTES_PER_POINT: u64 = 16;

/// An owned float64 copy of the 2-D array-like `value` of heights, its grid checked against
/// `limits` and its memory against what is available before anything is converted or copied
/// (an array's shape is known beforehand; a nested list is already as large as its copy).
fn heights_within(value: &Bound<'_, PyAny>, limits: &Limits) -> PyResult<Array2<f64>> {
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
fn float_map<'py>(value: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
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
fn window(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    let (x, y) = lengths(value, name)?;
    judge(value.py(), name, x, plausible::window(x, Spelling::Python))?;
    if y != x {
        judge(value.py(), name, y, plausible::window(y, Spelling::Python))?;
    }
    Ok((x, y))
}

/// `(lx, ly)` from a length or a pair of lengths [m], each positive and finite.
fn lengths(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
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
fn range(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    value.extract::<(f64, f64)>().map_err(|_| invalid(name, "expected a pair (start, end)"))
}

/// A pixel range `(start, end)`: indices ≥ 0.
fn pixels(value: &Bound<'_, PyAny>, name: &str) -> PyResult<(usize, usize)> {
    value.extract::<(usize, usize)>().map_err(|_| invalid(name, "expected a pair (start, end) of pixel indices ≥ 0"))
}

/// A read-only view of `array`, whose data `owner` holds and never changes.
fn view_of<'py>(array: &Array2<f64>, owner: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    // SAFETY: `owner` is a frozen pyclass that owns `array` and never mutates or moves its
    // buffer; the view keeps `owner` alive and is made read-only.
    let view = unsafe { PyArray2::borrow_from_array(array, owner) };
    let kwargs = PyDict::new(view.py());
    kwargs.set_item("write", false)?;
    view.call_method("setflags", (), Some(&kwargs))?;
    Ok(view)
}

/// A height map: heights [m] of shape (ny, nx) (row index y, column index x) on a window of
/// physical size (lx, ly) [m].
///
/// ``Topography(heights, physical_size=(lx, ly), periodic=False, *, max_points=None)`` takes
/// any 2-D array of heights in metres (copied; NaN marks a missing point), refusing what the
/// command line's readers refuse: more than ``max_points`` points (default 2^28), heights beyond
/// ±1e50 m (infinite ones included), and a copy the memory cannot hold (a ``MemoryError``).
/// Methods return new topographies.
#[pyclass(frozen, module = "asperity")]
struct Topography {
    inner: CoreTopography,
    /// The channels of the file it was read from.
    channels: Vec<String>,
}

impl Topography {
    fn wrap(inner: CoreTopography) -> Self {
        Topography { channels: vec![inner.channel.clone()], inner }
    }
}

#[pymethods]
impl Topography {
    #[new]
    #[pyo3(signature = (heights, physical_size, periodic = false, *, max_points = None))]
    fn new(
        heights: &Bound<'_, PyAny>,
        physical_size: &Bound<'_, PyAny>,
        periodic: bool,
        max_points: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let size = window(physical_size, "physical_size")?;
        let heights = heights_within(heights, &limits(max_points)?)?;
        if heights.nrows() == 0 || heights.ncols() == 0 {
            return Err(invalid("heights", format!("an empty {:?} array", heights.dim())));
        }
        let topography = CoreTopography {
            heights,
            physical_size: Some(size),
            periodic,
            height_unit_known: true,
            channel: "heights".into(),
            provenance: Provenance { file: None, format: "array".into(), height_unit: Some("m".into()) },
        };
        // The readers' check: such heights overflow the statistics and solves made of them.
        topography.require_representable().map_err(|e| match e {
            asperity::Error::Invalid { reason, .. } => invalid("heights", reason),
            e => error(e),
        })?;
        Ok(Topography::wrap(topography))
    }

    /// Heights [m], float64 of shape (ny, nx): a read-only view, no copy.
    #[getter]
    fn heights<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        view_of(&slf.get().inner.heights, slf.clone().into_any())
    }

    /// Physical size (lx, ly) [m], or None when the file states none.
    #[getter]
    fn physical_size(&self) -> Option<(f64, f64)> {
        self.inner.physical_size
    }

    /// Pixel size (dx, dy) [m], or None without a physical size.
    #[getter]
    fn pixel_size(&self) -> Option<(f64, f64)> {
        self.inner.physical_size.map(|(lx, ly)| (lx / self.inner.nx() as f64, ly / self.inner.ny() as f64))
    }

    /// Grid shape (ny, nx).
    #[getter]
    fn shape(&self) -> (usize, usize) {
        self.inner.heights.dim()
    }

    /// Whether the map repeats across its edges.
    #[getter]
    fn periodic(&self) -> bool {
        self.inner.periodic
    }

    /// Names of the channels of the file it was read from.
    #[getter]
    fn channels(&self) -> Vec<String> {
        self.channels.clone()
    }

    /// Name of the channel the heights come from.
    #[getter]
    fn channel(&self) -> String {
        self.inner.channel.clone()
    }

    /// Height unit of the file as it states it or as ``read_topography(height_unit=)`` gave it
    /// ("nm", "µm", …; heights are in metres all the same), or None when neither does.
    #[getter]
    fn height_unit(&self) -> Option<String> {
        self.inner.provenance.height_unit.clone()
    }

    /// The file it was read from, or None.
    #[getter]
    fn file(&self) -> Option<PathBuf> {
        self.inner.provenance.file.clone()
    }

    /// Number of missing (NaN) points.
    #[getter]
    fn missing_points(&self) -> usize {
        self.inner.missing_points()
    }

    /// Levelled (least squares): "none", "mean", "plane" (the default, as a study levels a
    /// file), "poly:N" (a polynomial of total degree N ≤ 8) or "sphere" (the best-fitting
    /// sphere subtracted: a ball's curvature); or line by line, "line:N" (each scan line's
    /// polynomial of degree N ≤ 3 along x subtracted) or "line:median", optionally followed by
    /// a whole-map mode ("line:1,plane").
    #[pyo3(signature = (kind = "plane"))]
    fn detrend(&self, py: Python<'_>, kind: &str) -> PyResult<Topography> {
        let detrend: Detrend = kind.parse().map_err(|e: String| invalid("kind", e))?;
        let mut topo = self.inner.clone();
        py.detach(|| detrend.apply(&mut topo)).map_err(error)?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
    }

    /// The part inside a window: ``x=(x0, x1), y=(y0, y1)`` [m] from the map's origin, or
    /// ``columns=(i0, i1), rows=(j0, j1)`` in pixels (end excluded). A side left out is kept
    /// whole. The pixel size is kept.
    #[pyo3(signature = (x = None, y = None, *, columns = None, rows = None))]
    fn crop(
        &self,
        x: Option<&Bound<'_, PyAny>>,
        y: Option<&Bound<'_, PyAny>>,
        columns: Option<&Bound<'_, PyAny>>,
        rows: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Topography> {
        let window = if columns.is_some() || rows.is_some() {
            if x.is_some() || y.is_some() {
                return Err(invalid("crop", "give lengths (x, y) or pixels (columns, rows), not both"));
            }
            let columns = columns.map(|v| pixels(v, "columns")).transpose()?;
            let rows = rows.map(|v| pixels(v, "rows")).transpose()?;
            let (c, r) = (columns.unwrap_or((0, self.inner.nx())), rows.unwrap_or((0, self.inner.ny())));
            CropWindow::Pixels { x: c.0..c.1, y: r.0..r.1 }
        } else {
            let (lx, ly) = self.inner.physical_size.unwrap_or((f64::INFINITY, f64::INFINITY));
            let x = x.map(|v| range(v, "x")).transpose()?.unwrap_or((0.0, lx));
            let y = y.map(|v| range(v, "y")).transpose()?.unwrap_or((0.0, ly));
            CropWindow::Physical { x, y }
        };
        let topo = resample::crop(&self.inner, &window).map_err(error)?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
    }

    /// Resampled (cubic convolution) to the pixel size nearest to ``pixel_size`` [m] that
    /// divides the physical size, which is kept; at most ``max_points`` points (default 2^28).
    #[pyo3(signature = (pixel_size, *, max_points = None))]
    fn resample(&self, py: Python<'_>, pixel_size: f64, max_points: Option<&Bound<'_, PyAny>>) -> PyResult<Topography> {
        let limits = limits(max_points)?;
        judge(py, "pixel_size", pixel_size, plausible::pixel(pixel_size, Spelling::Python))?;
        let topo = py.detach(|| resample::resample(&self.inner, pixel_size, &limits)).map_err(error)?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
    }

    /// A spherical cap of radius ``radius`` [m] added, apex at the window's centre (a paraboloid
    /// with ``paraboloid=True``): a ball scanned after its curvature was levelled away, as
    /// ``asperity contact --cap-radius``. The result is not periodic.
    #[pyo3(signature = (radius, *, paraboloid = false))]
    fn add_cap(&self, py: Python<'_>, radius: f64, paraboloid: bool) -> PyResult<Topography> {
        judge(py, "radius", radius, plausible::radius(radius, Spelling::Python))?;
        let shape = if paraboloid { CapShape::Paraboloid } else { CapShape::Sphere };
        let prep = Preparation { cap: Some(Cap { radius, shape }), ..Preparation::default() };
        let topo = py
            .detach(|| prep.apply(self.inner.clone()))
            .map_err(|e| error_naming(e, &[("--sphere-radius", "radius")]))?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
    }

    /// The statistics ``asperity topo info`` reports, with SurfaceTopography's definitions, as
    /// a dict: ``mean`` and ``rms_height`` [m] (Sq), ``rms_gradient`` [1] (√⟨|∇h|²⟩),
    /// ``rms_slope_from_profile`` [1] (along x), ``rms_curvature_from_area`` [1/m] (half the
    /// Laplacian) and ``rms_curvature_from_profile`` [1/m] (along x), from forward (slopes) and
    /// central (curvatures) differences. Needs the physical size and no missing point.
    fn statistics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let topo = &self.inner;
        let (heights, derivatives) =
            py.detach(|| Ok((stats::height_stats(topo)?, stats::slope_curvature(topo)?))).map_err(error)?;
        let dict = PyDict::new(py);
        dict.set_item("mean", heights.mean)?;
        dict.set_item("rms_height", heights.rms_height)?;
        dict.set_item("rms_gradient", derivatives.rms_gradient)?;
        dict.set_item("rms_slope_from_profile", derivatives.rms_slope_from_profile)?;
        dict.set_item("rms_curvature_from_area", derivatives.rms_curvature_from_area_per_m)?;
        dict.set_item("rms_curvature_from_profile", derivatives.rms_curvature_from_profile_per_m)?;
        Ok(dict)
    }

    /// Missing points filled harmonically (each the mean of its four neighbours).
    fn fill_missing(&self, py: Python<'_>) -> PyResult<Topography> {
        let mut topo = self.inner.clone();
        py.detach(|| fill_missing(&mut topo)).map_err(error)?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
    }

    fn __repr__(&self) -> String {
        let size = match self.inner.physical_size {
            Some((lx, ly)) => format!("{lx:e} × {ly:e} m"),
            None => "size unknown".into(),
        };
        let from = match &self.inner.provenance.file {
            Some(f) => format!(" from {}", f.display()),
            None => String::new(),
        };
        format!("<Topography {}×{} points (ny × nx), {size}{from}>", self.inner.ny(), self.inner.nx())
    }
}

/// Read a topography file in any format asperity reads (detected from its content and
/// extension; ``format`` overrides): a ``Topography`` (a 2-D map), or a ``Profile`` when the
/// file holds a line profile (a stylus scan, a two-column table), as ``asperity topo info``
/// tells them apart. ``channel``: name or 0-based index (default: the first height channel).
/// ``size``: the physical size [m], needed for a bare array (.npy), checked against a size the
/// file states. ``height_unit``: unit of a file that states none (of a profile's heights, and
/// of its positions unless ``position_unit`` gives theirs). ``max_points``: the largest grid read (default 2^28), the file read only up to
/// 128 bytes a point.
#[pyfunction]
#[pyo3(signature = (path, channel = None, *, size = None, height_unit = None, position_unit = None, format = None,
                    max_points = None))]
fn read_topography(
    py: Python<'_>,
    path: PathBuf,
    channel: Option<&Bound<'_, PyAny>>,
    size: Option<&Bound<'_, PyAny>>,
    height_unit: Option<String>,
    position_unit: Option<String>,
    format: Option<String>,
    max_points: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyAny>> {
    let options = io::ReadOptions {
        format,
        channel: channel.map(|c| c.str().map(|s| s.to_string())).transpose()?,
        physical_size: size.map(|s| window(s, "size")).transpose()?,
        height_unit,
        position_unit,
        limits: limits(max_points)?,
    };
    let (any, channels) = py.detach(|| io::read_any(&path, &options)).map_err(error)?;
    Ok(match any {
        AnyTopography::Map(inner) => Py::new(py, Topography { inner, channels })?.into_any(),
        AnyTopography::Profile(inner) => Py::new(py, Profile { inner })?.into_any(),
    })
}

/// A line profile: heights along x at increasing positions, both in metres (as stored when
/// the file states no unit and none was given: ``height_unit`` is then None). Its statistics
/// and spectrum are SurfaceTopography's for line scans; what needs a 2-D map (contact) does
/// not take it.
#[pyclass(frozen, module = "asperity")]
struct Profile {
    inner: CoreProfile,
}

#[pymethods]
impl Profile {
    /// Positions along x [m], the first 0: a float64 copy.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.positions().to_vec().into_pyarray(py)
    }

    /// Heights [m], NaN where missing: a float64 copy.
    #[getter]
    fn heights<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.inner.heights().to_vec().into_pyarray(py)
    }

    /// Number of points.
    #[getter]
    fn points(&self) -> usize {
        self.inner.points()
    }

    /// Length [m]: points × step when uniform, else the last position.
    #[getter]
    fn length(&self) -> f64 {
        self.inner.length()
    }

    /// The step [m] of equally spaced positions; None when they are not.
    #[getter]
    fn step(&self) -> Option<f64> {
        self.inner.step()
    }

    /// The column the heights come from.
    #[getter]
    fn channel(&self) -> String {
        self.inner.channel.clone()
    }

    /// The heights' unit as the file states it ("m" when given as ``height_unit``); None when
    /// unknown.
    #[getter]
    fn height_unit(&self) -> Option<String> {
        match (&self.inner.provenance.height_unit, self.inner.height_unit_known) {
            (Some(u), _) => Some(u.clone()),
            (None, true) => Some("m".into()),
            (None, false) => None,
        }
    }

    /// The file read, None for a profile made otherwise.
    #[getter]
    fn file(&self) -> Option<PathBuf> {
        self.inner.provenance.file.clone()
    }

    /// Number of missing (NaN) points.
    #[getter]
    fn missing_points(&self) -> usize {
        self.inner.missing_points()
    }

    /// The statistics ``asperity topo info`` reports of a line profile, with
    /// SurfaceTopography's definitions for line scans, as a dict: ``mean`` and ``rms_height``
    /// [m] (Rq), ``rms_slope`` [1] (Rdq, forward differences) and ``rms_curvature`` [1/m]
    /// (Rddq, central differences); of a non-uniform profile along the line between its points.
    /// Needs the units of the positions and heights.
    fn statistics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = &self.inner;
        let ((mean, rms), slope, curvature) = py
            .detach(|| {
                p.require_metres()?;
                Ok((stats::profile_height(p)?, stats::profile_rms_slope(p)?, stats::profile_rms_curvature(p)?))
            })
            .map_err(error)?;
        let dict = PyDict::new(py);
        dict.set_item("mean", mean)?;
        dict.set_item("rms_height", rms)?;
        dict.set_item("rms_slope", slope)?;
        dict.set_item("rms_curvature", curvature)?;
        Ok(dict)
    }

    /// Levelled (least squares, over the defined points): "mean", "plane" (the straight line,
    /// the default), "poly:N" or "line:N" (the polynomial of degree N along x), "line:median"
    /// or "none", as ``asperity topo info --detrend`` levels a profile.
    #[pyo3(signature = (kind = "plane"))]
    fn detrend(&self, py: Python<'_>, kind: &str) -> PyResult<Profile> {
        let detrend: Detrend = kind.parse().map_err(|e: String| invalid("kind", e))?;
        let mut inner = self.inner.clone();
        py.detach(|| detrend.apply_to_profile(&mut inner)).map_err(|e| error_naming(e, &[("--detrend", "kind")]))?;
        Ok(Profile { inner })
    }

    fn __repr__(&self) -> String {
        let spacing = match self.inner.step() {
            Some(step) => format!("step {step:e} m"),
            None => "non-uniform".into(),
        };
        let from = match &self.inner.provenance.file {
            Some(f) => format!(" from {}", f.display()),
            None => String::new(),
        };
        format!("<Profile {} points, length {:e} m, {spacing}{from}>", self.inner.points(), self.inner.length())
    }
}

/// The compound roughness h = h_ball − h_wafer on the ball's grid (the wafer interpolated at
/// the ball's sample positions, the windows centred on each other).
#[pyfunction]
fn compound(py: Python<'_>, ball: &Topography, wafer: &Topography) -> PyResult<Topography> {
    let inner = py.detach(|| resample::compound(&ball.inner, &wafer.inner)).map_err(error)?;
    Ok(Topography::wrap(inner))
}

/// A synthetic surface: self-affine random-phase roughness (Hurst exponent ``hurst``,
/// C(q) ∝ q^(−2(1+H)), RMS height ``rms`` [m] or RMS slope ``rms_slope``, flat below the
/// wavevector of ``rolloff`` [m], nothing below ``cutoff`` [m] or above ``long_cutoff`` [m]
/// wavelengths) on an optional cap of radius ``sphere_radius`` [m] (a paraboloid with
/// ``paraboloid=True``), apex at the centre. ``size``: lx or (lx, ly) [m]; ``grid``: n or
/// (nx, ny) points, at most ``max_points`` in all (default 2^28). The same seed gives
/// bit-identical heights, as ``asperity topo generate``.
#[pyfunction]
#[pyo3(signature = (*, size, grid, seed, hurst = None, rms = None, rms_slope = None, rolloff = None,
                    cutoff = None, long_cutoff = None, sphere_radius = None, paraboloid = false,
                    max_points = None))]
#[allow(clippy::too_many_arguments)]
fn generate(
    py: Python<'_>,
    size: &Bound<'_, PyAny>,
    grid: &Bound<'_, PyAny>,
    seed: &Bound<'_, PyAny>,
    hurst: Option<f64>,
    rms: Option<f64>,
    rms_slope: Option<f64>,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    long_cutoff: Option<f64>,
    sphere_radius: Option<f64>,
    paraboloid: bool,
    max_points: Option<&Bound<'_, PyAny>>,
) -> PyResult<Topography> {
    let limits = limits(max_points)?;
    let seed = whole(seed, "seed")?;
    let size = window(size, "size")?;
    let grid = match grid.extract::<usize>() {
        Ok(n) => (n, n),
        Err(_) => grid.extract::<(usize, usize)>().map_err(|_| invalid("grid", "expected n or (nx, ny) points"))?,
    };
    if let Some(h) = rms {
        judge(py, "rms", h, plausible::roughness(h, Spelling::Python))?;
    }
    if let Some(r) = sphere_radius {
        judge(py, "sphere_radius", r, plausible::radius(r, Spelling::Python))?;
    }
    let roughness = match (hurst, rms, rms_slope) {
        (None, None, None) => None,
        (None, ..) => return Err(invalid("hurst", "roughness (rms or rms_slope) needs the Hurst exponent")),
        (Some(_), Some(_), Some(_)) => return Err(invalid("rms", "give rms or rms_slope, not both")),
        (Some(_), None, None) => return Err(invalid("rms", "give the roughness's rms or rms_slope")),
        (Some(hurst), rms, slope) => Some(SelfAffine {
            hurst,
            rolloff_wavelength: rolloff,
            short_cutoff_wavelength: cutoff,
            long_cutoff_wavelength: long_cutoff,
            amplitude: match (rms, slope) {
                (Some(h), _) => Amplitude::RmsHeight(h),
                (None, s) => Amplitude::RmsSlope(s.expect("one of rms and rms_slope")),
            },
        }),
    };
    let cap = sphere_radius
        .map(|radius| Cap { radius, shape: if paraboloid { CapShape::Paraboloid } else { CapShape::Sphere } });
    let surface = SyntheticSurface { size, grid, roughness, cap, seed };
    let inner = py.detach(|| surface.generate_within(&limits)).map_err(error)?;
    Ok(Topography::wrap(inner))
}

/// A 1-D float64 array.
type Spectrum<'py> = Bound<'py, PyArray1<f64>>;

/// The power spectral density (mean removed), as ``asperity topo psd``: of a ``Topography``
/// the isotropic ``(q, c)``, wavevector |q| [rad/m] and C(q) [m⁴]; of a uniform ``Profile``
/// its 1-D spectrum, C(q) [m³] at q = 2πk/L. ``window``: "auto" (Hann for non-periodic maps
/// and for profiles, none for periodic maps), "hann" or "none".
#[pyfunction]
#[pyo3(signature = (topography, window = "auto"))]
fn psd<'py>(py: Python<'py>, topography: &Bound<'py, PyAny>, window: &str) -> PyResult<(Spectrum<'py>, Spectrum<'py>)> {
    let chosen = match window {
        "auto" => None,
        "hann" => Some(Window::Hann),
        "none" => Some(Window::None),
        other => return Err(invalid("window", format!("'{other}' is not auto, hann or none"))),
    };
    let spectrum = if let Ok(t) = topography.cast::<Topography>() {
        let t = &t.get().inner;
        py.detach(|| stats::psd(t, chosen.unwrap_or_else(|| Window::default_for(t))))
    } else if let Ok(p) = topography.cast::<Profile>() {
        let p = &p.get().inner;
        // A measured profile does not repeat across its ends.
        py.detach(|| p.require_metres().and_then(|_| stats::profile_psd(p, chosen.unwrap_or(Window::Hann))))
    } else {
        return Err(invalid("topography", "expected a Topography or a Profile"));
    }
    .map_err(error)?;
    Ok((spectrum.q.into_pyarray(py), spectrum.c.into_pyarray(py)))
}

/// One load of a contact solve: the pressure, gap and displacement maps and what summarises
/// them, as a load of ``asperity contact``'s contact.json.
#[pyclass(frozen, module = "asperity")]
struct ContactSolution {
    /// Normal load N [N].
    #[pyo3(get)]
    load: f64,
    /// Mean pressure N / (lx·ly) [Pa].
    #[pyo3(get)]
    mean_pressure: f64,
    /// Pressure [Pa], float64 of shape (ny, nx).
    #[pyo3(get)]
    pressure: Py<PyArray2<f64>>,
    /// Gap [m], float64 of shape (ny, nx): zero on the contact, positive elsewhere.
    #[pyo3(get)]
    gap: Py<PyArray2<f64>>,
    /// Elastic surface displacement [m], float64 of shape (ny, nx) (into the body positive).
    #[pyo3(get)]
    displacement: Py<PyArray2<f64>>,
    /// Fraction of the window in contact.
    #[pyo3(get)]
    contact_fraction: f64,
    /// Real contact area [m²].
    #[pyo3(get)]
    contact_area: f64,
    /// Pixels with p > 0.
    #[pyo3(get)]
    contact_points: usize,
    /// Number of contact patches (4-connected clusters, wrapping when periodic).
    #[pyo3(get)]
    patches: usize,
    /// Patch sizes in pixels, largest first.
    #[pyo3(get)]
    patch_sizes: Vec<usize>,
    /// Largest local pressure [Pa].
    #[pyo3(get)]
    max_pressure: f64,
    /// Share of the load carried within 2 % of the window's edges (at least 2 pixels); above
    /// 0.01 the contact is cut by the window (a warning).
    #[pyo3(get)]
    edge_load_fraction: f64,
    /// Share of the load carried at p ≥ ``hardness``, or None without a hardness.
    #[pyo3(get)]
    load_above_hardness_fraction: Option<f64>,
    /// Hardness of the softer body [Pa] given to ``contact``, or None.
    #[pyo3(get)]
    hardness: Option<f64>,
    /// Whether the pressure was capped at ``hardness`` (elastic–perfectly-plastic).
    #[pyo3(get)]
    plastic: bool,
    /// Effective modulus E* [Pa] of the bodies.
    #[pyo3(get)]
    effective_modulus: f64,
    /// Conjugate-gradient iterations.
    #[pyo3(get)]
    iterations: usize,
    /// Applications of the influence operator, in FFT pairs (None with adhesion).
    #[pyo3(get)]
    operator_applications: Option<f64>,
    /// Relative residual at convergence.
    #[pyo3(get)]
    residual: f64,
    /// Wall-clock time of the solve [s].
    #[pyo3(get)]
    seconds: f64,
    /// Physical size (lx, ly) [m] of the window.
    #[pyo3(get)]
    physical_size: (f64, f64),
    /// "periodic" or "free".
    #[pyo3(get)]
    boundary: &'static str,
    /// The warnings about this load, as ``warnings.warn`` gave them (and the command line
    /// prints them): an unusual load, a contact cut by the window, pressures at the hardness.
    #[pyo3(get)]
    warnings: Vec<String>,
    /// With adhesion: the compressive force N_c, the integral of ``pressure`` [N]; None
    /// without.
    #[pyo3(get)]
    compressive_force: Option<f64>,
    /// With adhesion: the adhesive force N_a = N_c − N, the integral of the tension as a
    /// positive number [N]; None without.
    #[pyo3(get)]
    adhesive_force: Option<f64>,
    /// With adhesion: the traction [Pa], float64 of shape (ny, nx), tensile negative
    /// (``pressure`` is its compressive part where the gap is zero); None without.
    #[pyo3(get)]
    traction: Option<Py<PyArray2<f64>>>,
    /// With adhesion: the separation [m] (periodic: the mean gap; free: the rigid body's position
    /// from first touch of its highest point); None without.
    #[pyo3(get)]
    separation: Option<f64>,
    /// With ``pull_off=True``: the pull-off force [N], the most tensile load with an equilibrium;
    /// None otherwise.
    #[pyo3(get)]
    pull_off: Option<f64>,
    /// The elastic bodies, for the tangential problem of ``slide``.
    bodies: Vec<Material>,
}

#[pymethods]
impl ContactSolution {
    fn __repr__(&self) -> String {
        format!(
            "<ContactSolution {:e} N: {} contact points in {} patches, {} iterations>",
            self.load, self.contact_points, self.patches, self.iterations
        )
    }
}

/// What one load's solve leaves, before it becomes Python objects.
struct Solved {
    index: usize,
    report: core_contact::SolveReport,
    summary: core_contact::ContactSummary,
    pressure: Array2<f64>,
    gap: Array2<f64>,
    displacement: Array2<f64>,
    /// With adhesion: its report and the traction.
    adhesive: Option<(core_contact::AdhesiveReport, Array2<f64>)>,
}

/// Elastic normal contact of a rigid rough surface on an elastic half-space (boundary integral
/// method, Polonsky–Keer conjugate gradient at imposed load), as ``asperity contact``.
///
/// ``topography``: a ``Topography`` with heights [m] and a physical size [m] (higher heights
/// touch first), prepared as it should be solved (detrended, capped). ``loads`` [N]: one or a
/// sequence; solved in increasing order, each from the previous solution, and returned in the
/// order given. ``youngs`` [Pa] and ``poisson`` of the elastic body (default silicon: 130e9 Pa
/// and 0.26); ``youngs2`` [Pa] and ``poisson2`` of an elastic counter-body (default None:
/// rigid; 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2). ``hardness`` [Pa] of the softer body (default None;
/// silicon ≈ 12e9 Pa): each solution reports the share of its load carried at p ≥ hardness and a
/// warning when it is not zero; ``plastic=True`` (default False) caps the pressure at it
/// (elastic–perfectly-plastic). ``boundary``: "periodic" (default) or "free". ``tolerance``
/// (default 1e-10): on the solver's relative residual, below 1e-2.
/// ``max_iter`` (default 20000): iteration limit per load. ``device``: "cpu" (default, every
/// core) or "gpu" (the first NVIDIA GPU; a build with the ``gpu`` feature).
///
/// Adhesion, as ``asperity contact --adhesion-work``: ``adhesion_work`` [J/m²] (default None:
/// none; plausible from 1e-4 to 10) with ``adhesion_stress`` [Pa] or ``adhesion_range`` [m],
/// ``adhesion_law`` "maugis" (default) or "exponential"; loads may then be zero or negative
/// (tensile) and are solved from the largest down, each solution carrying
/// ``compressive_force``, ``adhesive_force``, ``traction`` and ``separation``; ``pull_off=True``
/// also finds the pull-off force (``pull_off`` on each solution).
///
/// Values no contact problem has (``youngs=130``, a load pressing harder than E*) raise
/// ``asperity.Error`` with the unit likely meant; unusual ones, a contact cut by the window's
/// edges and pressures at the hardness are ``UserWarning``s, kept in each solution's
/// ``warnings``. The GIL is released while solving; Ctrl-C stops the solve.
#[pyfunction]
#[pyo3(signature = (topography, loads, *, youngs = Material::SILICON.youngs, poisson = Material::SILICON.poisson,
                    youngs2 = None, poisson2 = None, hardness = None, plastic = false, boundary = "periodic",
                    tolerance = SolverOptions::default().convergence.tolerance,
                    max_iter = SolverOptions::default().convergence.max_iterations, device = "cpu",
                    adhesion_work = None, adhesion_stress = None, adhesion_range = None, adhesion_law = "maugis",
                    pull_off = false),
       text_signature = "(topography, loads, *, youngs=130e9, poisson=0.26, youngs2=None, poisson2=None, \
                         hardness=None, plastic=False, boundary='periodic', tolerance=1e-10, max_iter=20000, \
                         device='cpu', adhesion_work=None, adhesion_stress=None, adhesion_range=None, \
                         adhesion_law='maugis', pull_off=False)")]
#[allow(clippy::too_many_arguments)]
fn contact(
    py: Python<'_>,
    topography: &Bound<'_, PyAny>,
    loads: &Bound<'_, PyAny>,
    youngs: f64,
    poisson: f64,
    youngs2: Option<f64>,
    poisson2: Option<f64>,
    hardness: Option<f64>,
    plastic: bool,
    boundary: &str,
    tolerance: f64,
    max_iter: usize,
    device: &str,
    adhesion_work: Option<f64>,
    adhesion_stress: Option<f64>,
    adhesion_range: Option<f64>,
    adhesion_law: &str,
    pull_off: bool,
) -> PyResult<Vec<ContactSolution>> {
    let names = [
        ("--load", "loads"),
        ("--adhesion-work", "adhesion_work"),
        ("--adhesion-stress", "adhesion_stress"),
        ("--adhesion-range", "adhesion_range"),
        ("--adhesion-law", "adhesion_law"),
    ];
    let named = |e| error_naming(e, &names);
    let loads: Vec<f64> = match loads.extract::<f64>() {
        Ok(l) => vec![l],
        Err(_) => loads.extract().map_err(|_| invalid("loads", "expected a load or a sequence of loads [N]"))?,
    };
    if loads.is_empty() {
        return Err(invalid("loads", "no load given"));
    }
    let law = match adhesion_work {
        Some(w) => {
            let law = CohesiveLaw::from_options(adhesion_law, w, adhesion_stress, adhesion_range).map_err(named)?;
            judge(py, "adhesion_work", w, plausible::adhesion_work(w, Spelling::Python))?;
            if plastic {
                return Err(invalid("plastic", "is not solved with adhesion (adhesion_work)"));
            }
            if device != "cpu" {
                return Err(invalid("device", "adhesive contact (adhesion_work) runs on the CPU"));
            }
            if let Some(l) = loads.iter().find(|l| !l.is_finite()) {
                return Err(invalid("loads", format!("loads must be finite, got {l} N")));
            }
            Some(law)
        }
        None if adhesion_stress.is_some() || adhesion_range.is_some() || pull_off => {
            return Err(invalid("adhesion_work", "is needed by adhesion_stress, adhesion_range and pull_off"));
        }
        None => {
            core_contact::check_loads(&loads).map_err(named)?;
            None
        }
    };
    judge(py, "youngs", youngs, plausible::modulus(youngs, Spelling::Python))?;
    let mut bodies = vec![Material::new(youngs, poisson, "youngs/poisson").map_err(error)?];
    match (youngs2, poisson2) {
        (Some(e2), Some(nu2)) => {
            judge(py, "youngs2", e2, plausible::modulus(e2, Spelling::Python))?;
            bodies.push(Material::new(e2, nu2, "youngs2/poisson2").map_err(error)?);
        }
        (None, None) => {}
        _ => return Err(invalid("youngs2/poisson2", "give both for an elastic counter-body, or neither")),
    }
    let e_star = match bodies[..] {
        [a, b] => core_contact::combined_modulus(&a, &b),
        [a] => a.plane_strain_modulus(),
        _ => unreachable!("one or two bodies"),
    };
    let boundary = match boundary {
        "periodic" => Boundary::Periodic,
        "free" => Boundary::Free,
        other => return Err(invalid("boundary", format!("'{other}' is not periodic or free"))),
    };
    let device = match device {
        "cpu" => Device::Cpu,
        "gpu" if Device::GPU_BUILT => Device::Gpu,
        "gpu" => return Err(invalid("device", Device::UNAVAILABLE)),
        other => return Err(invalid("device", format!("'{other}' is not cpu or gpu"))),
    };
    let options = SolverOptions { convergence: Convergence { tolerance, max_iterations: max_iter }, device };
    options.convergence.check().map_err(error)?;
    let topography = match topography.cast::<Topography>() {
        Ok(t) => t,
        Err(_) if topography.cast::<Profile>().is_ok() => {
            return Err(invalid(
                "topography",
                "a line profile, not a 2-D map: contact (and slide, a study) needs a 2-D map of heights; \
                 psd(), Profile.statistics() and Profile.detrend() take profiles",
            ))
        }
        Err(_) => {
            let kind = topography.get_type().name()?;
            return Err(PyTypeError::new_err(format!(
                "topography: expected a Topography (a 2-D map of heights), not {kind}"
            )));
        }
    };
    let surface = &topography.get().inner;
    let size = core_contact::contact_size(surface).map_err(error)?;
    if plastic && hardness.is_none() {
        return Err(invalid("plastic", "needs hardness, the cap on the pressure [Pa]"));
    }
    if let Some(h) = hardness {
        if !(h > 0.0 && h.is_finite()) {
            return Err(invalid("hardness", format!("must be positive and finite, got {h} Pa")));
        }
        judge(py, "hardness", h, plausible::hardness(h, Spelling::Python))?;
        let heaviest = loads.iter().copied().fold(0.0, f64::max);
        if plastic && heaviest / (size.0 * size.1) >= h {
            return Err(invalid(
                "hardness",
                format!("{h:e} Pa cannot carry {heaviest:e} N on the {:e} m² window", size.0 * size.1),
            ));
        }
    }
    // Every load checked before any is solved, as the command line does.
    let mut warnings: Vec<Vec<String>> = vec![Vec::new(); loads.len()];
    for (&load, said) in loads.iter().zip(&mut warnings) {
        // With adhesion a load may be zero or tensile: its size is what is judged.
        let load = if law.is_some() { load.abs() } else { load };
        if law.is_some() && load == 0.0 {
            continue;
        }
        core_contact::check_load(load, size, e_star).map_err(named)?;
        said.extend(judge(py, "loads", load, plausible::load(load, size, e_star, Spelling::Python))?);
    }
    // The ways to keep a contact inside the window, in Python's words.
    let remedies: Vec<String> = [
        (boundary == Boundary::Periodic, "a free boundary (boundary=\"free\")"),
        (true, "a crop (Topography.crop)"),
        (true, "a detrend (Topography.detrend)"),
        (true, "a cap (Topography.add_cap)"),
    ]
    .into_iter()
    .filter_map(|(left, remedy)| left.then(|| remedy.to_string()))
    .collect();
    let shape = surface.heights.dim();
    let mut signals = Signals::new(py)?;
    let solved = py.detach(|| -> asperity::Result<(Vec<Solved>, Option<f64>)> {
        let heights = surface.heights.as_standard_layout();
        let field = |v: Vec<f64>| Array2::from_shape_vec(shape, v).expect("a field has the grid's shape");
        if let Some(law) = law {
            let slice = heights.as_slice().expect("standard layout");
            let mut solver = AdhesiveSolver::new(slice, shape, size, e_star, boundary, law, options.convergence)?;
            let mut order: Vec<usize> = (0..loads.len()).collect();
            order.sort_by(|&a, &b| loads[b].total_cmp(&loads[a]));
            let mut solved = Vec::with_capacity(loads.len());
            for index in order {
                if signals.check().is_break() {
                    return Err(asperity::Error::Interrupted { what: "adhesive contact solve".into() });
                }
                let report = solver.solve(loads[index])?;
                let pressure = solver.compressive_pressure();
                let summary = core_contact::summarize(&pressure, shape, size, boundary, hardness);
                let normal = core_contact::SolveReport {
                    load: report.load,
                    mean_pressure: report.load / (size.0 * size.1),
                    iterations: report.iterations,
                    residual: report.residual,
                    operator_applications: f64::NAN,
                    seconds: report.seconds,
                    hardness: None,
                };
                solved.push(Solved {
                    index,
                    report: normal,
                    summary,
                    pressure: field(pressure),
                    gap: field(solver.gap()),
                    displacement: field(solver.displacement()),
                    adhesive: Some((report, field(solver.traction()))),
                });
            }
            solved.sort_by_key(|s| s.index);
            let pull_off = if pull_off { Some(solver.pull_off()?.load) } else { None };
            return Ok((solved, pull_off));
        }
        let mut solver =
            ContactSolver::new(heights.as_slice().expect("standard layout"), shape, size, e_star, boundary, options)?;
        solver.set_hardness(hardness.filter(|_| plastic))?;
        let mut order: Vec<usize> = (0..loads.len()).collect();
        order.sort_by(|&a, &b| loads[a].total_cmp(&loads[b]));
        let mut solved = Vec::with_capacity(loads.len());
        for index in order {
            let report = solver.solve(loads[index], |_, _| signals.check())?;
            let summary = core_contact::summarize(solver.pressure(), shape, size, boundary, hardness);
            solved.push(Solved {
                index,
                report,
                summary,
                pressure: field(solver.pressure().to_vec()),
                gap: field(solver.gap()),
                displacement: field(solver.displacement()),
                adhesive: None,
            });
        }
        solved.sort_by_key(|s| s.index);
        Ok((solved, None))
    });
    let (solved, pull_off) = solved.map_err(|e| signals.error(e))?;
    let mut solutions = Vec::with_capacity(solved.len());
    for (s, mut said) in solved.into_iter().zip(warnings) {
        let missed = s.adhesive.as_ref().and_then(|(r, _)| r.missed(loads[s.index]));
        for w in s.summary.warnings(&remedies).into_iter().chain(missed) {
            let line = format!("at {}: {w}", asperity::quantity::show(s.report.load, &asperity::quantity::FORCE));
            warn(py, &line, 1)?;
            said.push(line);
        }
        solutions.push(ContactSolution {
            load: s.report.load,
            mean_pressure: s.report.mean_pressure,
            pressure: s.pressure.into_pyarray(py).unbind(),
            gap: s.gap.into_pyarray(py).unbind(),
            displacement: s.displacement.into_pyarray(py).unbind(),
            contact_fraction: s.summary.contact_fraction,
            contact_area: s.summary.contact_area,
            contact_points: s.summary.contact_points,
            patches: s.summary.patch_sizes.len(),
            patch_sizes: s.summary.patch_sizes,
            max_pressure: s.summary.max_pressure,
            edge_load_fraction: s.summary.edge_load_fraction,
            load_above_hardness_fraction: s.summary.load_above_hardness_fraction,
            hardness,
            plastic,
            effective_modulus: e_star,
            iterations: s.report.iterations,
            operator_applications: Some(s.report.operator_applications).filter(|_| s.adhesive.is_none()),
            residual: s.report.residual,
            seconds: s.report.seconds,
            physical_size: size,
            boundary: boundary.name(),
            warnings: said,
            compressive_force: s.adhesive.as_ref().map(|(r, _)| r.compressive_force),
            adhesive_force: s.adhesive.as_ref().map(|(r, _)| r.adhesive_force),
            separation: s.adhesive.as_ref().map(|(r, _)| r.separation),
            traction: s.adhesive.map(|(_, t)| t.into_pyarray(py).unbind()),
            pull_off,
            bodies: bodies.clone(),
        });
    }
    Ok(solutions)
}

/// Count and shares of one class of elements at the critical state.
#[pyclass(frozen, get_all, module = "asperity")]
#[derive(Clone)]
struct ClassShare {
    /// Number of elements in the class.
    count: usize,
    /// Fraction of the normal load N they carry.
    normal_fraction: f64,
    /// Fraction of the static friction force F_S they carry.
    friction_fraction: f64,
}

impl From<CoreShare> for ClassShare {
    fn from(s: CoreShare) -> Self {
        ClassShare { count: s.count, normal_fraction: s.normal_fraction, friction_fraction: s.friction_fraction }
    }
}

#[pymethods]
impl ClassShare {
    fn __repr__(&self) -> String {
        format!(
            "<ClassShare count={}, normal_fraction={}, friction_fraction={}>",
            self.count, self.normal_fraction, self.friction_fraction
        )
    }
}

/// The onset of sliding of a pressure map under the stick-slip transition model (equal load
/// sharing), as ``asperity onset``.
#[pyclass(frozen, module = "asperity")]
struct Onset {
    inner: CoreOnset,
    loads: ElementLoads,
    /// The pressure map [Pa] it was computed from.
    pressure: Py<PyArray2<f64>>,
    /// Pixel area [m²], and whether it is known (else 1, and forces are not in newtons).
    pixel_area: f64,
    area_known: bool,
}

impl Onset {
    fn newtons(&self, x: f64) -> Option<f64> {
        self.area_known.then_some(x)
    }
}

#[pymethods]
impl Onset {
    /// Static friction coefficient F_S / N.
    #[getter]
    fn static_coefficient(&self) -> f64 {
        self.inner.static_coefficient()
    }

    /// Dynamic friction coefficient (mu_d).
    #[getter]
    fn dynamic_coefficient(&self) -> f64 {
        self.inner.dynamic_coefficient()
    }

    /// Friction drop F_S / (mu_d N).
    #[getter]
    fn friction_drop(&self) -> f64 {
        self.inner.friction_drop()
    }

    /// Local static friction coefficient of the law.
    #[getter]
    fn mu_s(&self) -> f64 {
        self.inner.law.mu_s
    }

    /// Local dynamic friction coefficient of the law.
    #[getter]
    fn mu_d(&self) -> f64 {
        self.inner.law.mu_d
    }

    /// Name of the law, if it has one.
    #[getter]
    fn law(&self) -> Option<String> {
        self.inner.law.name.clone()
    }

    /// Number of contact elements M (pixels with p > 0).
    #[getter]
    fn elements(&self) -> usize {
        self.inner.elements
    }

    /// k*: how many elements slipped before the peak.
    #[getter]
    fn critical_index(&self) -> usize {
        self.inner.critical_index
    }

    /// Pressure of the critical elements [Pa].
    #[getter]
    fn critical_pressure(&self) -> f64 {
        self.inner.critical_normal_force / self.pixel_area
    }

    /// Normal load N = Σ p_i a [N], or None without a physical size or pixel area.
    #[getter]
    fn normal_force(&self) -> Option<f64> {
        self.newtons(self.inner.normal_force)
    }

    /// Static friction force F_S [N], or None without a physical size or pixel area.
    #[getter]
    fn static_force(&self) -> Option<f64> {
        self.newtons(self.inner.static_force)
    }

    /// Elements stuck at mu_s at the critical state.
    #[getter]
    fn critical(&self) -> ClassShare {
        self.inner.critical.into()
    }

    /// Elements that slipped before the peak (at mu_d).
    #[getter]
    fn pre_sliding(&self) -> ClassShare {
        self.inner.pre_sliding.into()
    }

    /// Elements stuck below mu_s at the critical state.
    #[getter]
    fn subcritical(&self) -> ClassShare {
        self.inner.subcritical.into()
    }

    /// The class of every pixel at the critical state, int8 of shape (ny, nx): 0 no contact,
    /// 1 pre-sliding, 2 critical, 3 subcritical (as classes.npy).
    #[getter]
    fn classes<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<i8>> {
        let pressure = self.pressure.bind(py).readonly();
        let view = pressure.as_array();
        py.detach(|| self.inner.class_map(&view, self.pixel_area)).into_pyarray(py)
    }

    /// The local stress ratio τ/σ of every pixel at δ = ``fraction`` · δ_peak, float64 of
    /// shape (ny, nx), NaN out of contact (as stress_ratio.npy).
    #[pyo3(signature = (fraction = 1.0))]
    fn stress_ratio<'py>(&self, py: Python<'py>, fraction: f64) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let pressure = self.pressure.bind(py).readonly();
        let view = pressure.as_array();
        let map = py.detach(|| self.inner.stress_ratio_map(&view, self.pixel_area, fraction)).map_err(error)?;
        Ok(map.into_pyarray(py))
    }

    /// The friction–displacement curve, as curve.csv names its columns: a dict of arrays
    /// ``element_shear_n`` (s = k_t·δ, the shear on every stuck element [N]), ``force_n`` (F
    /// [N]), ``coefficient`` (F / N), ``stuck``
    /// (elements stuck), and ``peak`` (the index of F_S). ``loading``: "equal_load_sharing"
    /// (the model) or "rigid_displacement" (no redistribution). At most ``max_points``
    /// vertices, the peak kept exactly. Without a physical size, forces are in units of
    /// pascal × m² (the coefficients are right).
    #[pyo3(signature = (loading = "equal_load_sharing", max_points = 2000))]
    fn curve<'py>(&self, py: Python<'py>, loading: &str, max_points: usize) -> PyResult<Bound<'py, PyDict>> {
        let loading = Loading::ALL.into_iter().find(|l| l.name() == loading).ok_or_else(|| {
            invalid("loading", format!("'{loading}' is not equal_load_sharing or rigid_displacement"))
        })?;
        let curve = py.detach(|| Curve::new(&self.loads, &self.inner.law, loading, max_points));
        let n = curve.normal_force;
        let column =
            |f: fn(&asperity::friction::CurvePoint) -> f64| -> Vec<f64> { curve.points.iter().map(f).collect() };
        let dict = PyDict::new(py);
        dict.set_item("element_shear_n", column(|p| p.element_shear).into_pyarray(py))?;
        dict.set_item("force_n", column(|p| p.force).into_pyarray(py))?;
        dict.set_item(
            "coefficient",
            column(|p| p.force).into_iter().map(|f| f / n).collect::<Vec<_>>().into_pyarray(py),
        )?;
        dict.set_item("stuck", curve.points.iter().map(|p| p.stuck as u64).collect::<Vec<_>>().into_pyarray(py))?;
        dict.set_item("peak", curve.peak)?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        format!(
            "<Onset {} elements: static coefficient {}, friction drop {}>",
            self.inner.elements,
            self.inner.static_coefficient(),
            self.inner.friction_drop()
        )
    }
}

/// The local law from mu_s/mu_d, a measured curve (with its averaging window) or a preset
/// name, as ``asperity onset`` takes it: each coefficient judged
/// ([`plausible::friction_coefficient`]).
fn friction_law(
    py: Python<'_>,
    mu_s: Option<f64>,
    mu_d: Option<f64>,
    law: Option<&str>,
    curve: Option<&PathBuf>,
    curve_window: Option<&Bound<'_, PyAny>>,
) -> PyResult<FrictionLaw> {
    let curve_window = curve_window.map(|w| range(w, "window")).transpose()?;
    if curve_window.is_some() && curve.is_none() {
        return Err(invalid("window", "applies to a curve only"));
    }
    let pair = match (mu_s, mu_d, curve, law) {
        (Some(_), _, Some(_), _) | (_, Some(_), Some(_), _) => {
            return Err(invalid("curve", "give mu_s and mu_d, or a curve, not both"))
        }
        (Some(mu_s), Some(mu_d), None, _) => {
            judge(py, "mu_s", mu_s, plausible::friction_coefficient(mu_s))?;
            judge(py, "mu_d", mu_d, plausible::friction_coefficient(mu_d))?;
            FrictionLaw::new(mu_s, mu_d).map_err(error)?
        }
        (Some(_), None, ..) => return Err(invalid("mu_s", "needs mu_d too")),
        (None, Some(_), ..) => return Err(invalid("mu_d", "needs mu_s too")),
        (None, None, Some(path), _) => py.detach(|| FrictionLaw::from_curve_file(path, curve_window)).map_err(error)?,
        (None, None, None, Some(name)) => return FrictionLaw::preset(name).map_err(error),
        (None, None, None, None) => {
            return Err(invalid("mu_s", "give the local friction law: mu_s and mu_d, a curve, or a preset law name"))
        }
    };
    Ok(match law {
        Some(name) => pair.named(name),
        None => pair,
    })
}

/// The stick-slip transition model on a pressure map [Pa] (float64 array (ny, nx), or a
/// ContactSolution, whose physical size it then takes): static and dynamic friction
/// coefficients, friction drop and the element classes at the critical state.
///
/// The local law is ``mu_s`` and ``mu_d`` (with ``law`` as its name), a measured nanoscale
/// friction curve ``curve`` (a CSV file of displacement, friction coefficient, as ``asperity
/// onset --curve`` reads it: mu_s its peak, mu_d its mean after the peak, or over ``window``
/// (start, end) past the peak, in the curve's displacement unit), or a preset ``law`` ("hold
/// 100 s", "hold 10 s": illustrative placeholders). ``physical_size`` (lx, ly) [m] or
/// ``pixel_area`` [m²] give forces in newtons; the coefficients do not need them.
#[pyfunction]
#[pyo3(signature = (pressure, physical_size = None, *, mu_s = None, mu_d = None, law = None, curve = None,
                    window = None, pixel_area = None))]
#[allow(clippy::too_many_arguments)]
fn onset(
    py: Python<'_>,
    pressure: &Bound<'_, PyAny>,
    physical_size: Option<&Bound<'_, PyAny>>,
    mu_s: Option<f64>,
    mu_d: Option<f64>,
    law: Option<&str>,
    curve: Option<PathBuf>,
    window: Option<&Bound<'_, PyAny>>,
    pixel_area: Option<f64>,
) -> PyResult<Onset> {
    let law = friction_law(py, mu_s, mu_d, law, curve.as_ref(), window)?;
    let (map, solution_size) = match pressure.cast::<ContactSolution>() {
        Ok(s) => (s.get().pressure.bind(py).readonly(), Some(s.get().physical_size)),
        Err(_) => (float_map(pressure, "pressure")?, None),
    };
    let (ny, nx) = map.as_array().dim();
    let size = physical_size.map(|s| crate::window(s, "physical_size")).transpose()?.or(solution_size);
    let area = match (size, pixel_area) {
        (Some(_), Some(_)) => return Err(invalid("pixel_area", "give physical_size or pixel_area, not both")),
        (Some((lx, ly)), None) => Some(lx / nx as f64 * (ly / ny as f64)),
        (None, Some(a)) if a.is_finite() && a > 0.0 => Some(a),
        (None, Some(a)) => return Err(invalid("pixel_area", format!("must be positive and finite, got {a} m²"))),
        (None, None) => None,
    };
    let pixel_area = area.unwrap_or(1.0);
    let view: ArrayView2<f64> = map.as_array();
    let (loads, inner) = py
        .detach(|| {
            let loads = ElementLoads::from_pressure(&view, pixel_area)?;
            let onset = CoreOnset::new(&loads, &law);
            Ok((loads, onset))
        })
        .map_err(error)?;
    let array: Bound<'_, PyArray2<f64>> = (*map).clone();
    Ok(Onset { inner, loads, pressure: array.unbind(), pixel_area, area_known: area.is_some() })
}

/// The shear maps of a sliding state: shear_x, shear_y [Pa] and the classes (int8: 0 no
/// contact, 1 slipped, 2 critical, 3 stuck), as slide's shear_x.npy, shear_y.npy, classes.npy.
fn shear_maps(solver: &TangentialSolver, state: &Snapshot) -> (Array2<f64>, Array2<f64>, Array2<i8>) {
    let (ny, nx) = solver.shape();
    let (mut sx, mut sy) = (Array2::<f64>::zeros((ny, nx)), Array2::<f64>::zeros((ny, nx)));
    let mut classes = Array2::<i8>::zeros((ny, nx));
    for ((&i, q), c) in solver.points().iter().zip(&state.traction).zip(&state.classes) {
        let at = (i / nx, i % nx);
        sx[at] = q[0];
        sy[at] = q[1];
        classes[at] = *c as i8;
    }
    (sx, sy, classes)
}

/// The onset of sliding with elastic sharing (``slide``), as ``asperity slide``'s slide.json,
/// curve.csv and maps at the peak force.
#[pyclass(frozen, module = "asperity")]
struct Slide {
    /// Normal load N [N].
    #[pyo3(get)]
    load: f64,
    /// Contact points (pixels with p > 0).
    #[pyo3(get)]
    contact_points: usize,
    /// Local static friction coefficient mu_s.
    #[pyo3(get)]
    mu_s: f64,
    /// Local dynamic friction coefficient mu_d: the dynamic coefficient of the interface.
    #[pyo3(get)]
    mu_d: f64,
    /// Name of the law, if it has one.
    #[pyo3(get)]
    law: Option<String>,
    /// Slip-weakening distance d_c [m]: 0 for the instant drop, None for a measured curve.
    #[pyo3(get)]
    slip_distance: Option<f64>,
    /// F_S: the largest tangential force [N].
    #[pyo3(get)]
    static_force: f64,
    /// F_S / N.
    #[pyo3(get)]
    static_coefficient: f64,
    /// F_S / (mu_d N).
    #[pyo3(get)]
    friction_drop: f64,
    /// The rigid displacement δ at F_S [m], or None when F_S is the steady sliding force (δ → ∞).
    #[pyo3(get)]
    peak_displacement: Option<f64>,
    /// At the peak: points stuck below their bound, …
    #[pyo3(get)]
    stuck: ClassShare,
    /// … points on their bound that never slipped, …
    #[pyo3(get)]
    critical: ClassShare,
    /// … and points that slipped before it.
    #[pyo3(get)]
    slipped: ClassShare,
    /// The static coefficient of equal load sharing (``onset``) on the same pressure.
    #[pyo3(get)]
    equal_sharing_static_coefficient: f64,
    /// The friction drop of equal load sharing on the same pressure.
    #[pyo3(get)]
    equal_sharing_friction_drop: f64,
    /// The static coefficient of equal load sharing with the same slip weakening (each element
    /// a spring–slider of the contact's stuck stiffness K_t / n), as ``asperity slide``'s
    /// ``equal_sharing_same_law``; None for a measured curve.
    #[pyo3(get)]
    equal_sharing_same_law_static_coefficient: Option<f64>,
    /// Its friction drop; None for a measured curve.
    #[pyo3(get)]
    equal_sharing_same_law_friction_drop: Option<f64>,
    /// Shear traction along x [Pa] at the peak, float64 (ny, nx).
    #[pyo3(get)]
    shear_x: Py<PyArray2<f64>>,
    /// Shear traction along y [Pa] at the peak, float64 (ny, nx).
    #[pyo3(get)]
    shear_y: Py<PyArray2<f64>>,
    /// Class of each pixel at the peak, int8 (ny, nx): 0 no contact, 1 slipped, 2 critical,
    /// 3 stuck.
    #[pyo3(get)]
    classes: Py<PyArray2<i8>>,
    /// Displacement steps along the path to sliding.
    #[pyo3(get)]
    steps: usize,
    /// Tangential solves along the path (a step solves once more per cascade round).
    #[pyo3(get)]
    solves: usize,
    /// Conjugate-gradient iterations of the tangential solves, summed.
    #[pyo3(get)]
    iterations: usize,
    /// Wall-clock time [s].
    #[pyo3(get)]
    seconds: f64,
    points: Vec<SlidePoint>,
}

#[pymethods]
impl Slide {
    /// The friction–displacement path, as curve.csv: a dict of arrays ``displacement_m`` (δ
    /// [m], increasing; a cascade of slips at one δ adds entries at that δ as the force falls),
    /// ``force_n`` (F [N]), ``coefficient`` (F / N), ``stick_points`` and ``slip_points``.
    fn curve<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let column = |f: fn(&SlidePoint) -> f64| -> Vec<f64> { self.points.iter().map(f).collect() };
        let dict = PyDict::new(py);
        dict.set_item("displacement_m", column(|p| p.displacement_m).into_pyarray(py))?;
        dict.set_item("force_n", column(|p| p.force_n).into_pyarray(py))?;
        let n = self.load;
        dict.set_item(
            "coefficient",
            column(|p| p.force_n).into_iter().map(|f| f / n).collect::<Vec<_>>().into_pyarray(py),
        )?;
        dict.set_item(
            "stick_points",
            self.points.iter().map(|p| p.stick_points as u64).collect::<Vec<_>>().into_pyarray(py),
        )?;
        dict.set_item(
            "slip_points",
            self.points.iter().map(|p| p.slip_points as u64).collect::<Vec<_>>().into_pyarray(py),
        )?;
        Ok(dict)
    }

    fn __repr__(&self) -> String {
        format!(
            "<Slide {} contact points: static coefficient {}, friction drop {} (equal sharing {})>",
            self.contact_points, self.static_coefficient, self.friction_drop, self.equal_sharing_friction_drop
        )
    }
}

/// A partial-slip state at an imposed tangential force (``slide(tangential_force=Q)``).
#[pyclass(frozen, get_all, module = "asperity")]
struct PartialSlip {
    /// Normal load N [N].
    load: f64,
    /// The Coulomb coefficient μ = mu_s of the ramp.
    mu: f64,
    /// The tangential force reached [N].
    tangential_force: f64,
    /// The rigid displacement δ that carries it [m].
    displacement: f64,
    /// Contact points stuck (below their bound μ p).
    stick_points: usize,
    /// Contact points slipping (on their bound μ p).
    slip_points: usize,
    /// Shear traction along x [Pa], float64 (ny, nx).
    shear_x: Py<PyArray2<f64>>,
    /// Shear traction along y [Pa], float64 (ny, nx).
    shear_y: Py<PyArray2<f64>>,
    /// Class of each pixel, int8 (ny, nx): 0 no contact, 1 slipping, 3 stuck.
    classes: Py<PyArray2<i8>>,
    /// Tangential solves of the force ramp.
    solves: usize,
    /// Conjugate-gradient iterations of those solves, summed.
    iterations: usize,
    /// Wall-clock time [s].
    seconds: f64,
}

#[pymethods]
impl PartialSlip {
    fn __repr__(&self) -> String {
        format!(
            "<PartialSlip Q {:e} N at δ {:e} m: {} stuck, {} slipping>",
            self.tangential_force, self.displacement, self.stick_points, self.slip_points
        )
    }
}

/// The onset of sliding with elastic sharing between the contact points, as ``asperity
/// slide``: the body is displaced rigidly along x and the shear tractions of the contact
/// points of ``solution`` (a ContactSolution, elastic or plastic) follow from the elastic
/// half-space of its bodies and boundary, with a local law that has memory: mu_s until a point
/// first slips, then falling linearly to mu_d over an accumulated slip ``slip_distance`` [m]
/// (default 2e-9, the study's; 0: at once, the instant drop).
/// The normal pressure stays fixed (normal and tangential problems uncoupled).
///
/// The law: ``mu_s`` and ``mu_d`` (dimensionless, with ``law`` as its name), a preset ``law``,
/// or a measured friction curve ``curve`` (CSV of displacement, friction coefficient, as
/// ``onset``'s) whose displacement unit ``curve_unit`` [m] (1e-9 for nm) it needs: mu_s is
/// its peak and past the peak μ follows the curve as a function of each point's accumulated
/// slip (its own slip weakening; mu_d, for the equal-sharing values, its mean after the peak
/// or over ``window``). ``tangential_force`` [N] (default None): instead of the path to sliding, the
/// partial-slip state at that force under Coulomb friction at mu_s (a ``PartialSlip``).
/// ``tolerance`` (default 1e-6): of the tangential solve, below 1e-2; ``max_iter`` (default
/// 20000): iterations of one tangential solve. Returns a ``Slide`` (static coefficient,
/// friction drop, the equal-sharing values on the same pressure, the curve, the shear maps).
/// The GIL is released while it runs; Ctrl-C stops the path to sliding at its next step (the
/// partial-slip ramp once it has finished).
#[pyfunction]
#[pyo3(signature = (solution, *, mu_s = None, mu_d = None, law = None, curve = None, curve_unit = None,
                    window = None, slip_distance = None, tangential_force = None,
                    tolerance = TangentialOptions::default().tolerance,
                    max_iter = TangentialOptions::default().max_iterations),
       text_signature = "(solution, *, mu_s=None, mu_d=None, law=None, curve=None, curve_unit=None, window=None, \
                         slip_distance=None, tangential_force=None, tolerance=1e-6, max_iter=20000)")]
#[allow(clippy::too_many_arguments)]
fn slide(
    py: Python<'_>,
    solution: &ContactSolution,
    mu_s: Option<f64>,
    mu_d: Option<f64>,
    law: Option<&str>,
    curve: Option<PathBuf>,
    curve_unit: Option<f64>,
    window: Option<&Bound<'_, PyAny>>,
    slip_distance: Option<f64>,
    tangential_force: Option<f64>,
    tolerance: f64,
    max_iter: usize,
) -> PyResult<Py<PyAny>> {
    let base = friction_law(py, mu_s, mu_d, law, curve.as_ref(), window)?;
    let curve_weakening = match (&curve, curve_unit) {
        (None, None) => None,
        (None, Some(_)) => return Err(invalid("curve_unit", "applies to a curve only")),
        (Some(_), None) => {
            return Err(invalid("curve_unit", "a curve needs its displacement unit [m] (1e-9 for nm) to be followed"))
        }
        (Some(_), Some(unit)) if !(unit > 0.0 && unit.is_finite()) => {
            return Err(invalid("curve_unit", format!("must be a positive length, got {unit} m")))
        }
        (Some(_), Some(_)) if slip_distance.is_some() || tangential_force.is_some() => {
            let with = if slip_distance.is_some() { "slip_distance" } else { "tangential_force" };
            return Err(invalid(with, "not used with a curve, whose own slip weakening it follows"));
        }
        (Some(path), Some(unit)) => Some(Weakening::Curve(py.detach(|| slip_curve_file(path, unit)).map_err(error)?)),
    };
    let weakening = match (curve_weakening, slip_distance) {
        (Some(curve), _) => curve,
        (None, Some(_)) if tangential_force.is_some() => {
            return Err(invalid("slip_distance", "not used with tangential_force (a Coulomb ramp at mu_s)"))
        }
        (None, Some(0.0)) => Weakening::Instant,
        (None, Some(dc)) if !(dc > 0.0 && dc.is_finite()) => {
            return Err(invalid(
                "slip_distance",
                format!("must be positive and finite, or 0 for the instant drop, got {dc:e} m"),
            ))
        }
        (None, Some(dc)) => {
            judge(py, "slip_distance", dc, plausible::slip_distance(dc, Spelling::Python))?;
            Weakening::Linear(dc)
        }
        // A Coulomb ramp at mu_s has no weakening.
        (None, None) if tangential_force.is_some() => Weakening::Instant,
        (None, None) => Weakening::Linear(DEFAULT_SLIP_DISTANCE_M),
    };
    let options = TangentialOptions { tolerance, max_iterations: max_iter };
    options.check().map_err(error)?;
    let load = solution.load;
    if let Some(q) = tangential_force {
        if !(q > 0.0 && q.is_finite() && q < base.mu_s * load) {
            return Err(invalid(
                "tangential_force",
                format!("must lie in (0, μN) = (0, {:.6e}) N for a partial-slip state, got {q:e} N", base.mu_s * load),
            ));
        }
    }
    let pressure: Vec<f64> = solution.pressure.bind(py).readonly().as_array().iter().copied().collect();
    let shape = solution.pressure.bind(py).readonly().as_array().dim();
    let boundary = if solution.boundary == Boundary::Free.name() { Boundary::Free } else { Boundary::Periodic };
    if boundary == Boundary::Periodic && pressure.iter().all(|p| *p > 0.0) {
        return Err(invalid(
            "solution",
            format!(
                "at {load:e} N every point of the periodic window touches (full contact): the periodic half-space \
                 has no stiffness for a uniform shift, so there is no sliding onset to find; lower the load or \
                 solve with boundary=\"free\""
            ),
        ));
    }
    let compliance = ShearCompliance::of(&solution.bodies);
    let law = SlipLaw { mu_s: base.mu_s, mu_d: base.mu_d, weakening };
    let size = solution.physical_size;
    let names = [("--mu-s", "mu_s"), ("--mu-d", "mu_d"), ("--tangential-force", "tangential_force")];
    let start = Instant::now();
    if let Some(q) = tangential_force {
        let (solver, (state, work)) = py
            .detach(|| {
                let mut solver = TangentialSolver::new(&pressure, shape, size, compliance, boundary, options)?;
                let ramp = ramp_force(&mut solver, law.mu_s, q)?;
                Ok((solver, ramp))
            })
            .map_err(|e| error_naming(e, &names))?;
        let (sx, sy, classes) = shear_maps(&solver, &state);
        let partial = PartialSlip {
            load,
            mu: law.mu_s,
            tangential_force: state.point.force_n,
            displacement: state.point.displacement_m,
            stick_points: state.point.stick_points,
            slip_points: state.point.slip_points,
            shear_x: sx.into_pyarray(py).unbind(),
            shear_y: sy.into_pyarray(py).unbind(),
            classes: classes.into_pyarray(py).unbind(),
            solves: work.solves,
            iterations: work.iterations,
            seconds: start.elapsed().as_secs_f64(),
        };
        return Ok(Py::new(py, partial)?.into_any());
    }
    let mut signals = Signals::new(py)?;
    let (solver, onset, equal) = py
        .detach(|| {
            let mut solver = TangentialSolver::new(&pressure, shape, size, compliance, boundary, options)?;
            let onset = elastic_onset(&mut solver, &law, PEAK_TOLERANCE, |_| signals.check())?;
            let map = Array2::from_shape_vec(shape, pressure.clone()).expect("the pressure's shape");
            let loads = ElementLoads::from_pressure(&map, solver.pixel_area())?;
            let equal = CoreOnset::new(&loads, &FrictionLaw::new(law.mu_s, law.mu_d)?);
            let same_law = match law.weakening {
                Weakening::Curve(_) => None,
                _ => Some(spring_slider_onset(&loads, &law, element_stiffness(onset.stuck_stiffness, loads.len()))?),
            };
            Ok((solver, onset, (equal, same_law)))
        })
        .map_err(|e| match e {
            asperity::Error::Interrupted { .. } => signals.error(e),
            e => error_naming(e, &names),
        })?;
    let (equal, same_law) = equal;
    let slip_distance = law.slip_distance();
    let (sx, sy, classes) = shear_maps(&solver, &onset.peak);
    let result = Slide {
        load,
        contact_points: solver.points().len(),
        mu_s: law.mu_s,
        mu_d: law.mu_d,
        law: base.name.clone(),
        slip_distance,
        static_force: onset.static_force,
        static_coefficient: onset.static_coefficient(),
        friction_drop: onset.friction_drop(),
        peak_displacement: Some(onset.peak.point.displacement_m).filter(|d| d.is_finite()),
        stuck: onset.stuck.into(),
        critical: onset.critical.into(),
        slipped: onset.slipped.into(),
        equal_sharing_static_coefficient: equal.static_coefficient(),
        equal_sharing_friction_drop: equal.friction_drop(),
        equal_sharing_same_law_static_coefficient: same_law.map(|e| e.static_coefficient()),
        equal_sharing_same_law_friction_drop: same_law.map(|e| e.friction_drop()),
        shear_x: sx.into_pyarray(py).unbind(),
        shear_y: sy.into_pyarray(py).unbind(),
        classes: classes.into_pyarray(py).unbind(),
        steps: onset.work.steps,
        solves: onset.work.solves,
        iterations: onset.work.iterations,
        seconds: start.elapsed().as_secs_f64(),
        points: onset.curve,
    };
    Ok(Py::new(py, result)?.into_any())
}

/// The slide-hold-slide analysis as JSON ({"cycles", "groups", "skipped"}); see
/// ``asperity.analyse_shs``.
#[pyfunction]
#[pyo3(signature = (time_s, friction_n, normal_n, displacement_m, speed, window, window_start, peak_within,
                    min_duration, hold_fraction, slide_fraction, group_tolerance))]
#[allow(clippy::too_many_arguments)]
fn _analyse_shs(
    py: Python<'_>,
    time_s: Vec<f64>,
    friction_n: Vec<f64>,
    normal_n: Vec<f64>,
    displacement_m: Option<Vec<f64>>,
    speed: f64,
    window: f64,
    window_start: f64,
    peak_within: f64,
    min_duration: f64,
    hold_fraction: f64,
    slide_fraction: f64,
    group_tolerance: f64,
) -> PyResult<String> {
    let options = ShsOptions {
        speed,
        window,
        window_start,
        peak_within,
        min_duration,
        hold_fraction,
        slide_fraction,
        group_tolerance,
    };
    options.validate().map_err(error)?;
    let analysis = py
        .detach(|| {
            let trace = Trace::new("trace", time_s, friction_n, normal_n, displacement_m)?;
            shs::analyse(&trace, &options)
        })
        .map_err(error)?;
    serde_json::to_string(&analysis).map_err(|e| invalid("trace", e.to_string()))
}

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
fn _run_study(
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
    m.add_class::<Topography>()?;
    m.add_class::<Profile>()?;
    m.add_class::<ContactSolution>()?;
    m.add_class::<Onset>()?;
    m.add_class::<ClassShare>()?;
    m.add_class::<Slide>()?;
    m.add_class::<PartialSlip>()?;
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(compound, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(psd, m)?)?;
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    m.add_function(wrap_pyfunction!(onset, m)?)?;
    m.add_function(wrap_pyfunction!(slide, m)?)?;
    m.add_function(wrap_pyfunction!(_analyse_shs, m)?)?;
    m.add_function(wrap_pyfunction!(_run_study, m)?)?;
    Ok(())
}
