//! Writing one file safely: through a temporary beside it and a rename ([`write_atomic`]),
//! replacing only a regular file, never an input ([`check_output_file`]), and recording it in
//! the open [`Ledger`] whose folder holds it; the ledger's own rewrite ([`Ledger::retain`]) goes
//! the same way. Above the ledger and the temporaries (and, in its tests, the locks); must not
//! import the staged folders.
//!
//! Imports only `error` and the files of `output`; must not import topography, contact, friction,
//! study, report, plot, shs, cli.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ndarray::Array2;
use ndarray_npy::WritableElement;
use serde::Serialize;

use super::ledger::{self, Ledger, Line};
use super::temp;
use crate::error::{Error, Result};

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
pub(super) fn the_input<'a, P: AsRef<Path>>(meta: &std::fs::Metadata, inputs: &'a [P]) -> Option<&'a Path> {
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

/// `path` with symbolic links in its last component followed (a dangling link gives where it
/// points to).
pub(super) fn resolve_symlinks(path: &Path) -> Result<PathBuf> {
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

impl Ledger {
    /// Keep in the ledger file `file` only the lines of the paths `keep` chooses (a torn or
    /// foreign line goes too), rewriting it atomically.
    pub fn retain(file: &Path, keep: impl Fn(&Path) -> bool) -> Result<()> {
        let text = match std::fs::read(file) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => return Err(Error::io(file, e)),
        };
        let kept: Vec<&[u8]> = text
            .split(|&b| b == b'\n')
            .filter(|line| serde_json::from_slice::<Line>(line).is_ok_and(|l| keep(Path::new(&l.path))))
            .collect();
        write_atomic(file, |w| kept.iter().try_for_each(|line| w.write_all(line).and_then(|()| w.write_all(b"\n"))))
    }
}

#[cfg(test)]
mod tests {
    use std::fs::{self, OpenOptions};

    use super::super::lock::{Access, Lock};
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
    fn writes_below_the_folder_are_recorded_before_they_appear_and_torn_lines_skipped() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("R");
        let file = dir.join("solves/written.jsonl");
        std::fs::create_dir_all(dir.join("solves")).unwrap();
        assert!(Ledger::read(&file).unwrap().is_none());
        {
            let _ledger = Ledger::open(&dir, &file);
            write_json(&dir.join("results.json"), &1).unwrap();
            write_json(&root.path().join("elsewhere.json"), &1).unwrap();
            Lock::acquire(&dir.join("solves/a.lock"), Access::Shared, false).unwrap();
            // A line torn by a crash, then a name with a line break in it.
            let mut f = OpenOptions::new().append(true).open(&file).unwrap();
            f.write_all(b"\"snapshots/lab").unwrap();
            write_json(&dir.join("odd\nname.json"), &1).unwrap();
        }
        write_json(&dir.join("after.json"), &1).unwrap();
        let recorded = Ledger::read(&file).unwrap().unwrap();
        let paths: Vec<_> = recorded.iter().map(|w| w.path.clone()).collect();
        assert_eq!(paths, ["results.json", "solves/a.lock", "odd\nname.json"].map(PathBuf::from));
        let meta = |p: &str| std::fs::symlink_metadata(dir.join(p)).unwrap();
        assert!(recorded[0].is(&meta("results.json")) && recorded[1].is(&meta("solves/a.lock")));
    }

    /// A line naming a user's file (hand-edited, or the identity of a file since replaced) does
    /// not make it the ledger's, nor does a line of an older ledger without identity.
    #[test]
    fn only_the_very_file_written_is_the_ledgers() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("R");
        let file = dir.join("written.jsonl");
        std::fs::create_dir_all(&dir).unwrap();
        {
            let _ledger = Ledger::open(&dir, &file);
            write_json(&dir.join("results.json"), &1).unwrap();
        }
        std::fs::write(dir.join("mine.txt"), "mine").unwrap();
        let mut f = OpenOptions::new().append(true).open(&file).unwrap();
        writeln!(
            f,
            "{{\"path\":\"mine.txt\",\"identity\":{{\"dev\":1,\"ino\":2,\"len\":4,\"mtime\":[0,0]}}}}\n\"mine.txt\""
        )
        .unwrap();
        let recorded = Ledger::read(&file).unwrap().unwrap();
        assert_eq!(recorded.len(), 2);
        let meta = |p: &str| std::fs::symlink_metadata(dir.join(p)).unwrap();
        assert!(recorded[0].is(&meta("results.json")));
        assert!(!recorded[1].is(&meta("mine.txt")));
        // The user's own file in place of the output written.
        std::fs::remove_file(dir.join("results.json")).unwrap();
        std::fs::write(dir.join("results.json"), "mine").unwrap();
        assert!(!recorded[0].is(&meta("results.json")));
    }
}
