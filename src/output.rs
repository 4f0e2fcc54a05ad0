//! Writing results so that nothing half-written is ever left behind: every file goes through
//! a temporary file in the same directory and a rename, and a command's output directory is
//! built aside and moved into place only once complete.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use ndarray::Array2;
use ndarray_npy::WritableElement;
use serde::Serialize;

use crate::error::{Error, Result};

/// Write a file atomically: `fill` writes into a temporary file beside `path`, which is then
/// renamed over `path`. A failure or a panic in `fill` leaves `path` untouched.
pub fn write_atomic(path: &Path, fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let io = |e| Error::io(path, e);
    let tmp = tempfile::Builder::new().prefix(".asperity-").suffix(".partial").tempfile_in(dir).map_err(io)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        fill(&mut w).map_err(io)?;
        w.flush().map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
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

/// An output directory under construction. Files are written into a hidden sibling
/// directory; [`StagedDir::commit`] moves it to its final name. Dropped without a commit (an
/// error or a panic on the way), it is removed, so `DIR` never holds a partial result.
#[derive(Debug)]
pub struct StagedDir {
    target: PathBuf,
    staging: Option<tempfile::TempDir>,
}

impl StagedDir {
    /// Start building the directory `target`. Its parent is created if needed.
    pub fn new(target: &Path) -> Result<Self> {
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        fs::create_dir_all(&parent).map_err(|e| Error::io(&parent, e))?;
        if target.is_file() {
            return Err(Error::invalid("--out", format!("{} is a file, not a directory", target.display())));
        }
        let staging = tempfile::Builder::new()
            .prefix(".asperity-")
            .suffix(".partial")
            .tempdir_in(&parent)
            .map_err(|e| Error::io(&parent, e))?;
        Ok(StagedDir { target: target.to_path_buf(), staging: Some(staging) })
    }

    /// Where to write a file named `name` while the directory is being built.
    pub fn path(&self, name: &str) -> PathBuf {
        self.staging.as_ref().expect("staging exists until commit").path().join(name)
    }

    /// Move the finished directory into place, replacing an earlier one of the same name.
    pub fn commit(mut self) -> Result<PathBuf> {
        let staging = self.staging.take().expect("staging exists until commit").keep();
        let io = |e| Error::io(&self.target, e);
        if self.target.exists() {
            // Swap the old result aside first so that the target is never a mix of both.
            let old = staging.with_extension("old");
            fs::rename(&self.target, &old).map_err(io)?;
            fs::rename(&staging, &self.target).map_err(io)?;
            fs::remove_dir_all(&old).map_err(io)?;
        } else {
            fs::rename(&staging, &self.target).map_err(io)?;
        }
        Ok(self.target.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_fill_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.json");
        let r = write_atomic(&path, |_| Err(std::io::Error::other("boom")));
        assert!(r.is_err());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn uncommitted_dir_vanishes_and_commit_replaces() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        {
            let s = StagedDir::new(&target).unwrap();
            write_json(&s.path("a.json"), &1).unwrap();
        }
        assert_eq!(fs::read_dir(root.path()).unwrap().count(), 0);
        let s = StagedDir::new(&target).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        s.commit().unwrap();
        let s = StagedDir::new(&target).unwrap();
        write_json(&s.path("b.json"), &2).unwrap();
        s.commit().unwrap();
        let names: Vec<_> = fs::read_dir(&target).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("b.json")]);
        assert_eq!(fs::read_dir(root.path()).unwrap().count(), 1);
    }
}
