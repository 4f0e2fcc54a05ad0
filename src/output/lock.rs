//! Advisory locks on lock files (`flock`): held while a process works, released by the kernel
//! when it ends, however it ends, so a crash never leaves a stale lock.
//!
//! Imports only `error` and the files of `output`; must not import topography, contact, friction,
//! study, report, plot, shs, cli.

use std::fs::{File, OpenOptions, TryLockError};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Make room for `count` lock files held open at once (a study's run holds one per solve):
/// raise the soft limit on open files towards the hard one where it is short (1024 on many
/// systems). Past the hard limit, the open that fails names its file and the reason.
pub fn make_room(count: usize) {
    let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit fills the struct it is given; setrlimit only reads it.
    if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) } != 0 {
        return;
    }
    // The files of the run itself besides its locks: inputs, outputs, the ledger.
    let want = (count as libc::rlim_t).saturating_add(256);
    if limit.rlim_cur < want {
        limit.rlim_cur = want.min(limit.rlim_max);
        unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, &limit) };
    }
}

/// How a lock is shared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Many holders at once, none exclusive.
    Shared,
    /// One holder.
    Exclusive,
}

/// A held lock; dropping it releases it. The lock file itself stays.
#[derive(Debug)]
pub struct Lock {
    file: File,
    path: PathBuf,
}

impl Lock {
    /// Take the lock on `path` (created if missing, and then recorded in an open
    /// [`Ledger`](super::Ledger) of its folder). With `wait`, block until it is free;
    /// without, `None` when another process holds it.
    pub fn acquire(path: &Path, access: Access, wait: bool) -> Result<Option<Lock>> {
        let io = |e| Error::io(path, e);
        super::ledger::check(path)?;
        let open = |create_new| OpenOptions::new().read(true).write(true).create_new(create_new).open(path);
        let file = match open(true) {
            Ok(file) => {
                // A kill before the record leaves an empty lock file that `--fresh` lists as not
                // written by asperity: the record needs the file's identity.
                super::ledger::record(path, &file.metadata().map_err(io)?)?;
                file
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => open(false).map_err(io)?,
            Err(e) => return Err(io(e)),
        };
        let lock = Lock { file, path: path.to_path_buf() };
        Ok(lock.take(access, wait)?.then_some(lock))
    }

    /// Change a held exclusive lock into a shared one. (`flock` does it by release and retake,
    /// so the caller holds another lock that keeps out whoever could take it exclusively.)
    pub fn share(self) -> Result<Lock> {
        self.file.unlock().map_err(|e| Error::io(&self.path, e))?;
        self.take(Access::Shared, true)?;
        Ok(self)
    }

    fn take(&self, access: Access, wait: bool) -> Result<bool> {
        let io = |e| Error::io(&self.path, e);
        match (access, wait) {
            (Access::Shared, true) => self.file.lock_shared().map_err(io).map(|()| true),
            (Access::Exclusive, true) => self.file.lock().map_err(io).map(|()| true),
            (access, false) => {
                let r = if access == Access::Shared { self.file.try_lock_shared() } else { self.file.try_lock() };
                match r {
                    Ok(()) => Ok(true),
                    Err(TryLockError::WouldBlock) => Ok(false),
                    Err(TryLockError::Error(e)) => Err(io(e)),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_and_exclusive_exclude_each_other_until_released() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.lock");
        let a = Lock::acquire(&path, Access::Shared, false).unwrap().unwrap();
        let b = Lock::acquire(&path, Access::Shared, false).unwrap().unwrap();
        assert!(Lock::acquire(&path, Access::Exclusive, false).unwrap().is_none());
        drop((a, b));
        let c = Lock::acquire(&path, Access::Exclusive, false).unwrap().unwrap();
        assert!(Lock::acquire(&path, Access::Shared, false).unwrap().is_none());
        let c = c.share().unwrap();
        assert!(Lock::acquire(&path, Access::Shared, false).unwrap().is_some());
        drop(c);
        assert!(path.is_file());
    }
}
