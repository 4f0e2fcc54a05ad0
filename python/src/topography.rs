//! Topographies in Python: `Topography` (a height map) and `Profile` (a line scan), reading
//! them from files, generating synthetic surfaces, their statistics and spectra.
//!
//! Must not import contact, friction, shs or study of this crate (they take its topographies).

use std::path::PathBuf;

use asperity::plausible::{self, Spelling};
use asperity::topography::detrend::Detrend;
use asperity::topography::missing::fill_missing;
use asperity::topography::prepare::Preparation;
use asperity::topography::profile::Profile as CoreProfile;
use asperity::topography::resample::{self, CropWindow};
use asperity::topography::stats::{self, Window};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};
use asperity::topography::{io, AnyTopography, Provenance, Topography as CoreTopography};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{error, error_naming, invalid, judge};
use crate::units::{heights_within, limits, pixels, range, view_of, whole, window};

/// A height map: heights [m] of shape (ny, nx) (row index y, column index x) on a window of
/// physical size (lx, ly) [m].
///
/// ``Topography(heights, physical_size=(lx, ly), periodic=False, *, max_points=None)`` takes
/// any 2-D array of heights in metres (copied; NaN marks a missing point), refusing what the
/// command line's readers refuse: more than ``max_points`` points (default 2^28), heights beyond
/// ±1e50 m (infinite ones included), and a copy the memory cannot hold (a ``MemoryError``).
/// Methods return new topographies.
#[pyclass(frozen, module = "asperity")]
pub(crate) struct Topography {
    pub(crate) inner: CoreTopography,
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
        let from = from_file(&self.inner.provenance.file);
        format!("<Topography {}×{} points (ny × nx), {size}{from}>", self.inner.ny(), self.inner.nx())
    }
}

/// " from FILE" in a repr, or nothing for what was not read from a file.
fn from_file(file: &Option<PathBuf>) -> String {
    file.as_ref().map_or_else(String::new, |f| format!(" from {}", f.display()))
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
pub(crate) fn read_topography(
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
pub(crate) struct Profile {
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
        let from = from_file(&self.inner.provenance.file);
        format!("<Profile {} points, length {:e} m, {spacing}{from}>", self.inner.points(), self.inner.length())
    }
}

/// The compound roughness h = h_ball − h_wafer on the ball's grid (the wafer interpolated at
/// the ball's sample positions, the windows centred on each other).
#[pyfunction]
pub(crate) fn compound(py: Python<'_>, ball: &Topography, wafer: &Topography) -> PyResult<Topography> {
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
pub(crate) fn generate(
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
pub(crate) fn psd<'py>(
    py: Python<'py>,
    topography: &Bound<'py, PyAny>,
    window: &str,
) -> PyResult<(Spectrum<'py>, Spectrum<'py>)> {
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
