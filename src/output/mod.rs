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
mod write;

use std::path::Path;

use crate::error::{Error, Result};

pub use aside::MANIFEST;
pub use ledger::{Ledger, Written};
pub use lock::{make_room, Access, Lock};
pub use staged::{Committed, StagedDir};
pub use temp::{is_temporary, remove_temporaries, Interrupted};
pub use write::{check_output_file, write_atomic, write_json, write_npy};

/// Remove the temporaries a killed process left in `dir` (not below it): a folder with all it
/// holds, a link but not what it points to. Only for a folder whose writers the caller has
/// locked out.
pub fn remove_stale_temporaries(dir: &Path) -> Result<()> {
    temp::remove_temporaries_in(dir, |_| true).map_err(|e| Error::io(dir, e))
}

#[cfg(test)]
mod tests {
    use std::fs;
    use std::os::unix::fs::PermissionsExt;

    use super::*;

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
