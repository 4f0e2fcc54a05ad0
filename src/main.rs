//! The `asperity` command: a thin layer over the library.
//!
//! Must not hold a command's work (that is `cli`'s) nor physics (the library's): it parses and
//! dispatches.
//! It imports only `cli` and the library's public API (`asperity::…`), never a module's internals.

mod cli;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Static friction of rough interfaces from their measured topography: elastic contact by the
/// boundary integral method, then the stick-slip transition model of Peng, Roch, Bonn & Weber
/// (PRL 134, 176202, 2025). Units are SI throughout: metres, pascals, newtons.
/// The version, and whether this build has the GPU backend (`--device gpu`).
#[cfg(feature = "gpu")]
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (commit ", env!("ASPERITY_COMMIT"), "; GPU backend: built; --device gpu needs an NVIDIA driver)");
#[cfg(not(feature = "gpu"))]
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (commit ", env!("ASPERITY_COMMIT"), "; GPU backend: not built; build with --features gpu)");

#[derive(Parser)]
#[command(name = "asperity", version = VERSION, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    // Each command's help is its arguments' doc: a summary (its line in `asperity --help`),
    // then what `asperity COMMAND --help` adds.
    Contact(cli::contact::ContactArgs),
    Onset(cli::onset::Args),
    Slide(cli::slide::SlideArgs),
    Topo(cli::topo::TopoArgs),
    Shs(cli::shs::Args),
    Run(cli::run::RunArgs),
    Slurm(cli::slurm::SlurmArgs),
}

fn main() -> ExitCode {
    if let Err(e) = cli::handle_signals() {
        cli::message(&format!("error: {e}"));
        return ExitCode::FAILURE;
    }
    let command = cli::negative_values_reach_their_option(Cli::command());
    let cli = match command.try_get_matches().and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(cli) => cli,
        Err(e) => return cli::exit_on_usage_error(e),
    };
    // The worker threads, started once, before any work (a bad RAYON_NUM_THREADS is refused).
    let started = asperity::limits::start_threads();
    let result: asperity::Result<()> = started.and_then(|_| match cli.command {
        Command::Contact(args) => cli::contact::run(args),
        Command::Onset(args) => cli::onset::run(args),
        Command::Slide(args) => cli::slide::run(args),
        Command::Topo(args) => cli::topo::run(args),
        Command::Shs(args) => cli::shs::run(args),
        Command::Run(args) => cli::run::run(args),
        Command::Slurm(args) => cli::slurm::run(args),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            cli::message(&format!("error: {e}"));
            ExitCode::FAILURE
        }
    }
}
