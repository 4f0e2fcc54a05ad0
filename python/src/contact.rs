//! Normal contact in Python: `contact()` (elastic, plastic or adhesive) and the
//! `ContactSolution` of each load, as `asperity contact` solves and reports them.
//!
//! Must not import friction, shs or study of this crate (friction takes its solutions).

use asperity::contact::{
    self as core_contact, AdhesiveSolver, Boundary, CohesiveLaw, ContactSolver, Convergence, Device, Material,
    SolverOptions,
};
use asperity::plausible::{self, Spelling};
use ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;

use crate::errors::{error, error_naming, invalid, judge, warn, Signals};
use crate::topography::{Profile, Topography};

/// One load of a contact solve: the pressure, gap and displacement maps and what summarises
/// them, as a load of ``asperity contact``'s contact.json.
#[pyclass(frozen, module = "asperity")]
pub(crate) struct ContactSolution {
    /// Normal load N [N].
    #[pyo3(get)]
    pub(crate) load: f64,
    /// Mean pressure N / (lx·ly) [Pa].
    #[pyo3(get)]
    mean_pressure: f64,
    /// Pressure [Pa], float64 of shape (ny, nx).
    #[pyo3(get)]
    pub(crate) pressure: Py<PyArray2<f64>>,
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
    pub(crate) physical_size: (f64, f64),
    /// "periodic" or "free".
    #[pyo3(get)]
    pub(crate) boundary: &'static str,
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
    pub(crate) bodies: Vec<Material>,
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
    /// With adhesion: the cohesive tension at the window's edge, a fraction of the strength.
    edge_tension: f64,
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
/// none; plausible from 1e-4 to 10) with ``adhesion_stress`` [Pa] (1e4 to 1e12) or
/// ``adhesion_range`` [m] (1e-12 to 1e-6),
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
pub(crate) fn contact(
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
            if let Some(s) = adhesion_stress {
                judge(py, "adhesion_stress", s, plausible::adhesion_stress(s, Spelling::Python))?;
            }
            if let Some(r) = adhesion_range {
                judge(py, "adhesion_range", r, plausible::adhesion_range(r, Spelling::Python))?;
            }
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
        None if adhesion_stress.is_some() || adhesion_range.is_some() || pull_off || adhesion_law != "maugis" => {
            return Err(invalid(
                "adhesion_work",
                "is needed by adhesion_stress, adhesion_range, adhesion_law and pull_off",
            ));
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
                    edge_tension: solver.edge_tension(),
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
                edge_tension: 0.0,
            });
        }
        solved.sort_by_key(|s| s.index);
        Ok((solved, None))
    });
    let (solved, pull_off) = solved.map_err(|e| signals.error(e))?;
    let mut solutions = Vec::with_capacity(solved.len());
    for (s, mut said) in solved.into_iter().zip(warnings) {
        for w in s.summary.warnings(&remedies).into_iter().chain(core_contact::edge_tension_warning(s.edge_tension)) {
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
