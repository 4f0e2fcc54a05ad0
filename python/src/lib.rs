//! The Python module `asperity._asperity`: a thin PyO3 layer over the library's public API.
//!
//! It converts arguments and results (numpy float64 arrays of shape (ny, nx), SI units) and
//! adds no physics. Long work runs with the GIL released and stops on Ctrl-C: the solver's
//! per-iteration callback checks for signals. Every library error becomes `asperity.Error`
//! (a `ValueError`) with the command line's one-line message.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use asperity::contact::{self as core_contact, Boundary, ContactSolver, Material, SolverOptions};
use asperity::friction::{ClassShare as CoreShare, Curve, ElementLoads, FrictionLaw, Loading, Onset as CoreOnset};
use asperity::limits::Limits;
use asperity::shs::{self, ShsOptions, Trace};
use asperity::study::config::StudyConfig;
use asperity::study::run::{Progress, Study};
use asperity::topography::detrend::Detrend;
use asperity::topography::missing::fill_missing;
use asperity::topography::resample::{self, CropWindow};
use asperity::topography::stats::{self, Window};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};
use asperity::topography::{io, Provenance, Topography as CoreTopography};
use ndarray::{Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

pyo3::create_exception!(
    asperity,
    Error,
    PyValueError,
    "Bad input or a computation that failed: the one-line message of the asperity command line."
);

/// A library error as `asperity.Error`: its one line as the command line prints it, control
/// characters escaped.
fn error(e: asperity::Error) -> PyErr {
    Error::new_err(asperity::error::one_line(&e.to_string()))
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
    error(asperity::Error::invalid(name, reason))
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
/// ``Topography(heights, physical_size=(lx, ly), periodic=False)`` takes any 2-D array of
/// heights in metres (copied; NaN marks a missing point). Methods return new topographies.
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
    #[pyo3(signature = (heights, physical_size, periodic = false))]
    fn new(heights: &Bound<'_, PyAny>, physical_size: &Bound<'_, PyAny>, periodic: bool) -> PyResult<Self> {
        let size = lengths(physical_size, "physical_size")?;
        let heights = float_map(heights, "heights")?.as_array().to_owned();
        if heights.nrows() == 0 || heights.ncols() == 0 {
            return Err(invalid("heights", format!("an empty {:?} array", heights.dim())));
        }
        Ok(Topography::wrap(CoreTopography {
            heights,
            physical_size: Some(size),
            periodic,
            height_unit_known: true,
            channel: "heights".into(),
            provenance: Provenance { file: None, format: "array".into(), height_unit: Some("m".into()) },
        }))
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

    /// Height unit as the file states it ("nm", "µm", …; heights are in metres all the same),
    /// or None when it states none.
    #[getter]
    fn unit(&self) -> Option<String> {
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

    /// Levelled: "none", "mean", "plane", "poly:N" (least squares, N ≤ 8) or "sphere".
    #[pyo3(signature = (kind = "plane"))]
    fn detrend(&self, py: Python<'_>, kind: &str) -> PyResult<Topography> {
        let detrend: Detrend = kind.parse().map_err(|e: String| invalid("--detrend", e))?;
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
                return Err(invalid("--crop", "give lengths (x, y) or pixels (columns, rows), not both"));
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
        let topo = py.detach(|| resample::resample(&self.inner, pixel_size, &limits)).map_err(error)?;
        Ok(Topography { inner: topo, channels: self.channels.clone() })
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
/// extension; ``format`` overrides). ``channel``: name or 0-based index (default: the first
/// height channel). ``size``: the physical size [m], needed for a bare array (.npy), checked
/// against a size the file states. ``height_unit``: unit of a file that states none.
/// ``max_points``: the largest grid read (default 2^28), the file read only up to 128 bytes a
/// point.
#[pyfunction]
#[pyo3(signature = (path, channel = None, *, size = None, height_unit = None, format = None, max_points = None))]
fn read_topography(
    py: Python<'_>,
    path: PathBuf,
    channel: Option<&Bound<'_, PyAny>>,
    size: Option<&Bound<'_, PyAny>>,
    height_unit: Option<String>,
    format: Option<String>,
    max_points: Option<&Bound<'_, PyAny>>,
) -> PyResult<Topography> {
    let options = io::ReadOptions {
        format,
        channel: channel.map(|c| c.str().map(|s| s.to_string())).transpose()?,
        physical_size: size.map(|s| lengths(s, "--size")).transpose()?,
        height_unit,
        limits: limits(max_points)?,
    };
    let (inner, channels) = py.detach(|| io::read_listing(&path, &options)).map_err(error)?;
    Ok(Topography { inner, channels })
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
    let seed = whole(seed, "--seed")?;
    let size = lengths(size, "--size")?;
    let grid = match grid.extract::<usize>() {
        Ok(n) => (n, n),
        Err(_) => grid.extract::<(usize, usize)>().map_err(|_| invalid("--grid", "expected n or (nx, ny) points"))?,
    };
    let roughness = match (hurst, rms, rms_slope) {
        (None, None, None) => None,
        (None, ..) => return Err(invalid("--hurst", "roughness (rms or rms_slope) needs the Hurst exponent")),
        (Some(_), Some(_), Some(_)) => return Err(invalid("--rms", "give rms or rms_slope, not both")),
        (Some(_), None, None) => return Err(invalid("--rms", "give the roughness's rms or rms_slope")),
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

/// The isotropic power spectral density of a topography (mean removed): ``(q, c)``, the
/// wavevector |q| [rad/m] and C(q) [m⁴], as ``asperity topo psd``. ``window``: "auto" (Hann
/// for non-periodic maps, none for periodic ones), "hann" or "none".
#[pyfunction]
#[pyo3(signature = (topography, window = "auto"))]
fn psd<'py>(py: Python<'py>, topography: &Topography, window: &str) -> PyResult<(Spectrum<'py>, Spectrum<'py>)> {
    let window = match window {
        "auto" => Window::default_for(&topography.inner),
        "hann" => Window::Hann,
        "none" => Window::None,
        other => return Err(invalid("--window", format!("'{other}' is not auto, hann or none"))),
    };
    let spectrum = py.detach(|| stats::psd(&topography.inner, window)).map_err(error)?;
    Ok((spectrum.q.into_pyarray(py), spectrum.c.into_pyarray(py)))
}

/// One load of a contact solve: the pressure and gap maps and what summarises them.
#[pyclass(frozen, get_all, module = "asperity")]
struct ContactSolution {
    /// Normal load N [N].
    load: f64,
    /// Mean pressure N / (lx·ly) [Pa].
    mean_pressure: f64,
    /// Pressure [Pa], float64 of shape (ny, nx).
    pressure: Py<PyArray2<f64>>,
    /// Gap [m], float64 of shape (ny, nx): zero on the contact, positive elsewhere.
    gap: Py<PyArray2<f64>>,
    /// Fraction of the window in contact.
    contact_fraction: f64,
    /// Real contact area [m²].
    contact_area: f64,
    /// Pixels with p > 0.
    contact_points: usize,
    /// Number of contact patches (4-connected clusters, wrapping when periodic).
    patches: usize,
    /// Patch sizes in pixels, largest first.
    patch_sizes: Vec<usize>,
    /// Conjugate-gradient iterations.
    iterations: usize,
    /// Residual at convergence.
    residual: f64,
    /// Wall-clock time of the solve [s].
    seconds: f64,
    /// Physical size (lx, ly) [m] of the window.
    physical_size: (f64, f64),
    /// "periodic" or "free".
    boundary: &'static str,
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
}

/// Elastic normal contact of a rigid rough surface on an elastic half-space (boundary integral
/// method, Polonsky–Keer conjugate gradient at imposed load), as ``asperity contact``.
///
/// ``loads`` [N]: one or a sequence; solved in increasing order, each from the previous
/// solution, and returned in the order given. ``youngs`` [Pa] and ``poisson`` of the elastic
/// body (default silicon, 130 GPa and 0.26); ``youngs2``/``poisson2`` for an elastic
/// counter-body (1/E* = (1−ν1²)/E1 + (1−ν2²)/E2). ``boundary``: "periodic" or "free".
/// ``tolerance``: on the solver's relative residual. ``max_iter``: iteration limit per load.
/// The GIL is released while solving; Ctrl-C stops the solve.
#[pyfunction]
#[pyo3(signature = (topography, loads, *, youngs = Material::SILICON.youngs, poisson = Material::SILICON.poisson,
                    youngs2 = None, poisson2 = None, boundary = "periodic",
                    tolerance = SolverOptions::default().tolerance,
                    max_iter = SolverOptions::default().max_iterations))]
#[allow(clippy::too_many_arguments)]
fn contact(
    py: Python<'_>,
    topography: &Topography,
    loads: &Bound<'_, PyAny>,
    youngs: f64,
    poisson: f64,
    youngs2: Option<f64>,
    poisson2: Option<f64>,
    boundary: &str,
    tolerance: f64,
    max_iter: usize,
) -> PyResult<Vec<ContactSolution>> {
    let loads: Vec<f64> = match loads.extract::<f64>() {
        Ok(l) => vec![l],
        Err(_) => loads.extract().map_err(|_| invalid("--load", "expected a load or a sequence of loads [N]"))?,
    };
    if loads.is_empty() {
        return Err(invalid("--load", "no load given"));
    }
    core_contact::check_loads(&loads).map_err(error)?;
    let body = Material::new(youngs, poisson, "--youngs/--poisson").map_err(error)?;
    let e_star = match (youngs2, poisson2) {
        (Some(e2), Some(nu2)) => {
            core_contact::combined_modulus(&body, &Material::new(e2, nu2, "--youngs2/--poisson2").map_err(error)?)
        }
        (None, None) => body.plane_strain_modulus(),
        _ => return Err(invalid("--youngs2/--poisson2", "give both for an elastic counter-body, or neither")),
    };
    let boundary = match boundary {
        "periodic" => Boundary::Periodic,
        "free" => Boundary::Free,
        other => return Err(invalid("boundary", format!("'{other}' is not periodic or free"))),
    };
    let surface = &topography.inner;
    let size = core_contact::contact_size(surface).map_err(error)?;
    // Every load checked before any is solved, as the command line does.
    for &load in &loads {
        core_contact::check_load(load, size, e_star).map_err(error)?;
    }
    let shape = surface.heights.dim();
    let options = SolverOptions { tolerance, max_iterations: max_iter, ..Default::default() };
    let mut signals = Signals::new(py)?;
    let solved = py.detach(|| -> asperity::Result<Vec<Solved>> {
        let heights = surface.heights.as_standard_layout();
        let mut solver =
            ContactSolver::new(heights.as_slice().expect("standard layout"), shape, size, e_star, boundary, options)?;
        let mut order: Vec<usize> = (0..loads.len()).collect();
        order.sort_by(|&a, &b| loads[a].total_cmp(&loads[b]));
        let mut solved = Vec::with_capacity(loads.len());
        for index in order {
            let report = solver.solve(loads[index], |_, _| signals.check())?;
            let summary = core_contact::summarize(solver.pressure(), shape, size, boundary, None);
            let field = |v: Vec<f64>| Array2::from_shape_vec(shape, v).expect("a field has the grid's shape");
            solved.push(Solved {
                index,
                report,
                summary,
                pressure: field(solver.pressure().to_vec()),
                gap: field(solver.gap()),
            });
        }
        solved.sort_by_key(|s| s.index);
        Ok(solved)
    });
    let solved = solved.map_err(|e| signals.error(e))?;
    Ok(solved
        .into_iter()
        .map(|s| ContactSolution {
            load: s.report.load,
            mean_pressure: s.report.mean_pressure,
            pressure: s.pressure.into_pyarray(py).unbind(),
            gap: s.gap.into_pyarray(py).unbind(),
            contact_fraction: s.summary.contact_fraction,
            contact_area: s.summary.contact_area,
            contact_points: s.summary.contact_points,
            patches: s.summary.patch_sizes.len(),
            patch_sizes: s.summary.patch_sizes,
            iterations: s.report.iterations,
            residual: s.report.residual,
            seconds: s.report.seconds,
            physical_size: size,
            boundary: boundary.name(),
        })
        .collect())
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

    /// The friction–displacement curve, as a dict of arrays: ``shear`` (s = k_t·δ, the shear
    /// on every stuck element [N]), ``force`` (F [N]), ``coefficient`` (F / N), ``stuck``
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
        dict.set_item("shear", column(|p| p.element_shear).into_pyarray(py))?;
        dict.set_item("force", column(|p| p.force).into_pyarray(py))?;
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

/// The local law from mu_s/mu_d or a preset name, as ``asperity onset`` takes it.
fn friction_law(mu_s: Option<f64>, mu_d: Option<f64>, law: Option<&str>) -> asperity::Result<FrictionLaw> {
    let pair = match (mu_s, mu_d, law) {
        (Some(mu_s), Some(mu_d), _) => FrictionLaw::new(mu_s, mu_d)?,
        (Some(_), None, _) => return Err(asperity::Error::invalid("--mu-s", "needs --mu-d too")),
        (None, Some(_), _) => return Err(asperity::Error::invalid("--mu-d", "needs --mu-s too")),
        (None, None, Some(name)) => return FrictionLaw::preset(name),
        (None, None, None) => {
            return Err(asperity::Error::invalid(
                "--mu-s",
                "give the local friction law: mu_s and mu_d, or a preset law name",
            ))
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
/// The local law is ``mu_s`` and ``mu_d`` (with ``law`` as its name), or a preset ``law``
/// ("hold 100 s", "hold 10 s": illustrative placeholders). ``physical_size`` (lx, ly) [m] or
/// ``pixel_area`` [m²] give forces in newtons; the coefficients do not need them.
#[pyfunction]
#[pyo3(signature = (pressure, physical_size = None, *, mu_s = None, mu_d = None, law = None, pixel_area = None))]
fn onset(
    py: Python<'_>,
    pressure: &Bound<'_, PyAny>,
    physical_size: Option<&Bound<'_, PyAny>>,
    mu_s: Option<f64>,
    mu_d: Option<f64>,
    law: Option<&str>,
    pixel_area: Option<f64>,
) -> PyResult<Onset> {
    let law = friction_law(mu_s, mu_d, law).map_err(error)?;
    let (map, solution_size) = match pressure.cast::<ContactSolution>() {
        Ok(s) => (s.get().pressure.bind(py).readonly(), Some(s.get().physical_size)),
        Err(_) => (float_map(pressure, "pressure")?, None),
    };
    let (ny, nx) = map.as_array().dim();
    let size = physical_size.map(|s| lengths(s, "--size")).transpose()?.or(solution_size);
    let area = match (size, pixel_area) {
        (Some(_), Some(_)) => return Err(invalid("--pixel-area", "give physical_size or pixel_area, not both")),
        (Some((lx, ly)), None) => Some(lx / nx as f64 * (ly / ny as f64)),
        (None, Some(a)) if a.is_finite() && a > 0.0 => Some(a),
        (None, Some(a)) => return Err(invalid("--pixel-area", format!("must be positive and finite, got {a} m²"))),
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

/// The slide-hold-slide analysis as JSON ({"cycles", "groups", "skipped"}); see
/// ``asperity.analyse_shs``.
#[pyfunction]
#[pyo3(signature = (time_s, friction_n, normal_n, displacement_m, speed, window, peak_within, min_duration,
                    hold_fraction, slide_fraction, group_tolerance))]
#[allow(clippy::too_many_arguments)]
fn _analyse_shs(
    py: Python<'_>,
    time_s: Vec<f64>,
    friction_n: Vec<f64>,
    normal_n: Vec<f64>,
    displacement_m: Option<Vec<f64>>,
    speed: f64,
    window: f64,
    peak_within: f64,
    min_duration: f64,
    hold_fraction: f64,
    slide_fraction: f64,
    group_tolerance: f64,
) -> PyResult<String> {
    let options =
        ShsOptions { speed, window, peak_within, min_duration, hold_fraction, slide_fraction, group_tolerance };
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
    Start { total: usize, done: usize, onsets: usize, onsets_done: usize },
    Slid { topography: String, load_n: f64, law: String, iterations: usize, seconds: f64 },
    Solved { topography: String, load_n: f64, iterations: usize, seconds: f64 },
}

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
    let config = if quick { config.quick() } else { config };
    let study = py.detach(|| Study::prepare(config, &origin)).map_err(error)?;
    // Read before any solve, as the command line does: a bad experiments file costs nothing.
    let experiments = asperity::report::experiments(&study).map_err(error)?;

    // The study runs on its own thread; this one (Python's, where signal handlers run) reports
    // its progress and looks for Ctrl-C, which stops the run after the solves under way.
    let stop = AtomicBool::new(false);
    let (events, mut received) = mpsc::channel::<Event>();
    let outcome = std::thread::scope(|scope| -> PyResult<asperity::Result<asperity::study::run::Outcome>> {
        let runner = scope.spawn(|| {
            let events = events;
            study.run(&out, fresh, &|event| {
                let _ = events.send(match event {
                    Progress::Start { total, done, onsets, onsets_done } => {
                        Event::Start { total, done, onsets, onsets_done }
                    }
                    Progress::Slid { topography, load_n, law, iterations, seconds } => Event::Slid {
                        topography: topography.to_string(),
                        load_n,
                        law: law.to_string(),
                        iterations,
                        seconds,
                    },
                    Progress::Solved { topography, load_n, iterations, seconds } => {
                        Event::Solved { topography: topography.to_string(), load_n, iterations, seconds }
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
                            Event::Start { total, done, onsets, onsets_done } => {
                                dict.set_item("event", "start")?;
                                dict.set_item("total", total)?;
                                dict.set_item("done", done)?;
                                dict.set_item("onsets", onsets)?;
                                dict.set_item("onsets_done", onsets_done)?;
                            }
                            Event::Slid { topography, load_n, law, iterations, seconds } => {
                                dict.set_item("event", "slid")?;
                                dict.set_item("topography", topography)?;
                                dict.set_item("load_n", load_n)?;
                                dict.set_item("law", law)?;
                                dict.set_item("iterations", iterations)?;
                                dict.set_item("seconds", seconds)?;
                            }
                            Event::Solved { topography, load_n, iterations, seconds } => {
                                dict.set_item("event", "solved")?;
                                dict.set_item("topography", topography)?;
                                dict.set_item("load_n", load_n)?;
                                dict.set_item("iterations", iterations)?;
                                dict.set_item("seconds", seconds)?;
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
    m.add_class::<ContactSolution>()?;
    m.add_class::<Onset>()?;
    m.add_class::<ClassShare>()?;
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(compound, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(psd, m)?)?;
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    m.add_function(wrap_pyfunction!(onset, m)?)?;
    m.add_function(wrap_pyfunction!(_analyse_shs, m)?)?;
    m.add_function(wrap_pyfunction!(_run_study, m)?)?;
    Ok(())
}
