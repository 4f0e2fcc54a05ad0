//! The `asperity` command: a thin layer over the library.

mod cli;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Static friction of rough interfaces from their measured topography: elastic contact by the
/// boundary integral method, then the stick-slip transition model of Peng, Roch, Bonn & Weber
/// (PRL 134, 176202, 2025). Units are SI throughout: metres, pascals, newtons.
#[derive(Parser)]
#[command(name = "asperity", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Elastic normal contact of a topography at one or more loads: pressure maps and contact
    /// statistics (boundary integral method).
    Contact(cli::contact::ContactArgs),
    /// Static friction, friction drop and element classes from a pressure map (stick-slip model)
    Onset(cli::onset::Args),
    /// Sliding onset with elastic interaction between the contact points (tangential solve on
    /// the half-space): static friction, friction drop, shear maps
    Slide(cli::slide::SlideArgs),
    /// Topographies: inspect, prepare, synthesise, analyse (`topo info | convert | generate | psd`).
    Topo(cli::topo::TopoArgs),
    /// Static and dynamic friction after each hold of a slide-hold-slide trace
    Shs(cli::shs::Args),
    Run(cli::run::RunArgs),
    Slurm(cli::slurm::SlurmArgs),
}

fn main() -> ExitCode {
    if let Err(e) = cli::handle_signals() {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    let command = cli::negative_values_reach_their_option(Cli::command());
    let cli = match command.try_get_matches().and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(cli) => cli,
        Err(e) => return cli::exit_on_usage_error(e),
    };
    let result: asperity::Result<()> = match cli.command {
        Command::Contact(args) => cli::contact::run(args),
        Command::Onset(args) => cli::onset::run(args),
        Command::Slide(args) => cli::slide::run(args),
        Command::Topo(args) => cli::topo::run(args),
        Command::Shs(args) => cli::shs::run(args),
        Command::Run(args) => cli::run::run(args),
        Command::Slurm(args) => cli::slurm::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}", cli::one_short_line(&format!("error: {e}")));
            ExitCode::FAILURE
        }
    }
}
