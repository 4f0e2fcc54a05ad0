//! Writing results safely, the one mechanism every command uses:
//!
//! - every file goes through a temporary file beside it and a rename ([`write_atomic`]), so a
//!   file is whole or absent, never half-written;
//! - a command's output folder is built aside and moved into place once complete
//!   ([`StagedDir`]), replacing only an earlier output of the same command;
//! - every temporary (`.asperity-*.partial`) is registered until renamed or removed, so an
//!   interrupted process removes them ([`remove_temporaries`]);
//! - work shared between processes is guarded by advisory locks ([`Lock`]);
//! - what is written into a folder shared with its user is recorded ([`Ledger`]), so that only
//!   that is ever removed from it;
//! - files and folders get the permissions the umask gives, as with any Unix tool.
//!
//! Imports only `error` and the files of `output`; must not import topography, contact, friction,
//! study, report, plot, shs, cli.

mod aside;
mod ledger;
mod lock;
mod staged;
mod temp;

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ndarray::Array2;
use ndarray_npy::WritableElement;
use serde::Serialize;

use crate::error::{Error, Result};

pub use aside::MANIFEST;
pub use ledger::{Ledger, Written};
pub use lock::{Access, Lock};
pub use staged::{Committed, StagedDir};
pub use temp::{is_temporary, remove_temporaries, Interrupted};

/// Write a file atomically: `fill` writes into a temporary file beside `path`, which is then
/// renamed over `path`. A failure or a panic in `fill`, or a failed rename, leaves `path`
/// untouched and no temporary behind. A symbolic link at `path` is followed: the file it points
/// to is written, the link kept. Only a regular file is replaced: a folder, device, named pipe
/// or socket at `path` is refused, and so is, below the folder of an open [`Ledger`], a file
/// that ledger's writer did not write. Below the folder of an open [`Ledger`], `path` is recorded
/// before it is renamed into place.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let shown = path;
    let path = resolve_symlinks(path)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let io = |e| Error::io(shown, e);
    replaceable(shown, &path)?;
    ledger::may_replace(shown)?;
    temp::remove_orphaned_temporaries_once(dir);
    let tmp = temp::TempFile::new_in(dir).map_err(io)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w).map_err(io)?;
        w.flush().map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    // Again: something else may have taken the name while the file was written.
    replaceable(shown, &path)?;
    ledger::may_replace(shown)?;
    ledger::record(shown, &tmp.as_file().metadata().map_err(io)?)?;
    tmp.persist(&path).map_err(io)
}

/// Refuse, before any work, a single-file output `path` that may not be written: what is there
/// (symbolic links followed) must be nothing or a regular file, and none of `inputs`, compared
/// as `cp` does by device and inode, so that a hard link or a symbolic link to an input counts.
/// [`write_atomic`] checks the kind again when it writes.
pub fn check_output_file(path: &Path, inputs: &[&Path]) -> Result<()> {
    replaceable(path, &resolve_symlinks(path)?)?;
    let Ok(out) = std::fs::metadata(path) else { return Ok(()) };
    match the_input(&out, inputs) {
        Some(input) => Err(Error::file(
            path,
            format!("is the input {} (the same file): write the output to another name", input.display()),
        )),
        None => Ok(()),
    }
}

/// The one of `inputs` that is the file of `meta`, compared as `cp` does, by device and inode
/// (links followed): a hard link or a symbolic link to an input is that input.
fn the_input<'a, P: AsRef<Path>>(meta: &std::fs::Metadata, inputs: &'a [P]) -> Option<&'a Path> {
    use std::os::unix::fs::MetadataExt;
    inputs
        .iter()
        .map(AsRef::as_ref)
        .find(|input| std::fs::metadata(input).is_ok_and(|m| (m.dev(), m.ino()) == (meta.dev(), meta.ino())))
}

/// Refuse to replace `path` (shown as `shown`) unless it is missing or a regular file: a
/// rename would put a file in place of a device, a named pipe or a socket.
fn replaceable(shown: &Path, path: &Path) -> Result<()> {
    use std::os::unix::fs::FileTypeExt;
    let kind = match std::fs::symlink_metadata(path) {
        Ok(m) => m.file_type(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(shown, e)),
    };
    let what = if kind.is_file() {
        return Ok(());
    } else if kind.is_dir() {
        "a folder"
    } else if kind.is_fifo() {
        "a named pipe (FIFO)"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    };
    Err(Error::file(shown, format!("{what}: an output replaces only a regular file; choose another name")))
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

/// Remove the temporaries a killed process left in `dir` (not below it): a folder with all it
/// holds, a link but not what it points to. Only for a folder whose writers the caller has
/// locked out.
pub fn remove_stale_temporaries(dir: &Path) -> Result<()> {
    temp::remove_temporaries_in(dir, |_| true).map_err(|e| Error::io(dir, e))
}

/// Rename `from` to `to` unless something is at `to` (then an `AlreadyExists` error): never
/// over anything, as a plain rename would be over an empty folder or a file.
fn rename_no_replace(from: &Path, to: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (f, t) = (c(from)?, c(to)?);
    // SAFETY: valid NUL-terminated paths, relative to the working folder.
    let r = unsafe { libc::renameat2(libc::AT_FDCWD, f.as_ptr(), libc::AT_FDCWD, t.as_ptr(), libc::RENAME_NOREPLACE) };
    if r == 0 {
        return Ok(());
    }
    let e = std::io::Error::last_os_error();
    // A filesystem without the flag: look, then rename (a race only with another writer of `to`).
    if e.raw_os_error() == Some(libc::EINVAL) {
        if std::fs::symlink_metadata(to).is_ok() {
            return Err(std::io::ErrorKind::AlreadyExists.into());
        }
        return std::fs::rename(from, to);
    }
    Err(e)
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

    /// A single-file write clears what a killed writer left beside it (SIGKILL: no handler ran),
    /// and never a living process's temporary.
    #[test]
    fn a_killed_writers_temporary_goes_with_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let mut ended = std::process::Command::new("true").spawn().unwrap();
        ended.wait().unwrap();
        let gone = format!("{}abc.partial", temp::owner_tag(ended.id()));
        let living = format!("{}abc.partial", temp::owner_tag(std::process::id()));
        fs::write(d.join(&gone), "half").unwrap();
        fs::write(d.join(&living), "half").unwrap();
        write_json(&d.join("x.json"), &1).unwrap();
        let mut names: Vec<_> =
            fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        names.sort();
        assert_eq!(names, [living, "x.json".to_string()]);
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

    /// A named pipe at `path`.
    fn fifo(path: &Path) {
        let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    }

    #[test]
    fn only_a_regular_file_is_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        fifo(&d.join("pipe.npy"));
        std::os::unix::fs::symlink("pipe.npy", d.join("link.npy")).unwrap();
        fs::create_dir(d.join("folder.json")).unwrap();
        for (name, what) in [("pipe.npy", "a named pipe"), ("link.npy", "a named pipe"), ("folder.json", "a folder")] {
            let path = d.join(name);
            for e in [write_json(&path, &1).unwrap_err(), check_output_file(&path, &[]).unwrap_err()] {
                let e = e.to_string();
                assert!(e.starts_with(&format!("{}: {what}", path.display())) && !e.contains('\n'), "{e}");
            }
        }
        let kind = |n: &str| fs::symlink_metadata(d.join(n)).unwrap().file_type();
        use std::os::unix::fs::FileTypeExt;
        assert!(kind("pipe.npy").is_fifo() && kind("link.npy").is_symlink() && kind("folder.json").is_dir());
        assert_eq!(fs::read_dir(d).unwrap().count(), 3, "no temporary stays");
        // A regular file, and nothing, may be replaced.
        fs::write(d.join("old.json"), "0").unwrap();
        check_output_file(&d.join("old.json"), &[]).unwrap();
        check_output_file(&d.join("new.json"), &[]).unwrap();
        write_json(&d.join("old.json"), &1).unwrap();
        assert_eq!(fs::read_to_string(d.join("old.json")).unwrap(), "1\n");
    }

    #[test]
    fn an_input_is_never_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let input = d.join("w.gsf");
        fs::write(&input, "heights").unwrap();
        fs::hard_link(&input, d.join("hard.gsf")).unwrap();
        std::os::unix::fs::symlink("w.gsf", d.join("soft.gsf")).unwrap();
        fs::write(d.join("other.gsf"), "other").unwrap();
        for out in ["w.gsf", "hard.gsf", "soft.gsf", "./w.gsf"] {
            let e = check_output_file(&d.join(out), &[&d.join("other.gsf"), &input]).unwrap_err().to_string();
            assert!(e.contains(&format!("is the input {}", input.display())), "{out}: {e}");
        }
        // The input through a link is the same file too.
        let e = check_output_file(&input, &[&d.join("soft.gsf")]).unwrap_err().to_string();
        assert!(e.contains("is the input"), "{e}");
        check_output_file(&d.join("other.gsf"), &[&input]).unwrap();
        check_output_file(&d.join("new.gsf"), &[&input]).unwrap();
        assert_eq!(fs::read_to_string(&input).unwrap(), "heights");
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
        let staged = StagedDir::new(&dir.path().join("out"), "test", &[]).unwrap();
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
        let staged = StagedDir::new(&dir.path().join("out"), "test", &[]).unwrap();
        let out = staged.commit().unwrap().dir;
        assert_eq!(fs::metadata(&out).unwrap().permissions().mode() & 0o777, 0o777 & !umask);
    }

    #[test]
    fn stale_temporaries_go_with_their_content_and_links_are_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        fs::write(d.join(".asperity-a.partial"), "").unwrap();
        fs::create_dir_all(d.join(".asperity-b.partial/inside")).unwrap();
        fs::create_dir(d.join("kept")).unwrap();
        fs::write(d.join("kept/mine"), "mine").unwrap();
        fs::write(d.join("notes.partial"), "mine").unwrap();
        std::os::unix::fs::symlink("kept", d.join(".asperity-c.partial")).unwrap();
        remove_stale_temporaries(d).unwrap();
        let mut names: Vec<_> = fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        assert_eq!(names, ["kept", "notes.partial"]);
        assert_eq!(fs::read_to_string(d.join("kept/mine")).unwrap(), "mine");
        remove_stale_temporaries(&d.join("missing")).unwrap();
    }
}
