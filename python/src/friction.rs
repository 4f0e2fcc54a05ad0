//! The onset of sliding in Python: `onset()` (equal load sharing, the stick-slip transition
//! model) and `slide()` (elastic sharing, or a partial-slip state), with their results
//! `Onset`, `Slide`, `PartialSlip` and `ClassShare`, as `asperity onset` and `asperity slide`.
//!
//! Must not import shs or study of this crate.

use std::path::PathBuf;
use std::time::Instant;

use asperity::contact::{Boundary, ShearCompliance, TangentialOptions, TangentialSolver};
use asperity::friction::{
    check_curve_unit, check_partial_slip_force, elastic_onset, element_stiffness, ramp_force, slip_curve_file,
    spring_slider_onset, ClassShare as CoreShare, Curve, ElementLoads, FrictionLaw, Loading, Onset as CoreOnset,
    SlidePoint, SlipLaw, Weakening, DEFAULT_SLIP_DISTANCE_M, PEAK_TOLERANCE,
};
use asperity::plausible::{self, Spelling};
use ndarray::{Array2, ArrayView2};
use numpy::{IntoPyArray, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::contact::ContactSolution;
use crate::errors::{error, error_naming, invalid, judge, Signals};
use crate::units::{float_map, range};

/// Count and shares of one class of elements at the critical state.
#[pyclass(frozen, get_all, module = "asperity")]
#[derive(Clone)]
pub(crate) struct ClassShare {
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
pub(crate) struct Onset {
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
pub(crate) fn onset(
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
    let size = physical_size.map(|s| crate::units::window(s, "physical_size")).transpose()?.or(solution_size);
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

/// The onset of sliding with elastic sharing (``slide``), as ``asperity slide``'s slide.json,
/// curve.csv and maps at the peak force.
#[pyclass(frozen, module = "asperity")]
pub(crate) struct Slide {
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
    /// … points on their bound that never slipped before the peak's increment, …
    #[pyo3(get)]
    critical: ClassShare,
    /// … points that slipped before it, still weakening (0 < s < d_c), …
    #[pyo3(get)]
    weakening: ClassShare,
    /// … and points that slipped before it, fully weakened (s ≥ d_c; at mu_d).
    #[pyo3(get)]
    weakened: ClassShare,
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
    /// Class of each pixel at the peak, int8 (ny, nx): 0 no contact, 1 weakened, 2 critical,
    /// 3 stuck, 4 weakening.
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
pub(crate) struct PartialSlip {
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
pub(crate) fn slide(
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
    if let (Some(_), Some(unit)) = (&curve, curve_unit) {
        check_curve_unit(unit, "curve_unit").map_err(error)?;
    }
    let curve_weakening = match (&curve, curve_unit) {
        (None, None) => None,
        (None, Some(_)) => return Err(invalid("curve_unit", "applies to a curve only")),
        (Some(_), None) => {
            return Err(invalid("curve_unit", "a curve needs its displacement unit [m] (1e-9 for nm) to be followed"))
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
        (None, Some(dc)) => {
            let weakening = Weakening::of_slip_distance(dc, "slip_distance").map_err(error)?;
            if dc != 0.0 {
                judge(py, "slip_distance", dc, plausible::slip_distance(dc, Spelling::Python))?;
            }
            weakening
        }
        // A Coulomb ramp at mu_s has no weakening.
        (None, None) if tangential_force.is_some() => Weakening::Instant,
        (None, None) => Weakening::Linear(DEFAULT_SLIP_DISTANCE_M),
    };
    let options = TangentialOptions { tolerance, max_iterations: max_iter };
    options.check().map_err(error)?;
    let load = solution.load;
    if let Some(q) = tangential_force {
        check_partial_slip_force(q, base.mu_s, load, "tangential_force").map_err(error)?;
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
        let (sx, sy, classes) = state.maps(&solver);
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
    let (sx, sy, classes) = onset.peak.maps(&solver);
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
        stuck: onset.classes.stuck.into(),
        critical: onset.classes.critical.into(),
        weakening: onset.classes.weakening.into(),
        weakened: onset.classes.weakened.into(),
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
