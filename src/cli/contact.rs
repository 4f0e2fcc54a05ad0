//! `asperity contact`: elastic normal contact of a topography at one or more loads.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;

use asperity::contact::{self, Boundary, ContactSolver, Material, SolverOptions};
use asperity::output::{self, StagedDir};
use asperity::topography::{io, Topography};
use asperity::{Error, Result};

use super::ReadArgs;

/// Press a rigid rough surface on an elastic half-space (boundary integral method,
/// Polonsky–Keer conjugate gradient at imposed load) and write the pressure maps.
///
/// Writes DIR/contact.json and one DIR/pressure-NNN.npy (float64, Pa, shape ny×nx) per load,
/// numbered in the order the loads are given. Loads are solved in increasing order, each
/// starting from the previous solution.
#[derive(Args)]
pub struct ContactArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// Normal load [N, or with a unit: 1mN]; repeat for a sweep (--load 1e-4 --load 1e-3 …) or
    /// give a list (0.1mN,1mN).
    #[arg(long, value_name = "N", required = true, value_delimiter = ',', allow_negative_numbers = true, value_parser = super::force)]
    load: Vec<f64>,
    /// Young's modulus of the elastic body [Pa, or with a unit: 130GPa] (default: silicon).
    #[arg(long, value_name = "E", default_value_t = Material::SILICON.youngs, allow_negative_numbers = true, value_parser = super::pressure)]
    youngs: f64,
    /// Poisson's ratio of the elastic body, in (−1, 0.5) (default: silicon).
    #[arg(long, value_name = "NU", default_value_t = Material::SILICON.poisson, allow_negative_numbers = true)]
    poisson: f64,
    /// Young's modulus of a second elastic body [Pa]; with --poisson2, the two combine as
    /// 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2. Without it the counter-body is rigid.
    #[arg(long, value_name = "E2", requires = "poisson2", allow_negative_numbers = true, value_parser = super::pressure)]
    youngs2: Option<f64>,
    /// Poisson's ratio of the second elastic body.
    #[arg(long, value_name = "NU2", requires = "youngs2", allow_negative_numbers = true)]
    poisson2: Option<f64>,
    /// Free (non-periodic) boundary: the window is an isolated patch of an infinite half-space,
    /// as for a sphere on a flat. Default: periodic.
    #[arg(long)]
    free: bool,
    /// Convergence tolerance on the solver's relative residual (complementarity and
    /// penetration, relative to mean pressure × RMS height).
    #[arg(long, value_name = "T", default_value = "1e-10")]
    tolerance: f64,
    /// Iteration limit per load; a solve that has not converged by then is an error.
    #[arg(long, value_name = "K", default_value_t = SolverOptions::default().max_iterations)]
    max_iter: usize,
    /// Also write gap-NNN.npy and displacement-NNN.npy [m] for each load.
    #[arg(long)]
    fields: bool,
    /// Output directory (replaced as a whole when the run completes; nothing is left behind
    /// by a failed run).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// `DIR/contact.json`.
#[derive(Serialize)]
struct ContactFile {
    surface: PathBuf,
    channel: String,
    grid: [usize; 2],
    physical_size_m: [f64; 2],
    effective_modulus_pa: f64,
    boundary: &'static str,
    tolerance: f64,
    loads: Vec<LoadEntry>,
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
    iterations: usize,
    operator_applications: f64,
    residual: f64,
    seconds: f64,
    pressure_file: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    gap_file: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    displacement_file: Option<String>,
}

pub fn run(args: ContactArgs) -> Result<()> {
    // Every check before any long work.
    for &load in &args.load {
        if !(load > 0.0 && load.is_finite()) {
            return Err(Error::invalid("--load", format!("loads must be positive and finite, got {load} N")));
        }
    }
    let body = Material::new(args.youngs, args.poisson, "--youngs/--poisson")?;
    let e_star = match (args.youngs2, args.poisson2) {
        (Some(e2), Some(nu2)) => contact::combined_modulus(&body, &Material::new(e2, nu2, "--youngs2/--poisson2")?),
        _ => body.plane_strain_modulus(),
    };
    let path = &args.read.file;
    let surface = io::read(path, &args.read.options())?;
    let size = ready_for_contact(&surface, path)?;
    let boundary = if args.free { Boundary::Free } else { Boundary::Periodic };
    let options = SolverOptions { tolerance: args.tolerance, max_iterations: args.max_iter };
    let shape = (surface.ny(), surface.nx());
    let heights = surface.heights.as_standard_layout();
    let mut solver =
        ContactSolver::new(heights.as_slice().expect("standard layout"), shape, size, e_star, boundary, options)?;

    let out = StagedDir::new(&args.out)?;
    let mut order: Vec<usize> = (0..args.load.len()).collect();
    order.sort_by(|&a, &b| args.load[a].total_cmp(&args.load[b]));
    let bar = super::progress_bar(args.load.len() as u64, "solving");
    let mut entries: Vec<Option<LoadEntry>> = (0..args.load.len()).map(|_| None).collect();
    for index in order {
        let load = args.load[index];
        bar.set_message(format!("{load:.3e} N"));
        let report = solver.solve(load, |it, residual| {
            if it % 16 == 0 {
                bar.set_message(format!("{load:.3e} N, iteration {it}, residual {residual:.1e}"));
            }
        })?;
        let summary = contact::summarize(solver.pressure(), shape, size, boundary);
        let to_field = |v: Vec<f64>| ndarray::Array2::from_shape_vec(shape, v).expect("field has the grid's shape");
        let pressure_file = format!("pressure-{index:03}.npy");
        output::write_npy(&out.path(&pressure_file), &to_field(solver.pressure().to_vec()))?;
        let (gap_file, displacement_file) = if args.fields {
            let (g, d) = (format!("gap-{index:03}.npy"), format!("displacement-{index:03}.npy"));
            output::write_npy(&out.path(&g), &to_field(solver.gap()))?;
            output::write_npy(&out.path(&d), &to_field(solver.displacement()))?;
            (Some(g), Some(d))
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
            iterations: report.iterations,
            operator_applications: report.operator_applications,
            residual: report.residual,
            seconds: report.seconds,
            pressure_file,
            gap_file,
            displacement_file,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let file = ContactFile {
        surface: path.clone(),
        channel: surface.channel.clone(),
        grid: [shape.0, shape.1],
        physical_size_m: [size.0, size.1],
        effective_modulus_pa: e_star,
        boundary: boundary.name(),
        tolerance: args.tolerance,
        loads: entries.into_iter().map(|e| e.expect("every load solved")).collect(),
    };
    output::write_json(&out.path("contact.json"), &file)?;
    let dir = out.commit()?;
    eprintln!("wrote {}", dir.join("contact.json").display());
    Ok(())
}

/// The physical size of a surface that the contact solver can take, or a one-line reason
/// naming the file.
pub fn ready_for_contact(surface: &Topography, path: &std::path::Path) -> Result<(f64, f64)> {
    let bad = surface.heights.iter().filter(|h| !h.is_finite()).count();
    if bad > 0 {
        return Err(Error::file(
            path,
            format!("{bad} heights are missing, NaN or infinite: fill them (asperity topo convert --fill-missing) or crop them away"),
        ));
    }
    if surface.nx() < 2 || surface.ny() < 2 {
        return Err(Error::file(
            path,
            format!("a {}×{} grid is too small for contact: at least 2×2 points", surface.ny(), surface.nx()),
        ));
    }
    surface
        .physical_size
        .ok_or_else(|| Error::file(path, "the file states no physical size: give it with --size LX[,LY] (metres)"))
}
