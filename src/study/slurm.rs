//! Batch scripts that run a study on a Slurm cluster as [shards](super::shard): a job array
//! whose task I runs `asperity run … --shard I/N`, and a job that assembles the results once
//! they are all done (`asperity run …` without a shard, which solves nothing twice). Only the
//! scripts' text and their writing are here; submitting them is the command line's.
//!
//! It must not import the study file or the runner (the scripts only name the command), nor
//! `plot`, `report`, `cli` or `python`.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::limits::MAX_THREADS;
use crate::output;

/// The first line after the shebang of every script asperity writes: how it recognises its own.
const MARK: &str = "# Written by asperity slurm";
/// The folder of the scripts and the jobs' logs in the study's DIR.
pub const FOLDER: &str = "slurm";
/// The name in [`FOLDER`] of the script that runs the shards (a Slurm job array).
pub const SHARDS: &str = "shards.sh";
/// The name in [`FOLDER`] of the script of the job that writes the table, figures and report
/// once every shard is done.
pub const ASSEMBLE: &str = "assemble.sh";

/// What the scripts run and ask of the scheduler.
#[derive(Debug, Clone)]
pub struct SlurmJob {
    /// The asperity binary the nodes run: an absolute path, on a filesystem they share.
    pub binary: PathBuf,
    /// The arguments of `asperity run` common to every job (study, `--out DIR`, …), paths
    /// absolute.
    pub run_args: Vec<String>,
    /// The study's DIR (absolute): the scripts and logs go into its [`FOLDER`].
    pub dir: PathBuf,
    /// Number of shards N (array tasks 1 to N).
    pub shards: usize,
    /// Slurm's `--partition`; none: the cluster's default.
    pub partition: Option<String>,
    /// Slurm's `--time` per job (Slurm's forms: minutes, `H:MM:SS`, `D-HH`…); none: the
    /// partition's default.
    pub time: Option<String>,
    /// Slurm's `--mem` per job (`4G`); none: the partition's default.
    pub mem: Option<String>,
    /// CPUs per task, 1 to [`MAX_THREADS`]; the solver then uses as many threads.
    pub cpus: Option<usize>,
}

impl SlurmJob {
    /// The job array's script: task I of 1..=N runs shard I/N.
    pub fn shards_script(&self) -> Result<String> {
        let logs = "shard-%a.log";
        let run = format!("{} --shard \"$SLURM_ARRAY_TASK_ID/{}\"", self.command()?, self.shards);
        let what = format!("the {} shards of a study, one task each", self.shards);
        self.script(&what, "asperity-shards", Some(self.shards), logs, &run)
    }

    /// The assembling job's script (submitted with `--dependency=afterok:<the array's id>`):
    /// the study without a shard, which finds every solve done and writes the table, figures
    /// and report.
    pub fn assemble_script(&self) -> Result<String> {
        let what = "the table, figures and report once every shard is done";
        self.script(what, "asperity-assemble", None, "assemble.log", &self.command()?)
    }

    /// Write both scripts into the DIR's [`FOLDER`] (atomically), replacing only scripts
    /// asperity wrote there. Returns their paths: the array's, the assembling job's.
    pub fn write(&self) -> Result<(PathBuf, PathBuf)> {
        let scripts = [(SHARDS, self.shards_script()?), (ASSEMBLE, self.assemble_script()?)];
        let folder = self.folder();
        std::fs::create_dir_all(&folder).map_err(|e| Error::io(&folder, e))?;
        for (name, _) in &scripts {
            let path = folder.join(name);
            match std::fs::read_to_string(&path) {
                Ok(text) if text.lines().nth(1).is_some_and(|l| l.starts_with(MARK)) => {}
                Ok(_) | Err(_) if path.symlink_metadata().is_ok() => {
                    return Err(Error::invalid(
                        "--out",
                        format!("{} exists and is not a script asperity wrote: move it away", path.display()),
                    ))
                }
                _ => {}
            }
        }
        for (name, text) in &scripts {
            output::write_atomic(&folder.join(name), |w| w.write_all(text.as_bytes()))?;
        }
        Ok((folder.join(SHARDS), folder.join(ASSEMBLE)))
    }

    fn folder(&self) -> PathBuf {
        self.dir.join(FOLDER)
    }

    /// The command that submits both scripts, every path quoted for the shell, to paste into
    /// one: the array, then the assembling job once every task has succeeded.
    pub fn submit_line(&self) -> Result<String> {
        let script = |name: &str| -> Result<String> {
            let path = self.folder().join(name);
            quote(&text(&path, "the script's path")?)
        };
        Ok(format!(
            "id=$(sbatch --parsable {}) && sbatch --dependency=afterok:${{id%%;*}} {}",
            script(SHARDS)?,
            script(ASSEMBLE)?
        ))
    }

    /// `exec asperity run …`, every word quoted for the shell.
    fn command(&self) -> Result<String> {
        let mut words = vec![quote(&text(&self.binary, "the asperity binary")?)?, "run".to_string()];
        for a in &self.run_args {
            words.push(quote(a)?);
        }
        Ok(format!("exec {}", words.join(" ")))
    }

    /// A script named `name` that runs `run`, its log `log` (a Slurm filename pattern) in the
    /// [`FOLDER`].
    fn script(&self, what: &str, name: &str, array: Option<usize>, log: &str, run: &str) -> Result<String> {
        let mut lines = vec![
            "#!/bin/sh".to_string(),
            format!("{MARK} {}: {what}.", env!("CARGO_PKG_VERSION")),
            format!("#SBATCH --job-name={name}"),
        ];
        if let Some(n) = array {
            lines.push(format!("#SBATCH --array=1-{n}"));
        }
        // Slurm expands `%` in the log's path (`%j`, `%a`): the folder's own are written `%%`.
        let folder = text(&self.folder(), "the log's path")?.replace('%', "%%");
        lines.push(format!("#SBATCH --output={}/{log}", directive(&folder, "--out")?));
        for (option, value) in [("--partition", &self.partition), ("--time", &self.time), ("--mem", &self.mem)] {
            if let Some(v) = value {
                lines.push(format!("#SBATCH {option}={}", directive(v, option)?));
            }
        }
        if let Some(c) = self.cpus {
            if !(1..=MAX_THREADS).contains(&c) {
                return Err(Error::invalid("--cpus", format!("{c} CPUs: a job runs 1 to {MAX_THREADS} threads")));
            }
            lines.push(format!("#SBATCH --cpus-per-task={c}"));
            // The solver's threads (rayon) follow the CPUs given, not the node's.
            lines.push(format!("export RAYON_NUM_THREADS={c}"));
        }
        lines.push(run.to_string());
        Ok(lines.join("\n") + "\n")
    }
}

/// A path as text (a script is text).
fn text(path: &Path, what: &str) -> Result<String> {
    path.to_str()
        .map(String::from)
        .ok_or_else(|| Error::file(path, format!("{what} is not UTF-8: cannot go in a script")))
}

/// A word quoted for the shell.
fn quote(word: &str) -> Result<String> {
    shlex::try_quote(word).map(|q| q.into_owned()).map_err(|e| {
        Error::invalid("slurm", format!("{}: cannot be quoted for the shell: {e}", crate::quantity::quoted(word)))
    })
}

/// A value of an `#SBATCH` line, which Slurm reads up to the first space: no spaces, quotes or
/// control characters (a newline would start a line of the script).
fn directive(value: &str, option: &str) -> Result<String> {
    if value.is_empty() || value.chars().any(|c| c.is_whitespace() || c.is_control() || "\"'\\#$`".contains(c)) {
        return Err(Error::invalid(
            option,
            format!(
                "{} cannot go in an #SBATCH line (no spaces, quotes or special characters)",
                crate::quantity::quoted(value)
            ),
        ));
    }
    Ok(value.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(dir: &Path) -> SlurmJob {
        SlurmJob {
            binary: PathBuf::from("/opt/my tools/asperity"),
            run_args: vec!["/home/a/study's.toml".into(), "--out".into(), dir.join("out").display().to_string()],
            dir: dir.join("out"),
            shards: 3,
            partition: Some("short".into()),
            time: Some("1:00:00".into()),
            mem: None,
            cpus: Some(4),
        }
    }

    #[test]
    fn the_scripts_run_every_shard_then_assemble() {
        let dir = tempfile::tempdir().unwrap();
        let job = job(dir.path());
        let out = dir.path().join("out").display().to_string();
        let shards = job.shards_script().unwrap();
        let lines: Vec<&str> = shards.lines().collect();
        assert_eq!(lines[0], "#!/bin/sh");
        assert!(lines.contains(&"#SBATCH --array=1-3"), "{shards}");
        assert!(lines.contains(&"#SBATCH --partition=short") && lines.contains(&"#SBATCH --time=1:00:00"));
        assert!(lines.contains(&"#SBATCH --cpus-per-task=4") && lines.contains(&"export RAYON_NUM_THREADS=4"));
        assert!(!shards.contains("--mem"));
        assert!(lines.contains(&format!("#SBATCH --output={out}/slurm/shard-%a.log").as_str()), "{shards}");
        let run = format!(
            "exec '/opt/my tools/asperity' run \"/home/a/study's.toml\" --out {out} --shard \"$SLURM_ARRAY_TASK_ID/3\""
        );
        assert_eq!(*lines.last().unwrap(), run);
        let assemble = job.assemble_script().unwrap();
        assert!(!assemble.contains("--array") && !assemble.contains("--shard"), "{assemble}");
        assert!(assemble.ends_with(&format!("run \"/home/a/study's.toml\" --out {out}\n")), "{assemble}");

        // Written, rewritten; a file of the user's in their place is kept and refused.
        let (a, b) = job.write().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), shards);
        assert_eq!(std::fs::read_to_string(&b).unwrap(), assemble);
        job.write().unwrap();
        std::fs::write(&b, "#!/bin/sh\nmine\n").unwrap();
        let e = job.write().unwrap_err().to_string();
        assert!(e.contains("assemble.sh exists and is not a script asperity wrote"), "{e}");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "#!/bin/sh\nmine\n");
    }

    #[test]
    fn values_that_would_break_a_line_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        for bad in ["1:00\n#SBATCH --x", "a b", "", "$(rm)"] {
            let mut job = job(dir.path());
            job.time = Some(bad.into());
            let e = job.shards_script().unwrap_err().to_string();
            assert!(e.starts_with("--time: ") && e.contains("#SBATCH"), "{e}");
        }
    }
}
