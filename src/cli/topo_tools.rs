//! `asperity topo convert | generate | psd`: prepare a measured topography for the contact
//! solver, synthesise one, or print its power spectral density.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::{Path, PathBuf};

use clap::{ArgGroup, Args};

use asperity::output::{check_output_file, write_atomic, write_npy};
use asperity::plausible::{self, Spelling};
use asperity::quantity::{self, human};
use asperity::topography::detrend::{Detrend, SphereFit};
use asperity::topography::io::{read_any, write_gsf};
use asperity::topography::missing::{fill_missing, refuse_missing};
use asperity::topography::prepare::Preparation;
use asperity::topography::profile::Profile;
use asperity::topography::resample::{crop, resample, CropWindow};
use asperity::topography::stats::{height_stats, profile_psd, psd, rms_slope, Window};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};
use asperity::topography::{AnyTopography, Topography};
use asperity::{Error, Result};

use super::{parse_size, ReadArgs};

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// How to prepare it, applied in this order: crop, missing points, detrend.
#[derive(Args)]
pub struct PrepareArgs {
    /// Crop window X0:X1,Y0:Y1, end excluded: pixel indices (0-based), or lengths with a unit
    /// [m, um, nm…] from the map's origin (e.g. 0um:10um,0um:10um); a 2-D map's
    #[arg(long, value_name = "X0:X1,Y0:Y1", value_parser = parse_crop)]
    pub crop: Option<CropWindow>,
    /// Fill missing points harmonically (each the mean of its four neighbours)
    #[arg(long, conflicts_with = "refuse_missing")]
    pub fill_missing: bool,
    /// Refuse a map with missing points, counting them (the default)
    #[arg(long)]
    pub refuse_missing: bool,
    /// Levelling: none, mean, plane, poly:N (total degree N ≤ 8, least squares) or sphere (fits
    /// and subtracts a sphere, reporting its radius [m]); or each scan line on its own, line:N (its
    /// polynomial of degree N ≤ 3 along x subtracted) or line:median (shifted by its median),
    /// then optionally the whole map: line:1,plane. A line profile: mean, plane (its straight
    /// line), poly:N or line:N (its polynomial of degree N along x), line:median
    #[arg(long, default_value = "none", value_parser = parse_detrend)]
    pub detrend: Detrend,
}

impl PrepareArgs {
    /// The same preparation for the library: crop, missing points, detrend.
    pub fn preparation(&self) -> Preparation {
        Preparation {
            crop: self.crop.clone(),
            fill_missing: self.fill_missing && !self.refuse_missing,
            detrend: self.detrend,
            ..Preparation::default()
        }
    }
}

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// `asperity topo convert`.
#[derive(Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    pub read: ReadArgs,
    /// Output file: a map's heights [m] as a float64 .npy array of shape (ny, nx), or as .gsf
    /// (float32, with the physical size); a line profile's as .csv or .txt (columns x_m and
    /// height_m [m], comma- or tab-separated)
    pub out: PathBuf,
    #[command(flatten)]
    pub prepare: PrepareArgs,
    /// Resample (cubic convolution) to this pixel size [m, or with a unit: 20nm], keeping the
    /// physical size: the pixel becomes size / round(size / P)
    #[arg(long, value_name = "P", value_parser = super::length)]
    pub pixel_size: Option<f64>,
}

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// `asperity topo generate`.
#[derive(Args)]
#[command(group(ArgGroup::new("amplitude").required(true).args(["rms", "rms_slope"])))]
pub struct GenerateArgs {
    /// Physical size LX[,LY] [m, or with a unit: 31.13um] (LY defaults to LX)
    #[arg(long, value_name = "LX[,LY]", value_parser = parse_size)]
    pub size: (f64, f64),
    /// Grid NX[,NY] [points] (NY defaults to NX)
    #[arg(long, value_name = "NX[,NY]", value_parser = parse_grid)]
    pub grid: (usize, usize),
    /// Hurst exponent H, 0 < H ≤ 1: C(q) ∝ q^(−2(1+H)) [1]
    #[arg(long)]
    pub hurst: f64,
    /// RMS height of the roughness [m, or with a unit: 22nm]
    #[arg(long, value_name = "R", value_parser = super::length)]
    pub rms: Option<f64>,
    /// RMS slope of the roughness, forward differences [1]
    #[arg(long)]
    pub rms_slope: Option<f64>,
    /// Roll-off wavelength [m, or with a unit: 5um]: the spectrum is flat above it [default:
    /// none]
    #[arg(long, value_name = "LAMBDA", value_parser = super::length)]
    pub rolloff: Option<f64>,
    /// Short cut-off wavelength [m, or with a unit]: no roughness below it [default: down to
    /// the pixel]
    #[arg(long, value_name = "LAMBDA", value_parser = super::length)]
    pub cutoff: Option<f64>,
    /// Long cut-off wavelength, the largest present [m, or with a unit] [default: the window
    /// size]
    #[arg(long, value_name = "LAMBDA", value_parser = super::length)]
    pub long_cutoff: Option<f64>,
    /// Add a sphere cap of this radius [m, or with a unit: 1.5mm], apex (highest point) at the
    /// window's centre
    #[arg(long, value_name = "R", value_parser = super::length)]
    pub sphere_radius: Option<f64>,
    /// Make the cap the paraboloid −ρ²/(2R) instead of the exact sphere
    #[arg(long, requires = "sphere_radius")]
    pub paraboloid: bool,
    /// Seed of the random phases: the same seed gives the same surface [integer]
    #[arg(long, value_name = "S", value_parser = super::count::<u64>)]
    pub seed: u64,
    /// Output file: heights [m] as a float64 .npy array of shape (ny, nx), or as .gsf (float32,
    /// with the physical size)
    pub out: PathBuf,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// `asperity topo psd`.
#[derive(Args)]
pub struct PsdArgs {
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub prepare: PrepareArgs,
    /// Window before the FFT: auto (hann for non-periodic maps and for line profiles, none for
    /// periodic maps), hann or none
    #[arg(long, default_value = "auto", value_parser = ["auto", "hann", "none"])]
    pub window: String,
}

/// Prepare a map; the fitted sphere when `--detrend sphere`.
fn prepare(mut topo: Topography, prep: &PrepareArgs) -> Result<(Topography, Option<SphereFit>)> {
    // The outputs are heights in metres: a unit the file does not state is never guessed.
    topo.require_metres()?;
    if let Some(window) = &prep.crop {
        topo = crop(&topo, window)?;
    }
    if prep.fill_missing && !prep.refuse_missing {
        fill_missing(&mut topo)?;
    } else {
        refuse_missing(&topo)?;
    }
    let fit = prep.detrend.apply(&mut topo)?;
    Ok((topo, fit))
}

fn describe_fit(fit: &SphereFit) -> String {
    format!(
        "sphere fit: radius {} m, apex at ({}, {}) m, height {} m; residual {} m RMS",
        human(fit.radius),
        human(fit.apex.0),
        human(fit.apex.1),
        human(fit.apex_height),
        human(fit.rms_residual)
    )
}

/// The output format, from the name's extension: .npy (float64) or .gsf (float32) for a map,
/// .csv or .txt for a line profile.
#[derive(Clone, Copy)]
enum OutFormat {
    Npy,
    Gsf,
    /// Two columns and a row of their names, separated by this character.
    Columns(char),
}

impl OutFormat {
    fn of(out: &Path) -> Result<Self> {
        match out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("npy") => Ok(OutFormat::Npy),
            Some("gsf") => Ok(OutFormat::Gsf),
            Some("csv") => Ok(OutFormat::Columns(',')),
            Some("txt") => Ok(OutFormat::Columns('\t')),
            _ => Err(Error::invalid(
                "OUT",
                format!(
                    "{}: name it *.npy (float64) or *.gsf (float32), or for a line profile *.csv or *.txt",
                    out.display()
                ),
            )),
        }
    }

    /// An error unless this is a map's format: .csv and .txt hold line profiles.
    fn require_map(self, out: &Path) -> Result<()> {
        match self {
            OutFormat::Columns(_) => Err(Error::invalid(
                "OUT",
                format!(
                    "{}: .csv and .txt hold line profiles; name a 2-D map *.npy (float64) or *.gsf (float32)",
                    out.display()
                ),
            )),
            _ => Ok(()),
        }
    }

    fn write(self, out: &Path, topo: &Topography) -> Result<()> {
        match self {
            OutFormat::Npy => write_npy(out, &topo.heights),
            OutFormat::Gsf => write_gsf(out, topo),
            OutFormat::Columns(_) => self.require_map(out),
        }
    }

    /// Write a profile's positions (from the file's origin) and heights \[m], one point a line
    /// (shortest round-trip digits, `NaN` for a missing height).
    fn write_profile(self, out: &Path, p: &Profile) -> Result<()> {
        let OutFormat::Columns(sep) = self else {
            return Err(Error::invalid(
                "OUT",
                format!(
                    "{}: {} is a line profile, and .npy and .gsf hold 2-D maps: name it *.csv or *.txt",
                    out.display(),
                    p.provenance.file.as_deref().unwrap_or(Path::new("the input")).display()
                ),
            ));
        };
        write_atomic(out, |w| {
            writeln!(w, "x_m{sep}height_m")?;
            for (x, h) in p.positions().iter().zip(p.heights()) {
                writeln!(w, "{:e}{sep}{h:e}", p.origin() + x)?;
            }
            Ok(())
        })
    }
}

/// The first option of `prep` (or `--pixel-size`) that prepares 2-D maps only, as an error for
/// the line profile `p`; `--detrend` levels a profile too.
pub(super) fn refuse_map_options(p: &Profile, crop: bool, fill_missing: bool, pixel_size: bool) -> Result<()> {
    let given = [(crop, "--crop"), (fill_missing, "--fill-missing"), (pixel_size, "--pixel-size")];
    match given.into_iter().find(|(g, _)| *g) {
        Some((_, option)) => Err(Error::invalid(
            option,
            format!(
                "{} is a line profile: {option} prepares 2-D maps",
                p.provenance.file.as_deref().unwrap_or(Path::new("the input")).display()
            ),
        )),
        None => Ok(()),
    }
}

fn describe(out: &Path, topo: &Topography) -> String {
    let npy = OutFormat::of(out).is_ok_and(|f| matches!(f, OutFormat::Npy));
    let size = match topo.physical_size {
        // A .npy array holds heights only: say how its size travels.
        Some((lx, ly)) if npy => {
            let (lx, ly) = (human(lx), human(ly));
            format!(
                "physical size {lx} × {ly} m, which a .npy does not hold: read it back with --size {lx},{ly}, \
                 or write .gsf, which keeps it"
            )
        }
        Some((lx, ly)) => {
            let (lx, ly) = (human(lx), human(ly));
            format!("physical size {lx} × {ly} m (--size {lx},{ly})")
        }
        None => "physical size unknown (give it with --size when reading it)".to_string(),
    };
    format!("wrote {}: {} × {} points (nx × ny), {size}", out.display(), topo.nx(), topo.ny())
}

/// `asperity topo convert`.
pub fn convert(args: ConvertArgs) -> Result<()> {
    let format = OutFormat::of(&args.out)?;
    check_output_file(&args.out, &[&args.read.file])?;
    let topo = match read_any(&args.read.file, &args.read.options())?.0 {
        AnyTopography::Map(topo) => topo,
        AnyTopography::Profile(mut p) => {
            let prep = &args.prepare;
            refuse_map_options(&p, prep.crop.is_some(), prep.fill_missing, args.pixel_size.is_some())?;
            p.require_metres()?;
            refuse_missing_points(&p)?;
            prep.detrend.apply_to_profile(&mut p)?;
            format.write_profile(&args.out, &p)?;
            let uniform = if p.step().is_some() { "uniform" } else { "non-uniform" };
            return super::print(&format!(
                "wrote {}: a line profile of {} points, {uniform}, {} m long\n",
                args.out.display(),
                p.points(),
                human(p.length())
            ));
        }
    };
    format.require_map(&args.out)?;
    let (mut topo, fit) = prepare(topo, &args.prepare)?;
    if let Some(p) = args.pixel_size {
        topo = resample(&topo, p, &args.read.limits.limits())?;
    }
    format.write(&args.out, &topo)?;
    let fit = fit.map(|fit| describe_fit(&fit) + "\n").unwrap_or_default();
    super::print(&format!("{fit}{}\n", describe(&args.out, &topo)))
}

/// `asperity topo generate`.
pub fn generate(args: GenerateArgs) -> Result<()> {
    if let Some(rms) = args.rms {
        super::judge("--rms", plausible::roughness(rms, Spelling::CommandLine))?;
    }
    let format = OutFormat::of(&args.out)?;
    check_output_file(&args.out, &[])?;
    format.require_map(&args.out)?;
    let amplitude = match (args.rms, args.rms_slope) {
        (_, Some(g)) => Amplitude::RmsSlope(g),
        (h, None) => Amplitude::RmsHeight(h.expect("clap requires one of --rms and --rms-slope")),
    };
    let surface = SyntheticSurface {
        size: args.size,
        grid: args.grid,
        roughness: Some(SelfAffine {
            hurst: args.hurst,
            rolloff_wavelength: args.rolloff,
            short_cutoff_wavelength: args.cutoff,
            long_cutoff_wavelength: args.long_cutoff,
            amplitude,
        }),
        cap: args
            .sphere_radius
            .map(|radius| Cap { radius, shape: if args.paraboloid { CapShape::Paraboloid } else { CapShape::Sphere } }),
        seed: args.seed,
    };
    let topo = surface.generate_within(&args.limits.limits())?;
    format.write(&args.out, &topo)?;
    let stats = height_stats(&topo)?;
    super::print(&format!(
        "{}; rms height {} m, rms slope {}\n",
        describe(&args.out, &topo),
        human(stats.rms_height),
        human(rms_slope(&topo)?)
    ))
}

/// A profile is written whole: the default refusal of missing points, as for a map.
fn refuse_missing_points(p: &Profile) -> Result<()> {
    match p.missing_points() {
        0 => Ok(()),
        n => Err(p.error(format!("{n} of {} points are missing (a line profile's are not filled)", p.points()))),
    }
}

/// `asperity topo psd`: CSV `q_rad_per_m,psd_m4` on stdout (of a line profile `psd_m3`).
pub fn power_spectrum(args: PsdArgs) -> Result<()> {
    let window = match args.window.as_str() {
        "hann" => Some(Window::Hann),
        "none" => Some(Window::None),
        _ => None,
    };
    let (spectrum, unit) = match read_any(&args.read.file, &args.read.options())?.0 {
        AnyTopography::Map(topo) => {
            let (topo, fit) = prepare(topo, &args.prepare)?;
            if let Some(fit) = fit {
                super::message(&describe_fit(&fit));
            }
            (psd(&topo, window.unwrap_or_else(|| Window::default_for(&topo)))?, "m4")
        }
        AnyTopography::Profile(mut p) => {
            let prep = &args.prepare;
            refuse_map_options(&p, prep.crop.is_some(), prep.fill_missing, false)?;
            p.require_metres()?;
            prep.detrend.apply_to_profile(&mut p)?;
            // A measured profile does not repeat across its ends.
            (profile_psd(&p, window.unwrap_or(Window::Hann))?, "m3")
        }
    };
    super::to_stdout(|w| {
        writeln!(w, "q_rad_per_m,psd_{unit}")?;
        for (q, c) in spectrum.q.iter().zip(&spectrum.c) {
            writeln!(w, "{q:e},{c:e}")?;
        }
        Ok(())
    })
}

/// `NX[,NY]`: point counts.
fn parse_grid(s: &str) -> std::result::Result<(usize, usize), String> {
    let parse = |v: &str| match v.trim().parse::<usize>() {
        Ok(n) if n >= 2 => Ok(n),
        _ => Err(format!("'{v}' is not a number of points ≥ 2")),
    };
    match s.split_once(',') {
        Some((x, y)) => Ok((parse(x)?, parse(y)?)),
        None => parse(s).map(|n| (n, n)),
    }
}

pub(super) fn parse_detrend(s: &str) -> std::result::Result<Detrend, String> {
    s.parse()
}

/// One crop bound: a pixel index, or a length with a unit (in metres).
enum Bound {
    Pixel(usize),
    Length(f64),
}

fn parse_bound(s: &str) -> std::result::Result<Bound, String> {
    let s = s.trim();
    if let Ok(i) = s.parse::<usize>() {
        return Ok(Bound::Pixel(i));
    }
    // A length's value is checked where the window is cut (`resample::crop`).
    match quantity::parse(s, &quantity::LENGTH, false) {
        Ok(v) => Ok(Bound::Length(v)),
        Err(_) if s.starts_with('-') => {
            Err(format!("{} is negative: bounds are pixel indices ≥ 0 or lengths ≥ 0", quantity::quoted(s)))
        }
        Err(_) => Err(format!("{} is neither a pixel index nor a length with a unit (e.g. 10um)", quantity::quoted(s))),
    }
}

/// `X0:X1,Y0:Y1`, all four pixel indices or all four lengths with units.
pub(super) fn parse_crop(s: &str) -> std::result::Result<CropWindow, String> {
    let bad = || format!("{} is not X0:X1,Y0:Y1", quantity::quoted(s));
    let (x, y) = s.split_once(',').ok_or_else(bad)?;
    let range = |r: &str| -> std::result::Result<(Bound, Bound), String> {
        let (a, b) = r.split_once(':').ok_or_else(bad)?;
        Ok((parse_bound(a)?, parse_bound(b)?))
    };
    match (range(x)?, range(y)?) {
        ((Bound::Pixel(x0), Bound::Pixel(x1)), (Bound::Pixel(y0), Bound::Pixel(y1))) => {
            Ok(CropWindow::Pixels { x: x0..x1, y: y0..y1 })
        }
        ((Bound::Length(x0), Bound::Length(x1)), (Bound::Length(y0), Bound::Length(y1))) => {
            Ok(CropWindow::Physical { x: (x0, x1), y: (y0, y1) })
        }
        _ => Err(format!("{} mixes pixel indices and lengths", quantity::quoted(s))),
    }
}
