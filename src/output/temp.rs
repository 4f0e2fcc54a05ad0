//! The temporaries: every `.asperity-*.partial` file or folder asperity creates is registered
//! here from its creation until it is renamed into place or removed, so that an interrupted
//! process can remove them all ([`remove_temporaries`], called on SIGINT/SIGTERM).

use std::fs::Permissions;
use std::io;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// Every temporary's name starts so…
pub const PREFIX: &str = ".asperity-";
/// …and ends so.
pub const SUFFIX: &str = ".partial";

/// Whether `name` is one of asperity's temporaries.
pub fn is_temporary(name: &std::ffi::OsStr) -> bool {
    name.to_str().is_some_and(|n| n.starts_with(PREFIX) && n.ends_with(SUFFIX))
}

struct Registry {
    /// Set once the process is being interrupted: no temporary is created after it.
    closed: bool,
    next: u64,
    paths: Vec<(u64, PathBuf)>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry { closed: false, next: 0, paths: Vec::new() });

fn registry() -> MutexGuard<'static, Registry> {
    // A panic elsewhere never leaves the list half-changed: recover it.
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

impl Registry {
    fn add(&mut self, path: &Path) -> Entry {
        self.next += 1;
        self.paths.push((self.next, path.to_path_buf()));
        Entry(self.next)
    }
}

/// A registered path; dropping it forgets the path (after its owner has removed or renamed it).
#[derive(Debug)]
struct Entry(u64);

impl Drop for Entry {
    fn drop(&mut self) {
        registry().paths.retain(|(id, _)| *id != self.0);
    }
}

/// The registry, held by an interrupted process until it exits.
pub struct Interrupted {
    _registry: MutexGuard<'static, Registry>,
}

/// Remove every temporary in flight and refuse new ones: the process is being interrupted.
/// Hold the result until the process exits: a writer that meets a removed temporary then
/// blocks instead of reporting it as an error and ending the process first.
pub fn remove_temporaries() -> Interrupted {
    let mut registry = registry();
    registry.closed = true;
    for (_, path) in registry.paths.drain(..) {
        // The file may be gone already: renamed into place, or never finished.
        let _ = if path.is_dir() { std::fs::remove_dir_all(&path) } else { std::fs::remove_file(&path) };
    }
    Interrupted { _registry: registry }
}

fn builder<'a>() -> tempfile::Builder<'a, 'a> {
    let mut b = tempfile::Builder::new();
    b.prefix(PREFIX).suffix(SUFFIX);
    b
}

fn interrupted() -> io::Error {
    io::Error::new(io::ErrorKind::Interrupted, "interrupted")
}

/// A temporary file, removed when dropped unless [persisted](TempFile::persist).
#[derive(Debug)]
pub(super) struct TempFile {
    // Fields drop in order: the file is removed before its entry is forgotten.
    file: tempfile::NamedTempFile,
    _entry: Entry,
}

impl TempFile {
    /// A new temporary file in `dir`, with the permissions the umask gives (not 0600).
    pub fn new_in(dir: &Path) -> io::Result<TempFile> {
        let mut registry = registry();
        if registry.closed {
            return Err(interrupted());
        }
        let file = builder().permissions(Permissions::from_mode(0o666)).tempfile_in(dir)?;
        let entry = registry.add(file.path());
        Ok(TempFile { file, _entry: entry })
    }

    pub fn as_file(&self) -> &std::fs::File {
        self.file.as_file()
    }

    /// Rename the file to `path`; on failure it is removed.
    pub fn persist(self, path: &Path) -> io::Result<()> {
        let TempFile { file, _entry } = self;
        file.persist(path).map(drop).map_err(|e| e.error)
    }
}

/// A temporary folder, removed with its content when dropped unless renamed into place.
#[derive(Debug)]
pub(super) struct TempDir {
    dir: tempfile::TempDir,
    _entry: Entry,
}

impl TempDir {
    /// A new temporary folder in `parent`, with the permissions the umask gives (not 0700).
    pub fn new_in(parent: &Path) -> io::Result<TempDir> {
        let mut registry = registry();
        if registry.closed {
            return Err(interrupted());
        }
        let dir = builder().permissions(Permissions::from_mode(0o777)).tempdir_in(parent)?;
        let entry = registry.add(dir.path());
        Ok(TempDir { dir, _entry: entry })
    }

    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Move the folder to `target` (absent, or an empty folder). When `previous` names an
    /// earlier output at `target`, it is first moved aside to a registered temporary, which is
    /// returned for its owner to empty: the two renames happen with the registry held, so an
    /// interruption finds either the old folder or the new one at `target`, never neither.
    pub fn rename_into_place(self, target: &Path, previous: bool) -> io::Result<Option<Aside>> {
        let mut registry = registry();
        if registry.closed {
            return Err(interrupted());
        }
        if !previous {
            std::fs::rename(self.dir.path(), target)?;
            let _ = self.dir.keep();
            return Ok(None);
        }
        let mut aside = self.dir.path().as_os_str().to_owned();
        aside.push(".old");
        aside.push(SUFFIX);
        let aside = PathBuf::from(aside);
        std::fs::rename(target, &aside)?;
        if let Err(e) = std::fs::rename(self.dir.path(), target) {
            // Put the earlier output back; the new one is removed with `self`.
            std::fs::rename(&aside, target)?;
            return Err(e);
        }
        let entry = registry.add(&aside);
        let _ = self.dir.keep();
        Ok(Some(Aside { path: aside, _entry: entry }))
    }
}

/// An earlier output moved aside by [`TempDir::rename_into_place`], registered until its owner
/// has emptied and removed it.
#[derive(Debug)]
pub(super) struct Aside {
    pub path: PathBuf,
    _entry: Entry,
}
