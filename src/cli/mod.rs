//! Command implementations: each parses its arguments (clap) and calls the library.

pub mod contact;
pub mod onset;
pub mod run;
pub mod shs;
pub mod slide;
pub mod topo;
pub mod topo_tools;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::builder::PossibleValuesParser;
use clap::Args;

use asperity::quantity;
use asperity::topography::io::{self, ReadOptions};

/// Print a usage error as one line (help and version requests print in full) and exit 2.
pub fn exit_on_usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            }
        }
        _ => {
            let text = e.render().to_string();
            eprintln!("{}", text.lines().next().unwrap_or("error: invalid usage"));
            ExitCode::from(2)
        }
    }
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
    /// defaults to m.
    #[arg(long, value_name = "U")]
    height_unit: Option<String>,
    /// File format, overriding detection.
    #[arg(long, value_name = "F", value_parser = PossibleValuesParser::new(io::format_names()))]
    format: Option<String>,
}

impl ReadArgs {
    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            format: self.format.clone(),
            channel: self.channel.clone(),
            physical_size: self.size,
            height_unit: self.height_unit.clone(),
        }
    }
}

/// `LX` or `LX,LY`: lengths, bare numbers in metres or with a unit ("31.13um").
fn parse_size(s: &str) -> std::result::Result<(f64, f64), String> {
    match s.split_once(',') {
        Some((lx, ly)) => Ok((length(lx)?, length(ly)?)),
        None => length(s).map(|l| (l, l)),
    }
}

// Clap value parsers for quantities: a bare number in SI units, or a number with its unit as
// in the study file ("1mN", "31.13 µm", "130GPa").

/// A length [m].
pub fn length(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::LENGTH, true)
}

/// A force [N].
pub fn force(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::FORCE, true)
}

/// A pressure or modulus [Pa].
pub fn pressure(s: &str) -> std::result::Result<f64, String> {
    quantity::parse(s, &quantity::PRESSURE, true)
}

/// A progress bar on stderr for long work, hidden when stderr is not a terminal.
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(&format!(
            "{what} {{bar:30}} {{pos}}/{{len}} [{{elapsed_precise}}, eta {{eta}}] {{msg}}"
        ))
        .expect("valid progress template"),
    );
    bar
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
        assert_eq!(force("1mN"), Ok(1e-3));
        assert_eq!(pressure("130 GPa"), Ok(130e9));
    }
}
