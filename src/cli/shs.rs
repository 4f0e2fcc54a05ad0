//! `asperity shs`: static and dynamic friction after each hold of a slide-hold-slide trace.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::PathBuf;

use asperity::error::escaped;
use asperity::shs::{self, Analysis, ShsOptions, ShsPoint, Stat, TraceFormat};
use asperity::{plot, Error};

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// Static and dynamic friction after each hold of a slide-hold-slide trace.
///
/// Finds every hold and restart in a slide-hold-slide friction trace and reports, per restart,
/// the hold time, the static peak F_S, the dynamic friction F_D (mean over a window after the
/// peak), the normal force N, mu_s = F_S/N, mu_d = F_D/N and the friction drop F_S/F_D, then
/// the restarts grouped by hold time (mean ± sample standard deviation). The initial slide
/// before the first hold is not a restart. With a displacement column, a hold is the stage at
/// rest (below 0.1 × its sliding speed) for at least --min-duration, whether the force is released
/// or stays loaded, and its duration runs from the stage stopping to its moving again. Without
/// one, displacement is derived from time and --speed, and holds are seen in the friction signal
/// alone: the force must fall near zero, and a hold lasts while it stays there. Each hold found
/// and not measured (too short, no complete restart after it) is named with the reason on
/// stderr. A coefficient that is not finite or above 10 is refused, naming the trace's row.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Trace CSV with a header row: time_s [s], friction_n [N], normal_n [N] and optionally
    /// displacement_m [m] (rename with the --*-column options, rescale with --*-unit)
    #[arg(value_name = "TRACE.csv")]
    trace: PathBuf,
    /// Print the restarts and groups as JSON instead of a table
    #[arg(long)]
    json: bool,
    /// Write one point per hold-time group (load_n [N], friction_drop, their standard
    /// deviations, hold_s [s], n_restarts, …) as CSV for the friction-drop-vs-load figure
    #[arg(long, value_name = "POINTS.csv")]
    out: Option<PathBuf>,
    /// Draw the trace with the detected holds, peaks and windows as PNG (and SVG beside it)
    #[arg(long, value_name = "TRACE.png")]
    plot: Option<PathBuf>,
    /// Sliding displacement after the peak over which F_D and N are averaged [m, or with a
    /// unit: 1um]
    #[arg(long, value_name = "M", default_value = "1e-6", value_parser = super::length)]
    window: f64,
    /// Sliding displacement from the peak to the start of that window [m, or with a unit:
    /// 0.5um], to leave out the fall from F_S to steady sliding (0: at the peak)
    #[arg(long, value_name = "M", default_value = "0", value_parser = super::length)]
    window_start: f64,
    /// Sliding speed [m/s, or with a unit: 0.3um/s]; used to derive displacement from time
    /// when the trace has none
    #[arg(long, value_name = "M_PER_S", default_value = "3e-7", value_parser = super::speed)]
    speed: f64,
    /// Sliding displacement after the restart within which the static peak is sought [m, or
    /// with a unit: 2um]
    #[arg(long, value_name = "M", default_value = "2e-6", value_parser = super::length)]
    peak_within: f64,
    /// Shortest hold, and shortest slide, that count [s, or with a unit: 500ms]; briefer stops,
    /// dips or bursts are noise, and each hold so dropped is reported
    #[arg(long, value_name = "S", default_value = "1", value_parser = super::time)]
    min_duration: f64,
    /// Friction below this fraction of the sliding level counts as a hold, when the trace has no
    /// displacement column [dimensionless]
    #[arg(long, value_name = "FRACTION", default_value_t = 0.2)]
    hold_fraction: f64,
    /// Friction above this fraction of the sliding level counts as sliding again, when the trace
    /// has no displacement column [dimensionless]
    #[arg(long, value_name = "FRACTION", default_value_t = 0.5)]
    slide_fraction: f64,
    /// Hold times within this relative spread of a group's shortest are grouped [dimensionless]
    #[arg(long, value_name = "FRACTION", default_value_t = 0.25)]
    group_tolerance: f64,
    /// Name of the time column (its unit: --time-unit)
    #[arg(long, value_name = "NAME", default_value = "time_s")]
    time_column: String,
    /// Unit of the time column: s, ms, us, min or h
    #[arg(long, value_name = "UNIT", default_value = "s")]
    time_unit: String,
    /// Name of the friction force column (its unit: --friction-unit)
    #[arg(long, value_name = "NAME", default_value = "friction_n")]
    friction_column: String,
    /// Unit of the friction column: N, mN, uN (µN), nN or kN
    #[arg(long, value_name = "UNIT", default_value = "N")]
    friction_unit: String,
    /// Name of the normal force column (its unit: --normal-unit)
    #[arg(long, value_name = "NAME", default_value = "normal_n")]
    normal_column: String,
    /// Unit of the normal force column: N, mN, uN (µN), nN or kN
    #[arg(long, value_name = "UNIT", default_value = "N")]
    normal_unit: String,
    /// Name of the displacement column, which must then exist [default: displacement_m if present]
    #[arg(long, value_name = "NAME")]
    displacement_column: Option<String>,
    /// Unit of the displacement column: m, mm, um (µm), nm, …
    #[arg(long, value_name = "UNIT", default_value = "m")]
    displacement_unit: String,
}

pub fn run(args: Args) -> asperity::Result<()> {
    let unit = |option: &str, value: &str, parse: fn(&str) -> Option<f64>, known: &str| {
        parse(value).ok_or_else(|| Error::invalid(option, format!("unknown unit '{value}' (use {known})")))
    };
    let forces = "N, mN, uN, nN or kN";
    let format = TraceFormat {
        time_column: args.time_column,
        friction_column: args.friction_column,
        normal_column: args.normal_column,
        displacement_column: args.displacement_column,
        time_unit: unit("--time-unit", &args.time_unit, shs::seconds_per, "s, ms, us, min or h")?,
        friction_unit: unit("--friction-unit", &args.friction_unit, asperity::quantity::newtons_per, forces)?,
        normal_unit: unit("--normal-unit", &args.normal_unit, asperity::quantity::newtons_per, forces)?,
        displacement_unit: unit(
            "--displacement-unit",
            &args.displacement_unit,
            asperity::quantity::metres_per,
            "m, mm, um, nm",
        )?,
    };
    let options = ShsOptions {
        speed: args.speed,
        window: args.window,
        window_start: args.window_start,
        peak_within: args.peak_within,
        min_duration: args.min_duration,
        hold_fraction: args.hold_fraction,
        slide_fraction: args.slide_fraction,
        group_tolerance: args.group_tolerance,
    };
    options.validate()?;
    // The figure's .svg goes beside its .png.
    let outputs = [args.out.clone(), args.plot.clone(), args.plot.as_ref().map(|p| p.with_extension("svg"))];
    let outputs: Vec<&PathBuf> = outputs.iter().flatten().collect();
    for (i, out) in outputs.iter().enumerate() {
        asperity::output::check_output_file(out, &[&args.trace])?;
        // Two outputs of one name: the second would replace the first without a word.
        if let Some(first) = outputs[..i].iter().find(|o| o == &out) {
            return Err(Error::invalid(
                "--plot",
                format!("{} is also written as {}: give each output its own name", out.display(), first.display()),
            ));
        }
    }
    let trace = shs::read_trace(&args.trace, &format)?;
    let analysis = shs::analyse(&trace, &options)?;

    for skipped in &analysis.skipped {
        super::message(&format!("warning: {}: {}", args.trace.display(), skipped.reason));
    }
    if let Some(path) = &args.out {
        let points: Vec<ShsPoint> = analysis.groups.iter().map(ShsPoint::from).collect();
        shs::write_points(path, &points)?;
    }
    if let Some(path) = &args.plot {
        plot::write_figure(path, &plot::trace_figure(&trace, &analysis, &options))?;
    }
    if args.json {
        super::print_json(&analysis)
    } else {
        super::print(&table(&escaped(&args.trace.display().to_string()), &analysis, &options))
    }
}

/// The restarts and groups as aligned text, forces in a prefixed unit that suits them.
fn table(name: &str, a: &Analysis, options: &ShsOptions) -> String {
    let biggest = a.cycles.iter().map(|c| c.normal_force_n.max(c.static_force_n)).fold(0.0, f64::max);
    let (k, unit) = plot::prefixed(biggest, "N");
    let found_on = if a.holds_from == "displacement" { "the stage's displacement" } else { "the friction" };
    let mut s = format!(
        "{name}: {} holds found on {found_on}, {} skipped; {} restarts after holds, {} hold-time groups; F_D and \
         N over {} µm {}\n\n",
        a.holds_found,
        a.skipped.len(),
        a.cycles.len(),
        a.groups.len(),
        asperity::quantity::human(options.window * 1e6),
        if options.window_start > 0.0 {
            format!("from {} µm after each peak", asperity::quantity::human(options.window_start * 1e6))
        } else {
            "after each peak".to_string()
        }
    );
    let f = format!("F_S [{unit}]");
    let d = format!("F_D [{unit}]");
    let n = format!("N [{unit}]");
    s += &format!("{:>10} {f:>12} {d:>12} {n:>12} {:>8} {:>8} {:>8}\n", "hold [s]", "mu_s", "mu_d", "drop");
    for c in &a.cycles {
        s += &format!(
            "{:>10.2} {:>12.4} {:>12.4} {:>12.4} {:>8.4} {:>8.4} {:>8.4}\n",
            c.hold_s,
            c.static_force_n * k,
            c.dynamic_force_n * k,
            c.normal_force_n * k,
            c.static_coefficient,
            c.dynamic_coefficient,
            c.friction_drop
        );
    }
    let pm = |st: Stat, scale: f64, prec: usize| match st.std {
        Some(sd) => format!("{:.prec$} ± {:.prec$}", st.mean * scale, sd * scale),
        None => format!("{:.prec$}", st.mean * scale),
    };
    s += &format!("\n{:>18} {:>3} {n:>20} {:>18} {:>18} {:>18}\n", "hold [s]", "n", "mu_s", "mu_d", "drop");
    for g in &a.groups {
        s += &format!(
            "{:>18} {:>3} {:>20} {:>18} {:>18} {:>18}\n",
            pm(g.hold_s, 1.0, 2),
            g.n_restarts,
            pm(g.normal_force_n, k, 4),
            pm(g.static_coefficient, 1.0, 4),
            pm(g.dynamic_coefficient, 1.0, 4),
            pm(g.friction_drop, 1.0, 4)
        );
    }
    s
}
