//! Command implementations: each parses its arguments (clap) and calls the library.

pub mod contact;
pub mod onset;
pub mod run;
pub mod shs;
pub mod topo;
pub mod topo_tools;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::builder::PossibleValuesParser;
use clap::Args;

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
    /// Physical size in metres, LX or LX,LY (LY defaults to LX): needed for a bare array
    /// (.npy), checked against the size a file states.
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

/// `LX` or `LX,LY` in metres.
fn parse_size(s: &str) -> std::result::Result<(f64, f64), String> {
    let number = |t: &str| t.trim().parse::<f64>().map_err(|_| format!("'{t}' is not a length in metres"));
    match s.split_once(',') {
        Some((lx, ly)) => Ok((number(lx)?, number(ly)?)),
        None => number(s).map(|l| (l, l)),
    }
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
        assert!(parse_size("10um").is_err());
    }
}
