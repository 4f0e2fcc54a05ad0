//! `asperity slide`: the onset of sliding with elastic interaction between the contact points.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use ndarray::Array2;
use serde::{Deserialize, Serialize};

use asperity::contact::{
    self, Boundary, ContactSolver, ShearCompliance, SolverOptions, TangentialOptions, TangentialSolver,
};
use asperity::friction::{
    check_curve_unit, check_partial_slip_force, check_peak_tolerance, elastic_onset, element_stiffness, ramp_force,
    slip_curve_file, spring_slider_onset, ElementLoads, FrictionLaw, Onset, SlideClasses, SlideStage, SlideWork,
    SlipLaw, Snapshot, Weakening, DEFAULT_SLIP_DISTANCE_M, PEAK_TOLERANCE,
};
use asperity::limits::Limits;
use asperity::output::{self, StagedDir};
use asperity::plausible::{self, Spelling};
use asperity::quantity::{show, FORCE};
use asperity::topography::io;
use asperity::{Error, Result};

use super::{MaterialArgs, ReadArgs};

/// Sliding onset with elastic interaction between the contact points (tangential solve on the
/// half-space): static friction, friction drop, shear maps.
///
/// The body is displaced rigidly along x, quasi-statically, and the shear tractions on the
/// contact points follow from the elastic half-space (Cerruti) with a local law that has memory
/// (mu_s until a point first slips, then falling to mu_d over a slip-weakening distance, 2 nm
/// unless --slip-distance says otherwise; 0 is the instant drop). The normal
/// pressure is that of the normal solve (or of the contact directory given) and stays
/// fixed; normal and tangential problems are uncoupled (exact for identical bodies,
/// Goodman's approximation otherwise). F_S is the largest force once every cascade of slips has
/// settled: a march from δ = 0 brackets it and a search in δ locates it to --peak-tolerance.
///
/// Writes DIR/slide.json (its keys end in their unit: _n newtons, _m metres; beside elastic
/// sharing, equal sharing with the instant drop, the paper's model, and with the same
/// weakening, each element a spring–slider of the contact's stuck stiffness K_t / n),
/// DIR/curve.csv (displacement_m, force_n, stick_points, slip_points of the settled states: the
/// march's and the search's), DIR/shear_x.npy and DIR/shear_y.npy (Pa) and DIR/classes.npy
/// (int8: 0 no contact, 1 weakened: slipped, fully weakened (slip ≥ d_c, at mu_d; every
/// slipped point under the instant drop), 2 critical: on its bound, slipping for the first time,
/// 3 stuck: below its bound, never slipped, 4 weakening: slipped, 0 < slip < d_c) at the peak
/// force, or at the imposed --tangential-force; slide.json counts them (stuck, critical,
/// weakening, weakened).
#[derive(Args)]
#[command(mut_arg("file", |a| a.value_name("SURFACE|CONTACT_DIR").help(
    "A topography file, in any format asperity reads (solved for --load first), or the output \
     directory of `asperity contact` (its pressure at --load)"
)))]
pub struct SlideArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// Normal load [N, or with a unit: 10mN]; with a contact directory, which of its loads.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = super::force)]
    load: Option<f64>,
    /// Local static friction coefficient mu_s (dimensionless, ≥ mu_d).
    #[arg(long, allow_negative_numbers = true)]
    mu_s: Option<f64>,
    /// Local dynamic friction coefficient mu_d (dimensionless, > 0).
    #[arg(long, allow_negative_numbers = true)]
    mu_d: Option<f64>,
    /// Name of the local law: alone, a preset ("hold 100 s", "hold 10 s": ILLUSTRATIVE
    /// values); with --mu-s/--mu-d or --curve, a label.
    #[arg(long)]
    law: Option<String>,
    /// A measured nanoscale friction curve, CSV of (displacement, friction coefficient), as
    /// `onset` reads it: mu_s is its peak, and past the peak μ follows the curve as a function
    /// of the accumulated slip (displacement unit: --curve-unit).
    #[arg(long, conflicts_with_all = ["mu_s", "mu_d", "slip_distance"], requires = "curve_unit")]
    curve: Option<PathBuf>,
    /// The displacement unit of --curve as a length (1nm, 1um, 1e-9).
    #[arg(long, value_name = "LENGTH", value_parser = super::length)]
    curve_unit: Option<f64>,
    /// START,END past the peak of --curve over which mu_d is averaged, in the curve's unit.
    #[arg(long, requires = "curve", value_delimiter = ',', value_name = "START,END", allow_hyphen_values = true)]
    window: Option<Vec<f64>>,
    /// Slip-weakening distance d_c [m, or with a unit: 1nm]: μ falls linearly from mu_s to
    /// mu_d over an accumulated slip d_c; 0 is the instant drop, at once on the first slip
    /// [default: 2nm, the study's, at which the drop converges in the pixel].
    #[arg(long, value_name = "DC", allow_hyphen_values = true, value_parser = super::length)]
    slip_distance: Option<f64>,
    /// Ramp the tangential force to Q [N, or with a unit: 0.2mN] under Coulomb friction at
    /// mu_s (mu_d is not used) and write that partial-slip state instead of the path to
    /// sliding: slide.json (tangential_force_n, displacement_m, stick_points, slip_points) and
    /// the maps, no curve.csv.
    #[arg(
        long,
        value_name = "Q",
        allow_negative_numbers = true,
        value_parser = super::force,
        conflicts_with_all = ["slip_distance", "curve"]
    )]
    tangential_force: Option<f64>,
    #[command(flatten)]
    material: MaterialArgs,
    #[command(flatten)]
    device: super::DeviceArgs,
    /// Tolerance of the tangential solve (relative norm of its projected gradient, below 1e-2); the march
    /// from δ = 0 that brackets F_S solves to 100 times it, at most 1e-4.
    #[arg(long, value_name = "T", default_value_t = TangentialOptions::default().tolerance)]
    tolerance: f64,
    /// The search for F_S ends when the settled forces of its bracket agree within this fraction of F_S
    /// (or, before a snap, when the last stable state is located as closely), in (0, 0.1).
    #[arg(long, value_name = "R", default_value_t = PEAK_TOLERANCE)]
    peak_tolerance: f64,
    /// Iteration limit of one tangential solve.
    #[arg(long, value_name = "K", default_value_t = TangentialOptions::default().max_iterations)]
    max_iter: usize,
    /// Output directory, with a manifest.json of the files written: a new or empty folder, or
    /// an earlier output of `asperity slide`, replaced as a whole when the run completes
    /// (anything else is refused; nothing is left behind by a failed run).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// The part of `asperity contact`'s contact.json this command reads.
#[derive(Deserialize)]
struct ContactResult {
    grid: [usize; 2],
    physical_size_m: [f64; 2],
    effective_modulus_pa: f64,
    boundary: Boundary,
    loads: Vec<ContactLoad>,
}

#[derive(Deserialize)]
struct ContactLoad {
    load_n: f64,
    pressure_file: String,
}

/// The pressure the tangential problem starts from.
struct Normal {
    pressure: Vec<f64>,
    shape: (usize, usize),
    size: (f64, f64),
    boundary: Boundary,
    load: f64,
}

#[derive(Serialize)]
struct LawReport {
    name: Option<String>,
    mu_s: f64,
    mu_d: f64,
    weakening: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    slip_distance_m: Option<f64>,
}

#[derive(Serialize)]
struct EqualSharing {
    static_coefficient: f64,
    friction_drop: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    peak_displacement_m: Option<f64>,
}

#[derive(Serialize)]
struct WorkReport {
    #[serde(flatten)]
    work: SlideWork,
    /// FFT pairs: two per operator application.
    fft_pairs: usize,
    seconds: f64,
}

/// slide.json for the path to sliding.
#[derive(Serialize)]
struct OnsetReport {
    input: String,
    boundary: &'static str,
    contact_points: usize,
    law: LawReport,
    load_n: f64,
    static_force_n: f64,
    static_coefficient: f64,
    dynamic_coefficient: f64,
    friction_drop: f64,
    /// None (null) when F_S is the steady sliding force, reached as δ → ∞.
    peak_displacement_m: Option<f64>,
    #[serde(flatten)]
    classes: SlideClasses,
    /// The paper's model: equal sharing, the instant drop.
    equal_sharing: EqualSharing,
    /// Equal sharing with the law's own weakening (spring–sliders of K_t / n); absent for a
    /// measured μ(slip).
    #[serde(skip_serializing_if = "Option::is_none")]
    equal_sharing_same_law: Option<EqualSharing>,
    work: WorkReport,
}

/// slide.json for a partial-slip state at an imposed tangential force.
#[derive(Serialize)]
struct RampReport {
    input: String,
    boundary: &'static str,
    contact_points: usize,
    load_n: f64,
    mu: f64,
    tangential_force_n: f64,
    displacement_m: f64,
    stick_points: usize,
    slip_points: usize,
    work: WorkReport,
}

pub fn run(args: SlideArgs) -> Result<()> {
    // Everything that can be checked is checked before the normal solve.
    let law = law(&args)?;
    let (bodies, e_star) = args.material.bodies()?;
    let options = TangentialOptions { tolerance: args.tolerance, max_iterations: args.max_iter };
    options.check()?;
    check_peak_tolerance(args.peak_tolerance)?;
    if let Some(q) = args.tangential_force {
        if !(q > 0.0 && q.is_finite()) {
            return Err(Error::invalid("--tangential-force", format!("must be positive and finite, got {q:e} N")));
        }
        // The normal solve carries the load exactly: N = --load (a contact directory's load
        // is checked once read, and the ramp checks the N it sums).
        if let Some(load) = args.load {
            check_partial_slip_force(q, law.mu_s, load, "--tangential-force")?;
        }
    }
    // Before the normal solve: an --out that cannot be written is said at once.
    // Inputs are never outputs: the curve read too.
    let read: Vec<&Path> = std::iter::once(args.read.file.as_path()).chain(args.curve.as_deref()).collect();
    let out = StagedDir::new(&args.out, "slide", &read)?;
    let normal = normal_pressure(&args, e_star)?;
    // Checked before the solve for a topography; a contact folder's pressures tell it here.
    if normal.boundary == Boundary::Periodic && normal.pressure.iter().all(|p| *p > 0.0) {
        return Err(full_contact(normal.load));
    }
    let mut solver = TangentialSolver::new(
        &normal.pressure,
        normal.shape,
        normal.size,
        ShearCompliance::of(&bodies),
        normal.boundary,
        options,
    )?;
    let input = args.read.file.display().to_string();
    let start = Instant::now();
    let work_report =
        |work: SlideWork| WorkReport { work, fft_pairs: 2 * work.applications, seconds: start.elapsed().as_secs_f64() };
    let contact_points = solver.points().len();
    if let Some(q) = args.tangential_force {
        let (state, work) = ramp_force(&mut solver, law.mu_s, q)?;
        write_maps(&out, &solver, &state)?;
        let report = RampReport {
            input,
            boundary: normal.boundary.name(),
            contact_points,
            load_n: normal.load,
            mu: law.mu_s,
            tangential_force_n: state.point.force_n,
            displacement_m: state.point.displacement_m,
            stick_points: state.point.stick_points,
            slip_points: state.point.slip_points,
            work: work_report(work),
        };
        output::write_json(&out.path("slide.json"), &report)?;
        super::message(&format!(
            "Q {:.6e} N at δ {:.6e} m: {} stuck, {} slipping ({} solves, {} iterations, {:.1} s)",
            report.tangential_force_n,
            report.displacement_m,
            report.stick_points,
            report.slip_points,
            work.solves,
            work.iterations,
            report.work.seconds
        ));
    } else {
        // The march from δ = 0, then the search for the peak.
        let bar = super::progress_bar(2, "sliding", false);
        let batch = !std::io::stderr().is_terminal();
        let mut last_line = Instant::now();
        let onset = elastic_onset(&mut solver, &law, args.peak_tolerance, |p| {
            let stage = match p.stage {
                SlideStage::March => "march from δ = 0",
                SlideStage::Search => "search for the peak",
            };
            let line = format!(
                "{stage}: δ {:.4e} m, F {:.4e} N (largest {:.4e} N), {} stuck, {} slipping; {} steps, {} solves",
                p.point.displacement_m,
                p.point.force_n,
                p.largest_force_n,
                p.point.stick_points,
                p.point.slip_points,
                p.work.steps,
                p.work.solves
            );
            if batch {
                if last_line.elapsed() >= super::BATCH_PROGRESS {
                    last_line = Instant::now();
                    super::message(&format!("sliding: {line} after {:.0} s", start.elapsed().as_secs_f64()));
                }
            } else {
                bar.set_position(u64::from(p.stage == SlideStage::Search));
                bar.set_message(line);
            }
        });
        bar.finish_and_clear();
        let onset = onset?;
        write_maps(&out, &solver, &onset.peak)?;
        write_curve(&out.path("curve.csv"), &onset.curve)?;
        let (ny, nx) = normal.shape;
        let pressure = Array2::from_shape_vec((ny, nx), normal.pressure.clone()).expect("grid shape");
        let area = solver.pixel_area();
        let loads = ElementLoads::from_pressure(&pressure, area)?;
        let equal = Onset::new(&loads, &FrictionLaw::new(law.mu_s, law.mu_d)?);
        let same_law = match law.weakening {
            Weakening::Curve(_) => None,
            _ => {
                let k = element_stiffness(onset.stuck_stiffness, loads.len());
                let same = spring_slider_onset(&loads, &law, k)?;
                Some(EqualSharing {
                    static_coefficient: same.static_coefficient(),
                    friction_drop: same.friction_drop(),
                    peak_displacement_m: Some(same.peak_displacement_m),
                })
            }
        };
        let report = OnsetReport {
            input,
            boundary: normal.boundary.name(),
            contact_points,
            law: law_report(&args, &law),
            load_n: normal.load,
            static_force_n: onset.static_force,
            static_coefficient: onset.static_coefficient(),
            dynamic_coefficient: law.mu_d,
            friction_drop: onset.friction_drop(),
            peak_displacement_m: Some(onset.peak.point.displacement_m).filter(|d| d.is_finite()),
            classes: onset.classes,
            equal_sharing: EqualSharing {
                static_coefficient: equal.static_coefficient(),
                friction_drop: equal.friction_drop(),
                peak_displacement_m: None,
            },
            equal_sharing_same_law: same_law,
            work: work_report(onset.work),
        };
        output::write_json(&out.path("slide.json"), &report)?;
        super::message(&format!(
            "friction drop {:.6} (equal sharing {:.6}{}), static coefficient {:.6} ({} steps, {} solves, {} iterations, {:.1} s)",
            report.friction_drop,
            report.equal_sharing.friction_drop,
            report.equal_sharing_same_law.as_ref().map_or(String::new(), |e| format!(", with the same weakening {:.6}", e.friction_drop)),
            report.static_coefficient,
            onset.work.steps,
            onset.work.solves,
            onset.work.iterations,
            report.work.seconds
        ));
    }
    let dir = super::commit(out)?;
    super::message(&format!("wrote {}", dir.join("slide.json").display()));
    Ok(())
}

/// The local law with its weakening.
fn law(args: &SlideArgs) -> Result<SlipLaw> {
    if args.curve.is_none() && args.curve_unit.is_some() {
        return Err(Error::invalid(
            "--curve-unit",
            "is the unit of --curve only: give --curve FILE, or drop --curve-unit",
        ));
    }
    let base = super::onset::law_from_options(
        args.mu_s,
        args.mu_d,
        args.curve.as_deref(),
        args.window.as_deref(),
        args.law.as_deref(),
    )?;
    let weakening = match (&args.curve, args.slip_distance) {
        (Some(path), _) => {
            let unit = args.curve_unit.expect("clap requires --curve-unit with --curve");
            check_curve_unit(unit, "--curve-unit")?;
            Weakening::Curve(slip_curve_file(path, unit)?)
        }
        (None, Some(dc)) => {
            let weakening = Weakening::of_slip_distance(dc, "--slip-distance")?;
            if dc != 0.0 {
                super::judge("--slip-distance", plausible::slip_distance(dc, Spelling::CommandLine))?;
            }
            weakening
        }
        // A Coulomb ramp at mu_s has no weakening.
        (None, None) if args.tangential_force.is_some() => Weakening::Instant,
        (None, None) => Weakening::Linear(DEFAULT_SLIP_DISTANCE_M),
    };
    Ok(SlipLaw { mu_s: base.mu_s, mu_d: base.mu_d, weakening })
}

fn law_report(args: &SlideArgs, law: &SlipLaw) -> LawReport {
    let weakening = match law.weakening {
        Weakening::Instant => "instant",
        Weakening::Linear(_) => "linear",
        Weakening::Curve(_) => "curve",
    };
    let slip_distance_m = law.slip_distance();
    let name = args.law.clone().or_else(|| args.curve.as_ref().map(|p| p.display().to_string()));
    LawReport { name, mu_s: law.mu_s, mu_d: law.mu_d, weakening, slip_distance_m }
}

/// The normal pressure: solved here for a topography, or read from a contact directory.
/// The error of a load that puts a periodic window in full contact.
fn full_contact(load: f64) -> Error {
    Error::invalid(
        "--load",
        format!(
            "at {load:e} N every point of the periodic window touches (full contact): the periodic half-space has \
             no stiffness for a uniform shift, so there is no sliding onset to find; lower the load or solve with \
             --free"
        ),
    )
}

fn normal_pressure(args: &SlideArgs, e_star: f64) -> Result<Normal> {
    let path = &args.read.file;
    if path.is_dir() {
        if let Some(option) = args.read.given() {
            return Err(Error::invalid(
                option,
                "not used with a contact directory: its contact.json gives the surface",
            ));
        }
        return read_contact_dir(path, args.load, e_star, args.material.free, &args.read.limits.limits());
    }
    let load = args.load.ok_or_else(|| Error::invalid("--load", "give the normal load for a topography"))?;
    if !(load > 0.0 && load.is_finite()) {
        return Err(Error::invalid("--load", format!("must be positive and finite, got {load} N")));
    }
    let surface = io::read(path, &args.read.options())?;
    let size = contact::contact_size(&surface)?;
    contact::check_load(load, size, e_star)?;
    super::judge("--load", plausible::load(load, size, e_star, Spelling::CommandLine))?;
    let boundary = args.material.boundary();
    let shape = (surface.ny(), surface.nx());
    // Both solves' memory before the first one's work.
    contact::check_solves_memory(shape, boundary).map_err(|reason| Error::file(path, reason))?;
    let heights = surface.heights.as_standard_layout();
    let heights = heights.as_slice().expect("standard layout");
    if boundary == Boundary::Periodic && load >= contact::full_contact_load(heights, shape, size, e_star) {
        return Err(full_contact(load));
    }
    let options = SolverOptions { device: args.device.device, ..SolverOptions::default() };
    let mut solver = ContactSolver::new(heights, shape, size, e_star, boundary, options)?;
    let report = solver.solve(load, |_, _| {})?;
    super::message(&format!("normal solve: {} iterations, {:.1} s", report.iterations, report.seconds));
    // As `contact` warns: a contact cut by the window, or pressures beyond belief.
    let remedies: Vec<String> =
        (!args.material.free).then(|| "a free boundary (--free)".to_string()).into_iter().collect();
    for w in contact::summarize(solver.pressure(), shape, size, boundary, None).warnings(&remedies) {
        super::message(&format!(
            "warning: at {}: {w} (`asperity contact` levels, crops and caps; `slide` takes its folder)",
            show(load, &FORCE)
        ));
    }
    Ok(Normal { pressure: solver.pressure().to_vec(), shape, size, boundary, load })
}

fn read_contact_dir(dir: &Path, load: Option<f64>, e_star: f64, free: bool, limits: &Limits) -> Result<Normal> {
    let (json_path, contact): (_, ContactResult) = super::onset::read_contact_json(dir, limits)?;
    let [ny, nx] = contact.grid;
    let [lx, ly] = contact.physical_size_m;
    if !(lx.is_finite() && ly.is_finite() && lx > 0.0 && ly > 0.0 && nx >= 2 && ny >= 2) {
        return Err(Error::file(&json_path, format!("grid {ny}×{nx} of size {lx}×{ly} m is not a valid surface")));
    }
    if (contact.effective_modulus_pa - e_star).abs() > 1e-9 * e_star {
        return Err(Error::invalid(
            "--youngs/--poisson",
            format!(
                "give the materials of the contact solve: its effective modulus is {:.6e} Pa, these give {e_star:.6e} Pa",
                contact.effective_modulus_pa
            ),
        ));
    }
    if free && contact.boundary != Boundary::Free {
        return Err(Error::invalid("--free", format!("{} was solved with a periodic boundary", json_path.display())));
    }
    let known = || contact.loads.iter().map(|l| format!("{:e}", l.load_n)).collect::<Vec<_>>().join(", ");
    let entry = match (load, &contact.loads[..]) {
        (_, []) => return Err(Error::file(&json_path, "it holds no load")),
        (None, [one]) => one,
        (None, _) => {
            return Err(Error::invalid(
                "--load",
                format!("{} holds several loads, choose one [N]: {}", json_path.display(), known()),
            ))
        }
        (Some(n), loads) => loads.iter().find(|l| (l.load_n - n).abs() <= 1e-9 * n).ok_or_else(|| {
            Error::invalid("--load", format!("{n:e} N is not among the loads of {}: {}", json_path.display(), known()))
        })?,
    };
    let area = lx / nx as f64 * (ly / ny as f64);
    let (_, pressure) =
        super::onset::read_load_map(&json_path, &entry.pressure_file, entry.load_n, (ny, nx), area, limits)?;
    Ok(Normal {
        pressure: pressure.iter().copied().collect(),
        shape: (ny, nx),
        size: (lx, ly),
        boundary: contact.boundary,
        load: entry.load_n,
    })
}

/// shear_x.npy, shear_y.npy \[Pa] and classes.npy of a state.
fn write_maps(out: &StagedDir, solver: &TangentialSolver, state: &Snapshot) -> Result<()> {
    let (sx, sy, classes) = state.maps(solver);
    output::write_npy(&out.path("shear_x.npy"), &sx)?;
    output::write_npy(&out.path("shear_y.npy"), &sy)?;
    output::write_npy(&out.path("classes.npy"), &classes)
}

fn write_curve(path: &Path, curve: &[asperity::friction::SlidePoint]) -> Result<()> {
    output::write_atomic(path, |w| {
        writeln!(w, "displacement_m,force_n,stick_points,slip_points")?;
        for p in curve {
            writeln!(w, "{:e},{:e},{},{}", p.displacement_m, p.force_n, p.stick_points, p.slip_points)?;
        }
        Ok(())
    })
}
