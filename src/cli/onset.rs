//! `asperity onset`: the stick-slip transition model on one contact pressure map.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::{Path, PathBuf};

use asperity::error::escaped;
use asperity::friction::{write_curves_csv, ClassShare, Curve, ElementLoads, FrictionLaw, Loading, Onset};
use asperity::limits::Limits;
use asperity::output::{write_json, write_npy, StagedDir};
use asperity::plausible::{self, Spelling};
use asperity::quantity::{human, show, FORCE};
use asperity::study::config::MAX_SNAPSHOT_FRACTIONS;
use asperity::topography::io::ReadOptions;
use asperity::topography::AnyTopography;
use asperity::{Error, Result};
use ndarray::Array2;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit,
// `<f>` stands for a value.
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
/// Static friction, friction drop and element classes from a pressure map (stick-slip model).
///
/// The static friction coefficient, the friction drop and the critical, pre-sliding and
/// subcritical elements at the onset of sliding (the stick-slip transition model with equal
/// load sharing), from a contact pressure map.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A pressure map PRESSURE.npy [Pa], shape (ny, nx), or the output directory of
    /// `asperity contact` (its contact.json and pressure files).
    pub input: PathBuf,
    /// Local static friction coefficient mu_s (dimensionless, ≥ mu_d).
    #[arg(long, allow_negative_numbers = true)]
    pub mu_s: Option<f64>,
    /// Local dynamic friction coefficient mu_d (dimensionless, > 0).
    #[arg(long, allow_negative_numbers = true)]
    pub mu_d: Option<f64>,
    /// Name of the local law. Alone, a preset: "hold 100 s" or "hold 10 s" (ILLUSTRATIVE
    /// placeholder values, not the paper's measurements); with --mu-s/--mu-d or --curve, a
    /// label for that law.
    #[arg(long)]
    pub law: Option<String>,
    /// A measured nanoscale friction curve, CSV of (displacement, friction coefficient):
    /// mu_s is its peak, mu_d its mean over --window after the peak.
    #[arg(long, conflicts_with_all = ["mu_s", "mu_d"])]
    pub curve: Option<PathBuf>,
    /// START,END past the peak of --curve over which mu_d is averaged, in the curve's
    /// displacement unit [default: every point after the peak].
    #[arg(long, requires = "curve", value_delimiter = ',', value_name = "START,END", allow_hyphen_values = true)]
    pub window: Option<Vec<f64>>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write onset.json, classes.npy (int8: 0 no contact, 1 pre-sliding, 2 critical,
    /// 3 subcritical), stress_ratio.npy (float64, NaN out of contact), curve.csv and
    /// stress_ratio_<f>.npy snapshots and a manifest.json into this directory: a new or empty
    /// folder, or an earlier output of `asperity onset`, replaced as a whole.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Area of one pixel of a bare PRESSURE.npy [m², or with a unit: 400nm^2] (only forces in
    /// newtons need it).
    #[arg(long, conflicts_with = "size", value_name = "A", value_parser = super::area)]
    pub pixel_area: Option<f64>,
    /// Physical size LX[,LY] of a bare PRESSURE.npy [m, or with a unit: 31.13um] (LY defaults
    /// to LX), for forces in newtons.
    #[arg(long, value_delimiter = ',', value_name = "LX[,LY]", value_parser = super::length)]
    pub size: Option<Vec<f64>>,
    /// Which load of a contact directory: 0-based index into contact.json "loads" [default:
    /// every load, one line each (--json: a list of reports); --out needs one].
    #[arg(long, value_name = "K", value_parser = super::count::<usize>)]
    pub load_index: Option<usize>,
    /// Displacements δ/δ_peak (dimensionless, in (0, 1]) of the stress-ratio snapshots
    /// written with --out.
    #[arg(long, value_delimiter = ',', default_value = "0.25,0.5,0.75,1", allow_hyphen_values = true)]
    pub snapshots: Vec<f64>,
    /// Shear stiffness k_t of one element [N/m, or with a unit: 5mN/um]: curve.csv then
    /// states δ = s / k_t in metres (its delta_m column); without it that column is empty.
    #[arg(long, value_name = "K_T", value_parser = super::stiffness)]
    pub shear_stiffness: Option<f64>,
    /// Most rows per loading mode in curve.csv (the peak is always kept exactly).
    #[arg(long, value_name = "ROWS", default_value_t = 2000, value_parser = super::count::<usize>)]
    pub curve_rows: usize,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// The part of `asperity contact`'s contact.json this command reads.
#[derive(Deserialize)]
struct ContactResult {
    grid: [usize; 2],
    physical_size_m: [f64; 2],
    loads: Vec<ContactLoad>,
}

#[derive(Deserialize)]
struct ContactLoad {
    load_n: f64,
    pressure_file: String,
}

/// A pressure map and what is known of it.
struct Input {
    pressure: Array2<f64>,
    path: PathBuf,
    /// \[m²]; `None` for a bare map without --size or --pixel-area.
    pixel_area: Option<f64>,
    /// The load index and its imposed load \[N], for a contact directory.
    load: Option<(usize, f64)>,
}

#[derive(Serialize)]
struct LawReport<'a> {
    name: Option<&'a str>,
    mu_s: f64,
    mu_d: f64,
}

/// onset.json, and what --json prints.
#[derive(Serialize)]
struct Report<'a> {
    input: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    load_index: Option<usize>,
    law: LawReport<'a>,
    elements: usize,
    static_coefficient: f64,
    dynamic_coefficient: f64,
    friction_drop: f64,
    critical: ClassShare,
    pre_sliding: ClassShare,
    subcritical: ClassShare,
    /// k*: how many elements slipped before the peak.
    critical_index: usize,
    /// Pressure of the critical elements \[Pa].
    critical_pressure_pa: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pixel_area_m2: Option<f64>,
    /// N = Σ p_i · a \[N].
    #[serde(skip_serializing_if = "Option::is_none")]
    load_n: Option<f64>,
    /// The imposed load of the contact solve \[N].
    #[serde(skip_serializing_if = "Option::is_none")]
    imposed_load_n: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    static_force_n: Option<f64>,
    /// s* = mu_s · n_(k*): the shear of each stuck element at the peak \[N] (= k_t · δ_peak).
    #[serde(skip_serializing_if = "Option::is_none")]
    critical_shear_n: Option<f64>,
}

pub fn run(args: Args) -> Result<()> {
    let law = friction_law(&args)?;
    if let Some(f) = args.snapshots.iter().find(|f| !(**f > 0.0 && **f <= 1.0)) {
        return Err(Error::invalid("--snapshots", format!("δ/δ_peak must lie in (0, 1], got {f}")));
    }
    // Each snapshot is a map of the whole grid (12 at 1500² are 216 MB).
    if args.snapshots.len() > MAX_SNAPSHOT_FRACTIONS {
        return Err(Error::invalid(
            "--snapshots",
            format!(
                "{} fractions: at most {MAX_SNAPSHOT_FRACTIONS}, as a study's snapshot_fractions (each is a map of the grid)",
                args.snapshots.len()
            ),
        ));
    }
    let inputs = read_inputs(&args)?;
    if let (Some(_), [_, _, ..]) = (&args.out, &inputs[..]) {
        return Err(Error::invalid(
            "--out",
            format!(
                "writes the maps of one load, and the input {} holds {}: choose it with --load-index",
                args.input.display(),
                inputs.len()
            ),
        ));
    }
    let mut reports = Vec::with_capacity(inputs.len());
    for input in &inputs {
        // Without a pixel area the maps and coefficients are the same; only newtons are unknown.
        let area = input.pixel_area.unwrap_or(1.0);
        let loads = ElementLoads::from_pressure(&input.pressure, area).map_err(|e| match e {
            Error::Invalid { option, reason } if option == "pressure map" => Error::file(&input.path, reason),
            e => e,
        })?;
        let onset = Onset::new(&loads, &law);
        let report = report(input, &law, &onset)?;
        if let Some(dir) = &args.out {
            // Inputs are never outputs: the pressure map read and the curve too.
            let read: Vec<&Path> =
                [args.input.as_path(), input.path.as_path()].into_iter().chain(args.curve.as_deref()).collect();
            let staged = StagedDir::new(dir, "onset", &read)?;
            write_json(&staged.path("onset.json"), &report)?;
            write_npy(&staged.path("classes.npy"), &onset.class_map(&input.pressure, area))?;
            write_npy(&staged.path("stress_ratio.npy"), &onset.stress_ratio_map(&input.pressure, area, 1.0)?)?;
            let curves: Vec<Curve> =
                Loading::ALL.iter().map(|&m| Curve::new(&loads, &law, m, args.curve_rows)).collect();
            write_curves_csv(
                &staged.path("curve.csv"),
                &curves,
                onset.critical_shear(),
                input.pixel_area.is_some(),
                args.shear_stiffness,
            )?;
            for &f in &args.snapshots {
                let map = onset.stress_ratio_map(&input.pressure, area, f)?;
                write_npy(&staged.path(&format!("stress_ratio_{f}.npy")), &map)?;
            }
            super::commit(staged)?;
        }
        reports.push(report);
    }
    match (&reports[..], args.json) {
        ([one], true) => super::print_json(one),
        ([one], false) => super::print(&summary(one)),
        (all, true) => super::print_json(&all),
        (all, false) => super::print(&table(all)),
    }
}

/// The report of `onset` on `input`; an error naming the input when a number of it is not
/// finite (forces past the largest float), rather than printing it.
fn report<'a>(input: &Input, law: &'a FrictionLaw, onset: &Onset) -> Result<Report<'a>> {
    let area = input.pixel_area.unwrap_or(1.0);
    let newtons = |x: f64| input.pixel_area.map(|_| x);
    let report = Report {
        input: input.path.display().to_string(),
        load_index: input.load.map(|l| l.0),
        law: LawReport { name: law.name.as_deref(), mu_s: law.mu_s, mu_d: law.mu_d },
        elements: onset.elements,
        static_coefficient: onset.static_coefficient(),
        dynamic_coefficient: onset.dynamic_coefficient(),
        friction_drop: onset.friction_drop(),
        critical: onset.critical,
        pre_sliding: onset.pre_sliding,
        subcritical: onset.subcritical,
        critical_index: onset.critical_index,
        critical_pressure_pa: onset.critical_normal_force / area,
        pixel_area_m2: input.pixel_area,
        load_n: newtons(onset.normal_force),
        imposed_load_n: input.load.map(|l| l.1),
        static_force_n: newtons(onset.static_force),
        critical_shear_n: newtons(onset.critical_shear()),
    };
    let numbers = [
        ("the static coefficient", Some(report.static_coefficient)),
        ("the friction drop", Some(report.friction_drop)),
        ("the critical pressure [Pa]", Some(report.critical_pressure_pa)),
        ("the normal load [N]", report.load_n),
        ("the static friction force [N]", report.static_force_n),
        ("the critical shear [N]", report.critical_shear_n),
    ];
    if let Some((what, Some(v))) = numbers.into_iter().find(|(_, v)| v.is_some_and(|v| !v.is_finite())) {
        return Err(Error::file(
            &input.path,
            format!("{what} comes out as {v}: the forces of this map pass the largest float (check its unit and the pixel size)"),
        ));
    }
    Ok(report)
}

/// The local law from --mu-s/--mu-d, --curve or a preset --law, labelled by --law.
fn friction_law(args: &Args) -> Result<FrictionLaw> {
    law_from_options(args.mu_s, args.mu_d, args.curve.as_deref(), args.window.as_deref(), args.law.as_deref())
}

/// The local law from the options --mu-s, --mu-d, --curve (with --window) and --law, as every
/// command that takes a law reads them.
pub fn law_from_options(
    mu_s: Option<f64>,
    mu_d: Option<f64>,
    curve: Option<&Path>,
    window: Option<&[f64]>,
    name: Option<&str>,
) -> Result<FrictionLaw> {
    let window = match window {
        None => None,
        Some(&[start, end]) => Some((start, end)),
        Some(w) => return Err(Error::invalid("--window", format!("expected START,END, got {} values", w.len()))),
    };
    let law = match (mu_s, mu_d, curve, name) {
        (Some(mu_s), Some(mu_d), _, _) => {
            super::judge("--mu-s", plausible::friction_coefficient(mu_s))?;
            super::judge("--mu-d", plausible::friction_coefficient(mu_d))?;
            FrictionLaw::new(mu_s, mu_d)?
        }
        (Some(_), None, _, _) => return Err(Error::invalid("--mu-s", "needs --mu-d too")),
        (None, Some(_), _, _) => return Err(Error::invalid("--mu-d", "needs --mu-s too")),
        (_, _, Some(path), _) => FrictionLaw::from_curve_file(path, window)?,
        (_, _, None, Some(name)) => return FrictionLaw::preset(name),
        _ => {
            return Err(Error::invalid(
                "--mu-s",
                "give the local friction law: --mu-s and --mu-d, --curve FILE.csv, or a preset --law NAME",
            ))
        }
    };
    Ok(match name {
        Some(name) => law.named(name),
        None => law,
    })
}

/// The maps to run: a bare map, or the loads of a contact directory (every one, or
/// --load-index's).
fn read_inputs(args: &Args) -> Result<Vec<Input>> {
    if args.input.is_dir() {
        if args.size.is_some() || args.pixel_area.is_some() {
            let option = if args.size.is_some() { "--size" } else { "--pixel-area" };
            return Err(Error::invalid(option, "not used with a contact directory: its contact.json gives the size"));
        }
        return read_contact_dir(&args.input, args.load_index, &args.limits.limits());
    }
    if args.load_index.is_some() {
        return Err(Error::invalid("--load-index", "only a contact directory holds several loads"));
    }
    let pressure = read_pressure(&args.input, &args.limits.limits())?;
    let (ny, nx) = pressure.dim();
    let pixel_area = match (&args.size, args.pixel_area) {
        (Some(size), _) => {
            let (lx, ly) = match size[..] {
                [lx] => (lx, lx),
                [lx, ly] => (lx, ly),
                _ => return Err(Error::invalid("--size", format!("expected LX[,LY], got {} values", size.len()))),
            };
            if !(lx.is_finite() && ly.is_finite() && lx > 0.0 && ly > 0.0) {
                return Err(Error::invalid("--size", format!("sizes must be positive and finite, got {lx},{ly} m")));
            }
            for l in [lx, ly] {
                super::judge("--size", plausible::window(l, Spelling::CommandLine))?;
            }
            Some(lx / nx as f64 * (ly / ny as f64))
        }
        (None, Some(a)) => {
            if !(a.is_finite() && a > 0.0) {
                return Err(Error::invalid("--pixel-area", format!("must be positive and finite, got {a} m²")));
            }
            Some(a)
        }
        (None, None) => None,
    };
    Ok(vec![Input { pressure, path: args.input.clone(), pixel_area, load: None }])
}

pub fn read_pressure(path: &Path, limits: &Limits) -> Result<Array2<f64>> {
    let bytes = limits.read_file(path)?;
    let pressure = asperity::topography::io::npy::read_f64(&bytes).map_err(|r| not_a_pressure_map(path, limits, r))?;
    limits.check_grid(pressure.ncols(), pressure.nrows()).map_err(|r| Error::file(path, r))?;
    Ok(pressure)
}

/// Why `path` is no pressure map: `reason`, or that it is a line profile, which a user may have
/// meant as the surface to solve (onset starts from a solved contact, never from heights).
fn not_a_pressure_map(path: &Path, limits: &Limits, reason: String) -> Error {
    let opts = ReadOptions { limits: *limits, ..ReadOptions::default() };
    match asperity::topography::io::read_any(path, &opts) {
        Ok((AnyTopography::Profile(p), _)) => Error::file(
            path,
            format!(
                "a line profile ({} points along x), not a pressure map: onset needs a 2-D pressure map \
                 (.npy) or a contact directory, which `asperity contact` solves from a 2-D map of heights",
                p.points()
            ),
        ),
        _ => Error::file(path, reason),
    }
}

/// The pressure map \[Pa] of one load of a contact folder: `file`, as `contact.json` (at
/// `json_path`) names it, a file of the folder itself, of shape `grid` (ny, nx), its pressures
/// finite and not negative and carrying the folder's load `load_n` \[N] on pixels of
/// `pixel_area` \[m²] (a map edited since asperity wrote it is refused, not taken at another
/// load).
pub fn read_load_map(
    json_path: &Path,
    file: &str,
    load_n: f64,
    grid: (usize, usize),
    pixel_area: f64,
    limits: &Limits,
) -> Result<(PathBuf, Array2<f64>)> {
    let plain = Path::new(file).file_name().is_some_and(|name| name == file) && !file.contains(['/', '\\']);
    if !plain {
        return Err(Error::file(json_path, format!("pressure_file {file:?} must name a file of its own folder")));
    }
    let path = json_path.with_file_name(file);
    let pressure = read_pressure(&path, limits)?;
    if pressure.dim() != grid {
        let ((a, b), (ny, nx)) = (pressure.dim(), grid);
        return Err(Error::file(&path, format!("shape ({a}, {b}) differs from the grid ({ny}, {nx}) of contact.json")));
    }
    if let Some(((i, j), p)) = pressure.indexed_iter().find(|(_, p)| !(p.is_finite() && **p >= 0.0)) {
        return Err(Error::file(&path, format!("pressure at row {i}, column {j} is {p} Pa: not a contact pressure")));
    }
    let carried = pressure.sum() * pixel_area;
    if (carried - load_n).abs() > 1e-6 * load_n.abs() || load_n <= 0.0 {
        return Err(Error::file(
            &path,
            format!(
                "carries {carried:.6e} N, not the load {load_n:e} N that contact.json gives it: not the map asperity contact wrote"
            ),
        ));
    }
    Ok((path, pressure))
}

/// The path of `DIR/contact.json`, written by `asperity contact`, and what `T` reads of it.
pub fn read_contact_json<T: DeserializeOwned>(dir: &Path, limits: &Limits) -> Result<(PathBuf, T)> {
    let json_path = dir.join("contact.json");
    if !json_path.exists() {
        // A study's output folder is the likely mistake: it keeps no contact.json.
        let study = if dir.join("results.csv").exists() { " (it is a study's output)" } else { "" };
        return Err(Error::file(
            dir,
            format!(
                "holds no contact.json{study}: give a contact directory written by `asperity contact --out DIR`, \
                 or a surface file"
            ),
        ));
    }
    let text = limits.read_text(&json_path)?;
    let contact =
        serde_json::from_str(&text).map_err(|e| Error::file(&json_path, format!("not a contact result: {e}")))?;
    Ok((json_path, contact))
}

/// The loads of a contact directory: `load_index`'s, or every one in the order of its
/// contact.json.
fn read_contact_dir(dir: &Path, load_index: Option<usize>, limits: &Limits) -> Result<Vec<Input>> {
    let (json_path, contact): (_, ContactResult) = read_contact_json(dir, limits)?;
    let [ny, nx] = contact.grid;
    let [lx, ly] = contact.physical_size_m;
    if !(lx.is_finite() && ly.is_finite() && lx > 0.0 && ly > 0.0 && nx > 0 && ny > 0) {
        return Err(Error::file(&json_path, format!("grid {ny}×{nx} of size {lx}×{ly} m is not a valid surface")));
    }
    let count = contact.loads.len();
    let indices = match (load_index, count) {
        (_, 0) => return Err(Error::file(&json_path, "it holds no load")),
        (None, _) => 0..count,
        (Some(i), _) if i >= count => {
            return Err(Error::invalid(
                "--load-index",
                format!("{i} is out of range: {} holds {count} loads (0 to {})", json_path.display(), count - 1),
            ))
        }
        (Some(i), _) => i..i + 1,
    };
    let area = lx / nx as f64 * (ly / ny as f64);
    indices
        .map(|index| {
            let load = &contact.loads[index];
            let (path, pressure) = read_load_map(&json_path, &load.pressure_file, load.load_n, (ny, nx), area, limits)?;
            Ok(Input { pressure, path, pixel_area: Some(area), load: Some((index, load.load_n)) })
        })
        .collect()
}

/// One line per load of a contact directory: its load, contact points, coefficients and
/// the shares of N of the element classes.
fn table(reports: &[Report]) -> String {
    use std::fmt::Write;
    let law = &reports[0].law;
    // The loads of one contact directory: the table is the directory's, not its first map's.
    let first = Path::new(&reports[0].input);
    let common = first.parent().filter(|d| reports.iter().all(|r| Path::new(&r.input).parent() == Some(*d)));
    let input = match common {
        Some(dir) if reports.len() > 1 => format!("{}, {} loads", dir.display(), reports.len()),
        _ => reports[0].input.clone(),
    };
    let mut s = format!("{}  ({})\n", escaped(&input), law_line(law));
    let _ = writeln!(
        s,
        "{:<12} {:>8} {:>10} {:>9} {:>12} {:>14} {:>14}",
        "load", "elements", "static", "drop", "critical N", "pre-sliding N", "subcritical N"
    );
    for r in reports {
        let _ = writeln!(
            s,
            "{:<12} {:>8} {:>10.6} {:>9.6} {:>10.2} % {:>12.2} % {:>12.2} %",
            r.imposed_load_n.map_or("?".into(), |n| show(n, &FORCE)),
            r.elements,
            r.static_coefficient,
            r.friction_drop,
            100.0 * r.critical.normal_fraction,
            100.0 * r.pre_sliding.normal_fraction,
            100.0 * r.subcritical.normal_fraction
        );
    }
    s
}

/// The law as the readable output names it.
fn law_line(law: &LawReport) -> String {
    match law.name {
        Some(name) => format!("\"{}\": mu_s {}, mu_d {}", escaped(name), human(law.mu_s), human(law.mu_d)),
        None => format!("mu_s {}, mu_d {}", human(law.mu_s), human(law.mu_d)),
    }
}

/// The readable form of the report, one quantity a line.
fn summary(r: &Report) -> String {
    use std::fmt::Write;
    let mut s = format!("{}  ({})\n", escaped(&r.input), law_line(&r.law));
    let _ = writeln!(s, "elements            {}", r.elements);
    if let (Some(n), Some(fs)) = (r.load_n, r.static_force_n) {
        let _ = writeln!(s, "normal load         {n:.6e} N");
        let _ = writeln!(s, "static friction     {fs:.6e} N");
    }
    let _ = writeln!(s, "static coefficient  {:.6}", r.static_coefficient);
    let _ = writeln!(s, "dynamic coefficient {:.6}", r.dynamic_coefficient);
    let _ = writeln!(s, "friction drop       {:.6}", r.friction_drop);
    let _ = writeln!(s, "                    count       of N      of F_S");
    for (name, c) in [("critical", r.critical), ("pre-sliding", r.pre_sliding), ("subcritical", r.subcritical)] {
        let _ = writeln!(
            s,
            "{name:<19} {:<11} {:>6.2} %  {:>6.2} %",
            c.count,
            100.0 * c.normal_fraction,
            100.0 * c.friction_fraction
        );
    }
    s
}
