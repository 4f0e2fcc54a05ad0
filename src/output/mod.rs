//! Writing results safely, the one mechanism every command uses:
//!
//! - every file goes through a temporary file beside it and a rename ([`write_atomic`]), so a
//!   file is whole or absent, never half-written;
//! - a command's output folder is built aside and moved into place once complete
//!   ([`StagedDir`]), replacing only an earlier output of the same command;
//! - every temporary (`.asperity-*.partial`) is registered until renamed or removed, so an
//!   interrupted process removes them ([`remove_temporaries`]);
//! - work shared between processes is guarded by advisory locks ([`Lock`]);
//! - files and folders get the permissions the umask gives, as with any Unix tool.

mod lock;
mod staged;
mod temp;

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ndarray::Array2;
use ndarray_npy::WritableElement;
use serde::Serialize;

use crate::error::{Error, Result};

pub use lock::{Access, Lock};
pub use staged::{StagedDir, MANIFEST};
pub use temp::{is_temporary, remove_temporaries, Interrupted};

/// Write a file atomically: `fill` writes into a temporary file beside `path`, which is then
/// renamed over `path`. A failure or a panic in `fill`, or a failed rename, leaves `path`
/// untouched and no temporary behind. A symbolic link at `path` is followed: the file it points
/// to is written, the link kept.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let shown = path;
    let path = resolve_symlinks(path)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let io = |e| Error::io(shown, e);
    let tmp = temp::TempFile::new_in(dir).map_err(io)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w).map_err(io)?;
        w.flush().map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(&path).map_err(io)
}

/// Write a 2-D array as a `.npy` file (row-major, shape (ny, nx)), atomically.
pub fn write_npy<T: WritableElement>(path: &Path, field: &Array2<T>) -> Result<()> {
    use ndarray_npy::WriteNpyExt;
    write_atomic(path, |w| field.write_npy(w).map_err(std::io::Error::other))
}

/// Write `value` as pretty-printed JSON with a trailing newline, atomically.
pub fn write_json<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

/// Remove the temporaries a killed process left in `dir` (not below it). Only for a folder
/// whose writers the caller has locked out.
pub fn remove_stale_temporaries(dir: &Path) -> Result<()> {
    remove_matching(dir, Entries::Any, |name| is_temporary(name.as_ref()))
}

/// Which entries of a folder [`remove_matching`] may remove.
#[derive(Clone, Copy, PartialEq)]
pub enum Entries {
    /// Regular files only.
    Files,
    /// Any entry, a folder with all it holds (a symbolic link is removed, not followed).
    Any,
}

/// Remove the `entries` of `dir` (not below it) whose names `pick` chooses; none when `dir` is
/// missing.
pub fn remove_matching(dir: &Path, entries: Entries, pick: impl Fn(&str) -> bool) -> Result<()> {
    let listing = match std::fs::read_dir(dir) {
        Ok(listing) => listing,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(dir, e)),
    };
    for entry in listing {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        if !entry.file_name().to_str().is_some_and(&pick) {
            continue;
        }
        let path = entry.path();
        let kind = entry.file_type().map_err(|e| Error::io(&path, e))?;
        let removed = match entries {
            Entries::Files if !kind.is_file() => continue,
            Entries::Any if kind.is_dir() => std::fs::remove_dir_all(&path),
            _ => std::fs::remove_file(&path),
        };
        removed.map_err(|e| Error::io(&path, e))?;
    }
    Ok(())
}

/// `path` with symbolic links in its last component followed (a dangling link gives where it
/// points to).
fn resolve_symlinks(path: &Path) -> Result<PathBuf> {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&path) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&path).map_err(|e| Error::io(&path, e))?;
                path = match path.parent() {
                    Some(parent) if to.is_relative() => parent.join(to),
                    _ => to,
                };
            }
            _ => return Ok(path),
        }
    }
    Err(Error::file(path, "too many levels of symbolic links"))
}

#[cfg(test)]
mod tests {
    use std::fs;
    use std::os::unix::fs::PermissionsExt;

    use super::*;

    #[test]
    fn failed_fill_or_rename_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.json");
        let r = write_atomic(&path, |_| Err(std::io::Error::other("boom")));
        assert!(r.is_err());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
        // A folder in the way: the rename fails, the temporary goes.
        fs::create_dir(dir.path().join("d")).unwrap();
        fs::write(dir.path().join("d/keep"), "mine").unwrap();
        assert!(write_json(&dir.path().join("d"), &1).is_err());
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, ["d"]);
    }

    #[test]
    fn a_link_is_written_through_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("link.json");
        std::os::unix::fs::symlink("sub/target.json", &link).unwrap();
        fs::create_dir(dir.path().join("sub")).unwrap();
        write_json(&link, &7).unwrap();
        assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(fs::read_to_string(dir.path().join("sub/target.json")).unwrap(), "7\n");
    }

    #[test]
    fn interrupted_temporaries_are_removed_and_no_new_one_is_made() {
        // This test closes the process's registry: it runs alone in its own process below.
        if std::env::var_os("ASPERITY_TEST_REGISTRY").is_none() {
            let exe = std::env::current_exe().unwrap();
            let o = std::process::Command::new(exe)
                .args(["--exact", "output::tests::interrupted_temporaries_are_removed_and_no_new_one_is_made"])
                .env("ASPERITY_TEST_REGISTRY", "1")
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&o.stdout);
            assert!(o.status.success() && stdout.contains("1 passed"), "{stdout}");
            return;
        }
        let dir = tempfile::tempdir().unwrap();
        let staged = StagedDir::new(&dir.path().join("out"), "test").unwrap();
        let file = temp::TempFile::new_in(dir.path()).unwrap();
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
        drop(remove_temporaries());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
        assert!(write_json(&dir.path().join("late.json"), &1).is_err());
        drop((file, staged));
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn permissions_follow_the_umask() {
        // The umask of this process, read without changing it for the other tests' threads
        // (Linux reports it in /proc).
        let status = fs::read_to_string("/proc/self/status").unwrap();
        let umask = status.lines().find_map(|l| l.strip_prefix("Umask:")).unwrap().trim();
        let umask = u32::from_str_radix(umask, 8).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.json");
        write_json(&file, &1).unwrap();
        assert_eq!(fs::metadata(&file).unwrap().permissions().mode() & 0o777, 0o666 & !umask);
        let staged = StagedDir::new(&dir.path().join("out"), "test").unwrap();
        let out = staged.commit().unwrap();
        assert_eq!(fs::metadata(&out).unwrap().permissions().mode() & 0o777, 0o777 & !umask);
    }

    #[test]
    fn remove_matching_takes_only_the_chosen_kind() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        fs::write(d.join("00.json"), "").unwrap();
        fs::write(d.join("notes.txt"), "mine").unwrap();
        fs::create_dir_all(d.join("01.json/inside")).unwrap();
        fs::create_dir(d.join("kept")).unwrap();
        std::os::unix::fs::symlink("kept", d.join("02.json")).unwrap();
        let json = |n: &str| n.ends_with(".json");
        remove_matching(d, Entries::Files, json).unwrap();
        let mut names: Vec<_> = fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        assert_eq!(names, ["01.json", "02.json", "kept", "notes.txt"]);
        // Any kind: the folder with what it holds, the link but not where it points.
        remove_matching(d, Entries::Any, json).unwrap();
        let mut names: Vec<_> = fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        assert_eq!(names, ["kept", "notes.txt"]);
        remove_matching(&d.join("missing"), Entries::Any, json).unwrap();
    }
}
