//! Command implementations: each parses its arguments (clap) and calls the library.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

pub mod contact;
pub mod onset;
pub mod run;
pub mod shs;
pub mod slide;
pub mod slurm;
pub mod topo;
pub mod topo_tools;

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::builder::PossibleValuesParser;
use clap::Args;

use asperity::contact::{combined_modulus, Boundary, Device, Material};
use asperity::error::{acts_on_terminal, escaped, one_line};
use asperity::limits::{Limits, DEFAULT_MAX_POINTS};
use asperity::plausible::{self, Spelling};
use asperity::quantity;
use asperity::topography::io::{self, ReadOptions};
use asperity::{Error, Result};

/// SIGINT and SIGTERM remove the temporaries in flight (`.asperity-*.partial`) and end the
/// process with 130 and 143 (locks go with the process); SIGPIPE, a reader such as `head` that
/// stops early, ends it quietly as it ends any Unix tool (Rust ignores it by default, which
/// turns every later print into a panic).
/// Set once a study run starts: its stop message then says that it resumes.
static RESUMABLE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// A stop from now on is of a study run, which resumes when run again.
pub fn stop_resumes() {
    RESUMABLE.store(true, std::sync::atomic::Ordering::SeqCst);
}

pub fn handle_signals() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    // SAFETY: restoring a signal's default disposition, before any other thread exists.
    if unsafe { libc::signal(libc::SIGPIPE, libc::SIG_DFL) } == libc::SIG_ERR {
        return Err(std::io::Error::last_os_error());
    }
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Held to the end: no writer gets to report a removed temporary and exit first.
            let _held = asperity::output::remove_temporaries();
            let name = if signal == SIGINT { "SIGINT" } else { "SIGTERM" };
            let resume = if RESUMABLE.load(std::sync::atomic::Ordering::SeqCst) {
                "; run the same command again to resume from its finished work"
            } else {
                ""
            };
            // Held to the exit (it is reentrant: `message` takes it again): no other thread's
            // line (a start line, a progress bar) comes after this one.
            let mut stderr = std::io::stderr().lock();
            // On a line of its own, below a progress bar.
            let _ = stderr.write_all(b"\n");
            message(&format!(
                "asperity: stopped by {name}; its temporaries removed, nothing half-written kept{resume}"
            ));
            std::process::exit(128 + signal);
        }
    })?;
    Ok(())
}

/// Print a usage error as one short line naming the option (help and version requests print
/// in full) and exit 2.
pub fn exit_on_usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    match e.kind() {
        // Asked for: on standard output, whose failure (a full disk) is an error as any command's.
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            use std::io::IsTerminal;
            let text = e.render();
            let shown = if std::io::stdout().is_terminal() { text.ansi().to_string() } else { text.to_string() };
            match to_stdout(|w| w.write_all(shown.as_bytes())) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    message(&format!("error: {e}"));
                    ExitCode::FAILURE
                }
            }
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            ExitCode::from(2)
        }
        _ => {
            message(&usage_line(&e));
            ExitCode::from(2)
        }
    }
}

/// Write to standard output through `fill`: the one way every command prints its results. A
/// failed write (a full disk) is an error naming standard output, not a panic; a reader that
/// stops early (`| head`) ends the process quietly by SIGPIPE first (see [`handle_signals`]).
pub fn to_stdout(fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let mut w = std::io::BufWriter::new(std::io::stdout().lock());
    fill(&mut w).and_then(|()| w.flush()).map_err(|e| Error::io("standard output", e))
}

/// Print `text` on standard output (see [`to_stdout`]), each of its lines [`escaped`]: a
/// command's readable output quotes file names, channel names and units.
pub fn print(text: &str) -> Result<()> {
    let lines: Vec<_> = text.split('\n').map(escaped).collect();
    to_stdout(|w| w.write_all(lines.join("\n").as_bytes()))
}

/// Print `value` as pretty JSON on standard output (see [`to_stdout`]). The characters that
/// [`escaped`] escapes and JSON allows raw in a string (DEL, C1 controls, bidirectional marks)
/// are written as JSON's `\uXXXX`: the output stays valid JSON, inert on a terminal.
pub fn print_json<T: serde::Serialize>(value: &T) -> Result<()> {
    use std::fmt::Write as _;
    let text = serde_json::to_string_pretty(value).map_err(|e| Error::invalid("--json", e.to_string()))?;
    let mut json = String::with_capacity(text.len() + 1);
    // A raw newline is the layout's: serde_json escapes those in strings.
    for c in text.chars() {
        if acts_on_terminal(c) && c != '\n' {
            let _ = write!(json, "\\u{:04x}", c as u32);
        } else {
            json.push(c);
        }
    }
    json.push('\n');
    to_stdout(|w| w.write_all(json.as_bytes()))
}

/// Print one line on standard error (an error, a warning, what was written, progress) as
/// [`one_line`] has it, escaped and short with its reason whole: it may echo a path, a file's
/// content or an option's value. A failed write is ignored: nothing is left to tell it to.
pub fn message(line: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{}", one_line(line));
}

/// Move a command's finished output folder into place; a file that appeared in the earlier
/// output meanwhile is said, with where it was kept.
fn commit(out: asperity::output::StagedDir) -> asperity::error::Result<PathBuf> {
    let committed = out.commit()?;
    if let Some((_, line)) = &committed.kept {
        message(&format!("warning: {line}"));
    }
    Ok(committed.dir)
}

/// Clap's own first line of an error.
fn first_line(e: &clap::Error) -> String {
    e.render().to_string().lines().next().unwrap_or("error: invalid usage").to_string()
}

/// `error: --option: reason` for a bad value, else clap's first line, as one short line
/// ([`one_line`]; clap quotes a bad token whole).
fn usage_line(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let text = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.as_str()),
        _ => None,
    };
    // "--load <N>" → "--load".
    let option = text(ContextKind::InvalidArg).and_then(|a| a.split([' ', '=']).next());
    let value = text(ContextKind::InvalidValue).unwrap_or("");
    let line = match (e.kind(), option) {
        (ErrorKind::ValueValidation, Some(o)) => match std::error::Error::source(e) {
            Some(reason) => format!("error: {o}: {reason}"),
            None => format!("error: {o}: invalid value {}", quantity::quoted(value)),
        },
        (ErrorKind::InvalidValue, Some(o)) => match e.get(ContextKind::ValidValue) {
            Some(ContextValue::Strings(v)) if !v.is_empty() => {
                format!("error: {o}: {} is not a valid value (one of {})", quantity::quoted(value), v.join(", "))
            }
            // Clap refuses an empty path ("--out ''") as a value missing.
            _ if value.is_empty() && text(ContextKind::InvalidArg).is_some_and(|a| a.ends_with("<DIR>")) => {
                format!("error: {o}: an empty path is no folder: give the folder's path")
            }
            _ if value.is_empty() => format!("error: {o}: an empty value: give one (see --help)"),
            _ => format!("error: {o}: {} is not a valid value", quantity::quoted(value)),
        },
        (ErrorKind::MissingRequiredArgument, _) => match e.get(ContextKind::InvalidArg) {
            Some(ContextValue::Strings(missing)) => {
                format!("error: {} must be given (see --help)", missing.join(", "))
            }
            _ => first_line(e),
        },
        _ => first_line(e),
    };
    one_line(&line)
}

/// Let every option whose value is a number or a quantity take a value starting with '-'
/// (`--tolerance -1`, `--load -inf`, `--crop -5:5,…`), so that the option's own check refuses
/// it by name instead of clap taking it for an unknown flag. Paths and names are left as
/// clap parses them: a forgotten value there should not swallow the next option.
pub fn negative_values_reach_their_option(cmd: clap::Command) -> clap::Command {
    use clap::builder::ValueParser;
    let textual = [ValueParser::path_buf().type_id(), ValueParser::string().type_id()];
    cmd.mut_args(|a| {
        if a.get_action().takes_values() && !a.is_positional() && !textual.contains(&a.get_value_parser().type_id()) {
            a.allow_hyphen_values(true)
        } else {
            a
        }
    })
    .mut_subcommands(negative_values_reach_their_option)
}

/// A count or an integer seed: a whole number ≥ 0 (a clap value parser).
pub fn count<T: std::str::FromStr>(s: &str) -> std::result::Result<T, String> {
    s.trim().parse::<T>().map_err(|_| format!("{} is not a whole number ≥ 0", quantity::quoted(s)))
}

/// How to read a topography file: the options every command that reads one takes.
#[derive(Args)]
pub struct ReadArgs {
    /// Topography file, in any format asperity reads (detected from its content and extension).
    pub file: PathBuf,
    /// Channel to read, by name or 0-based index [default: the first height channel].
    #[arg(long, value_name = "C")]
    channel: Option<String>,
    /// Physical size LX or LX,LY [m, or with a unit: 31.13um] (LY defaults to LX): needed for
    /// a bare array (.npy), checked against the size a file states.
    #[arg(long, value_name = "LX[,LY]", value_parser = parse_size)]
    size: Option<(f64, f64)>,
    /// Unit of the heights of a file that states none (m, mm, µm, nm, Å); a bare array
    /// defaults to m. For a line profile, also the unit of its positions when the file states
    /// none and --position-unit is not given (SurfaceTopography's one length unit of a line scan).
    #[arg(long, value_name = "U")]
    height_unit: Option<String>,
    /// Unit of a line profile's positions when the file states none (m, mm, µm, nm, Å)
    /// [default: --height-unit's].
    #[arg(long, value_name = "U")]
    position_unit: Option<String>,
    /// File format, overriding detection (a short two-column table: profile or matrix).
    #[arg(long, value_name = "F", value_parser = PossibleValuesParser::new(io::format_names()))]
    format: Option<String>,
    #[command(flatten)]
    pub limits: LimitArgs,
}

impl ReadArgs {
    /// The first option of reading a topography that was given, if any: for an input that is
    /// not read as one, where it would do nothing.
    pub fn given(&self) -> Option<&'static str> {
        let given = [
            (self.channel.is_some(), "--channel"),
            (self.size.is_some(), "--size"),
            (self.height_unit.is_some(), "--height-unit"),
            (self.position_unit.is_some(), "--position-unit"),
            (self.format.is_some(), "--format"),
        ];
        given.into_iter().find(|(g, _)| *g).map(|(_, option)| option)
    }

    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            format: self.format.clone(),
            channel: self.channel.clone(),
            physical_size: self.size,
            height_unit: self.height_unit.clone(),
            position_unit: self.position_unit.clone(),
            limits: self.limits.limits(),
        }
    }
}

// Doc comments here are clap's --help text, printed as written (not Markdown): `[m]` states a unit.
#[allow(rustdoc::broken_intra_doc_links)]
/// The elastic bodies in contact and their boundary: the options of every command that solves
/// a contact.
#[derive(Args)]
pub struct MaterialArgs {
    /// Young's modulus of the elastic body [Pa, or with a unit: 130GPa] (default: silicon).
    #[arg(long, value_name = "E", default_value_t = Material::SILICON.youngs, allow_negative_numbers = true, value_parser = pressure)]
    youngs: f64,
    /// Poisson's ratio of the elastic body, in (−1, 0.5) (default: silicon).
    #[arg(long, value_name = "NU", default_value_t = Material::SILICON.poisson, allow_negative_numbers = true)]
    poisson: f64,
    /// Young's modulus of a second elastic body [Pa]; with --poisson2, the two combine as
    /// 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2. Without it the counter-body is rigid.
    #[arg(long, value_name = "E2", requires = "poisson2", allow_negative_numbers = true, value_parser = pressure)]
    youngs2: Option<f64>,
    /// Poisson's ratio of the second elastic body.
    #[arg(long, value_name = "NU2", requires = "youngs2", allow_negative_numbers = true)]
    poisson2: Option<f64>,
    /// Free (non-periodic) boundary: the window is an isolated patch of an infinite half-space,
    /// as for a sphere on a flat (a contact directory given to `slide` states its own).
    /// Default: periodic.
    #[arg(long)]
    pub free: bool,
}

impl MaterialArgs {
    /// The bodies (one on a rigid counter-body, else two) and their effective modulus E* \[Pa].
    pub fn bodies(&self) -> Result<(Vec<Material>, f64)> {
        judge("--youngs", plausible::modulus(self.youngs, Spelling::CommandLine))?;
        if let Some(e2) = self.youngs2 {
            judge("--youngs2", plausible::modulus(e2, Spelling::CommandLine))?;
        }
        let mut bodies = vec![Material::new(self.youngs, self.poisson, "--youngs/--poisson")?];
        if let (Some(e2), Some(nu2)) = (self.youngs2, self.poisson2) {
            bodies.push(Material::new(e2, nu2, "--youngs2/--poisson2")?);
        }
        let e_star = match bodies[..] {
            [a, b] => combined_modulus(&a, &b),
            [a] => a.plane_strain_modulus(),
            _ => unreachable!("one or two bodies"),
        };
        Ok((bodies, e_star))
    }

    /// The half-space's boundary: free with --free, else periodic.
    pub fn boundary(&self) -> Boundary {
        if self.free {
            Boundary::Free
        } else {
            Boundary::Periodic
        }
    }
}

/// Where the normal contact solves of a command run.
#[derive(Args)]
pub struct DeviceArgs {
    /// Where the normal contact solves run: "cpu" (every core), or "gpu" (the first NVIDIA GPU,
    /// through the CUDA driver, cuFFT and NVRTC found at run time; a build with `--features
    /// gpu`, see `asperity --version`).
    #[arg(long, value_name = "DEVICE", default_value = "cpu", value_parser = device)]
    pub device: Device,
}

fn device(s: &str) -> std::result::Result<Device, String> {
    match s {
        "cpu" => Ok(Device::Cpu),
        "gpu" if Device::GPU_BUILT => Ok(Device::Gpu),
        "gpu" => Err(Device::UNAVAILABLE.to_string()),
        _ => Err(format!("{s:?} is not a device: give cpu or gpu")),
    }
}

/// The input limit every command that reads or makes a grid takes.
#[derive(Args, Debug)]
pub struct LimitArgs {
    /// Largest grid accepted, read from a file or made [points; default 2^28 = 268435456]; a
    /// file is read only up to 128 bytes per point.
    #[arg(long, value_name = "N", value_parser = max_points, allow_hyphen_values = true)]
    max_points: Option<Limits>,
}

impl LimitArgs {
    /// The limits: --max-points, or the defaults.
    pub fn limits(&self) -> Limits {
        self.max_points.unwrap_or_default()
    }

    /// --max-points, when given.
    pub fn given(&self) -> Option<Limits> {
        self.max_points
    }
}

/// `--max-points N`: a count of points, written as an integer or in float notation (1e9).
fn max_points(s: &str) -> std::result::Result<Limits, String> {
    let n = match s.trim().parse::<usize>() {
        Ok(n) => n,
        Err(_) => match s.trim().parse::<f64>() {
            Ok(x) if x >= 0.0 && x.fract() == 0.0 && x < usize::MAX as f64 => x as usize,
            _ => {
                return Err(format!("{} is not a number of points (default {DEFAULT_MAX_POINTS})", quantity::quoted(s)))
            }
        },
    };
    Limits::new(n, "--max-points").map_err(|e| match e {
        asperity::Error::Invalid { reason, .. } => reason,
        e => e.to_string(),
    })
}

/// `--size LX` or `LX,LY`: lengths of a window, bare numbers in metres or with a unit
/// ("31.13um"); a size no measured window has is refused, an unusual one warned about.
fn parse_size(s: &str) -> std::result::Result<(f64, f64), String> {
    let window = |text: &str| -> std::result::Result<f64, String> {
        let l = length(text)?;
        match plausible::window(l, Spelling::CommandLine) {
            Ok(None) => Ok(l),
            Ok(Some(w)) => {
                message(&format!("warning: --size: {w}"));
                Ok(l)
            }
            Err(reason) => Err(reason),
        }
    };
    match s.split_once(',') {
        Some((lx, ly)) => Ok((window(lx)?, window(ly)?)),
        None => window(s).map(|l| (l, l)),
    }
}

/// `option`'s value as [`plausible`] judges it: refused in one line naming the option, or
/// warned about on stderr (unusual) and taken.
pub fn judge(option: &str, verdict: plausible::Verdict) -> Result<()> {
    match verdict {
        Ok(None) => Ok(()),
        Ok(Some(warning)) => {
            message(&format!("warning: {option}: {warning}"));
            Ok(())
        }
        Err(reason) => Err(Error::invalid(option, reason)),
    }
}

// Clap value parsers for quantities: a bare number in SI units, or a number with its unit as
// in the study file ("1mN", "31.13 µm", "130GPa").

/// A length \[m].
pub fn length(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::LENGTH, true)
}

/// A force \[N].
pub fn force(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::FORCE, true)
}

/// A work of adhesion \[J/m²].
pub fn surface_energy(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::SURFACE_ENERGY, true)
}

/// A pressure or modulus \[Pa].
pub fn pressure(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::PRESSURE, true)
}

/// An area \[m²].
pub fn area(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::AREA, true)
}

/// A duration \[s].
pub fn time(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::TIME, true)
}

/// A speed [m/s].
pub fn speed(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::SPEED, true)
}

/// A stiffness [N/m].
pub fn stiffness(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::STIFFNESS, true)
}

/// Time between progress lines when stderr is not a terminal (a batch log).
pub const BATCH_PROGRESS: std::time::Duration = std::time::Duration::from_secs(5);

/// A progress bar on stderr for long work, hidden when stderr is not a terminal; with `eta`
/// when its positions come at an even pace.
pub fn progress_bar(len: u64, what: &str, eta: bool) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(bar_style(what, "{pos}/{len}", eta));
    // The elapsed time goes on through a long solve.
    bar.enable_steady_tick(std::time::Duration::from_secs(1));
    bar
}

/// A progress bar's style: `what`, the bar, `position` (an indicatif template such as
/// `{pos}/{len}` or `{percent}%`), the elapsed time and, with `eta`, the time left.
pub fn bar_style(what: &str, position: &str, eta: bool) -> indicatif::ProgressStyle {
    let eta = if eta { ", eta {eta}" } else { "" };
    indicatif::ProgressStyle::with_template(&format!("{what} {{bar:30}} {position} [{{elapsed_precise}}{eta}] {{msg}}"))
        .expect("valid progress template")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1e-6"), Ok((1e-6, 1e-6)));
        assert_eq!(parse_size("1e-6, 2e-6"), Ok((1e-6, 2e-6)));
        assert_eq!(parse_size("31.13um"), Ok((31.13e-6, 31.13e-6)));
        assert!(parse_size("10 mN").unwrap_err().contains("not a length"));
        assert!(parse_size("31.13").unwrap_err().ends_with("did you mean 31.13um?"));
        assert!(parse_size("1e-6,31.13").unwrap_err().ends_with("did you mean 31.13um?"));
        assert_eq!(force("1mN"), Ok(1e-3));
        assert_eq!(pressure("130 GPa"), Ok(130e9));
    }
}
