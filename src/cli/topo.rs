//! `asperity topo …`: topography files. `info` tells what a file holds.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use ndarray::Array2;
use serde::Serialize;

use asperity::error::escaped;
use asperity::topography::detrend::Detrend;
use asperity::topography::io;
use asperity::topography::profile::Profile;
use asperity::topography::resample::{crop, CropWindow};
use asperity::topography::stats::{
    fit_psd, profile_height, profile_psd, profile_rms_curvature, profile_rms_slope, psd, psd_fit_window,
    slope_curvature, PsdFit, SlopeCurvature, SpectrumOf, Window,
};
use asperity::topography::{AnyTopography, Topography};

use super::{topo_tools, ReadArgs};
use asperity::Result;

/// Topographies: inspect, prepare, synthesise, analyse (`topo info | convert | generate | psd`).
///
/// Topography files: read them, whatever the instrument.
#[derive(Args)]
pub struct TopoArgs {
    #[command(subcommand)]
    command: TopoCommand,
}

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Subcommand)]
enum TopoCommand {
    /// Print a file's grid, physical size, channels, height unit and height statistics (of a line
    /// profile: points, length, uniformity, RMS height and RMS slope).
    Info(InfoArgs),
    /// Read a topography, crop, fill or refuse missing points, detrend, resample, and write its
    /// heights [m] as .npy or .gsf (a line profile as .csv or .txt)
    Convert(topo_tools::ConvertArgs),
    /// Synthesise a self-affine random-phase surface [m], optionally on a sphere cap, as .npy or .gsf
    Generate(topo_tools::GenerateArgs),
    /// Print the isotropic power spectral density as CSV q_rad_per_m,psd_m4 (of a uniform line
    /// profile its 1-D spectrum, q_rad_per_m,psd_m3)
    Psd(topo_tools::PsdArgs),
    /// List the file formats asperity reads: extensions, --format name, map or line profile,
    /// instrument, what is read (docs/formats.md says more)
    Formats(FormatsArgs),
}

// Doc comments here are clap's --help text, printed as written (not Markdown).
#[derive(Args)]
struct FormatsArgs {
    /// Print JSON: a list of {name, extensions, kind, instrument, reads}
    #[arg(long)]
    json: bool,
}

/// The registry's formats, as a table or JSON.
fn formats(args: FormatsArgs) -> Result<()> {
    let formats = io::formats();
    if args.json {
        return super::print_json(&formats);
    }
    let ending = |f: &io::FormatInfo| match f.extensions {
        [] => "(by content)".to_string(),
        // NanoScope's numbered endings .000 … .009 shown as a range.
        e if e.len() > 4 => format!(".{} .{} .{} … .{}", e[0], e[1], e[2], e[e.len() - 1]),
        e => e.iter().map(|e| format!(".{e}")).collect::<Vec<_>>().join(" "),
    };
    let width = formats.iter().map(|f| ending(f).chars().count()).max().unwrap_or(0);
    let name_width = formats.iter().map(|f| f.name.len()).max().unwrap_or(0);
    let mut text = String::new();
    for f in &formats {
        text.push_str(&format!(
            "{:width$}  {:name_width$}  {:7}  {}: {}\n",
            ending(f),
            f.name,
            f.kind,
            f.instrument,
            f.reads
        ));
    }
    text.push_str("gzip (.gz) and zip containers (archive.zip#member) are read in front of every format\n");
    super::print(&text)
}

pub fn run(args: TopoArgs) -> Result<()> {
    match args.command {
        TopoCommand::Info(args) => info(args),
        TopoCommand::Convert(args) => topo_tools::convert(args),
        TopoCommand::Generate(args) => topo_tools::generate(args),
        TopoCommand::Psd(args) => topo_tools::power_spectrum(args),
        TopoCommand::Formats(args) => formats(args),
    }
}

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
#[derive(Args)]
struct InfoArgs {
    #[command(flatten)]
    read: ReadArgs,
    /// Print JSON: kind ("map"), nx, ny, physical_size_m [m] (null when unknown), channels,
    /// channel, height_unit, height_unit_known, mean_m, rms_m, min_m, max_m [m],
    /// missing_points. When the height unit is unknown (or not a length) the statistics are
    /// mean, rms, min, max in the values as stored. A line profile: kind ("profile"), points,
    /// uniform, length_m and step_m [m] (length and step as stored when the positions' unit is
    /// unknown), on_stated_grid (the positions put on the grid of the step the header states),
    /// position_unit, the heights as for a map, rms_slope [1] and
    /// rms_curvature_per_m [1/m] (null unless both units are known), with SurfaceTopography's
    /// definitions for line scans. A map in metres with a size and no missing point adds
    /// SurfaceTopography's rms_gradient [1] (√⟨|∇h|²⟩), rms_slope_from_profile [1] (along x),
    /// rms_curvature_from_area_per_m [1/m] (half the Laplacian) and
    /// rms_curvature_from_profile_per_m [1/m] (along x); docs/your-scan.md says how they differ.
    /// With --psd-fit, psd_fit (see there).
    #[arg(long)]
    json: bool,
    /// Fit the PSD (as `topo psd` prints it, default window) in log–log, 10 log bins per
    /// decade weighing the same, from 2π/L (3 × 2π/L under the Hann window) up to π/(2·pixel)
    /// (the last octave below the Nyquist wavevector is the pixel's and the tip's): a plateau
    /// C0 below the roll-off q_r, then C = C0 (q/q_r)^s, the roll-off kept by the Bayesian
    /// information criterion. Of the map as read: level it first (topo convert --detrend plane).
    /// The Hurst exponent H from s = −2(1+H) for a map, s = −(1+2H) for a line profile;
    /// refused (with the reason) outside 0 < H ≤ 1, when the power law spans under half a
    /// decade, or when the residual exceeds 0.1 + twice a random surface's scatter. JSON:
    /// psd_fit {hurst, refusal, slope, rolloff_q_rad_per_m, rolloff_wavelength_m (null: no
    /// roll-off in the window), c0 [m⁴ of a map, m³ of a profile: the plateau, or C at the
    /// window's start without roll-off], psd_unit, power_law_q_rad_per_m, window_q_rad_per_m, bins, rms_residual_log10, expected_scatter_log10 [decades of C]}.
    /// Needs heights and positions in metres, a size, no missing point, a uniform profile
    #[arg(long)]
    psd_fit: bool,
    /// Crop window X0:X1,Y0:Y1 before the statistics, as topo psd --crop does (pixel indices,
    /// end excluded, or lengths with a unit from the map's origin); a 2-D map's
    #[arg(long, value_name = "X0:X1,Y0:Y1", value_parser = topo_tools::parse_crop)]
    crop: Option<CropWindow>,
    /// Level before the statistics (after --crop), as topo psd --detrend does: a map's
    /// line:1 is an AFM scan's usual first step, before a vendor's roughness; a line profile's
    /// is mean, plane (its straight line), poly:N or line:N (its polynomial of degree N along
    /// x), line:median
    #[arg(long, default_value = "none", value_parser = topo_tools::parse_detrend)]
    detrend: Detrend,
}

/// What `--psd-fit` adds to `topo info --json`: the fit, or only the reason there is none.
#[derive(Serialize)]
struct PsdFitInfo {
    hurst: Option<f64>,
    refusal: Option<String>,
    slope: Option<f64>,
    rolloff_q_rad_per_m: Option<f64>,
    rolloff_wavelength_m: Option<f64>,
    c0: Option<f64>,
    psd_unit: &'static str,
    power_law_q_rad_per_m: Option<[f64; 2]>,
    window_q_rad_per_m: Option<[f64; 2]>,
    bins: Option<usize>,
    rms_residual_log10: Option<f64>,
    expected_scatter_log10: Option<f64>,
}

impl PsdFitInfo {
    fn new(fit: std::result::Result<PsdFit, String>, psd_unit: &'static str) -> PsdFitInfo {
        match fit {
            Ok(f) => PsdFitInfo {
                hurst: f.hurst,
                refusal: f.refusal,
                slope: Some(f.slope),
                rolloff_q_rad_per_m: f.rolloff_q,
                rolloff_wavelength_m: f.rolloff_q.map(|q| 2.0 * std::f64::consts::PI / q),
                c0: Some(f.c0),
                psd_unit,
                power_law_q_rad_per_m: Some([f.power_law_q.0, f.power_law_q.1]),
                window_q_rad_per_m: Some([f.window_q.0, f.window_q.1]),
                bins: Some(f.bins),
                rms_residual_log10: Some(f.rms_residual_log10),
                expected_scatter_log10: Some(f.expected_scatter_log10),
            },
            Err(reason) => PsdFitInfo {
                hurst: None,
                refusal: Some(reason),
                slope: None,
                rolloff_q_rad_per_m: None,
                rolloff_wavelength_m: None,
                c0: None,
                psd_unit,
                power_law_q_rad_per_m: None,
                window_q_rad_per_m: None,
                bins: None,
                rms_residual_log10: None,
                expected_scatter_log10: None,
            },
        }
    }

    /// The fit of a map's isotropic PSD under its default window.
    fn of_map(topo: &Topography) -> PsdFitInfo {
        let fit = || -> std::result::Result<PsdFit, String> {
            if !topo.height_unit_known {
                return Err("the heights' unit is unknown (give it with --height-unit U)".into());
            }
            let window = Window::default_for(topo);
            let spectrum = psd(topo, window).map_err(|e| e.to_string())?;
            let ((lx, ly), (dx, dy)) = (
                topo.physical_size.expect("the PSD needs the size"),
                topo.pixel_size("the PSD").map_err(|e| e.to_string())?,
            );
            fit_psd(&spectrum, SpectrumOf::Map, psd_fit_window(lx.min(ly), dx.max(dy), window))
        };
        PsdFitInfo::new(fit(), "m4")
    }

    /// The fit of a uniform line profile's 1-D PSD under the Hann window.
    fn of_profile(p: &Profile) -> PsdFitInfo {
        let fit = || -> std::result::Result<PsdFit, String> {
            if !(p.height_unit_known && p.position_unit_known) {
                return Err("needs the units of the positions and the heights".into());
            }
            let spectrum = profile_psd(p, Window::Hann).map_err(|e| e.to_string())?;
            let step = p.step().expect("profile_psd refuses a non-uniform profile");
            fit_psd(&spectrum, SpectrumOf::Profile, psd_fit_window(step * p.points() as f64, step, Window::Hann))
        };
        PsdFitInfo::new(fit(), "m3")
    }

    /// The readable lines: H, the roll-off, C0, the range and the residual; or the reason.
    fn summary(&self) -> String {
        let law = if self.psd_unit == "m4" { "C ∝ q^−2(1+H)" } else { "C ∝ q^−(1+2H), a profile's" };
        let mut s = match (self.hurst, &self.refusal, self.slope) {
            (Some(h), _, Some(slope)) => format!("psd fit      H = {h:.3} (slope {slope:.3} of {law})\n"),
            (None, Some(why), Some(slope)) => format!("psd fit      no Hurst exponent (slope {slope:.3}): {why}\n"),
            (_, Some(why), None) => return format!("psd fit      none: {why}\n"),
            _ => return String::new(),
        };
        s += &match (self.rolloff_q_rad_per_m, self.rolloff_wavelength_m) {
            (Some(q), Some(l)) => format!("roll-off     λ_r = {} (q_r = {q:.3e} rad/m)\n", metres(&l)),
            _ => "roll-off     none in the window: C rises down to its smallest q\n".into(),
        };
        let unit = if self.psd_unit == "m4" { "m⁴" } else { "m³" };
        if let Some(c0) = self.c0 {
            s += &format!("C0           {c0:.3e} {unit}\n");
        }
        if let (Some([a, b]), Some([w0, w1]), Some(n)) =
            (self.power_law_q_rad_per_m, self.window_q_rad_per_m, self.bins)
        {
            s += &format!("power law    q = {a:.3e} … {b:.3e} rad/m; fitted {w0:.3e} … {w1:.3e} rad/m, {n} log bins\n");
        }
        if let (Some(r), Some(e)) = (self.rms_residual_log10, self.expected_scatter_log10) {
            s += &format!("residual     {r:.3} decades of C RMS (a random surface scatters by {e:.3})\n");
        }
        s
    }
}

/// What `topo info --json` prints for a map.
#[derive(Serialize)]
struct Info {
    file: PathBuf,
    format: String,
    kind: &'static str,
    nx: usize,
    ny: usize,
    physical_size_m: Option<[f64; 2]>,
    channels: Vec<String>,
    channel: String,
    height_unit: Option<String>,
    height_unit_known: bool,
    #[serde(flatten)]
    metres: Option<MetreStats>,
    #[serde(flatten)]
    as_stored: Option<StoredStats>,
    /// `None` without metres, a size, or with a missing point.
    #[serde(flatten)]
    slope_curvature: Option<SlopeCurvature>,
    missing_points: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    psd_fit: Option<PsdFitInfo>,
}

/// Height statistics in metres (`null` when no point is defined).
#[derive(Serialize)]
struct MetreStats {
    mean_m: Option<f64>,
    rms_m: Option<f64>,
    min_m: Option<f64>,
    max_m: Option<f64>,
}

/// Statistics of values whose unit is unknown, as stored: never presented as metres.
#[derive(Serialize)]
struct StoredStats {
    mean: Option<f64>,
    rms: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
}

/// What `topo info --json` prints for a line profile.
#[derive(Serialize)]
struct ProfileInfo {
    file: PathBuf,
    format: String,
    kind: &'static str,
    channels: Vec<String>,
    channel: String,
    points: usize,
    uniform: bool,
    /// Whether the positions were put on the grid of the step the file's header states.
    on_stated_grid: bool,
    position_unit: Option<String>,
    #[serde(flatten)]
    positions_m: Option<ExtentMetres>,
    #[serde(flatten)]
    positions_stored: Option<ExtentStored>,
    height_unit: Option<String>,
    height_unit_known: bool,
    #[serde(flatten)]
    metres: Option<MetreStats>,
    #[serde(flatten)]
    as_stored: Option<StoredStats>,
    /// \[1]; `None` unless both units are known.
    rms_slope: Option<f64>,
    /// [1/m]; `None` unless both units are known.
    rms_curvature_per_m: Option<f64>,
    missing_points: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    psd_fit: Option<PsdFitInfo>,
}

/// A profile's length and step (`None` when not uniform) \[m].
#[derive(Serialize)]
struct ExtentMetres {
    length_m: f64,
    step_m: Option<f64>,
}

/// A profile's length and step as stored, their unit unknown.
#[derive(Serialize)]
struct ExtentStored {
    length: f64,
    step: Option<f64>,
}

fn info(args: InfoArgs) -> Result<()> {
    if let Some(members) = io::container_members(&args.read.file, &args.read.options().limits)? {
        return container_info(args, members);
    }
    let (topo, channels) = io::read_any(&args.read.file, &args.read.options())?;
    let mut topo = match topo {
        AnyTopography::Map(topo) => topo,
        AnyTopography::Profile(mut p) => {
            topo_tools::refuse_map_options(&p, args.crop.is_some(), false, false)?;
            args.detrend.apply_to_profile(&mut p)?;
            return profile_info(args, &p, channels);
        }
    };
    if let Some(window) = &args.crop {
        topo = crop(&topo, window)?;
    }
    args.detrend.apply(&mut topo)?;
    let stats = Stats::of(&topo.heights);
    let info = Info {
        file: args.read.file,
        format: topo.provenance.format.clone(),
        kind: "map",
        nx: topo.nx(),
        ny: topo.ny(),
        physical_size_m: topo.physical_size.map(|(lx, ly)| [lx, ly]),
        channels,
        channel: topo.channel.clone(),
        height_unit: topo.provenance.height_unit.clone(),
        height_unit_known: topo.height_unit_known,
        metres: topo.height_unit_known.then(|| MetreStats {
            mean_m: stats.as_ref().map(|s| s.mean),
            rms_m: stats.as_ref().map(|s| s.rms),
            min_m: stats.as_ref().map(|s| s.min),
            max_m: stats.as_ref().map(|s| s.max),
        }),
        as_stored: (!topo.height_unit_known).then(|| StoredStats {
            mean: stats.as_ref().map(|s| s.mean),
            rms: stats.as_ref().map(|s| s.rms),
            min: stats.as_ref().map(|s| s.min),
            max: stats.as_ref().map(|s| s.max),
        }),
        slope_curvature: topo.height_unit_known.then(|| slope_curvature(&topo).ok()).flatten(),
        missing_points: topo.missing_points(),
        psd_fit: args.psd_fit.then(|| PsdFitInfo::of_map(&topo)),
    };
    if args.json {
        super::print_json(&info)
    } else {
        super::print(&summary(&info))
    }
}

/// What `topo info --json` prints for each member of a zip container.
#[derive(Serialize)]
struct MemberInfo {
    name: String,
    format: Option<&'static str>,
    kind: Option<&'static str>,
    nx: Option<usize>,
    ny: Option<usize>,
    /// The reason a member is not read as a topography.
    error: Option<String>,
}

/// `topo info` of a zip container: its members, what each holds, and how to name one.
fn container_info(args: InfoArgs, members: Vec<io::Member>) -> Result<()> {
    let members: Vec<MemberInfo> = members
        .into_iter()
        .map(|m| match m.content {
            Ok(c) => MemberInfo {
                name: m.name,
                format: Some(c.format),
                kind: Some(c.kind),
                nx: Some(c.grid.0),
                ny: Some(c.grid.1),
                error: None,
            },
            Err(e) => MemberInfo { name: m.name, format: None, kind: None, nx: None, ny: None, error: Some(e) },
        })
        .collect();
    if args.json {
        return super::print_json(&serde_json::json!({
            "file": args.read.file, "kind": "container", "members": members
        }));
    }
    let file = escaped(&args.read.file.display().to_string()).into_owned();
    let mut s = format!("file         {file} (zip container of {} files; read one as {file}#MEMBER)\n", members.len());
    for m in &members {
        s += &match (&m.error, m.kind, m.format) {
            (Some(e), ..) => format!("member       {}: not read: {}\n", escaped(&m.name), escaped(e)),
            (None, Some("profile"), Some(f)) => {
                format!("member       {}: line profile of {} points ({f})\n", escaped(&m.name), m.nx.unwrap_or(0))
            }
            (None, _, f) => format!(
                "member       {}: map of {} × {} points ({})\n",
                escaped(&m.name),
                m.nx.unwrap_or(0),
                m.ny.unwrap_or(0),
                f.unwrap_or("")
            ),
        };
    }
    super::print(&s)
}

/// `topo info` of a line profile: its statistics as SurfaceTopography defines them.
fn profile_info(args: InfoArgs, p: &Profile, channels: Vec<String>) -> Result<()> {
    let defined = || p.heights().iter().copied().filter(|h| !h.is_nan());
    let range = (defined().count() > 0)
        .then(|| (defined().fold(f64::INFINITY, f64::min), defined().fold(f64::NEG_INFINITY, f64::max)));
    // None where SurfaceTopography defines none (a non-uniform profile with missing points).
    let height = profile_height(p).ok();
    let stats = |known: bool| {
        (p.height_unit_known == known)
            .then(|| (height.map(|h| h.0), height.map(|h| h.1), range.map(|r| r.0), range.map(|r| r.1)))
    };
    let info = ProfileInfo {
        file: args.read.file,
        format: p.provenance.format.clone(),
        kind: "profile",
        channels,
        channel: p.channel.clone(),
        points: p.points(),
        uniform: p.step().is_some(),
        on_stated_grid: p.stated_grid == Some(Ok(())),
        position_unit: p.position_unit.clone(),
        positions_m: p.position_unit_known.then(|| ExtentMetres { length_m: p.length(), step_m: p.step() }),
        positions_stored: (!p.position_unit_known).then(|| ExtentStored { length: p.length(), step: p.step() }),
        height_unit: p.provenance.height_unit.clone(),
        height_unit_known: p.height_unit_known,
        metres: stats(true).map(|(mean_m, rms_m, min_m, max_m)| MetreStats { mean_m, rms_m, min_m, max_m }),
        as_stored: stats(false).map(|(mean, rms, min, max)| StoredStats { mean, rms, min, max }),
        rms_slope: (p.position_unit_known && p.height_unit_known).then(|| profile_rms_slope(p).ok()).flatten(),
        rms_curvature_per_m: (p.position_unit_known && p.height_unit_known)
            .then(|| profile_rms_curvature(p).ok())
            .flatten(),
        missing_points: p.missing_points(),
        psd_fit: args.psd_fit.then(|| PsdFitInfo::of_profile(p)),
    };
    if args.json {
        super::print_json(&info)
    } else {
        super::print(&profile_summary(&info))
    }
}

struct Stats {
    mean: f64,
    /// Population standard deviation.
    rms: f64,
    min: f64,
    max: f64,
}

impl Stats {
    /// `None` when every point is missing.
    fn of(heights: &Array2<f64>) -> Option<Stats> {
        let defined = || heights.iter().copied().filter(|h| !h.is_nan());
        let n = defined().count();
        if n == 0 {
            return None;
        }
        let mean = defined().sum::<f64>() / n as f64;
        // Deviations from the mean, not the mean of squares: heights of nm on an offset of µm
        // would lose their digits.
        let rms = (defined().map(|h| (h - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let min = defined().fold(f64::INFINITY, f64::min);
        let max = defined().fold(f64::NEG_INFINITY, f64::max);
        Some(Stats { mean, rms, min, max })
    }
}

/// The readable form of `info`, one quantity a line, lengths with SI prefixes.
fn summary(info: &Info) -> String {
    // Names and units as the file writes them, escaped: a name is never a second line.
    let quoted = |names: &[String]| names.iter().map(|n| format!("'{}'", escaped(n))).collect::<Vec<_>>().join(", ");
    let mut s = format!("file         {} ({})\n", escaped(&info.file.display().to_string()), info.format);
    s += &format!("channels     {}\n", quoted(&info.channels));
    s += &format!("channel      '{}'\n", escaped(&info.channel));
    s += &format!("grid         {} × {} points (nx × ny)\n", info.nx, info.ny);
    s += &match info.physical_size_m {
        Some([lx, ly]) => format!(
            "size         {} × {} (pixel {} × {})\n",
            metres(&lx),
            metres(&ly),
            metres(&(lx / info.nx as f64)),
            metres(&(ly / info.ny as f64))
        ),
        None => "size         not stated in the file (give it with --size LX[,LY], metres)\n".into(),
    };
    s += &match (&info.height_unit, info.height_unit_known) {
        (Some(u), true) => format!("height unit  {}\n", escaped(u)),
        (Some(u), false) => {
            format!("height unit  {}: not a length, and the file gives no factor to metres\n", escaped(u))
        }
        (None, _) => "height unit  unknown: the file states none (give it with --height-unit U)\n".into(),
    };
    let total = info.nx * info.ny;
    match (&info.metres, &info.as_stored) {
        (Some(MetreStats { mean_m: Some(mean), rms_m: Some(rms), min_m: Some(min), max_m: Some(max) }), _) => {
            s += &format!("mean         {}\n", metres(mean));
            s += &format!("rms          {}\n", metres(rms));
            s += &format!("min, max     {}, {}\n", metres(min), metres(max));
        }
        (_, Some(StoredStats { mean: Some(mean), rms: Some(rms), min: Some(min), max: Some(max) })) => {
            s += &format!("values       as stored, unit unknown: mean {mean:.4e}, rms {rms:.4e}\n");
            s += &format!("min, max     {min:.4e}, {max:.4e} (as stored)\n");
        }
        _ => s += "heights      none defined\n",
    }
    if let Some(g) = &info.slope_curvature {
        s += &format!("rms slope    {:.4} (gradient; {:.4} along x)\n", g.rms_gradient, g.rms_slope_from_profile);
        s += &format!(
            "rms curv.    {:.4e} 1/m (half the Laplacian; {:.4e} 1/m along x)\n",
            g.rms_curvature_from_area_per_m, g.rms_curvature_from_profile_per_m
        );
    }
    s += &format!("missing      {} of {total} points\n", info.missing_points);
    s += &info.psd_fit.as_ref().map_or(String::new(), PsdFitInfo::summary);
    s
}

/// The readable form of `info` of a line profile.
fn profile_summary(info: &ProfileInfo) -> String {
    let mut s = format!("file         {} ({})\n", info.file.display(), info.format);
    s += &format!("channel      '{}'\n", info.channel);
    let uniform = match (info.uniform, info.on_stated_grid) {
        (true, true) => "uniform positions (on the grid of the step the file states)",
        (true, false) => "uniform positions",
        (false, _) => "non-uniform positions",
    };
    s += &format!("profile      {} points along x, {uniform} (a line profile, not a 2-D map)\n", info.points);
    s += &match (&info.positions_m, &info.positions_stored) {
        (Some(ExtentMetres { length_m, step_m: Some(step) }), _) => {
            format!("length       {} (step {})\n", metres(length_m), metres(step))
        }
        (Some(ExtentMetres { length_m, step_m: None }), _) => format!("length       {}\n", metres(length_m)),
        (_, Some(ExtentStored { length, .. })) => format!(
            "length       {length:.4e} as stored: the file states no unit for the positions (give it with \
             --position-unit U)\n"
        ),
        _ => String::new(),
    };
    s += &match (&info.height_unit, info.height_unit_known) {
        (Some(u), _) => format!("height unit  {u}\n"),
        (None, true) => "height unit  given with --height-unit\n".into(),
        (None, false) => "height unit  unknown: the file states none (give it with --height-unit U)\n".into(),
    };
    match (&info.metres, &info.as_stored) {
        (Some(MetreStats { mean_m, rms_m, min_m: Some(min), max_m: Some(max) }), _) => {
            match (mean_m, rms_m) {
                (Some(mean), Some(rms)) => {
                    s += &format!("mean         {}\n", metres(mean));
                    s += &format!("rms          {}\n", metres(rms));
                }
                _ => s += "rms          none: missing points in a non-uniform profile\n",
            }
            s += &format!("min, max     {}, {}\n", metres(min), metres(max));
        }
        (_, Some(StoredStats { mean, rms, min: Some(min), max: Some(max) })) => {
            match (mean, rms) {
                (Some(mean), Some(rms)) => {
                    s += &format!("values       as stored, unit unknown: mean {mean:.4e}, rms {rms:.4e}\n")
                }
                _ => s += "rms          none: missing points in a non-uniform profile\n",
            }
            s += &format!("min, max     {min:.4e}, {max:.4e} (as stored)\n");
        }
        _ => s += "heights      none defined\n",
    }
    s += &match info.rms_slope {
        Some(g) => format!("rms slope    {g:.4}\n"),
        None if info.positions_m.is_some() && info.height_unit_known => {
            "rms slope    none: missing points in a non-uniform profile\n".into()
        }
        None => "rms slope    unknown: needs the units of the positions and the heights\n".into(),
    };
    if let Some(c) = info.rms_curvature_per_m {
        s += &format!("rms curv.    {c:.4e} 1/m\n");
    }
    s += &format!("missing      {} of {} points\n", info.missing_points, info.points);
    s += &info.psd_fit.as_ref().map_or(String::new(), PsdFitInfo::summary);
    s
}

/// A length with an SI prefix and four significant digits: `-18.79 nm`, `10.00 µm`; beyond
/// the prefixes (below 1 fm, from 1000 km) in metres with an exponent, `2.000e-16 m`.
fn metres(x: &f64) -> String {
    let x = *x;
    const PREFIXES: [(&str, f64); 7] =
        [("km", 1e3), ("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9), ("pm", 1e-12), ("fm", 1e-15)];
    if x == 0.0 || !x.is_finite() {
        return format!("{x} m");
    }
    if !(1e-15..1e6).contains(&x.abs()) {
        return format!("{x:.3e} m");
    }
    let (unit, scale) = PREFIXES.iter().copied().find(|&(_, s)| x.abs() >= s).unwrap_or(PREFIXES[6]);
    let v = x / scale;
    // The nudge keeps 10e-6 / 1e-6 = 9.999…8 at two decimals, as 10.00.
    let decimals = (3 - (v.abs() * (1.0 + 1e-12)).log10().floor() as i32).clamp(0, 3) as usize;
    format!("{v:.decimals$} {unit}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_over_defined_points() {
        let h = Array2::from_shape_vec((2, 3), vec![1.0, f64::NAN, 2.0, 3.0, 4.0, f64::NAN]).unwrap();
        let s = Stats::of(&h).unwrap();
        assert_eq!((s.mean, s.min, s.max), (2.5, 1.0, 4.0));
        assert!((s.rms - 1.25f64.sqrt()).abs() < 1e-15);
        assert!(Stats::of(&Array2::from_elem((2, 2), f64::NAN)).is_none());
    }

    #[test]
    fn lengths_read_well() {
        assert_eq!(metres(&10e-6), "10.00 µm");
        assert_eq!(metres(&-1.8790862671584778e-08), "-18.79 nm");
        assert_eq!(metres(&1.5), "1.500 m");
        assert_eq!(metres(&2e-15), "2.000 fm");
        // Not "0.000 fm", nor thirty digits of km.
        assert_eq!(metres(&2e-16), "2.000e-16 m");
        assert_eq!(metres(&-1.8e40), "-1.800e40 m");
    }
}
