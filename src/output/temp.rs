//! The temporaries: every `.asperity-*.partial` file or folder asperity creates is registered
//! here from its creation until it is renamed into place or removed, so that an interrupted
//! process can remove them all ([`remove_temporaries`], called on SIGINT/SIGTERM). Each name
//! carries its owner (host, boot, process id and start time), so that what a killed process
//! left is recognised as such and removed ([`remove_orphaned_temporaries`]), and never what a
//! living one works on.
//!
//! Imports only `error` and the files of `output`; must not import topography, contact, friction,
//! study, report, plot, shs, cli.

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

/// Who owns a temporary: `h<host>p<pid>s<start>-` after [`PREFIX`] in its name, `host` a digest
/// of the host's name and boot id (a process id means nothing on another machine sharing the
/// folder, or after a reboot), `start` the process's start time [clock ticks since boot], which
/// tells a reused process id from the owner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Owner {
    host: u64,
    pid: u32,
    start: u64,
}

impl Owner {
    /// This process.
    fn this() -> Owner {
        static THIS: std::sync::OnceLock<Owner> = std::sync::OnceLock::new();
        *THIS.get_or_init(|| {
            use std::hash::{Hash, Hasher};
            let mut name = [0u8; 256];
            // SAFETY: the buffer is writable for its whole length.
            let named = unsafe { libc::gethostname(name.as_mut_ptr().cast(), name.len()) } == 0;
            let boot = std::fs::read_to_string("/proc/sys/kernel/random/boot_id").unwrap_or_default();
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (named.then_some(name), boot.trim()).hash(&mut h);
            let pid = std::process::id();
            // Without /proc no start time is known: 0 matches no living process's, so
            // nothing can ever prove these temporaries orphaned.
            Owner { host: h.finish(), pid, start: start_time(pid).unwrap_or(0) }
        })
    }

    /// The owner written in a temporary's name, if it names one.
    fn of(name: &str) -> Option<Owner> {
        let tag = name.strip_prefix(PREFIX)?.strip_prefix('h')?.split_once('-')?.0;
        let (host, rest) = tag.split_once('p')?;
        let (pid, start) = rest.split_once('s')?;
        Some(Owner { host: u64::from_str_radix(host, 16).ok()?, pid: pid.parse().ok()?, start: start.parse().ok()? })
    }

    fn tag(&self) -> String {
        format!("{PREFIX}h{:016x}p{}s{}-", self.host, self.pid, self.start)
    }

    /// Whether the owner has provably ended: it ran on this host since its last boot, and no
    /// process with its id and start time lives (a zombie writes nothing more).
    fn is_gone(&self) -> bool {
        let this = Owner::this();
        if self.host != this.host || this.start == 0 || *self == this {
            return false;
        }
        match std::fs::read_to_string(format!("/proc/{}/stat", self.pid)) {
            Err(e) => e.kind() == io::ErrorKind::NotFound,
            Ok(stat) => {
                stat_fields(&stat).is_some_and(|f| f[0] == "Z" || f[19].parse::<u64>().ok() != Some(self.start))
            }
        }
    }
}

/// The fields of `/proc/PID/stat` after the command name (which may hold spaces): the state
/// first, the start time 20th.
fn stat_fields(stat: &str) -> Option<Vec<&str>> {
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    (fields.len() > 19).then_some(fields)
}

/// The start time of process `pid` [clock ticks since boot].
fn start_time(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    stat_fields(&stat)?[19].parse().ok()
}

/// The start of the name of a temporary owned by process `pid` of this host (started at tick 1
/// when it has ended).
#[cfg(test)]
pub(super) fn owner_tag(pid: u32) -> String {
    Owner { host: Owner::this().host, pid, start: start_time(pid).unwrap_or(1) }.tag()
}

/// Remove the temporaries in `dir` (not below it) whose owner has provably ended (killed before
/// it could remove them); those of living processes, and those naming no owner, stay.
pub fn remove_orphaned_temporaries(dir: &Path) -> io::Result<()> {
    remove_temporaries_in(dir, |name| Owner::of(name).is_some_and(|o| o.is_gone()))
}

/// [`remove_orphaned_temporaries`] in `dir`, once per folder in a process: the first file this
/// process writes into a folder clears what a killed writer left there (a `topo convert`
/// killed with SIGKILL, which no handler sees). Best effort: a folder that cannot be listed
/// fails the write itself, with its own error.
pub fn remove_orphaned_temporaries_once(dir: &Path) {
    static SWEPT: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    let mut swept = SWEPT.lock().unwrap_or_else(|e| e.into_inner());
    if !swept.iter().any(|d| d == dir) {
        let _ = remove_orphaned_temporaries(dir);
        swept.push(dir.to_path_buf());
    }
}

/// Remove the temporaries in `dir` (not below it) whose names `pick` chooses: a folder with all
/// it holds, a link but not what it points to; none when `dir` is missing.
pub fn remove_temporaries_in(dir: &Path, pick: impl Fn(&str) -> bool) -> io::Result<()> {
    let listing = match std::fs::read_dir(dir) {
        Ok(listing) => listing,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    for entry in listing {
        let entry = entry?;
        let name = entry.file_name();
        if !(is_temporary(&name) && name.to_str().is_some_and(&pick)) {
            continue;
        }
        let removed = remove(&entry.path(), entry.file_type()?.is_dir());
        // Another process may be removing it too.
        match removed {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    Ok(())
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
        let _ = remove(&path, path.is_dir());
    }
    Interrupted { _registry: registry }
}

/// Remove the temporary `path`: a file, a staging folder with all it holds, or an earlier
/// output moved aside, of which only its own files go ([`super::aside::retire`]: a user's file
/// that found its way there is kept, in a visible folder).
fn remove(path: &Path, is_dir: bool) -> io::Result<()> {
    if !is_dir {
        return std::fs::remove_file(path);
    }
    if path.to_str().is_some_and(|p| p.ends_with(ASIDE)) {
        return super::aside::retire(path, None).map(drop);
    }
    std::fs::remove_dir_all(path)
}

/// How the name of an earlier output moved aside ends.
const ASIDE: &str = ".old.partial";

fn builder(tag: &str) -> tempfile::Builder<'_, 'static> {
    let mut b = tempfile::Builder::new();
    b.prefix(tag).suffix(SUFFIX);
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
        let file = builder(&Owner::this().tag()).permissions(Permissions::from_mode(0o666)).tempfile_in(dir)?;
        let entry = registry.add(file.path());
        Ok(TempFile { file, _entry: entry })
    }

    pub fn as_file(&self) -> &std::fs::File {
        self.file.as_file()
    }

    /// Rename the file to `path`; on failure it is removed. The rename holds the registry, so
    /// that it never adds a name to a staging folder that an interruption is removing.
    pub fn persist(self, path: &Path) -> io::Result<()> {
        let registry = registry();
        if registry.closed {
            return Err(interrupted());
        }
        let TempFile { file, _entry } = self;
        let persisted = file.persist(path).map(drop).map_err(|e| e.error);
        // The entry's drop takes the registry again.
        drop(registry);
        persisted
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
        let dir = builder(&Owner::this().tag()).permissions(Permissions::from_mode(0o777)).tempdir_in(parent)?;
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
        aside.push(ASIDE);
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
