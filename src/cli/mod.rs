//! Command implementations: each parses its arguments (clap) and calls the library.

pub mod topo;

use std::process::ExitCode;

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
