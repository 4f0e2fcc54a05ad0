//! What a command wrote into a folder it shares with its user (a study's DIR), so that what it
//! removes later (`run --fresh`) is exactly that: a ledger file of one line per file written,
//! each a JSON string (the path relative to the folder), appended before the file is renamed
//! into place, so that no kill leaves an output unrecorded. Processes working in one folder at
//! once append under an exclusive `flock` of the ledger (also over a shared filesystem); a line
//! torn by a crash does not parse and is skipped.

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

    /// The paths recorded in the ledger file `file`, relative to its folder, in the order
    /// written, each once; `None` when there is no ledger.
    pub fn read(file: &Path) -> Result<Option<Vec<PathBuf>>> {
        let text = match std::fs::read(file) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::io(file, e)),
        };
        let (mut paths, mut seen) = (Vec::new(), std::collections::HashSet::new());
        for line in text.split(|&b| b == b'\n') {
            // A torn line, or anything that is not a relative path staying below the folder.
            let Ok(path) = serde_json::from_slice::<String>(line) else { continue };
            let path = PathBuf::from(path);
            let below = path.components().all(|c| matches!(c, std::path::Component::Normal(_)));
            if below && seen.insert(path.clone()) {
                paths.push(path);
            }
        }
        Ok(Some(paths))
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

/// Record `path` in the open ledger whose folder holds it (none: nothing to do). Called before
/// the file appears under its name.
pub(super) fn record(path: &Path) -> Result<()> {
    let found = open_ledgers().iter().find_map(|(_, folder, file)| {
        let relative = path.strip_prefix(folder).ok()?;
        (path != file && relative.components().next().is_some())
            .then(|| (folder.clone(), relative.to_path_buf(), file.clone()))
    });
    let Some((folder, relative, file)) = found else { return Ok(()) };
    // A link below the folder leads out of it: writing through it would replace a user's file.
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
    let io = |e| Error::io(&file, e);
    let mut line = serde_json::to_string(&relative.to_string_lossy()).map_err(|e| io(std::io::Error::other(e)))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_below_the_folder_are_recorded_before_they_appear_and_torn_lines_skipped() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("R");
        let file = dir.join("solves/written.jsonl");
        std::fs::create_dir_all(dir.join("solves")).unwrap();
        assert!(Ledger::read(&file).unwrap().is_none());
        {
            let _ledger = Ledger::open(&dir, &file);
            super::super::write_json(&dir.join("results.json"), &1).unwrap();
            super::super::write_json(&root.path().join("elsewhere.json"), &1).unwrap();
            super::super::Lock::acquire(&dir.join("solves/a.lock"), super::super::Access::Shared, false).unwrap();
            // A line torn by a crash, then a name with a line break in it.
            let mut f = OpenOptions::new().append(true).open(&file).unwrap();
            f.write_all(b"\"snapshots/lab").unwrap();
            super::super::write_json(&dir.join("odd\nname.json"), &1).unwrap();
        }
        super::super::write_json(&dir.join("after.json"), &1).unwrap();
        let recorded = Ledger::read(&file).unwrap().unwrap();
        let expected = ["results.json", "solves/a.lock", "odd\nname.json"].map(PathBuf::from);
        assert_eq!(recorded, expected);
    }
}
