//! A command's output folder, built aside and moved into place once complete, with a manifest
//! of the files it holds: the manifest is how a later run of the same command recognises the
//! folder as its own, the only kind of folder it replaces.
//!
//! Imports only `error` and the files of `output`; must not import topography, contact, friction,
//! study, report, plot, shs, cli.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use super::aside::{retire, Known, Manifest, MANIFEST};
use super::temp::{remove_orphaned_temporaries, TempDir};
use super::write::{resolve_symlinks, the_input, write_json};
use crate::error::{Error, Result};

/// An output folder under construction. Files are written into a hidden sibling folder;
/// [`StagedDir::commit`] moves it to its final name. Dropped without a commit (an error or a
/// panic on the way), it is removed, so `DIR` never holds a partial result.
///
/// An existing `DIR` is replaced only when it is empty or holds an earlier output of the same
/// command and nothing else; anything else is refused, before any work, so that no file asperity
/// did not write is ever deleted.
#[derive(Debug)]
pub struct StagedDir {
    /// As the user gave it, for messages.
    shown: PathBuf,
    /// Where the folder goes, symbolic links followed.
    target: PathBuf,
    written_by: String,
    /// The files the command reads: none of them may be among the earlier output's files.
    inputs: Vec<PathBuf>,
    staging: Option<TempDir>,
}

/// What is at the target now.
enum Found {
    Nothing,
    EmptyDir,
    /// An earlier output of the same command: its files (the manifest among them).
    Earlier(Vec<Known>),
}

/// What [`StagedDir::commit`] did.
#[derive(Debug)]
pub struct Committed {
    /// The output folder, as the user gave it.
    pub dir: PathBuf,
    /// Where files that appeared in the earlier output while it was replaced were kept (a
    /// visible folder beside the output), with a line saying so; none when nothing appeared.
    pub kept: Option<(PathBuf, String)>,
}

impl StagedDir {
    /// Start building the folder `target` as the output of `command` (e.g. "contact"), which
    /// reads the files `inputs`. Refuses a target it may not replace, and one whose earlier
    /// output holds an input (replacing the folder would delete it). The parent is created if
    /// needed.
    pub fn new(target: &Path, command: &str, inputs: &[&Path]) -> Result<Self> {
        let written_by = format!("asperity {command}");
        let resolved = resolve_symlinks(target)?;
        // `.`, `..` and `/` name no folder of their own: work on the folder they stand for.
        let resolved = match resolved.file_name() {
            Some(_) => resolved,
            None => fs::canonicalize(&resolved).map_err(|e| Error::io(target, e))?,
        };
        let parent = match resolved.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            Some(_) => PathBuf::from("."),
            None => {
                return Err(Error::invalid("--out", format!("{}: cannot replace the root folder", target.display())))
            }
        };
        let inputs = inputs.iter().map(|p| p.to_path_buf()).collect();
        let staged = StagedDir { shown: target.to_path_buf(), target: resolved, written_by, inputs, staging: None };
        staged.found()?;
        fs::create_dir_all(&parent).map_err(|e| Error::io(&parent, e))?;
        // What a killed run of a command left beside it goes: staging folders, earlier outputs
        // moved aside.
        remove_orphaned_temporaries(&parent).map_err(|e| Error::io(&parent, e))?;
        let staging = TempDir::new_in(&parent).map_err(|e| Error::io(&parent, e))?;
        Ok(StagedDir { staging: Some(staging), ..staged })
    }

    /// Where to write a file named `name` while the folder is being built.
    pub fn path(&self, name: &str) -> PathBuf {
        assert_ne!(name, MANIFEST, "the manifest is the staged folder's own file");
        self.staging.as_ref().expect("staging exists until commit").path().join(name)
    }

    /// Write the manifest and move the finished folder into place, replacing an earlier output
    /// of the same command. A file that appeared in the earlier output after it was checked (a
    /// user writing there at that moment) is never removed: it is kept in a visible folder
    /// beside the output, which [`Committed::kept`] names.
    pub fn commit(mut self) -> Result<Committed> {
        let staging = self.staging.take().expect("staging exists until commit");
        let io = |e| Error::io(&self.shown, e);
        let mut files: Vec<String> = fs::read_dir(staging.path())
            .map_err(io)?
            .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect::<std::io::Result<_>>()
            .map_err(io)?;
        files.sort();
        let manifest =
            Manifest { written_by: self.written_by.clone(), asperity: env!("CARGO_PKG_VERSION").to_string(), files };
        write_json(&staging.path().join(MANIFEST), &manifest)?;
        // Checked again: the folder may have changed while the command worked.
        let earlier = match self.found()? {
            Found::Earlier(files) => Some(files),
            Found::Nothing | Found::EmptyDir => None,
        };
        #[cfg(test)]
        tests::before_the_swap(&self.target);
        let aside = staging.rename_into_place(&self.target, earlier.is_some()).map_err(io)?;
        let mut kept = None;
        if let (Some(aside), Some(files)) = (aside, earlier) {
            // The new output is in place: what is left to do only tidies up, and fails no more.
            if let Ok(Some(folder)) = retire(&aside.path, Some(&files)) {
                let line = format!(
                    "{} changed while it was replaced: what appeared in the earlier output is kept in {}",
                    self.shown.display(),
                    folder.display()
                );
                kept = Some((folder, line));
            }
        }
        Ok(Committed { dir: self.shown.clone(), kept })
    }

    /// What the target holds, or why it may not be replaced.
    fn found(&self) -> Result<Found> {
        let shown = self.shown.display();
        let meta = match fs::metadata(&self.target) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Found::Nothing),
            Err(e) => return Err(Error::io(&self.shown, e)),
        };
        if !meta.is_dir() {
            return Err(Error::invalid("--out", format!("{shown} is a file, not a folder")));
        }
        let names: BTreeSet<String> = fs::read_dir(&self.target)
            .map_err(|e| Error::io(&self.shown, e))?
            .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
            .collect::<std::io::Result<_>>()
            .map_err(|e| Error::io(&self.shown, e))?;
        if names.is_empty() {
            return Ok(Found::EmptyDir);
        }
        let refuse = |why: String| Err(Error::invalid("--out", format!("{shown} {why}: choose another --out")));
        let path = self.target.join(MANIFEST);
        let manifest = fs::read_to_string(&path).ok().and_then(|t| serde_json::from_str::<Manifest>(&t).ok());
        let manifest = match manifest {
            Some(m) if m.written_by == self.written_by => m,
            Some(m) => {
                return refuse(format!(
                    "holds the output of `{}`, not of `{}` (its {MANIFEST} says so)",
                    m.written_by, self.written_by
                ))
            }
            None => {
                return refuse(format!(
                    "is not empty and holds no output of `{}` (no {MANIFEST} of it)",
                    self.written_by
                ))
            }
        };
        let listed: BTreeSet<&str> = manifest.files.iter().map(String::as_str).chain([MANIFEST]).collect();
        let others: Vec<&str> = names.iter().map(String::as_str).filter(|n| !listed.contains(n)).collect();
        if let Some(first) = others.first() {
            return refuse(format!(
                "holds {} file(s) `{}` did not write ({first}{}): move them away, or",
                others.len(),
                self.written_by,
                if others.len() > 1 { ", …" } else { "" }
            ));
        }
        // Its files are removed once the new output is in place: that must be allowed.
        if let Some(why) = not_removable_in(&self.target) {
            return refuse(format!("holds an earlier output this user may not remove ({why}): remove it, or"));
        }
        // Only files are removed from an earlier output: a folder or link in a listed file's
        // place is someone else's, and an input (the same file, as `cp` compares them) is read.
        let mut known = Vec::with_capacity(names.len());
        for name in &names {
            let meta = fs::symlink_metadata(self.target.join(name)).map_err(|e| Error::io(&self.shown, e))?;
            let kind = meta.file_type();
            if !kind.is_file() {
                let what = if kind.is_dir() { "a folder" } else { "not a regular file" };
                return refuse(format!(
                    "holds {name}, {what} where `{}` wrote a file: move it away, or",
                    self.written_by
                ));
            }
            if the_input(&meta, &self.inputs).is_some() {
                return refuse(format!(
                    "holds {name}, an input of this command, which replacing the folder would delete: copy it \
                     elsewhere, or"
                ));
            }
            known.push(Known::of(name.clone(), &meta));
        }
        Ok(Found::Earlier(known))
    }
}

/// Why this process may not remove files from the folder `dir`, if it may not: it needs write
/// and search permission on it, and where the folder is sticky, to own it or the files.
fn not_removable_in(dir: &Path) -> Option<String> {
    use std::os::unix::ffi::OsStrExt;
    use std::os::unix::fs::MetadataExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: a valid NUL-terminated path.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } != 0 {
        return Some(std::io::Error::last_os_error().to_string());
    }
    let meta = fs::metadata(dir).ok()?;
    // SAFETY: no arguments, cannot fail.
    let uid = unsafe { libc::geteuid() };
    let sticky = meta.mode() & libc::S_ISVTX as u32 != 0;
    if sticky && uid != 0 && meta.uid() != uid {
        let foreign = fs::read_dir(dir).ok()?.flatten().any(|e| e.metadata().is_ok_and(|m| m.uid() != uid));
        if foreign {
            return Some("a sticky folder holding files of another user".to_string());
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    thread_local! {
        /// What a test does in the instant between the last check of the target and the swap.
        static RACE: RefCell<Option<Box<dyn FnOnce(&Path)>>> = RefCell::new(None);
    }

    pub(super) fn before_the_swap(target: &Path) {
        if let Some(race) = RACE.with(|r| r.borrow_mut().take()) {
            race(target);
        }
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<_> =
            fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        n.sort();
        n
    }

    #[test]
    fn uncommitted_dir_vanishes_and_commit_replaces_its_own_output() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        {
            let s = StagedDir::new(&target, "test", &[]).unwrap();
            write_json(&s.path("a.json"), &1).unwrap();
        }
        assert!(names(root.path()).is_empty());
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        s.commit().unwrap();
        assert_eq!(names(&target), ["a.json", MANIFEST]);
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("b.json"), &2).unwrap();
        s.commit().unwrap();
        assert_eq!(names(&target), ["b.json", MANIFEST]);
        assert_eq!(names(root.path()), ["out"]);
    }

    #[test]
    fn a_folder_it_did_not_write_is_refused_and_kept() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("notes.txt"), "mine").unwrap();
        let e = StagedDir::new(&target, "test", &[]).unwrap_err().to_string();
        assert!(e.starts_with("--out: ") && e.contains("no manifest.json") && !e.contains('\n'), "{e}");

        // An earlier output of another command is not this one's.
        let other = root.path().join("other");
        let s = StagedDir::new(&other, "test", &[]).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        s.commit().unwrap();
        let e = StagedDir::new(&other, "else", &[]).unwrap_err().to_string();
        assert!(e.contains("holds the output of `asperity test`, not of `asperity else`"), "{e}");

        // Its own output with a file added by hand: refused, before and at commit.
        fs::write(other.join("notes.txt"), "mine").unwrap();
        let e = StagedDir::new(&other, "test", &[]).unwrap_err().to_string();
        assert!(e.contains("holds 1 file(s) `asperity test` did not write (notes.txt)"), "{e}");
        fs::remove_file(other.join("notes.txt")).unwrap();
        let s = StagedDir::new(&other, "test", &[]).unwrap();
        fs::write(other.join("late.txt"), "mine").unwrap();
        assert!(s.commit().unwrap_err().to_string().contains("(late.txt)"));
        assert_eq!(names(&other), ["a.json", "late.txt", MANIFEST]);
        assert_eq!(fs::read_to_string(target.join("notes.txt")).unwrap(), "mine");
        assert_eq!(names(root.path()), ["other", "out"]);
    }

    #[test]
    fn a_folder_or_link_in_a_listed_files_place_is_refused_and_kept() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        write_json(&s.path("b.json"), &1).unwrap();
        s.commit().unwrap();
        fs::remove_file(target.join("a.json")).unwrap();
        fs::create_dir(target.join("a.json")).unwrap();
        fs::write(target.join("a.json/mine"), "mine").unwrap();
        let e = StagedDir::new(&target, "test", &[]).unwrap_err().to_string();
        assert!(e.contains("holds a.json, a folder where `asperity test` wrote a file") && !e.contains('\n'), "{e}");
        // Made while the command works: refused at commit, nothing moved.
        fs::rename(target.join("a.json"), root.path().join("kept")).unwrap();
        fs::write(target.join("a.json"), "1").unwrap();
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("c.json"), &1).unwrap();
        fs::remove_file(target.join("b.json")).unwrap();
        std::os::unix::fs::symlink("../kept", target.join("b.json")).unwrap();
        let e = s.commit().unwrap_err().to_string();
        assert!(e.contains("holds b.json, not a regular file"), "{e}");
        assert_eq!(names(&target), ["a.json", "b.json", MANIFEST]);
        assert_eq!(names(root.path()), ["kept", "out"]);
        assert_eq!(fs::read_to_string(root.path().join("kept/mine")).unwrap(), "mine");
    }

    #[test]
    fn what_a_killed_process_left_beside_goes_and_a_living_ones_stays() {
        use super::super::temp::owner_tag;
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        // A process that has ended (a child, waited for), one that lives, and this one.
        let mut ended = std::process::Command::new("true").spawn().unwrap();
        ended.wait().unwrap();
        let mut living = std::process::Command::new("sleep").arg("30").spawn().unwrap();
        let kept = [
            format!("{}abc.partial", owner_tag(std::process::id())),
            format!("{}abc.partial", owner_tag(living.id())),
            ".asperity-Xy12Ab.partial".to_string(),
        ];
        let gone = owner_tag(ended.id());
        for name in kept.iter().chain(&[format!("{gone}abc.partial"), format!("{gone}abc.partial.old.partial")]) {
            fs::create_dir(r.join(name)).unwrap();
            fs::write(r.join(name).join("pressure.npy"), "").unwrap();
        }
        fs::write(r.join(format!("{gone}file.partial")), "").unwrap();
        // An earlier output moved aside holds its manifest, which lists its files.
        let manifest =
            Manifest { written_by: "asperity test".into(), asperity: "0".into(), files: vec!["pressure.npy".into()] };
        write_json(&r.join(format!("{gone}abc.partial.old.partial")).join(MANIFEST), &manifest).unwrap();
        StagedDir::new(&r.join("out"), "test", &[]).unwrap().commit().unwrap();
        living.kill().unwrap();
        living.wait().unwrap();
        let mut expected: Vec<String> = kept.into_iter().chain(["out".to_string()]).collect();
        expected.sort();
        assert_eq!(names(r), expected);
    }

    #[test]
    fn a_file_written_into_the_earlier_output_while_it_is_replaced_is_kept() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        s.commit().unwrap();
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("b.json"), &2).unwrap();
        // A user writes into the earlier output, and replaces one of its files by one of
        // their own, after the last check.
        RACE.with(|r| {
            *r.borrow_mut() = Some(Box::new(|t: &Path| {
                fs::write(t.join("mine.txt"), "mine").unwrap();
                fs::remove_file(t.join("a.json")).unwrap();
                fs::write(t.join("a.json"), "also mine").unwrap();
            }))
        });
        let committed = s.commit().unwrap();
        assert_eq!(names(&target), ["b.json", MANIFEST]);
        let (kept, line) = committed.kept.unwrap();
        assert_eq!(kept, root.path().join("asperity-kept-1"));
        assert!(line.contains("changed while it was replaced") && line.contains("asperity-kept-1"), "{line}");
        assert_eq!(names(&kept), ["a.json", "mine.txt"]);
        assert_eq!(fs::read_to_string(kept.join("a.json")).unwrap(), "also mine");
        // Nothing hidden is left for a later sweep to remove.
        assert_eq!(names(root.path()), ["asperity-kept-1", "out"]);
    }

    #[test]
    fn an_earlier_output_a_killed_process_left_aside_keeps_a_users_file() {
        use super::super::temp::owner_tag;
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        let mut ended = std::process::Command::new("true").spawn().unwrap();
        ended.wait().unwrap();
        let aside = r.join(format!("{}abc.partial.old.partial", owner_tag(ended.id())));
        fs::create_dir(&aside).unwrap();
        let manifest =
            Manifest { written_by: "asperity test".into(), asperity: "0".into(), files: vec!["a.json".into()] };
        write_json(&aside.join(MANIFEST), &manifest).unwrap();
        fs::write(aside.join("a.json"), "1").unwrap();
        fs::write(aside.join("mine.txt"), "mine").unwrap();
        // A kept folder of an earlier time is not written over.
        fs::create_dir(r.join("asperity-kept-1")).unwrap();
        super::super::temp::remove_orphaned_temporaries(r).unwrap();
        assert_eq!(names(r), ["asperity-kept-1", "asperity-kept-2"]);
        assert_eq!(names(&r.join("asperity-kept-2")), ["mine.txt"]);
    }

    #[test]
    fn an_earlier_output_this_user_may_not_empty_is_refused_before_any_work() {
        use std::os::unix::fs::PermissionsExt;
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("out");
        let s = StagedDir::new(&target, "test", &[]).unwrap();
        write_json(&s.path("a.json"), &1).unwrap();
        s.commit().unwrap();
        fs::set_permissions(&target, fs::Permissions::from_mode(0o555)).unwrap();
        let why = not_removable_in(&target);
        // SAFETY: no arguments.
        if unsafe { libc::geteuid() } == 0 {
            // The superuser may remove anything: tests/safety.rs tries another user.
            assert_eq!(why, None);
        } else {
            let e = StagedDir::new(&target, "test", &[]).unwrap_err().to_string();
            assert!(e.contains("holds an earlier output this user may not remove (Permission denied"), "{e}");
            assert_eq!(names(root.path()), ["out"]);
        }
        fs::set_permissions(&target, fs::Permissions::from_mode(0o755)).unwrap();
    }
}
