//! `asperity contact`: elastic normal contact of a topography at one or more loads.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::Serialize;

use asperity::contact::{self, AdhesiveSolver, CohesiveLaw, ContactSolver, Convergence, Device, SolverOptions};
use asperity::output::{self, StagedDir};
use asperity::plausible::{self, Spelling};
use asperity::quantity::{show, FORCE, PRESSURE};
use asperity::topography::detrend::Detrend;
use asperity::topography::io::{self, ReadOptions};
use asperity::topography::prepare::{compound_with, Preparation};
use asperity::topography::synth::{Cap, CapShape};
use asperity::{Error, Result};

use super::topo_tools::PrepareArgs;
use super::{MaterialArgs, ReadArgs};

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// Elastic normal contact of a topography at one or more loads: pressure maps and contact
/// statistics (boundary integral method).
///
/// Presses a rigid rough surface on an elastic half-space (Polonsky–Keer conjugate gradient at
/// imposed load). Writes DIR/contact.json and one DIR/pressure-NNN.npy (float64, Pa, shape
/// ny×nx) per load, numbered in the order the loads are given. Loads are solved in increasing order, each
/// starting from the previous solution. The surface is prepared as the study prepares a file
/// (crop, missing points, detrend, resample, cap, wafer), but as read unless told otherwise.
/// Every load reports the share of it carried within 2 % of the window's edges
/// (edge_load_fraction; above 0.01 a warning) and the largest pressure.
///
/// With --adhesion-work the surfaces also attract through a cohesive zone (Maugis–Dugdale or
/// exponential law; each step freezes the cohesive tension and solves the contact without
/// adhesion): loads may be zero or tensile (negative), are solved from the largest down (an
/// unloading: the first from the equilibrium without adhesion at its load, each next from the
/// last), and each reports its compressive and adhesive forces; pressure-NNN.npy then holds the
/// compressive part of the traction, traction-NNN.npy the traction (tensile negative). On a
/// free window, a cohesive tension at the window's edge above 1 % of the law's strength is
/// warned about.
#[derive(Args)]
pub struct ContactArgs {
    #[command(flatten)]
    read: ReadArgs,
    #[command(flatten)]
    prepare: PrepareArgs,
    /// Resample (cubic convolution) to this pixel size [m, or with a unit: 20nm], keeping the
    /// physical size.
    #[arg(long, value_name = "P", value_parser = super::length)]
    pixel_size: Option<f64>,
    /// Add a spherical cap of radius R [m, or with a unit: 1.5mm] to the levelled scan, apex at
    /// the window's centre: a ball scanned after its curvature was levelled away.
    #[arg(long, value_name = "R", value_parser = super::length)]
    cap_radius: Option<f64>,
    /// Counter-surface scan (a wafer) in any readable format: levelled with the same --detrend,
    /// interpolated onto the surface's grid and compounded, h = h_surface − h_wafer.
    #[arg(long, value_name = "FILE")]
    wafer: Option<PathBuf>,
    /// Hardness of the softer body [Pa, or with a unit: 12GPa] (silicon ≈ 12 GPa; none by
    /// default): reports the share of each load carried at p ≥ H and warns when it is not zero.
    /// The solve stays elastic unless --plastic caps the pressure at H.
    #[arg(long, value_name = "H", allow_negative_numbers = true, value_parser = super::pressure)]
    hardness: Option<f64>,
    /// Normal load [N, or with a unit: 1mN]; repeat for a sweep (--load 1e-4 --load 1e-3 …) or
    /// give a list (0.1mN,1mN).
    #[arg(long, value_name = "N", required = true, value_delimiter = ',', allow_negative_numbers = true, value_parser = super::force)]
    load: Vec<f64>,
    #[command(flatten)]
    material: MaterialArgs,
    /// Elastic–perfectly-plastic contact: cap the pressure at --hardness (0 ≤ p ≤ H); where it
    /// is reached the surface yields (penetrates) instead of loading further.
    #[arg(long)]
    plastic: bool,
    /// Convergence tolerance on the solver's relative residual (complementarity and
    /// penetration, relative to mean pressure × RMS height; with adhesion, the traction
    /// residual relative to the traction), below 1e-2.
    #[arg(long, value_name = "T", default_value = "1e-10")]
    tolerance: f64,
    /// Iteration limit per load; a solve that has not converged by then is an error.
    #[arg(long, value_name = "K", default_value_t = SolverOptions::default().convergence.max_iterations, value_parser = super::count::<usize>)]
    max_iter: usize,
    #[command(flatten)]
    device: super::DeviceArgs,
    #[command(flatten)]
    adhesion: AdhesionArgs,
    /// Also write gap-NNN.npy and displacement-NNN.npy [m] for each load.
    #[arg(long)]
    fields: bool,
    /// Output directory, with a manifest.json of the files written: a new or empty folder, or
    /// an earlier output of `asperity contact`, replaced as a whole when the run completes
    /// (anything else is refused; nothing is left behind by a failed run).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// The cohesive law of an adhesive contact, as the options give it.
#[derive(Args)]
pub struct AdhesionArgs {
    /// Work of adhesion w [J/m², or with a unit: 50mJ/m2]: adhesive contact, the surfaces held
    /// by a cohesive zone (with --adhesion-stress or --adhesion-range); judged plausible from
    /// 0.1 mJ/m² to 10 J/m² (silicon on silicon in air: of order 0.01–0.1 J/m²).
    #[arg(long, value_name = "W", value_parser = super::surface_energy)]
    pub adhesion_work: Option<f64>,
    /// Cohesive stress [Pa, or with a unit: 100MPa]: σ₀ of the Maugis–Dugdale law (its range
    /// h₀ = w/σ₀), the peak tension w/ρ of the exponential law; judged plausible from 10 kPa
    /// to 1 TPa.
    #[arg(long, value_name = "S", value_parser = super::pressure, requires = "adhesion_work", conflicts_with = "adhesion_range")]
    pub adhesion_stress: Option<f64>,
    /// Range of the cohesive law [m, or with a unit: 1nm]: h₀ of the Maugis–Dugdale law
    /// (σ₀ = w/h₀), ρ of the exponential law; judged plausible from 1 pm to 1 µm (van der Waals:
    /// a few tenths of a nanometre).
    #[arg(long, value_name = "R", value_parser = super::length, requires = "adhesion_work")]
    pub adhesion_range: Option<f64>,
    /// The cohesive law: maugis (a tension σ₀ while the gap is below h₀) or exponential (a
    /// tension (w/ρ)·e^(−g/ρ)).
    #[arg(long, value_name = "LAW", default_value = "maugis", value_parser = ["maugis", "exponential"], requires = "adhesion_work")]
    pub adhesion_law: String,
    /// Also find the pull-off force, the most tensile load with an equilibrium (pull_off_n in
    /// contact.json), by a sweep of the separation from the equilibrium at zero load (tens of
    /// solves at imposed separation: at 512² it costs about 30 times the loads' solves).
    #[arg(long, requires = "adhesion_work")]
    pub pull_off: bool,
}

impl AdhesionArgs {
    /// The cohesive law given, if any; a refusal names the option.
    pub fn law(&self) -> Result<Option<CohesiveLaw>> {
        let Some(w) = self.adhesion_work else { return Ok(None) };
        let law = CohesiveLaw::from_options(&self.adhesion_law, w, self.adhesion_stress, self.adhesion_range)?;
        super::judge("--adhesion-work", plausible::adhesion_work(w, Spelling::CommandLine))?;
        if let Some(s) = self.adhesion_stress {
            super::judge("--adhesion-stress", plausible::adhesion_stress(s, Spelling::CommandLine))?;
        }
        if let Some(r) = self.adhesion_range {
            super::judge("--adhesion-range", plausible::adhesion_range(r, Spelling::CommandLine))?;
        }
        Ok(Some(law))
    }
}

/// The cohesive law in `DIR/contact.json`.
#[derive(Serialize)]
struct AdhesionEntry {
    law: &'static str,
    work_j_m2: f64,
    /// σ₀, or the exponential law's peak tension w/ρ.
    stress_pa: f64,
    /// h₀ = w/σ₀, or the exponential law's ρ.
    range_m: f64,
}

/// `DIR/contact.json`.
#[derive(Serialize)]
struct ContactFile {
    surface: PathBuf,
    channel: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    wafer: Option<PathBuf>,
    grid: [usize; 2],
    physical_size_m: [f64; 2],
    effective_modulus_pa: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    hardness_pa: Option<f64>,
    boundary: &'static str,
    /// Whether the pressure was capped at the hardness (elastic–perfectly-plastic).
    plastic: bool,
    tolerance: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    adhesion: Option<AdhesionEntry>,
    /// The pull-off force [N] (negative), with --pull-off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pull_off_n: Option<f64>,
    loads: Vec<LoadEntry>,
    /// Plausibility warnings, one line each, as printed on stderr.
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct LoadEntry {
    load_n: f64,
    mean_pressure_pa: f64,
    contact_fraction: f64,
    contact_area_m2: f64,
    contact_points: usize,
    patches: usize,
    largest_patch_points: usize,
    max_pressure_pa: f64,
    edge_load_fraction: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    load_above_hardness_fraction: Option<f64>,
    /// With adhesion: N_c, the integral of the compressive pressure [N].
    #[serde(skip_serializing_if = "Option::is_none")]
    compressive_force_n: Option<f64>,
    /// With adhesion: N_a = N_c − N, the integral of the tension, positive [N].
    #[serde(skip_serializing_if = "Option::is_none")]
    adhesive_force_n: Option<f64>,
    /// With adhesion: points at zero gap (contact_points counts those with compressive traction).
    #[serde(skip_serializing_if = "Option::is_none")]
    touching_points: Option<usize>,
    /// With adhesion: the separation [m] (mean gap periodic; free, the rigid body's position
    /// from first touch).
    #[serde(skip_serializing_if = "Option::is_none")]
    separation_m: Option<f64>,
    iterations: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    operator_applications: Option<f64>,
    residual: f64,
    seconds: f64,
    pressure_file: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    traction_file: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gap_file: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    displacement_file: Option<String>,
}

pub fn run(args: ContactArgs) -> Result<()> {
    // Every check before any long work.
    let law = args.adhesion.law()?;
    match law {
        None => contact::check_loads(&args.load)?,
        Some(_) => {
            if let Some(load) = args.load.iter().find(|l| !l.is_finite()) {
                return Err(Error::invalid("--load", format!("loads must be finite, got {load} N")));
            }
            if args.plastic {
                return Err(Error::invalid("--plastic", "is not solved with adhesion (--adhesion-work)"));
            }
            if args.device.device != Device::Cpu {
                return Err(Error::invalid("--device", "adhesive contact (--adhesion-work) runs on the CPU"));
            }
        }
    }
    let (_, e_star) = args.material.bodies()?;
    if let Some(p) = args.pixel_size {
        super::judge("--pixel-size", plausible::pixel(p, Spelling::CommandLine))?;
    }
    if let Some(r) = args.cap_radius {
        super::judge("--cap-radius", plausible::radius(r, Spelling::CommandLine))?;
    }
    let options = SolverOptions {
        convergence: Convergence { tolerance: args.tolerance, max_iterations: args.max_iter },
        device: args.device.device,
    };
    options.convergence.check()?;
    let path = &args.read.file;
    let mut surface = prepare(&args)?;
    let size = contact::contact_size(&surface)?;
    if args.plastic && args.hardness.is_none() {
        return Err(Error::invalid("--plastic", "needs --hardness H, the cap on the pressure"));
    }
    if let Some(h) = args.hardness {
        if !(h > 0.0 && h.is_finite()) {
            return Err(Error::invalid("--hardness", format!("must be positive and finite, got {h} Pa")));
        }
        super::judge("--hardness", plausible::hardness(h, Spelling::CommandLine))?;
        let heaviest = args.load.iter().copied().fold(0.0, f64::max);
        if args.plastic && heaviest / (size.0 * size.1) >= h {
            return Err(Error::invalid(
                "--hardness",
                format!("{h:e} Pa cannot carry {heaviest:e} N on the {:e} m² window", size.0 * size.1),
            ));
        }
    }
    // With adhesion a load may be zero or tensile: its size is what is judged.
    for load in
        args.load.iter().map(|l| if law.is_some() { l.abs() } else { *l }).filter(|l| *l != 0.0 || law.is_none())
    {
        contact::check_load(load, size, e_star)?;
        super::judge("--load", plausible::load(load, size, e_star, Spelling::CommandLine))?;
    }
    let boundary = args.material.boundary();
    if let Some(law) = law {
        return run_adhesive(&args, surface, size, e_star, law);
    }
    let shape = (surface.ny(), surface.nx());
    let heights = surface.heights.as_standard_layout();
    // The solver's refusals (its memory, a grid too small) are of the file read.
    let mut solver =
        ContactSolver::new(heights.as_slice().expect("standard layout"), shape, size, e_star, boundary, options)
            .map_err(|e| match e {
                Error::Invalid { option, reason } if option == "surface" => Error::file(&path, reason),
                e => e,
            })?;
    // The solver keeps its own copy of the heights.
    drop(heights);
    surface.heights = ndarray::Array2::zeros((0, 0));
    solver.set_hardness(args.hardness.filter(|_| args.plastic))?;

    let inputs: Vec<&Path> = std::iter::once(path.as_path()).chain(args.wafer.as_deref()).collect();
    let out = StagedDir::new(&args.out, "contact", &inputs)?;
    let mut order: Vec<usize> = (0..args.load.len()).collect();
    order.sort_by(|&a, &b| args.load[a].total_cmp(&args.load[b]));
    let bar = super::progress_bar(args.load.len() as u64, "solving", true);
    let mut entries: Vec<Option<LoadEntry>> = (0..args.load.len()).map(|_| None).collect();
    let mut warnings = Vec::new();
    // The ways left to keep a contact inside the window: those not taken already.
    let remedies = remedies(&args);
    for index in order {
        let load = args.load[index];
        let shown = show(load, &FORCE);
        bar.set_message(shown.clone());
        let report = solver.solve(load, |it, residual| {
            if it % 16 == 0 {
                bar.set_message(format!("{shown}, iteration {it}, residual {residual:.1e}"));
            }
        })?;
        let summary = contact::summarize(solver.pressure(), shape, size, boundary, args.hardness);
        for w in summary.warnings(&remedies) {
            bar.suspend(|| super::message(&format!("warning: at {shown}: {w}")));
            warnings.push(format!("at {shown}: {w}"));
        }
        let to_field = |v: Vec<f64>| ndarray::Array2::from_shape_vec(shape, v).expect("field has the grid's shape");
        let pressure_file = format!("pressure-{index:03}.npy");
        output::write_npy(&out.path(&pressure_file), &to_field(solver.pressure().to_vec()))?;
        let (gap_file, displacement_file) = if args.fields {
            write_fields(&out, index, to_field(solver.gap()), to_field(solver.displacement()))?
        } else {
            (None, None)
        };
        entries[index] = Some(LoadEntry {
            load_n: load,
            mean_pressure_pa: report.mean_pressure,
            contact_fraction: summary.contact_fraction,
            contact_area_m2: summary.contact_area,
            contact_points: summary.contact_points,
            patches: summary.patch_sizes.len(),
            largest_patch_points: summary.patch_sizes.first().copied().unwrap_or(0),
            max_pressure_pa: summary.max_pressure,
            edge_load_fraction: summary.edge_load_fraction,
            load_above_hardness_fraction: summary.load_above_hardness_fraction,
            compressive_force_n: None,
            adhesive_force_n: None,
            touching_points: None,
            separation_m: None,
            iterations: report.iterations,
            operator_applications: Some(report.operator_applications),
            residual: report.residual,
            seconds: report.seconds,
            pressure_file,
            traction_file: None,
            gap_file,
            displacement_file,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let file = ContactFile {
        surface: path.clone(),
        channel: surface.channel.clone(),
        wafer: args.wafer.clone(),
        grid: [shape.0, shape.1],
        physical_size_m: [size.0, size.1],
        effective_modulus_pa: e_star,
        hardness_pa: args.hardness,
        boundary: boundary.name(),
        plastic: args.plastic,
        tolerance: args.tolerance,
        adhesion: None,
        pull_off_n: None,
        loads: entries.into_iter().map(|e| e.expect("every load solved")).collect(),
        warnings,
    };
    finish(out, &file)
}

/// Write contact.json, commit the output and print the table.
/// Write load `index`'s gap and displacement maps \[m] (`--fields`); their file names.
fn write_fields(
    out: &StagedDir,
    index: usize,
    gap: ndarray::Array2<f64>,
    displacement: ndarray::Array2<f64>,
) -> Result<(Option<String>, Option<String>)> {
    let (g, d) = (format!("gap-{index:03}.npy"), format!("displacement-{index:03}.npy"));
    output::write_npy(&out.path(&g), &gap)?;
    output::write_npy(&out.path(&d), &displacement)?;
    Ok((Some(g), Some(d)))
}

fn finish(out: StagedDir, file: &ContactFile) -> Result<()> {
    output::write_json(&out.path("contact.json"), file)?;
    let dir = super::commit(out)?;
    super::print(&load_table(&file.loads))?;
    if let Some(p) = file.pull_off_n {
        super::print(&format!("pull-off force: {}\n", show(p, &FORCE)))?;
    }
    super::message(&format!("wrote {}", dir.join("contact.json").display()));
    Ok(())
}

/// The ways left to keep a contact inside the window: those not taken already.
fn remedies(args: &ContactArgs) -> Vec<String> {
    [
        (!args.material.free, "a free boundary (--free)"),
        (args.prepare.crop.is_none(), "a crop (--crop)"),
        (args.prepare.detrend == Detrend::None, "a detrend (--detrend)"),
        (args.cap_radius.is_none(), "a cap (--cap-radius)"),
    ]
    .into_iter()
    .filter(|(left, _)| *left)
    .map(|(_, remedy)| remedy.to_string())
    .collect()
}

/// `asperity contact` with a cohesive law: the loads from the largest down, each from the last
/// state, then the pull-off force if asked.
fn run_adhesive(
    args: &ContactArgs,
    mut surface: asperity::topography::Topography,
    size: (f64, f64),
    e_star: f64,
    law: CohesiveLaw,
) -> Result<()> {
    let path = &args.read.file;
    let boundary = args.material.boundary();
    let shape = (surface.ny(), surface.nx());
    let convergence = Convergence { tolerance: args.tolerance, max_iterations: args.max_iter };
    let heights = surface.heights.as_standard_layout();
    let mut solver = AdhesiveSolver::new(
        heights.as_slice().expect("standard layout"),
        shape,
        size,
        e_star,
        boundary,
        law,
        convergence,
    )
    .map_err(|e| match e {
        Error::Invalid { option, reason } if option == "surface" => Error::file(path, reason),
        e => e,
    })?;
    drop(heights);
    surface.heights = ndarray::Array2::zeros((0, 0));
    let inputs: Vec<&Path> = std::iter::once(path.as_path()).chain(args.wafer.as_deref()).collect();
    let out = StagedDir::new(&args.out, "contact", &inputs)?;
    let mut order: Vec<usize> = (0..args.load.len()).collect();
    order.sort_by(|&a, &b| args.load[b].total_cmp(&args.load[a]));
    let bar = super::progress_bar(args.load.len() as u64, "solving", true);
    let mut entries: Vec<Option<LoadEntry>> = (0..args.load.len()).map(|_| None).collect();
    let mut warnings = Vec::new();
    let remedies = remedies(args);
    let to_field = |v: Vec<f64>| ndarray::Array2::from_shape_vec(shape, v).expect("field has the grid's shape");
    for index in order {
        let load = args.load[index];
        let shown = show(load, &FORCE);
        bar.set_message(shown.clone());
        let report = solver.solve(load)?;
        let pressure = solver.compressive_pressure();
        let summary = contact::summarize(&pressure, shape, size, boundary, args.hardness);
        let mut said = summary.warnings(&remedies);
        said.extend(contact::edge_tension_warning(solver.edge_tension()));
        for w in said {
            bar.suspend(|| super::message(&format!("warning: at {shown}: {w}")));
            warnings.push(format!("at {shown}: {w}"));
        }
        let (pressure_file, traction_file) = (format!("pressure-{index:03}.npy"), format!("traction-{index:03}.npy"));
        output::write_npy(&out.path(&pressure_file), &to_field(pressure))?;
        output::write_npy(&out.path(&traction_file), &to_field(solver.traction()))?;
        let (gap_file, displacement_file) = if args.fields {
            write_fields(&out, index, to_field(solver.gap()), to_field(solver.displacement()))?
        } else {
            (None, None)
        };
        entries[index] = Some(LoadEntry {
            load_n: load,
            mean_pressure_pa: report.load / (size.0 * size.1),
            contact_fraction: summary.contact_fraction,
            contact_area_m2: summary.contact_area,
            contact_points: summary.contact_points,
            patches: summary.patch_sizes.len(),
            largest_patch_points: summary.patch_sizes.first().copied().unwrap_or(0),
            max_pressure_pa: summary.max_pressure,
            edge_load_fraction: summary.edge_load_fraction,
            load_above_hardness_fraction: summary.load_above_hardness_fraction,
            compressive_force_n: Some(report.compressive_force),
            adhesive_force_n: Some(report.adhesive_force),
            touching_points: Some(report.contact_points),
            separation_m: Some(report.separation),
            iterations: report.iterations,
            operator_applications: None,
            residual: report.residual,
            seconds: report.seconds,
            pressure_file,
            traction_file: Some(traction_file),
            gap_file,
            displacement_file,
        });
        bar.inc(1);
    }
    let pull_off_n = if args.adhesion.pull_off {
        bar.set_message("pull-off");
        Some(solver.pull_off()?.load)
    } else {
        None
    };
    bar.finish_and_clear();
    let file = ContactFile {
        surface: path.clone(),
        channel: surface.channel.clone(),
        wafer: args.wafer.clone(),
        grid: [shape.0, shape.1],
        physical_size_m: [size.0, size.1],
        effective_modulus_pa: e_star,
        hardness_pa: args.hardness,
        boundary: boundary.name(),
        plastic: false,
        tolerance: args.tolerance,
        adhesion: Some(AdhesionEntry {
            law: law.name(),
            work_j_m2: law.work(),
            stress_pa: law.strength(),
            range_m: law.range(),
        }),
        pull_off_n,
        loads: entries.into_iter().map(|e| e.expect("every load solved")).collect(),
        warnings,
    };
    finish(out, &file)
}

/// One line per load, in the order given: what each solve found.
fn load_table(loads: &[LoadEntry]) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "{:<12} {:>14} {:>8} {:>13} {:>10}\n",
        "load", "contact points", "patches", "max pressure", "edge load"
    );
    for l in loads {
        let _ = writeln!(
            s,
            "{:<12} {:>14} {:>8} {:>13} {:>8.2} %",
            show(l.load_n, &FORCE),
            l.contact_points,
            l.patches,
            show(l.max_pressure_pa, &PRESSURE),
            100.0 * l.edge_load_fraction
        );
    }
    s
}

/// The surface as the solver takes it: read, prepared ([`Preparation`]) and compounded with
/// the wafer, if any; errors name the file or the option.
fn prepare(args: &ContactArgs) -> Result<asperity::topography::Topography> {
    let mut prep = args.prepare.preparation();
    prep.pixel_size = args.pixel_size;
    prep.cap = args.cap_radius.map(|radius| Cap { radius, shape: CapShape::Sphere });
    // The cap's checks name the option of `topo generate`; here it is --cap-radius.
    let renamed = |e: Error| match e {
        Error::Invalid { option, reason } if option == "--sphere-radius" => Error::invalid("--cap-radius", reason),
        other => other,
    };
    let surface = prep.apply(io::read(&args.read.file, &args.read.options())?).map_err(renamed)?;
    let wafer =
        match &args.wafer {
            Some(file) => {
                let level =
                    Preparation { fill_missing: prep.fill_missing, detrend: prep.detrend, ..Preparation::default() };
                Some(level.apply(io::read(
                    file,
                    &ReadOptions { limits: args.read.limits.limits(), ..ReadOptions::default() },
                )?)?)
            }
            None => None,
        };
    compound_with(surface, wafer)
}
