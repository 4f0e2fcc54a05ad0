//! What a run keeps on disk in DIR and reads back: the run's own names below `solves/`, the
//! solve records and the identity they are found by, claiming DIR (its locks, its ledger, the
//! refusal of what a run must not write over, `--fresh`'s discard), resuming from the records
//! (their names and readers, the rows they hold, the tidying of what no solve needs any more).
//!
//! It reads the [plan](super::plan); it must not import the scheduler or the progress
//! reports, nor `plot`, `report`, `cli` or `python`.

use std::hash::{Hash, Hasher};
use std::ops::Range;
use std::path::{Path, PathBuf};

use ndarray::Array2;
use serde::{Deserialize, Serialize};

use super::config::Plastic;
use super::plan::{Slot, Study};
use super::shard::Piece;
use super::{ResolutionRow, Row, Sharing, SolveFacts, COARSENING};
use crate::error::{Error, Result};
use crate::friction::Weakening;
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
/// How the records below `solves/` are found, stated in its fingerprint: by each solve's
/// identity ([`Study::stem`]). A DIR whose fingerprint lacks it was written by an asperity
/// that kept one fingerprint for the whole study and named its records by load index.
const RECORDS: u32 = 2;
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

/// The record of one finished solve, `solves/topographies/<topography>/<stem>.json`
/// ([`Study::stem`]).
#[derive(Serialize, Deserialize)]
pub(super) struct SolveRecord {
    pub(super) load_n: f64,
    /// Whether the solve started from no pressure, not from the solution of a lower load.
    pub(super) cold: bool,
    pub(super) solve: SolveFacts,
    /// Its rows, each under the key of its slot ([`Study::slot_key`]): those of every study
    /// that recorded this solve (sharings, laws, slip weakenings), in no order.
    pub(super) rows: Vec<KeyedRow>,
}

/// A row of a solve record and the key of the slot it fills ([`Study::slot_key`]).
#[derive(Clone, Serialize, Deserialize)]
pub(super) struct KeyedRow {
    pub(super) key: String,
    pub(super) row: Row,
}

impl SolveRecord {
    /// The row of the slot keyed `key`, if recorded.
    pub(super) fn row(&self, key: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.key == key).map(|r| &r.row)
    }
}

/// The normal solve of a load whose elastic onsets are not all done, `<stem>-normal.json`
/// beside its pressure map `<stem>-warm.npy`; the solve's record replaces it.
#[derive(Serialize, Deserialize)]
pub(super) struct NormalRecord {
    pub(super) load_n: f64,
    pub(super) cold: bool,
    pub(super) solve: SolveFacts,
}

/// What marks DIR as a study's, `solves/fingerprint.json`: the asperity that wrote it and how
/// its records are found ([`RECORDS`]); what each record was computed for is in its name.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Fingerprint {
    asperity: String,
    records: u32,
}

/// A digest that stays the same across builds and machines of one byte order (FNV-1a, 64
/// bits): the names of the records outlive the asperity that wrote them, which the standard
/// library's hasher does not promise.
struct Digest(u64);

impl Digest {
    fn new() -> Digest {
        Digest(0xcbf2_9ce4_8422_2325)
    }

    fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

impl Hasher for Digest {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

/// The digest of a topography's heights, grid and size as built, part of its solves' identity.
pub(super) fn heights_digest(t: &Topography) -> String {
    let mut h = Digest::new();
    t.heights.dim().hash(&mut h);
    t.physical_size.map(|(lx, ly)| (lx.to_bits(), ly.to_bits())).hash(&mut h);
    t.heights.iter().for_each(|v| v.to_bits().hash(&mut h));
    h.hex()
}

/// The digest of `value`'s JSON text.
fn json_digest(value: &serde_json::Value) -> String {
    let mut h = Digest::new();
    h.write(value.to_string().as_bytes());
    h.hex()
}

impl Study {
    /// The study as run, as a study file.
    pub(super) fn study_file(&self) -> Result<String> {
        let text = toml::to_string(&self.config).map_err(|e| Error::invalid("study", e.to_string()))?;
        Ok(format!("# The study as run by asperity {}.\n\n{text}", env!("CARGO_PKG_VERSION")))
    }

    /// Make `dir` this study's: new, holding the solves of studies (kept, or discarded when
    /// `fresh`), or what a start killed before its fingerprint leaves. Anything else is
    /// refused, and so are a DIR an asperity that named its records by load index wrote
    /// (unless `fresh`), and `fresh` in a DIR whose runs kept no ledger. Returns the locks of
    /// the run (the study's, shared, and every solve's of `pieces`) and its open ledger.
    pub(super) fn claim(&self, dir: &Path, fresh: bool, pieces: &[Piece]) -> Result<Claim> {
        let fingerprint = Fingerprint { asperity: env!("CARGO_PKG_VERSION").to_string(), records: RECORDS };
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
            Ok(text) => Some(serde_json::from_str::<Fingerprint>(&text).is_ok_and(|f| f.records == RECORDS)),
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
            Some(true) if !fresh => self.lock(&study_lock, Access::Shared, dir, "a study")?,
            Some(false) if !fresh => {
                return Err(Error::invalid(
                    "--out",
                    format!(
                        "{} holds the results of an earlier asperity, which named its records by load index: rerun \
                         with --fresh to start over, or choose another --out",
                        dir.display()
                    ),
                ))
            }
            stored => {
                let lock = self.lock(&study_lock, Access::Exclusive, dir, "a study")?;
                if stored.is_some() {
                    left = discard(dir, recorded.unwrap_or_default())?;
                }
                output::write_json(&stored_path, &fingerprint)?;
                // Safe to share by release and retake: the claim lock keeps other claims out.
                lock.share()?
            }
        };
        let sweeps = self.sweeps();
        let mut units = Vec::new();
        output::make_room(pieces.iter().map(|p| p.loads.len()).sum());
        for piece in pieces {
            let (u, plastic) = sweeps[piece.sweep];
            for (u, plastic) in std::iter::once((u, plastic)).chain(self.adhesive_unit(u).map(|a| (a, plastic))) {
                let unit = self.solves_dir(dir, u, plastic);
                std::fs::create_dir_all(&unit).map_err(|e| Error::io(&unit, e))?;
                let label = self.unit(u).0;
                let what = format!("topography \"{label}\"{}", if plastic { " (plastic)" } else { "" });
                for k in piece.loads.clone() {
                    let name = format!("{}.lock", self.stem(u, plastic, k));
                    units.push(self.lock(&unit.join(name), Access::Exclusive, dir, &what)?);
                }
            }
        }
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

    /// The stem of the names of sweep `u`'s solve at load `k`, elastic or `plastic`: its load
    /// and a digest of its identity, `<load>N-<digest>` (e.g. `1e-3N-0123456789abcdef`). The
    /// identity is what the solve depends on: its topography as built ([`heights_digest`]),
    /// the material, the contact settings (the cohesive law for an adhesive unit only) and the
    /// kind of solve, the load [N], and the
    /// asperity that computes it (whose solvers' own settings its rows depend on too); not the
    /// other loads, laws or outputs of the study, so that a study that changes those finds it.
    pub(super) fn stem(&self, u: usize, plastic: bool, k: usize) -> String {
        let mut material = self.config.material.clone();
        // Only the friction-drop figure's band reads it.
        material.youngs_uncertainty = None;
        let mut contact = self.config.contact.clone();
        contact.plastic = Plastic::One(plastic);
        // A solve without adhesion keeps the identity it had in a study without the key.
        if !self.adhesive(u) {
            contact.adhesion = None;
        }
        let identity = serde_json::json!({
            "asperity": env!("CARGO_PKG_VERSION"),
            "heights": self.digests[self.built(u)],
            "material": material,
            "contact": contact,
            "load_n": self.loads[k],
        });
        format!("{:e}N-{}", self.loads[k], json_digest(&identity))
    }

    /// The key of a solve's row in `slot` ([`SolveRecord::rows`]): what the row depends on
    /// beyond its solve, its sharing and its law (name, mu_s, mu_d) under its slip weakening
    /// (an elastic onset's, and equal sharing's under the same weakening, which the onset's
    /// stuck stiffness gives; the instant drop for the paper's equal sharing). The onsets'
    /// own settings are the program's, not the study's.
    pub(super) fn slot_key(&self, slot: &Slot) -> String {
        let law = &self.laws[slot.law];
        let weakening = match (slot.slip_distance, self.slip_law(slot).weakening) {
            (Some(d), _) if slot.sharing == Sharing::Equal && d == 0.0 => serde_json::json!("instant"),
            (_, Weakening::Instant) => serde_json::json!("instant"),
            (_, Weakening::Linear(d)) => serde_json::json!({ "linear_m": d }),
            (_, Weakening::Curve(points)) => serde_json::json!({ "curve": points }),
        };
        let key = serde_json::json!({
            "sharing": slot.sharing.name(),
            "law": { "name": law.name, "mu_s": law.mu_s, "mu_d": law.mu_d },
            "weakening": weakening,
        });
        json_digest(&key)
    }

    /// The folder of sweep `u`'s solve records, elastic or plastic.
    pub(super) fn solves_dir(&self, dir: &Path, u: usize, plastic: bool) -> PathBuf {
        plastic_dir(dir.join(SOLVES).join(TOPOGRAPHIES).join(self.unit(u).1), plastic)
    }

    /// The folder of the full pressure maps of unit `u`, elastic or `plastic`, that
    /// `output.pressure_maps` keeps, `<stem>.npy` each: `pressure/<topography>/` (an adhesive
    /// unit's compressive pressure in its `adhesive/`).
    pub(super) fn maps_dir(&self, dir: &Path, u: usize, plastic: bool) -> PathBuf {
        let maps = dir.join("pressure").join(self.unit(u).3);
        plastic_dir(if self.adhesive(u) { maps.join("adhesive") } else { maps }, plastic)
    }

    /// The record of the solve named `stem` in `solves` at `load` [N], if one is there.
    pub(super) fn read_solve(&self, solves: &Path, stem: &str, load: f64) -> Result<Option<SolveRecord>> {
        let path = solves.join(record_name(stem));
        if !path.is_file() {
            return Ok(None);
        }
        let record: SolveRecord = read_record(&path)?;
        if record.load_n != load {
            return Err(foreign(&path));
        }
        Ok(Some(record))
    }

    /// Whether sweep `u`'s solve at load `k`, elastic or `plastic`, is done for this study:
    /// recorded with a row for every slot of its layout, and with the pressure map and the
    /// snapshot the study keeps of it.
    pub(super) fn done(&self, dir: &Path, u: usize, plastic: bool, k: usize) -> Result<bool> {
        let stem = self.stem(u, plastic, k);
        let Some(record) = self.read_solve(&self.solves_dir(dir, u, plastic), &stem, self.loads[k])? else {
            return Ok(false);
        };
        let rows = self.layout(u).iter().all(|s| record.row(&self.slot_key(s)).is_some());
        let map = !self.keeps_maps(u) || self.maps_dir(dir, u, plastic).join(format!("{stem}.npy")).is_file();
        let shown = self.shows(u, plastic) && self.snapshot_indices().contains(&k);
        let snapshot = !shown || {
            let stem = self.snapshot_stem(k);
            ["json", "npy"].iter().all(|e| dir.join("snapshots").join(format!("{stem}.{e}")).is_file())
        };
        Ok(rows && map && snapshot)
    }

    /// Remove the parts of the solve named `stem` of sweep `u` in `solves` ([`Study::sweep`]),
    /// once it is recorded.
    pub(super) fn remove_parts(&self, solves: &Path, u: usize, stem: &str) -> Result<()> {
        remove_if_present(&solves.join(normal_name(stem)))?;
        self.layout(u)
            .iter()
            .filter(|s| s.sharing == Sharing::Elastic)
            .try_for_each(|s| remove_if_present(&solves.join(onset_name(stem, &self.slot_key(s)))))
    }

    /// Remove what no solve of `loads` of sweep `u` in `solves` needs any more, once all are
    /// recorded (a run killed between a record and these removals leaves them): their maps,
    /// but the last one's while the load after it waits for its record (another piece goes
    /// on from it); their parts. `stems` names the study's solves of the sweep, by load.
    pub(super) fn tidy(&self, solves: &Path, u: usize, stems: &[String], loads: Range<usize>) -> Result<()> {
        for k in loads.clone() {
            let next_waits =
                k + 1 == loads.end && k + 1 < stems.len() && !solves.join(record_name(&stems[k + 1])).is_file();
            if !next_waits {
                remove_if_present(&solves.join(warm_name(&stems[k])))?;
            }
            self.remove_parts(solves, u, &stems[k])?;
        }
        Ok(())
    }

    /// Every row from the solve records of `units`: topography × solve × law × load.
    pub(super) fn rows(&self, dir: &Path, units: std::ops::Range<usize>) -> Result<Vec<Row>> {
        let mut rows = Vec::with_capacity(units.len() * self.rows_per_solve() * self.loads.len());
        for (u, plastic) in self.recorded_units().into_iter().filter(|(u, _)| units.contains(u)) {
            let solves = self.solves_dir(dir, u, plastic);
            let layout = self.layout(u);
            let keys: Vec<String> = layout.iter().map(|s| self.slot_key(s)).collect();
            let records = (0..self.loads.len())
                .map(|k| {
                    let stem = self.stem(u, plastic, k);
                    let record = self.read_solve(&solves, &stem, self.loads[k])?;
                    record
                        .and_then(|r| keys.iter().map(|key| r.row(key).cloned()).collect::<Option<Vec<Row>>>())
                        .ok_or_else(|| foreign(&solves.join(record_name(&stem))))
                })
                .collect::<Result<Vec<_>>>()?;
            for l in 0..layout.len() {
                rows.extend(records.iter().map(|r| r[l].clone()));
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
    let is_record = |p: &Path| {
        p.starts_with(Path::new(SOLVES).join(TOPOGRAPHIES))
            && p.file_name().and_then(|n| n.to_str()).is_some_and(is_record_name)
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

/// The name of the record of the solve named `stem` ([`Study::stem`]) in its sweep's folder.
pub(super) fn record_name(stem: &str) -> String {
    format!("{stem}.json")
}

/// The name of the pressure map of the solve named `stem` that a solve goes on from.
pub(super) fn warm_name(stem: &str) -> String {
    format!("{stem}-warm.npy")
}

/// The name of the normal solve named `stem` while its elastic onsets are under way.
pub(super) fn normal_name(stem: &str) -> String {
    format!("{stem}-normal.json")
}

/// The name of the elastic onset of the solve named `stem` in the slot keyed `key`
/// ([`Study::slot_key`]), until the solve's record.
pub(super) fn onset_name(stem: &str, key: &str) -> String {
    format!("{stem}-elastic-{key}.json")
}

/// Whether `name` is a solve record's: `<stem>.json`, its stem ending in a digest.
fn is_record_name(name: &str) -> bool {
    name.strip_suffix(".json")
        .and_then(|stem| stem.rsplit_once("N-"))
        .is_some_and(|(_, digest)| digest.len() == 16 && digest.bytes().all(|b| b.is_ascii_hexdigit()))
}

/// The error of a record in `path` that is not the solve its name says.
fn foreign(path: &Path) -> Error {
    Error::file(path, "not the record of the solve its name says: rerun with --fresh")
}

/// Read a JSON record.
fn read_record<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::file(path, e.to_string()))
}

/// The normal solve named `stem` at `load` [N] recorded in `solves`, with its pressure map
/// [Pa] (row-major).
pub(super) fn read_normal(solves: &Path, stem: &str, load: f64) -> Result<(NormalRecord, Array2<f64>)> {
    let path = solves.join(normal_name(stem));
    let normal: NormalRecord = read_record(&path)?;
    if normal.load_n != load {
        return Err(foreign(&path));
    }
    Ok((normal, read_map(&solves.join(warm_name(stem)))?))
}

/// A pressure map [Pa] a run kept (`<stem>-warm.npy`), row-major.
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
