//! What a command wrote into a folder it shares with its user (a study's DIR), so that what it
//! removes later (`run --fresh`) is exactly that: a ledger file of one line per file written,
//! each a JSON object of the path relative to the folder and the file's identity (device,
//! inode, length and modification time: an inode number is reused at once by the next file), appended before the file is renamed into place, so that no kill leaves an output
//! unrecorded. A file is this ledger's only while it is the very file written: a user's file
//! named in a hand-edited line, or put where an output was, has another identity. Processes working in one folder at
//! once append under an exclusive `flock` of the ledger (also over a shared filesystem); a line
//! torn by a crash does not parse and is skipped. The ledger's rewrite ([`Ledger::retain`]) is in
//! `write.rs`, beside the write it goes through.
//!
//! Imports only `error`, none of the other files of `output` (they record through it); must not
//! import topography, contact, friction, study, report, plot, shs, cli.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Error, Result};

/// The ledgers open in this process: (id, folder, ledger file).
static OPEN: Mutex<Vec<(u64, PathBuf, PathBuf)>> = Mutex::new(Vec::new());
static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// An open ledger: while it lives, every file this process writes below its folder through
/// [`super::write_atomic`] (or locks there with [`super::Lock`], creating the lock file) is
/// recorded in it. Dropping it stops the recording.
#[derive(Debug)]
pub struct Ledger {
    id: u64,
}

impl Ledger {
    /// Record from now on what is written below `folder`, in the ledger file `file` (created
    /// with the first record). Paths below `folder` are matched as written, component by
    /// component: write below it through the same `folder` path.
    pub fn open(folder: &Path, file: &Path) -> Ledger {
        let id = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        open_ledgers().push((id, folder.to_path_buf(), file.to_path_buf()));
        Ledger { id }
    }

    /// The files recorded in the ledger file `file`, in the order first written, each once with
    /// every identity it was written with; `None` when there is no ledger.
    pub fn read(file: &Path) -> Result<Option<Vec<Written>>> {
        let text = match std::fs::read(file) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::io(file, e)),
        };
        let mut written: Vec<Written> = Vec::new();
        let mut index = std::collections::HashMap::new();
        for line in text.split(|&b| b == b'\n') {
            // A torn line, a line without an identity, or a path not staying below the folder.
            let Ok(Line { path, identity }) = serde_json::from_slice::<Line>(line) else { continue };
            let path = PathBuf::from(path);
            if !path.components().all(|c| matches!(c, std::path::Component::Normal(_))) {
                continue;
            }
            let at = *index.entry(path.clone()).or_insert_with(|| {
                written.push(Written { path, identities: Vec::new() });
                written.len() - 1
            });
            written[at].identities.push(identity);
        }
        Ok(Some(written))
    }
}

/// One ledger line.
#[derive(serde::Serialize, serde::Deserialize)]
pub(super) struct Line {
    pub(super) path: String,
    identity: Identity,
}

/// What tells a file from any other that takes its name or its inode: device, inode, length
/// [bytes] and modification time [s and ns since the epoch] once written (a rename keeps them
/// all).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
struct Identity {
    dev: u64,
    ino: u64,
    len: u64,
    mtime: (i64, i64),
}

impl Identity {
    fn of(meta: &std::fs::Metadata) -> Identity {
        use std::os::unix::fs::MetadataExt;
        Identity { dev: meta.dev(), ino: meta.ino(), len: meta.len(), mtime: (meta.mtime(), meta.mtime_nsec()) }
    }
}

/// A file the ledger records: its path relative to the folder, and its identity each time it
/// was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// The file's path relative to the ledger's folder.
    pub path: PathBuf,
    identities: Vec<Identity>,
}

impl Written {
    /// Whether `meta` (of what is now at the path) is a file the ledger's writer wrote there,
    /// unchanged since.
    pub fn is(&self, meta: &std::fs::Metadata) -> bool {
        meta.is_file() && self.identities.contains(&Identity::of(meta))
    }
}

impl Drop for Ledger {
    fn drop(&mut self) {
        open_ledgers().retain(|(id, ..)| *id != self.id);
    }
}

fn open_ledgers() -> std::sync::MutexGuard<'static, Vec<(u64, PathBuf, PathBuf)>> {
    OPEN.lock().unwrap_or_else(|e| e.into_inner())
}

/// Refuse a path below an open ledger's folder that passes through a symbolic link: it leads
/// out of the folder, and writing through it would replace a user's file. Returns the folder's
/// ledger file and the path relative to the folder (`None` when no open ledger holds `path`).
pub(super) fn check(path: &Path) -> Result<Option<(PathBuf, PathBuf)>> {
    let found = open_ledgers().iter().find_map(|(_, folder, file)| {
        let relative = path.strip_prefix(folder).ok()?;
        (path != file && relative.components().next().is_some())
            .then(|| (folder.clone(), relative.to_path_buf(), file.clone()))
    });
    let Some((folder, relative, file)) = found else { return Ok(None) };
    let mut below = folder;
    for part in relative.components() {
        below.push(part);
        if std::fs::symlink_metadata(&below).is_ok_and(|m| m.file_type().is_symlink()) {
            return Err(Error::file(
                &below,
                "a symbolic link in a folder asperity writes: it never writes through one (it would replace what \
                 the link points to); remove the link, or choose another --out",
            ));
        }
    }
    Ok(Some((file, relative)))
}

/// Refuse to replace what is at `path` below an open ledger's folder unless the ledger's writer
/// wrote it there, unchanged since: a file a user put where an output goes is never written
/// over (nothing there, or a path below no open ledger: nothing to check).
pub(super) fn may_replace(path: &Path) -> Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(path) else { return Ok(()) };
    let Some((file, relative)) = check(path)? else { return Ok(()) };
    let written = Ledger::read(&file)?.unwrap_or_default();
    if written.iter().any(|w| w.path == relative && w.is(&meta)) {
        return Ok(());
    }
    Err(Error::file(
        path,
        "is not a file asperity wrote (or was changed since), and asperity never writes over one: move it away, \
         or choose another --out",
    ))
}

/// Record `path`, the file of metadata `meta`, in the open ledger whose folder holds it (none:
/// nothing to do), refusing a path through a link ([`check`]). Called before the file appears
/// under its name.
pub(super) fn record(path: &Path, meta: &std::fs::Metadata) -> Result<()> {
    let Some((file, relative)) = check(path)? else { return Ok(()) };
    let io = |e| Error::io(&file, e);
    let record = Line { path: relative.to_string_lossy().into_owned(), identity: Identity::of(meta) };
    let mut line = serde_json::to_string(&record).map_err(|e| io(std::io::Error::other(e)))?;
    line.push('\n');
    let mut ledger = OpenOptions::new().read(true).append(true).create(true).open(&file).map_err(io)?;
    // Released when the file closes.
    ledger.lock().map_err(io)?;
    if !ends_a_line(&mut ledger).map_err(io)? {
        // A line a crash tore stays a line of its own.
        line.insert(0, '\n');
    }
    ledger.write_all(line.as_bytes()).map_err(io)?;
    ledger.sync_data().map_err(io)
}

/// Whether `file` is empty or ends with a newline.
fn ends_a_line(file: &mut File) -> std::io::Result<bool> {
    if file.metadata()?.len() == 0 {
        return Ok(true);
    }
    file.seek(SeekFrom::End(-1))?;
    let mut last = [0u8];
    file.read_exact(&mut last)?;
    Ok(last[0] == b'\n')
}
