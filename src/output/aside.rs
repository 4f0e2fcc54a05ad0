//! An earlier output moved aside while its replacement goes into place, and how it is retired:
//! the manifest that lists an output's files, the identity of each file found, and the removal
//! of only those files. Below both the staged folders and the temporaries' registry (which
//! retires an aside left by an interrupted replacement); it must not import either.

use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The manifest's name in an output folder.
pub const MANIFEST: &str = "manifest.json";

/// `DIR/manifest.json`: which command wrote the folder, and every file it wrote there.
#[derive(Debug, Serialize, Deserialize)]
pub(super) struct Manifest {
    /// "asperity contact", "asperity onset".
    pub(super) written_by: String,
    pub(super) asperity: String,
    pub(super) files: Vec<String>,
}

/// A file of an earlier output: its name and identity (device, inode, length [bytes] and
/// modification time [s, ns]: an inode number is reused at once by the next file), so that
/// only the very file found is removed, not one a user put in its place since.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct Known {
    name: String,
    identity: Option<(u64, u64, u64, i64, i64)>,
}

impl Known {
    pub(super) fn of(name: String, meta: &fs::Metadata) -> Known {
        use std::os::unix::fs::MetadataExt;
        Known { name, identity: Some((meta.dev(), meta.ino(), meta.len(), meta.mtime(), meta.mtime_nsec())) }
    }

    /// Whether `meta` is of this file: any file of its name when its identity is unknown.
    pub(super) fn is(&self, meta: &fs::Metadata) -> bool {
        self.identity.is_none_or(|_| Known::of(String::new(), meta).identity == self.identity)
    }
}

/// Empty and remove `aside`, an earlier output moved aside: only its own files go — those of
/// `known` (name and identity) when given, else those its manifest lists — and the manifest.
/// Anything else in it (a file a user wrote there while it was being replaced) is never
/// removed: the folder is then renamed to a visible name beside it, which is returned.
pub(super) fn retire(aside: &Path, known: Option<&[Known]>) -> std::io::Result<Option<PathBuf>> {
    let listed: Vec<Known> = match known {
        Some(k) => k.to_vec(),
        None => {
            let manifest = fs::read_to_string(aside.join(MANIFEST)).ok();
            let files =
                manifest.and_then(|t| serde_json::from_str::<Manifest>(&t).ok()).map_or(Vec::new(), |m| m.files);
            // Known by name only: the process that knew their identities was killed.
            files.into_iter().chain([MANIFEST.to_string()]).map(|name| Known { name, identity: None }).collect()
        }
    };
    for file in &listed {
        let path = aside.join(&file.name);
        let Ok(meta) = fs::symlink_metadata(&path) else { continue };
        if meta.is_file() && file.is(&meta) {
            match fs::remove_file(&path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
                _ => {}
            }
        }
    }
    match fs::remove_dir(aside) {
        Ok(()) => Ok(None),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) if e.kind() == std::io::ErrorKind::DirectoryNotEmpty => keep_visible(aside).map(Some),
        Err(e) => Err(e),
    }
}

/// Rename the folder `aside` to `asperity-kept-N` beside it, the first N free (never over
/// anything there).
fn keep_visible(aside: &Path) -> std::io::Result<PathBuf> {
    let parent = aside.parent().unwrap_or(Path::new("."));
    for n in 1..10_000 {
        let to = parent.join(format!("asperity-kept-{n}"));
        match rename_no_replace(aside, &to) {
            Ok(()) => return Ok(to),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::other("no free name asperity-kept-N beside it"))
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
