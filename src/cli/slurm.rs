//! `asperity slurm`: a study as a Slurm job array of shards and a job that assembles them.
//!
//! Must not hold physics or a check that Python needs too (those are the library's); it uses the
//! library through `asperity::…` only.

use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Args;

use asperity::study::slurm::SlurmJob;
use asperity::{Error, Result};

/// Write Slurm batch scripts that run a study on a cluster, split into N shards.
///
/// A job array of N tasks, task I running `asperity run STUDY --out DIR --shard I/N`, and a
/// job that assembles the table, figures and report once every task has succeeded (`asperity
/// run STUDY --out DIR`, which solves nothing twice). With --submit, submits both (the second with
/// --dependency=afterok:<the array's id>) and prints the job ids.
///
/// The scripts go into DIR/slurm/ (shards.sh, assemble.sh; the jobs' logs beside them); DIR
/// becomes the study's first, as `asperity run` makes it, so a DIR holding something else is
/// refused. They run this very asperity binary, by its absolute path, and the study and DIR
/// by theirs: the nodes must see them at the same paths (a shared filesystem).
#[derive(Args)]
pub struct SlurmArgs {
    /// Study file (TOML) [default: the embedded default study].
    study: Option<PathBuf>,
    /// Number of shards N: array tasks 1 to N.
    #[arg(long, value_name = "N", value_parser = shards)]
    shards: usize,
    /// Output directory of the study, on a filesystem the nodes share.
    #[arg(long, value_name = "DIR", default_value = "results")]
    out: PathBuf,
    /// The study at the --quick scale (as `asperity run --quick`).
    #[arg(long)]
    quick: bool,
    /// Slurm partition of every job.
    #[arg(long, value_name = "P")]
    partition: Option<String>,
    /// Time limit of each job, in Slurm's forms (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM,
    /// D-HH:MM:SS, UNLIMITED).
    #[arg(long, value_name = "T", value_parser = slurm_time)]
    time: Option<String>,
    /// CPUs per job, 1 to 4096 (the solver runs as many threads) [default: Slurm's].
    #[arg(long, value_name = "C", value_parser = super::count::<usize>)]
    cpus: Option<usize>,
    /// Memory per job, in Slurm's form: a whole number with an optional K, M, G or T (4G,
    /// 500M; megabytes without) [default: Slurm's].
    #[arg(long, value_name = "M", value_parser = slurm_memory)]
    mem: Option<String>,
    /// Submit the jobs with sbatch, and print their ids.
    #[arg(long)]
    submit: bool,
    #[command(flatten)]
    limits: super::LimitArgs,
}

pub fn run(args: SlurmArgs) -> Result<()> {
    let study = super::run::prepare(args.study.as_deref(), args.quick, &args.limits)?;
    // A shard without a solve is an array task queued for nothing (and 10^8 of them a flood of
    // a cluster's scheduler).
    if args.shards > study.solves() {
        return Err(Error::invalid(
            "--shards",
            format!(
                "{}: more shards than the study's {} loads of its sweeps (the least a shard takes); use at most {}",
                args.shards,
                study.solves(),
                study.solves()
            ),
        ));
    }
    let absolute = |p: &Path| -> Result<PathBuf> {
        let cwd = std::env::current_dir().map_err(|e| Error::io(".", e))?;
        Ok(cwd.join(p))
    };
    let dir = absolute(&args.out)?;
    let mut run_args = Vec::new();
    if let Some(path) = &args.study {
        run_args.push(text(&std::fs::canonicalize(path).map_err(|e| Error::io(path, e))?)?);
    }
    run_args.extend(["--out".to_string(), text(&dir)?]);
    if args.quick {
        run_args.push("--quick".into());
    }
    if let Some(limits) = args.limits.given() {
        run_args.extend(["--max-points".to_string(), limits.max_points.to_string()]);
    }
    let binary = std::env::current_exe().map_err(|e| Error::invalid("slurm", format!("the asperity binary: {e}")))?;
    let job = SlurmJob {
        binary,
        run_args,
        dir: dir.clone(),
        shards: args.shards,
        partition: args.partition,
        time: args.time,
        mem: args.mem,
        cpus: args.cpus,
    };
    // Checked before DIR is touched.
    job.shards_script()?;
    study.claim_dir(&dir)?;
    let (shards, assemble) = job.write()?;
    super::message(&format!("wrote {} ({} array tasks) and {}", shards.display(), args.shards, assemble.display()));
    if !args.submit {
        super::message(&format!("submit: {}", job.submit_line()?));
        return Ok(());
    }
    let array = sbatch(&shards, &[])?;
    let assembling = sbatch(&assemble, &[&format!("--dependency=afterok:{array}")])?;
    super::print(&format!(
        "shards job {array} (array 1-{})\nassembling job {assembling} (after every shard succeeded)\n",
        args.shards
    ))
}

/// Submit `script` with sbatch (and `options`); the job's id.
fn sbatch(script: &Path, options: &[&str]) -> Result<String> {
    let o = Command::new("sbatch").arg("--parsable").args(options).arg(script).output().map_err(|e| {
        Error::invalid("--submit", format!("sbatch: {e} (the scripts are written: submit them by hand)"))
    })?;
    let stdout = String::from_utf8_lossy(&o.stdout);
    // `--parsable` prints "id" or "id;cluster".
    let id = stdout.trim().split(';').next().unwrap_or_default();
    if !o.status.success() || id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        let stderr = String::from_utf8_lossy(&o.stderr);
        let why = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("no job id").trim().to_string();
        return Err(Error::invalid("--submit", format!("sbatch {}: {why}", script.display())));
    }
    Ok(id.to_string())
}

fn text(path: &Path) -> Result<String> {
    path.to_str().map(String::from).ok_or_else(|| Error::file(path, "not UTF-8: cannot go in a script"))
}

/// `--shards N`: at least 1.
fn shards(s: &str) -> std::result::Result<usize, String> {
    match super::count::<usize>(s)? {
        0 => Err("the number of shards must be at least 1".into()),
        n => Ok(n),
    }
}

/// A whole number as Slurm reads one: digits only.
fn digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

/// `--time`: Slurm's forms of a time limit (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM,
/// D-HH:MM:SS, UNLIMITED or infinite), which sbatch would otherwise refuse on the cluster.
fn slurm_time(s: &str) -> std::result::Result<String, String> {
    let (days, clock) = s.split_once('-').map_or((None, s), |(d, c)| (Some(d), c));
    let fields = clock.split(':').count();
    let slurm = matches!(s, "UNLIMITED" | "infinite")
        || (days.is_none_or(digits) && clock.split(':').all(digits) && (1..=3).contains(&fields));
    if slurm {
        Ok(s.to_string())
    } else {
        Err(format!(
            "{} is not a Slurm time limit: give minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS or UNLIMITED",
            asperity::quantity::quoted(s)
        ))
    }
}

/// `--mem`: Slurm's form of a memory size, a whole number with an optional K, M, G or T.
fn slurm_memory(s: &str) -> std::result::Result<String, String> {
    let number = s.strip_suffix(['K', 'M', 'G', 'T']).unwrap_or(s);
    if digits(number) {
        Ok(s.to_string())
    } else {
        Err(format!(
            "{} is not a Slurm memory size: give a whole number with an optional K, M, G or T (4G, 500M)",
            asperity::quantity::quoted(s)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_limits_and_memory_take_slurms_forms_only() {
        for t in ["90", "30:00", "12:00:00", "2-12", "2-12:30", "2-12:30:00", "UNLIMITED", "infinite"] {
            assert_eq!(slurm_time(t).as_deref(), Ok(t));
        }
        for t in ["forever", "", "1:2:3:4", "1h", "-5", "2-", "1-2-3", "1:-3"] {
            let e = slurm_time(t).unwrap_err();
            assert!(e.contains("is not a Slurm time limit: give minutes, MM:SS"), "{t}: {e}");
        }
        for m in ["4G", "500M", "1024", "2T", "64K"] {
            assert_eq!(slurm_memory(m).as_deref(), Ok(m));
        }
        for m in ["lots", "", "G", "4GB", "4.5G", "-1G"] {
            assert!(slurm_memory(m).unwrap_err().contains("is not a Slurm memory size"), "{m}");
        }
    }
}
