//! What a run keeps on disk in DIR and reads back: the run's own names below `solves/`, the
//! solve records, the fingerprint of the study, claiming DIR (its locks, its ledger, the
//! refusal of what a run must not write over, `--fresh`'s discard), resuming from the records
//! (their names and readers, the rows they hold, the tidying of what no solve needs any more).
//!
//! It reads the [plan](super::plan); it must not import the scheduler or the progress
//! reports, nor `plot`, `report`, `cli` or `python`.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::ops::Range;
use std::path::{Path, PathBuf};

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::config::StudyConfig;
use super::plan::Study;
use super::shard::Piece;
use super::{ResolutionRow, Row, Sharing, SolveFacts, COARSENING};
use crate::error::{Error, Result};
use crate::output::{self, Access, Ledger, Lock};
use crate::topography::io;
use crate::topography::Topography;

// The run's own names in `DIR/solves/`; topographies have theirs below `topographies/`.
pub(super) const SOLVES: &str = "solves";
const FINGERPRINT: &str = "fingerprint.json";
const CLAIM_LOCK: &str = "claim.lock";
const STUDY_LOCK: &str = "study.lock";
pub(super) const RESULTS_LOCK: &str = "results.lock";
const TOPOGRAPHIES: &str = "topographies";
/// The ledger of what runs wrote in DIR.
const LEDGER: &str = "written.jsonl";
/// The files of `solves/` that stay for good: `fresh` keeps them (the claim replaces the
/// fingerprint, and a lock file is never removed while a process may open it).
const KEPT: [&str; 5] = [FINGERPRINT, CLAIM_LOCK, STUDY_LOCK, RESULTS_LOCK, LEDGER];

/// Every name the runs write at the top of DIR (files, and folders with all below them): what
/// a user put there is never written over, so it is refused before anything is solved.
const DIR_OUTPUTS: [&str; 9] = [
    "study.toml",
    "results.csv",
    "results.json",
    "resolution.csv",
    "index.html",
    "figures",
    "pressure",
    "snapshots",
    SOLVES,
];

/// The locks a run holds while it works in DIR, and its ledger (none in a DIR an asperity
/// without ledgers started).
#[derive(Debug)]
pub(super) struct Claim {
    _study: Lock,
    _units: Vec<Lock>,
    _ledger: Option<Ledger>,
    /// What `fresh` left in DIR, not having written it.
    pub(super) left: Vec<PathBuf>,
}

/// The record of one finished solve, `solves/<topography>/NN.json`.
#[derive(Serialize, Deserialize)]
pub(super) struct SolveRecord {
    pub(super) load_n: f64,
    /// Whether the solve started from no pressure (the first of its piece of the load
    /// chain), not from the solution of the load before it.
    #[serde(default)]
    pub(super) cold: bool,
    pub(super) solve: SolveFacts,
    /// One row per sharing and law (sharing-major), in the study's order; the coarser copies
    /// of the resolution figure under equal sharing only.
    pub(super) rows: Vec<Row>,
}

/// The normal solve of a load whose elastic onsets are not all done, `NN-normal.json` beside
/// its pressure map `warm-NN.npy`; the solve's record replaces it.
#[derive(Serialize, Deserialize)]
pub(super) struct NormalRecord {
    pub(super) load_n: f64,
    pub(super) cold: bool,
    pub(super) solve: SolveFacts,
}

/// What a DIR's solves were computed for, `solves/fingerprint.json`.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Fingerprint {
    asperity: String,
    /// The resolved study, without the output options that do not change the solves.
    study: serde_json::Value,
    /// A digest of each topography's heights, grid and size as built.
    heights: Vec<String>,
}

impl Study {
    /// The study as run, as a study file.
    pub(super) fn study_file(&self) -> Result<String> {
        let text = toml::to_string(&self.config).map_err(|e| Error::invalid("study", e.to_string()))?;
        Ok(format!("# The study as run by asperity {}.\n\n{text}", env!("CARGO_PKG_VERSION")))
    }

    /// Make `dir` this study's: new, holding this study's solves (kept, or discarded when
    /// `fresh`), or what a start killed before its fingerprint leaves. Anything else is
    /// refused, and so is `fresh` in a DIR whose runs kept no ledger. Returns the locks of the
    /// run (the study's, shared, and every piece's of `pieces`) and its open ledger.
    pub(super) fn claim(&self, dir: &Path, fresh: bool, pieces: &[Piece]) -> Result<Claim> {
        let fingerprint = self.fingerprint()?;
        // Before anything is created in it.
        self.check_dir(dir)?;
        let solves = dir.join(SOLVES);
        std::fs::create_dir_all(&solves).map_err(|e| Error::io(&solves, e))?;
        let _claiming = Lock::acquire(&solves.join(CLAIM_LOCK), Access::Exclusive, true)?;
        self.check_dir(dir)?;
        // Only claims write here, and this one holds the claim lock.
        output::remove_stale_temporaries(&solves)?;
        let stored_path = solves.join(FINGERPRINT);
        let stored = match std::fs::read_to_string(&stored_path) {
            Ok(text) => Some(serde_json::from_str::<Fingerprint>(&text).ok()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(Error::io(&stored_path, e)),
        };
        let ledger_path = solves.join(LEDGER);
        let recorded = Ledger::read(&ledger_path)?;
        if recorded.is_some() {
            self.check_outputs(dir, &ledger_path)?;
        }
        // A DIR an asperity without ledgers wrote stays without one: a ledger begun now would
        // miss the earlier files, which a later `fresh` must not keep as this study's.
        let ledger = match (&stored, &recorded) {
            (Some(_), None) if fresh => {
                return Err(Error::invalid(
                    "--fresh",
                    format!(
                        "{} was written by an asperity that kept no record of its files, so --fresh cannot tell them \
                         from yours: move your own files out of it and remove it, or choose another --out",
                        dir.display()
                    ),
                ))
            }
            (Some(_), None) => None,
            _ => Some(Ledger::open(dir, &ledger_path)),
        };
        let mut left = Vec::new();
        let study_lock = solves.join(STUDY_LOCK);
        let study = match stored {
            Some(Some(f)) if f == fingerprint && !fresh => self.lock(&study_lock, Access::Shared, dir, "this study")?,
            Some(_) if !fresh => {
                return Err(Error::invalid(
                    "--out",
                    format!(
                        "{} holds the results of a different study than {}: rerun with --fresh to start over, or \
                         choose another --out",
                        dir.display(),
                        self.origin
                    ),
                ))
            }
            stored => {
                let lock = self.lock(&study_lock, Access::Exclusive, dir, "its study")?;
                if stored.is_some() {
                    left = discard(dir, recorded.unwrap_or_default())?;
                }
                output::write_json(&stored_path, &fingerprint)?;
                // Safe to share by release and retake: the claim lock keeps other claims out.
                lock.share()?
            }
        };
        let sweeps = self.sweeps();
        let first_mode = self.config.contact.plastic.modes()[0];
        let units = pieces
            .iter()
            .map(|piece| {
                let (u, plastic) = sweeps[piece.sweep];
                let unit = self.solves_dir(dir, u, plastic);
                std::fs::create_dir_all(&unit).map_err(|e| Error::io(&unit, e))?;
                let (label, folder, ..) = self.unit(u);
                let what = format!("topography \"{label}\"{}", if plastic { " (plastic)" } else { "" });
                let lock = self.lock_loads(&unit, piece.loads.clone(), dir, &what)?;
                // A whole chain's folders are this run's alone now: what a killed run left
                // there goes (a piece shares them with the other pieces' writers).
                if piece.loads.len() == self.loads.len() {
                    let pressure = plastic_dir(dir.join("pressure").join(folder), plastic);
                    output::remove_stale_temporaries(&unit)?;
                    output::remove_stale_temporaries(&pressure)?;
                    if u == 0 && plastic == first_mode {
                        output::remove_stale_temporaries(&dir.join("snapshots"))?;
                    }
                }
                Ok(lock)
            })
            .collect::<Result<Vec<_>>>()?;
        let text = self.study_file()?;
        output::write_atomic(&dir.join("study.toml"), |w| w.write_all(text.as_bytes()))?;
        Ok(Claim { _study: study, _units: units, _ledger: ledger, left })
    }

    /// Refuse, before anything in `dir` changes, a file where the runs write their outputs
    /// ([`DIR_OUTPUTS`]) that the ledger `ledger` does not hold as written by a run (a user's
    /// file, or one changed since), and an input of the study there (which a run would replace
    /// or `fresh` remove), compared as `cp` does, by device and inode.
    fn check_outputs(&self, dir: &Path, ledger: &Path) -> Result<()> {
        use std::os::unix::fs::MetadataExt;
        let inputs: Vec<(&Path, (u64, u64))> = self
            .config
            .input_files()
            .into_iter()
            .filter_map(|p| std::fs::metadata(p).ok().map(|m| (p, (m.dev(), m.ino()))))
            .collect();
        let mut found = Vec::new();
        files_below(dir, Path::new(""), &mut found)?;
        found.sort();
        // A lock file is opened, never written over, and may be another process's to record.
        let lock = |p: &Path| p.starts_with(SOLVES) && p.extension().is_some_and(|e| e == "lock");
        // Each file's identity first, the ledger after: runs working on other pieces write
        // meanwhile, and each records a file before the file takes its name, so every file seen
        // here is in the ledger as read below. What is refused is the first such path in order.
        let mut seen = Vec::new();
        for path in found {
            let first = path.components().next().map(|c| c.as_os_str().to_owned()).unwrap_or_default();
            if !DIR_OUTPUTS.iter().any(|o| first == *o) || is_kept(&path) || lock(&path) {
                continue;
            }
            let full = dir.join(&path);
            if std::fs::symlink_metadata(&full).is_ok_and(|m| m.file_type().is_symlink()) {
                seen.push(Err(Error::file(
                    &full,
                    "a symbolic link in a folder asperity writes: it never writes through one (it would replace what \
                     the link points to); remove the link, or choose another --out",
                )));
                continue;
            }
            // Gone meanwhile (a map another run's chain no longer needs): nothing to check.
            let Ok(meta) = std::fs::metadata(&full) else { continue };
            if let Some((input, _)) = inputs.iter().find(|(_, id)| *id == (meta.dev(), meta.ino())) {
                seen.push(Err(Error::file(
                    &full,
                    format!(
                        "is an input of the study ({}) where the study writes its results: keep inputs out of \
                         DIR's {}, or choose another --out",
                        input.display(),
                        DIR_OUTPUTS.join(", ")
                    ),
                )));
                continue;
            }
            if let Some(meta) = reached_without_links(dir, &path) {
                seen.push(Ok((path, meta)));
            }
        }
        let recorded = Ledger::read(ledger)?.unwrap_or_default();
        let by_path: std::collections::HashMap<&Path, &output::Written> =
            recorded.iter().map(|w| (w.path.as_path(), w)).collect();
        for found in seen {
            let (path, meta) = found?;
            if !by_path.get(path.as_path()).is_some_and(|w| w.is(&meta)) {
                return Err(Error::file(
                    dir.join(&path),
                    "is a file asperity did not write (or one changed since), where the study writes its results: \
                     asperity never writes over one; move it away, or choose another --out",
                ));
            }
        }
        Ok(())
    }

    /// Take a lock of the run in `dir`, waiting for it or refusing when another process holds
    /// it (working on `what`).
    fn lock(&self, path: &Path, access: Access, dir: &Path, what: &str) -> Result<Lock> {
        Lock::acquire(path, access, self.wait)?.ok_or_else(|| {
            Error::invalid(
                "--out",
                format!(
                    "{} is busy: another asperity run works on {what} there; wait for it with --wait, or choose \
                     another --out",
                    dir.display()
                ),
            )
        })
    }

    /// Lock loads `loads` of the sweep whose records are in `folder`: by its own lock file
    /// `loads-AA-BB.lock` (AA, BB its first and last load), once no other process holds the
    /// lock of a piece that overlaps it. Only claims take these locks, under the claim lock, so
    /// no new one appears meanwhile.
    fn lock_loads(&self, folder: &Path, loads: Range<usize>, dir: &Path, what: &str) -> Result<Lock> {
        let own = format!("loads-{:02}-{:02}.lock", loads.start, loads.end - 1);
        let lock = self.lock(&folder.join(&own), Access::Exclusive, dir, what)?;
        let entries = std::fs::read_dir(folder).map_err(|e| Error::io(folder, e))?;
        for entry in entries {
            let name = entry.map_err(|e| Error::io(folder, e))?.file_name();
            let Some(name) = name.to_str() else { continue };
            if let Some((first, last)) = lock_range(name) {
                if name != own && first < loads.end && last >= loads.start {
                    drop(self.lock(&folder.join(name), Access::Exclusive, dir, what)?);
                }
            }
        }
        Ok(lock)
    }

    /// Refuse a `dir` that is an empty path, a file, or holds neither a study's solves nor only
    /// what a start killed before its fingerprint leaves (the solves folder, its locks,
    /// temporaries): the rules of every caller (`asperity run`, `slurm`, Python's `run_study`).
    fn check_dir(&self, dir: &Path) -> Result<()> {
        // An empty path names no folder: its files would land beside the user's own.
        if dir.as_os_str().is_empty() {
            return Err(Error::invalid("--out", "an empty path names no folder: choose a new or empty folder"));
        }
        match std::fs::metadata(dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(e) => return Err(Error::io(dir, e)),
            Ok(m) if !m.is_dir() => {
                return Err(Error::invalid("--out", format!("{} is a file, not a directory", dir.display())))
            }
            Ok(_) => {}
        }
        let solves = dir.join(SOLVES);
        if solves.join(FINGERPRINT).is_file() {
            return Ok(());
        }
        let only = |d: &Path, names: &[&str]| -> Result<bool> {
            let entries = match std::fs::read_dir(d) {
                Ok(entries) => entries,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(true),
                Err(e) => return Err(Error::io(d, e)),
            };
            for entry in entries {
                let name = entry.map_err(|e| Error::io(d, e))?.file_name();
                if !(output::is_temporary(&name) || names.iter().any(|n| name == *n)) {
                    return Ok(false);
                }
            }
            Ok(true)
        };
        // A claim writes the fingerprint before anything else and never removes it: what it
        // wrote while this looked is a study's.
        if (only(dir, &[SOLVES])? && only(&solves, &[CLAIM_LOCK, STUDY_LOCK, LEDGER])?)
            || solves.join(FINGERPRINT).is_file()
        {
            return Ok(());
        }
        Err(Error::invalid("--out", format!("{} is not empty and holds no study: choose another --out", dir.display())))
    }

    fn fingerprint(&self) -> Result<Fingerprint> {
        let mut study = self.config.clone();
        let defaults = StudyConfig::default_study().output;
        // Figures, their snapshots' fractions and the measured points do not change a solve.
        study.output.figures = defaults.figures;
        study.output.snapshot_fractions = defaults.snapshot_fractions;
        study.output.experiments = None;
        // Nor do the input limits.
        study.limits = Default::default();
        let heights = self
            .topographies
            .iter()
            .map(|(_, t)| {
                let mut h = DefaultHasher::new();
                t.heights.dim().hash(&mut h);
                t.physical_size.map(|(lx, ly)| (lx.to_bits(), ly.to_bits())).hash(&mut h);
                t.heights.iter().for_each(|v| v.to_bits().hash(&mut h));
                format!("{:016x}", h.finish())
            })
            .collect();
        Ok(Fingerprint {
            asperity: env!("CARGO_PKG_VERSION").to_string(),
            study: serde_json::to_value(&study).map_err(|e| Error::invalid("study", e.to_string()))?,
            heights,
        })
    }

    /// The folder of sweep `u`'s solve records, elastic or plastic.
    pub(super) fn solves_dir(&self, dir: &Path, u: usize, plastic: bool) -> PathBuf {
        plastic_dir(dir.join(SOLVES).join(TOPOGRAPHIES).join(self.unit(u).1), plastic)
    }

    /// Remove the parts of load `k`'s solve in `solves` ([`Study::sweep`]), once it is
    /// recorded.
    pub(super) fn remove_parts(&self, solves: &Path, k: usize) -> Result<()> {
        remove_if_present(&solves.join(normal_name(k)))?;
        (0..self.laws.len()).try_for_each(|l| remove_if_present(&solves.join(onset_name(k, l))))
    }

    /// Remove what no solve of `loads` in `solves` needs any more (a run killed between a
    /// record and these removals leaves them): the maps of loads whose next load is
    /// recorded, and of the chain's last load once recorded; the parts of recorded solves.
    pub(super) fn tidy(&self, solves: &Path, loads: Range<usize>) -> Result<()> {
        let last = self.loads.len() - 1;
        for k in loads.clone() {
            let next_recorded = k + 1 < loads.end && solves.join(record_name(k + 1)).is_file();
            let recorded = solves.join(record_name(k)).is_file();
            if next_recorded || (k == last && recorded) {
                remove_if_present(&solves.join(warm_name(k)))?;
            }
            if recorded {
                self.remove_parts(solves, k)?;
            }
        }
        Ok(())
    }

    /// Every row from the solve records of `units`: topography × solve × law × load.
    pub(super) fn rows(&self, dir: &Path, units: std::ops::Range<usize>) -> Result<Vec<Row>> {
        let mut rows = Vec::with_capacity(units.len() * self.rows_per_solve() * self.loads.len());
        for (u, plastic) in self.sweeps().into_iter().filter(|(u, _)| units.contains(u)) {
            let solves = self.solves_dir(dir, u, plastic);
            let records = (0..self.loads.len())
                .map(|k| {
                    let path = solves.join(record_name(k));
                    let record: SolveRecord = read_record(&path)?;
                    let layout = self.layout(u);
                    let matches = record.rows.len() == layout.len()
                        && record.rows.iter().zip(&layout).all(|(r, s)| {
                            r.sharing == s.sharing
                                && r.law == super::law_name(&self.laws[s.law])
                                && r.slip_distance_m == s.slip_distance
                        });
                    if record.load_n != self.loads[k] || !matches {
                        return Err(foreign(&path));
                    }
                    Ok(record)
                })
                .collect::<Result<Vec<_>>>()?;
            for l in 0..self.layout(u).len() {
                rows.extend(records.iter().map(|r| r.rows[l].clone()));
            }
        }
        Ok(rows)
    }

    /// The resolution study's rows: the study's `rows` and those of the coarse sweeps, by
    /// coarsening (none without coarse sweeps).
    pub(super) fn resolution_rows(&self, dir: &Path, rows: &[Row]) -> Result<Vec<ResolutionRow>> {
        if self.coarse.is_empty() {
            return Ok(Vec::new());
        }
        let pixel = |t: &Topography| t.physical_size.expect("built with a physical size").0 / t.nx() as f64;
        let own = |name: &str| &self.topographies.iter().find(|(n, _)| n == name).expect("a row's topography").1;
        // The coarser copies are solved under equal sharing only.
        let mut out: Vec<ResolutionRow> =
            rows.iter().filter(|r| r.papers()).map(|r| ResolutionRow::new(1, pixel(own(&r.topography)), r)).collect();
        for factor in COARSENING {
            for (c, (_, f, topo)) in self.coarse.iter().enumerate() {
                if *f == factor {
                    let u = self.topographies.len() + c;
                    out.extend(self.rows(dir, u..u + 1)?.iter().map(|r| ResolutionRow::new(factor, pixel(topo), r)));
                }
            }
        }
        Ok(out)
    }
}

/// Whether `path` (relative to DIR) is one of the files of `solves/` kept for good ([`KEPT`]).
fn is_kept(path: &Path) -> bool {
    path.parent() == Some(Path::new(SOLVES)) && KEPT.iter().any(|k| path.ends_with(k))
}

/// Remove what runs wrote into `dir`, for `--fresh`: the files of its ledger, `recorded`, that
/// are still the very files written (the identity recorded; never a folder, nor what a link
/// points to, nor a user's file named by a hand-edited line or put in an output's place), then
/// the folders that held them once empty; files put in DIR by hand stay, and so do the folders
/// holding them. Returns those files, relative to `dir`. The fingerprint stays for the claim to
/// replace in one rename, so that a discard cut short still leaves a study's DIR (its ledger
/// whole until the end, for the next `fresh` to go on); the solve records go first, so that
/// what such a DIR resumes is solved again.
fn discard(dir: &Path, mut recorded: Vec<output::Written>) -> Result<Vec<PathBuf>> {
    let index = |s: &str| s.len() >= 2 && s.bytes().all(|b| b.is_ascii_digit());
    let is_record = |p: &Path| {
        p.starts_with(Path::new(SOLVES).join(TOPOGRAPHIES))
            && p.file_name().and_then(|n| n.to_str()?.strip_suffix(".json")).is_some_and(index)
    };
    recorded.retain(|w| !is_kept(&w.path));
    recorded.sort_by_key(|w| !is_record(&w.path));
    for written in &recorded {
        if reached_without_links(dir, &written.path).is_some_and(|m| written.is(&m)) {
            let full = dir.join(&written.path);
            std::fs::remove_file(&full).map_err(|e| Error::io(&full, e))?;
        }
    }
    // The emptied folders, deepest first; one still holding a file stays.
    let mut folders: Vec<&Path> = recorded.iter().flat_map(|w| w.path.ancestors().skip(1)).collect();
    folders.retain(|f| !f.as_os_str().is_empty() && *f != Path::new(SOLVES));
    folders.sort_by_key(|f| std::cmp::Reverse(f.components().count()));
    folders.dedup();
    for folder in folders {
        if reached_without_links(dir, folder).is_some_and(|m| m.is_dir()) {
            let _ = std::fs::remove_dir(dir.join(folder));
        }
    }
    // The ledger keeps what stays: the files of `solves/` kept for good.
    Ledger::retain(&dir.join(SOLVES).join(LEDGER), is_kept)?;
    let mut left = Vec::new();
    files_below(dir, Path::new(""), &mut left)?;
    left.retain(|p| !is_kept(p));
    left.sort();
    Ok(left)
}

/// What is at `path` (relative, below `dir`), if it is reached through folders only, no link
/// (the last component's own metadata, a link not followed).
fn reached_without_links(dir: &Path, path: &Path) -> Option<std::fs::Metadata> {
    let mut at = dir.to_path_buf();
    let mut meta = None;
    for part in path.components() {
        if meta.as_ref().is_some_and(|m: &std::fs::Metadata| !m.is_dir()) {
            return None;
        }
        at.push(part);
        meta = Some(std::fs::symlink_metadata(&at).ok()?);
    }
    meta
}

/// Push onto `found` every entry below `dir.join(at)` that is not a folder (links not followed,
/// temporaries skipped), relative to `dir`.
fn files_below(dir: &Path, at: &Path, found: &mut Vec<PathBuf>) -> Result<()> {
    let folder = dir.join(at);
    let entries = match std::fs::read_dir(&folder) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(&folder, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(&folder, e))?;
        if output::is_temporary(&entry.file_name()) {
            continue;
        }
        let path = at.join(entry.file_name());
        if entry.file_type().map_err(|e| Error::io(entry.path(), e))?.is_dir() {
            files_below(dir, &path, found)?;
        } else {
            found.push(path);
        }
    }
    Ok(())
}

/// The name of load `k`'s solve record in its sweep's folder.
pub(super) fn record_name(k: usize) -> String {
    format!("{k:02}.json")
}

/// The name of the pressure map of load `k` that a solve goes on from.
pub(super) fn warm_name(k: usize) -> String {
    format!("warm-{k:02}.npy")
}

/// The name of load `k`'s normal solve while its elastic onsets are under way.
pub(super) fn normal_name(k: usize) -> String {
    format!("{k:02}-normal.json")
}

/// The name of load `k`'s elastic onset under the study's law `l`, until the solve's record.
pub(super) fn onset_name(k: usize, l: usize) -> String {
    format!("{k:02}-elastic-{l:02}.json")
}

/// The error of a record in `path` that is not this study's.
fn foreign(path: &Path) -> Error {
    Error::file(path, "not a record of this study's solve: rerun with --fresh")
}

/// Read a JSON record.
fn read_record<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::file(path, e.to_string()))
}

/// The normal solve of load `k` (`load` [N]) recorded in `solves`, with its pressure map
/// [Pa] (row-major).
pub(super) fn read_normal(solves: &Path, k: usize, load: f64) -> Result<(NormalRecord, Array2<f64>)> {
    let path = solves.join(normal_name(k));
    let normal: NormalRecord = read_record(&path)?;
    if normal.load_n != load {
        return Err(foreign(&path));
    }
    Ok((normal, read_map(&solves.join(warm_name(k)))?))
}

/// A pressure map [Pa] a run kept (`warm-NN.npy`), row-major.
pub(super) fn read_map(path: &Path) -> Result<Array2<f64>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let pressure = io::npy::read_f64(&bytes).map_err(|r| Error::file(path, r))?;
    if !pressure.is_standard_layout() {
        return Err(Error::file(path, "not a row-major array"));
    }
    Ok(pressure)
}

/// The rows an elastic onset recorded in `path` for the solve of the rows named `name` at
/// `load` [N] under the law named `law`: the elastic one, then, `weakening` when the law has a
/// slip-weakening distance, equal sharing's under the same weakening.
pub(super) fn read_onset(path: &Path, name: &str, load: f64, law: &str, weakening: bool) -> Result<Vec<Row>> {
    let rows: Vec<Row> = read_record(path)?;
    let same = |r: &Row| r.law == law && r.topography == name && r.load_n == load;
    let ours = rows.len() == 1 + usize::from(weakening)
        && rows.iter().all(same)
        && rows[0].sharing == Sharing::Elastic
        && rows[1..].iter().all(|r| r.sharing == Sharing::Equal && r.slip_distance_m == rows[0].slip_distance_m);
    if ours {
        Ok(rows)
    } else {
        Err(foreign(path))
    }
}

/// The first and last load of a piece's lock file `loads-AA-BB.lock`.
fn lock_range(name: &str) -> Option<(usize, usize)> {
    let (first, last) = name.strip_prefix("loads-")?.strip_suffix(".lock")?.split_once('-')?;
    Some((first.parse().ok()?, last.parse().ok()?))
}

/// Remove the file `path`; a missing one is no error.
pub(super) fn remove_if_present(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io(path, e)),
        _ => Ok(()),
    }
}

/// `path`, or its `plastic` subfolder for a plastic sweep.
pub(super) fn plastic_dir(path: PathBuf, plastic: bool) -> PathBuf {
    if plastic {
        path.join("plastic")
    } else {
        path
    }
}
