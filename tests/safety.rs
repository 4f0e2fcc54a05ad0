//! What asperity guarantees about the files around it, tried as a careless or hostile user
//! would: it never deletes a file it did not write, leaves no temporary behind (failed renames,
//! SIGINT, SIGTERM, kills at any moment of a start), lets one writer at a time work on a unit of
//! a study, and writes files with the permissions the umask gives. Every input is tiny.

use std::fs::File;
use std::os::unix::fs::PermissionsExt;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use ndarray::Array2;

fn asperity(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The one line of a refusal.
fn refusal(o: &Output) -> String {
    // A study's warnings (a load unusually high for its small window) come before its error.
    let e: String = stderr(o).lines().filter(|l| !l.starts_with("warning: ")).map(|l| format!("{l}\n")).collect();
    assert!(!o.status.success() && o.status.code() == Some(1), "expected a refusal, got {o:?}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

fn succeeds(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// Sorted names in `dir`.
/// The one file in `folder` named for the solve at `load` [N] as `{:e}` writes it
/// (`1e-3N-<digest>…`), and ending `end`.
fn solve_file(folder: &Path, load: &str, end: &str) -> String {
    let found: Vec<String> =
        names(folder).into_iter().filter(|n| n.starts_with(&format!("{load}N-")) && n.ends_with(end)).collect();
    assert_eq!(found.len(), 1, "{}: {found:?}", folder.display());
    found[0].clone()
}

fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    n.sort();
    n
}

/// Every `.asperity-*.partial` temporary under `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    // A process may be renaming or removing what is listed here: skip what vanishes.
    let Ok(entries) = std::fs::read_dir(dir) else { return found };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with(".asperity-") {
            found.push(path.clone());
        }
        if path.is_dir() && !path.is_symlink() {
            found.extend(temporaries(&path));
        }
    }
    found
}

/// A small rough surface [m] as .npy, without a physical size of its own.
fn surface(path: &Path, n: usize) {
    let h = Array2::from_shape_fn((n, n), |(i, j)| {
        let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
        1e-9 * ((6.3 * x).sin() * (6.3 * y).cos()
            + 0.3 * (31.4 * x + 12.6 * y).sin()
            + 0.1 * ((i * 7 + j * 13) % 5) as f64)
    });
    ndarray_npy::write_npy(path, &h).unwrap();
}

/// A study of two topographies named like the run's own files, two loads, no figures.
const STUDY: &str = r#"
[[topography]]
name = "fingerprint.json"
synthetic = { size_m = ["1 µm", "1 µm"], grid = [16, 16], seed = 1, roughness = { hurst = 0.8, rms_height_m = "2 nm" }, cap = { radius_m = "10 µm" } }

[[topography]]
name = "study.lock"
synthetic = { size_m = ["1 µm", "1 µm"], grid = [16, 16], seed = 2, roughness = { hurst = 0.8, rms_height_m = "2 nm" }, cap = { radius_m = "10 µm" } }

[loads]
values = ["0.1 mN", "1 mN"]

[[law]]
preset = "hold 100 s"

[output]
figures = []
"#;

fn study_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), STUDY).unwrap();
    std::fs::write(dir.path().join("other.toml"), STUDY.replace("\"1 mN\"]", "\"2 mN\"]")).unwrap();
    dir
}

/// `asperity run STUDY --out OUT [extra]` in `dir`.
fn run(dir: &Path, study: &str, out: &str, extra: &[&str]) -> Output {
    let mut args = vec!["run", study, "--out", out];
    args.extend_from_slice(extra);
    asperity(dir, &args)
}

/// The loads [N] of the rows of a results.csv, as written.
fn loads(path: &Path) -> Vec<String> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let column = reader.headers().unwrap().iter().position(|h| h == "load_n").unwrap();
    reader.records().map(|r| r.unwrap()[column].to_string()).collect()
}

/// results.csv without its column of timings.
fn table(path: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let seconds = reader.headers().unwrap().iter().position(|h| h == "seconds").unwrap();
    reader
        .records()
        .map(|r| r.unwrap().iter().enumerate().filter(|(i, _)| *i != seconds).map(|(_, v)| v.to_string()).collect())
        .collect()
}

#[test]
fn contact_and_onset_replace_only_their_own_earlier_output() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::create_dir(dir.join("scans")).unwrap();
    surface(&dir.join("scans/s.npy"), 16);
    std::fs::write(dir.join("scans/notes.txt"), "mine").unwrap();
    let contact =
        |out: &str| asperity(dir, &["contact", "scans/s.npy", "--size", "1e-6", "--load", "1e-6", "--out", out]);

    // The folder of the input itself, and a folder of notes: refused, untouched.
    let e = refusal(&contact("scans"));
    assert!(e.starts_with("error: --out: scans is not empty") && e.contains("manifest.json"), "{e}");
    assert_eq!(names(&dir.join("scans")), ["notes.txt", "s.npy"]);
    assert_eq!(std::fs::read_to_string(dir.join("scans/notes.txt")).unwrap(), "mine");

    // A new folder, then the same command again: its own earlier output is replaced.
    succeeds(&contact("out"));
    assert_eq!(names(&dir.join("out")), ["contact.json", "manifest.json", "pressure-000.npy"]);
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["written_by"], "asperity contact");
    assert_eq!(manifest["files"], serde_json::json!(["contact.json", "pressure-000.npy"]));
    succeeds(&contact("out"));
    assert_eq!(names(&dir.join("out")), ["contact.json", "manifest.json", "pressure-000.npy"]);

    // A file added by hand: refused, the file survives.
    std::fs::write(dir.join("out/mine.txt"), "mine").unwrap();
    let e = refusal(&contact("out"));
    assert!(e.contains("did not write (mine.txt)"), "{e}");
    assert_eq!(names(&dir.join("out")), ["contact.json", "manifest.json", "mine.txt", "pressure-000.npy"]);
    std::fs::remove_file(dir.join("out/mine.txt")).unwrap();

    // onset: never into contact's output, its own is replaced.
    let onset = |out: &str| asperity(dir, &["onset", "out", "--mu-s", "0.6", "--mu-d", "0.4", "--out", out]);
    let e = refusal(&onset("out"));
    assert!(e.contains("holds the output of `asperity contact`, not of `asperity onset`"), "{e}");
    succeeds(&onset("onset"));
    succeeds(&onset("onset"));
    assert!(names(&dir.join("onset")).contains(&"manifest.json".to_string()));
    let e = refusal(&onset("scans"));
    assert!(e.contains("scans is not empty"), "{e}");

    // An empty folder is taken; `.` (here not empty) is refused.
    std::fs::create_dir(dir.join("empty")).unwrap();
    succeeds(&contact("empty"));
    let e =
        refusal(&asperity(&dir.join("scans"), &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "."]));
    assert!(e.contains("is not empty"), "{e}");
    assert_eq!(names(&dir.join("scans")), ["notes.txt", "s.npy"]);
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

#[test]
fn failed_renames_and_links_leave_no_temporary() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 8);
    // The output's name is taken by a folder: the final rename fails.
    std::fs::create_dir(dir.join("taken.npy")).unwrap();
    std::fs::write(dir.join("taken.npy/mine"), "mine").unwrap();
    let e = refusal(&asperity(dir, &["topo", "convert", "s.npy", "taken.npy", "--size", "1e-6"]));
    assert!(e.contains("taken.npy"), "{e}");
    assert_eq!(names(&dir.join("taken.npy")), ["mine"]);

    // A dangling link as --out: the folder is made where it points, the link kept.
    std::os::unix::fs::symlink("elsewhere/out", dir.join("link")).unwrap();
    succeeds(&asperity(dir, &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "link"]));
    assert!(std::fs::symlink_metadata(dir.join("link")).unwrap().file_type().is_symlink());
    assert!(dir.join("elsewhere/out/contact.json").is_file());
    // A link to a file as an output file: written through.
    std::os::unix::fs::symlink("elsewhere/t.npy", dir.join("t.npy")).unwrap();
    succeeds(&asperity(dir, &["topo", "convert", "s.npy", "t.npy", "--size", "1e-6"]));
    assert!(dir.join("elsewhere/t.npy").is_file() && dir.join("t.npy").is_symlink());
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

/// A named pipe at `path`.
fn fifo(path: &Path) {
    let c = std::ffi::CString::new(path.as_os_str().as_encoded_bytes()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
}

#[test]
fn an_output_replaces_only_a_regular_file_and_never_an_input() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 8);
    let before = std::fs::read(dir.join("s.npy")).unwrap();
    std::fs::write(dir.join("trace.csv"), "time_s,friction_n,normal_n\n0,1,2\n").unwrap();
    fifo(&dir.join("pipe.npy"));
    fifo(&dir.join("pipe.png"));
    std::os::unix::fs::symlink("pipe.npy", dir.join("to-pipe.npy")).unwrap();
    std::fs::hard_link(dir.join("s.npy"), dir.join("hard.npy")).unwrap();
    std::os::unix::fs::symlink("s.npy", dir.join("soft.npy")).unwrap();
    std::os::unix::fs::symlink("trace.csv", dir.join("fig.svg")).unwrap();
    let generate =
        ["topo", "generate", "--size", "1um", "--grid", "8", "--hurst", "0.8", "--rms", "1nm", "--seed", "1"];
    fn with<'a>(args: &[&'a str], out: &'a str) -> Vec<&'a str> {
        [args, &[out]].concat()
    }
    for (args, what) in [
        (with(&generate, "pipe.npy"), "pipe.npy: a named pipe (FIFO)"),
        (with(&generate, "to-pipe.npy"), "to-pipe.npy: a named pipe (FIFO)"),
        (with(&["topo", "convert", "s.npy", "--size", "1e-6"], "to-pipe.npy"), "to-pipe.npy: a named pipe (FIFO)"),
        (vec!["shs", "trace.csv", "--plot", "pipe.png"], "pipe.png: a named pipe (FIFO)"),
        (vec!["shs", "trace.csv", "--out", "pipe.npy"], "pipe.npy: a named pipe (FIFO)"),
        // The input itself, by its name, a symbolic link or a hard link, and the figure's .svg.
        (
            with(&["topo", "convert", "s.npy", "--size", "1e-6", "--detrend", "plane"], "s.npy"),
            "s.npy: is the input s.npy",
        ),
        (with(&["topo", "convert", "s.npy", "--size", "1e-6"], "soft.npy"), "soft.npy: is the input s.npy"),
        (with(&["topo", "convert", "soft.npy", "--size", "1e-6"], "hard.npy"), "hard.npy: is the input soft.npy"),
        (vec!["shs", "trace.csv", "--out", "trace.csv"], "trace.csv: is the input trace.csv"),
        (vec!["shs", "trace.csv", "--out", "t.csv", "--plot", "fig.png"], "fig.svg: is the input trace.csv"),
        (
            vec!["shs", "trace.csv", "--out", "same.png", "--plot", "same.png"],
            "--plot: same.png is also written as same.png",
        ),
        (vec!["shs", "trace.csv", "--out", "t.svg", "--plot", "t.png"], "--plot: t.svg is also written as t.svg"),
    ] {
        let e = refusal(&asperity(dir, &args));
        assert!(e.starts_with(&format!("error: {what}")), "{args:?}: {e}");
    }
    let kind = |n: &str| std::fs::symlink_metadata(dir.join(n)).unwrap().file_type();
    use std::os::unix::fs::FileTypeExt;
    assert!(kind("pipe.npy").is_fifo() && kind("pipe.png").is_fifo() && kind("to-pipe.npy").is_symlink());
    assert_eq!(std::fs::read(dir.join("s.npy")).unwrap(), before);
    assert_eq!(std::fs::read_to_string(dir.join("trace.csv")).unwrap(), "time_s,friction_n,normal_n\n0,1,2\n");
    assert!(!dir.join("t.csv").exists() && !dir.join("fig.png").exists());
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

#[test]
fn a_folder_in_place_of_an_earlier_outputs_file_is_refused_and_never_moved() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 16);
    let contact = || asperity(dir, &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "out"]);
    succeeds(&contact());
    std::fs::remove_file(dir.join("out/contact.json")).unwrap();
    std::fs::create_dir(dir.join("out/contact.json")).unwrap();
    std::fs::write(dir.join("out/contact.json/notes.txt"), "mine").unwrap();
    let e = refusal(&contact());
    assert!(e.contains("out holds contact.json, a folder where `asperity contact` wrote a file"), "{e}");
    assert_eq!(names(dir), ["out", "s.npy"]);
    assert_eq!(std::fs::read_to_string(dir.join("out/contact.json/notes.txt")).unwrap(), "mine");
}

#[test]
fn an_earlier_output_holding_an_input_is_not_replaced() {
    // onset reads a map of its own earlier output: replacing that folder would delete its input.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 16);
    succeeds(&asperity(dir, &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "c"]));
    succeeds(&asperity(dir, &["onset", "c", "--mu-s", "0.6", "--mu-d", "0.4", "--out", "o"]));
    let before = names(&dir.join("o"));
    let classes = std::fs::read(dir.join("o/classes.npy")).unwrap();
    let onset = |input: &str| {
        asperity(dir, &["onset", input, "--size", "1e-6", "--mu-s", "0.6", "--mu-d", "0.4", "--out", "o"])
    };
    let e = refusal(&onset("o/classes.npy"));
    assert!(e.contains("o holds classes.npy, an input of this command"), "{e}");
    // The same file under another name (a hard link) is the same input.
    std::fs::hard_link(dir.join("o/classes.npy"), dir.join("linked.npy")).unwrap();
    let e = refusal(&onset("linked.npy"));
    assert!(e.contains("o holds classes.npy, an input of this command"), "{e}");
    assert_eq!(names(&dir.join("o")), before);
    assert_eq!(std::fs::read(dir.join("o/classes.npy")).unwrap(), classes);
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

#[test]
fn what_a_killed_command_left_beside_its_output_goes_with_the_next_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 384);
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["contact", "s.npy", "--size", "1e-6", "--fields", "--out", "out"])
        .args(["--load", "1e-7,3e-7,1e-6,3e-6,1e-5,3e-5,1e-4", "--tolerance", "1e-13"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let killed = child.id();
    assert_eq!(interrupt(&mut child, libc::SIGKILL, || !temporaries(dir).is_empty()), None);
    assert_eq!(temporaries(dir).len(), 1, "{:?}", temporaries(dir));
    // A living process's temporary beside it stays (this test's own, named as asperity names it).
    let mut living = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["contact", "s.npy", "--size", "1e-6", "--fields", "--out", "slow"])
        .args(["--load", "1e-7,3e-7,1e-6,3e-6,1e-5,3e-5,1e-4", "--tolerance", "1e-13"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temporaries(dir).len() < 2 {
        assert!(start.elapsed() < Duration::from_secs(60), "the second run never started its output");
        std::thread::sleep(Duration::from_millis(1));
    }
    succeeds(&asperity(dir, &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "quick"]));
    let left = temporaries(dir);
    // Asked after the listing: still running now, it was running when listed.
    let still_running = living.try_wait().unwrap().is_none();
    let owned_by = |pid: u32| left.iter().filter(|t| t.to_string_lossy().contains(&format!("p{pid}s"))).count();
    assert_eq!(owned_by(killed), 0, "the killed run's temporary stays: {left:?}");
    // The living run may have finished meanwhile on a busy machine; while it runs, its own stays.
    if still_running {
        assert!(owned_by(living.id()) >= 1, "{left:?}");
    }
    living.kill().unwrap();
    living.wait().unwrap();
}

#[test]
fn sigint_at_any_moment_of_a_write_leaves_no_temporary() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let p = Array2::from_shape_fn((128, 128), |(i, j)| ((i * 7 + j * 13) % 11) as f64 * 1e6);
    ndarray_npy::write_npy(dir.join("p.npy"), &p).unwrap();
    // As many snapshots as onset takes.
    let snapshots: Vec<String> = (1..=12).map(|k| format!("{}", k as f64 / 12.0)).collect();
    let mut interrupted = 0;
    for i in 0..30 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--out", "o", "--snapshots"])
            .arg(snapshots.join(","))
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        // Once the staging folder is there, at a moment that moves through the writes.
        let start = Instant::now();
        while temporaries(dir).is_empty() && child.try_wait().unwrap().is_none() {
            assert!(start.elapsed() < Duration::from_secs(60));
        }
        std::thread::sleep(Duration::from_micros(200 * i));
        unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
        if child.wait().unwrap().code() == Some(130) {
            interrupted += 1;
        }
        assert!(temporaries(dir).is_empty(), "run {i}: {:?}", temporaries(dir));
        let _ = std::fs::remove_dir_all(dir.join("o"));
    }
    assert!(interrupted >= 10, "only {interrupted} of 30 runs were interrupted");
}

/// Every entry below `dir` that is not a folder, relative to it, sorted.
fn files_below(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() && !path.is_symlink() {
            found.extend(
                files_below(&path).into_iter().map(|f| format!("{}/{f}", path.file_name().unwrap().to_string_lossy())),
            );
        } else {
            found.push(path.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    found.sort();
    found
}

#[test]
fn a_run_never_writes_through_a_link_in_its_folder() {
    // A link in DIR in place of a run's file, or of a folder it writes in, leads to a user's
    // files: the run refuses instead of replacing them.
    // A run says its progress first, then its one error line.
    let last_error = |o: &Output| {
        assert_eq!(o.status.code(), Some(1), "{}", stderr(o));
        stderr(o).lines().last().unwrap_or_default().to_string()
    };
    let tmp = study_dir();
    let dir = tmp.path();
    let study = STUDY.replace("figures = []", "figures = [\"friction-drop\"]");
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    succeeds(&run(dir, "study.toml", "R", &[]));
    let r = dir.join("R");
    std::fs::write(dir.join("victim.csv"), "mine").unwrap();
    std::fs::remove_file(r.join("results.csv")).unwrap();
    std::os::unix::fs::symlink("../victim.csv", r.join("results.csv")).unwrap();
    let e = last_error(&run(dir, "study.toml", "R", &[]));
    assert!(e.contains("results.csv: a symbolic link in a folder asperity writes"), "{e}");
    assert_eq!(std::fs::read_to_string(dir.join("victim.csv")).unwrap(), "mine");
    std::fs::remove_file(r.join("results.csv")).unwrap();
    std::fs::create_dir(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/friction-drop.png"), "mine").unwrap();
    std::fs::remove_dir_all(r.join("figures")).unwrap();
    std::os::unix::fs::symlink("../mine", r.join("figures")).unwrap();
    let e = last_error(&run(dir, "study.toml", "R", &[]));
    assert!(e.contains("figures: a symbolic link in a folder asperity writes"), "{e}");
    assert_eq!(std::fs::read_to_string(dir.join("mine/friction-drop.png")).unwrap(), "mine");
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

#[test]
fn fresh_removes_what_runs_wrote_and_nothing_else() {
    let tmp = study_dir();
    let dir = tmp.path();
    let study = STUDY.replace("figures = []", "figures = [\"friction-drop\"]\npressure_maps = true");
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    // Another study, its second topography named otherwise.
    std::fs::write(dir.join("renamed.toml"), study.replace("name = \"study.lock\"", "name = \"ball\"")).unwrap();
    succeeds(&run(dir, "study.toml", "R", &[]));
    let r = dir.join("R");
    // What a user puts in DIR, named as a run names its files, and a link in place of a run's file.
    let mine = [
        "figures/class-map.png",
        "notes.txt",
        "pressure/my-measurements/00.npy",
        "snapshots/fingerprint.json-07.json",
        "snapshots/lab-notes.json",
        "solves/topographies/old-ball/07.json",
    ];
    for m in mine {
        std::fs::create_dir_all(r.join(m).parent().unwrap()).unwrap();
        std::fs::write(r.join(m), "mine").unwrap();
    }
    let maps = r.join("pressure/study.lock");
    let (first, second) = (solve_file(&maps, "1e-4", ".npy"), solve_file(&maps, "1e-3", ".npy"));
    let (first, second) = (format!("pressure/study.lock/{first}"), format!("pressure/study.lock/{second}"));
    std::fs::remove_file(r.join(&second)).unwrap();
    std::os::unix::fs::symlink("../../notes.txt", r.join(&second)).unwrap();
    // The user's own file put in place of an output, and a ledger edited by hand to claim the
    // user's files (an older ledger's bare path, a made-up identity): all stay.
    std::fs::remove_file(r.join(&first)).unwrap();
    std::fs::write(r.join(&first), "mine").unwrap();
    let mut ledger = std::fs::OpenOptions::new().append(true).open(r.join("solves/written.jsonl")).unwrap();
    std::io::Write::write_all(
        &mut ledger,
        b"\"notes.txt\"\n{\"path\":\"snapshots/lab-notes.json\",\"identity\":{\"dev\":1,\"ino\":2,\"len\":4,\"mtime\":[0,0]}}\n",
    )
    .unwrap();
    // Each of them is where a run writes: refused before anything changes, --fresh or not.
    let before = files_below(&r);
    for fresh in [&["--fresh"][..], &[]] {
        let e = refusal(&run(dir, "renamed.toml", "R", fresh));
        assert!(e.contains("R/figures/class-map.png: is a file asperity did not write"), "{e}");
        assert_eq!(files_below(&r), before);
    }
    let e = refusal(&run(dir, "study.toml", "R", &[]));
    assert!(e.contains("where the study writes its results: asperity never writes over one; move it away"), "{e}");
    // Moved away one by one, each next one is named; the link, then the user's file in place of
    // an output.
    let away = dir.join("away");
    std::fs::create_dir(&away).unwrap();
    for (i, m) in mine.iter().filter(|m| **m != "notes.txt").enumerate() {
        std::fs::rename(r.join(m), away.join(i.to_string())).unwrap();
        let e = refusal(&run(dir, "renamed.toml", "R", &["--fresh"]));
        assert!(!e.contains(m), "{m}: {e}");
    }
    let e = refusal(&run(dir, "renamed.toml", "R", &["--fresh"]));
    assert!(e.contains(&format!("R/{second}: a symbolic link in a folder asperity writes")), "{e}");
    std::fs::remove_file(r.join(&second)).unwrap();
    let e = refusal(&run(dir, "renamed.toml", "R", &["--fresh"]));
    assert!(e.contains(&format!("R/{first}: is a file asperity did not write")), "{e}");
    std::fs::rename(r.join(&first), away.join("00.npy")).unwrap();
    assert_eq!(files_below(&away).len(), 6);

    // What is left elsewhere in DIR stays, and is said.
    let o = run(dir, "renamed.toml", "R", &["--fresh"]);
    succeeds(&o);
    let err = stderr(&o);
    let said: Vec<&str> = err.lines().filter(|l| l.starts_with("--fresh")).collect();
    assert_eq!(said, ["--fresh: left 1 file(s) in R that asperity did not write: \"notes.txt\""], "{err}");
    assert_eq!(std::fs::read_to_string(r.join("notes.txt")).unwrap(), "mine");
    // The earlier study's files are gone, with the folders they alone were in.
    assert!(!r.join("solves/topographies/study.lock").exists());
    assert!(!r.join("pressure/study.lock").exists());
    succeeds(&run(dir, "renamed.toml", "clean", &[]));
    assert_eq!(table(&r.join("results.csv")), table(&dir.join("clean/results.csv")));
    // Again: what it wrote is recorded, the user's files still are not.
    let o = run(dir, "renamed.toml", "R", &["--fresh"]);
    succeeds(&o);
    assert!(stderr(&o).contains("--fresh: left 1 file(s)"), "{}", stderr(&o));

    // A DIR whose runs kept no record: --fresh refuses, removing nothing; it still resumes.
    std::fs::remove_file(r.join("solves/written.jsonl")).unwrap();
    let before = files_below(&r);
    let e = refusal(&run(dir, "study.toml", "R", &["--fresh"]));
    assert!(e.starts_with("error: --fresh: R was written by an asperity that kept no record of its files"), "{e}");
    assert_eq!(files_below(&r), before);
    let o = run(dir, "renamed.toml", "R", &[]);
    succeeds(&o);
    assert!(stderr(&o).contains("0 solved, 4 resumed"), "{}", stderr(&o));
    assert!(!r.join("solves/written.jsonl").exists());
}

#[test]
fn convert_without_a_physical_size_writes_and_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // An XYZ point list: its coordinates carry no unit, so no physical size (its heights are
    // stated in metres, as an unknown height unit is refused).
    let heights = Array2::from_shape_fn((8, 8), |(i, j)| 1e-9 * ((i * 7 + j * 3) % 5) as f64);
    let lines: String = heights.indexed_iter().map(|((i, j), h)| format!("{j} {i} {h:e}\n")).collect();
    std::fs::write(dir.join("s.xyz"), lines).unwrap();
    for out in ["o.npy", "o.gsf"] {
        let o = asperity(dir, &["topo", "convert", "s.xyz", out, "--height-unit", "m"]);
        succeeds(&o);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("8 × 8 points") && text.contains("physical size unknown"), "{text}");
    }
    let written: Array2<f64> = ndarray_npy::read_npy(dir.join("o.npy")).unwrap();
    assert_eq!(written, heights);
}

#[test]
fn a_reader_that_stops_early_ends_the_process_quietly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 8);
    let p = Array2::from_shape_fn((8, 8), |(i, j)| if (i + j) % 3 == 0 { 1e6 * (1 + i) as f64 } else { 0.0 });
    ndarray_npy::write_npy(dir.join("p.npy"), &p).unwrap();
    for args in [
        &["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--json"][..],
        &["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4"],
        &["topo", "info", "s.npy", "--size", "1e-6", "--json"],
        &["topo", "psd", "s.npy", "--size", "1e-6"],
        &["run", "--print-default"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(args)
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // `| head -c0`: the reader is gone before the first line.
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success() || o.status.signal() == Some(libc::SIGPIPE), "{args:?}: {o:?}");
        assert!(o.stderr.is_empty(), "{args:?}: {}", stderr(&o));
    }
}

/// Send `signal` to `child` once `ready` holds, and return its exit code.
fn interrupt(child: &mut std::process::Child, signal: i32, ready: impl Fn() -> bool) -> Option<i32> {
    let start = Instant::now();
    while !ready() {
        assert!(child.try_wait().unwrap().is_none(), "it ended before it could be interrupted");
        assert!(start.elapsed() < Duration::from_secs(60), "never ready to be interrupted");
        std::thread::sleep(Duration::from_millis(1));
    }
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
    child.wait().unwrap().code()
}

#[test]
fn sigint_and_sigterm_remove_the_temporaries_and_exit_130_and_143() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 384);
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        // A contact sweep far longer than it is given: the staging folder is there.
        let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["contact", "s.npy", "--size", "1e-6", "--fields", "--out", "out"])
            .args(["--load", "1e-7,3e-7,1e-6,3e-6,1e-5,3e-5,1e-4", "--tolerance", "1e-13"])
            .current_dir(dir)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let exit = interrupt(&mut child, signal, || !temporaries(dir).is_empty());
        assert_eq!(exit, Some(code));
        assert_eq!(names(dir), ["s.npy"]);
        let mut said = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut said).unwrap();
        let name = if signal == libc::SIGINT { "SIGINT" } else { "SIGTERM" };
        assert!(said.trim_end().ends_with("nothing half-written kept") && said.contains(name), "{said}");
    }

    // A study: interrupted, nothing half-written stays, and it resumes.
    std::fs::write(dir.join("study.toml"), STUDY.replace("grid = [16, 16]", "grid = [256, 256]")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", "res"])
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let exit = interrupt(&mut child, libc::SIGTERM, || dir.join("res/study.toml").exists());
    assert_eq!(exit, Some(143));
    let mut said = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut said).unwrap();
    assert!(said.trim_end().ends_with("again to resume from its finished work"), "{said}");
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
    assert!(!dir.join("res/results.csv").exists());
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "res"]));
}

#[test]
fn a_run_killed_at_any_moment_of_its_start_resumes_or_starts_fresh() {
    let tmp = study_dir();
    let dir = tmp.path();
    // What a run killed 1 ms after it started left (200 times out of 200): a fingerprint's
    // temporary and nothing else.
    std::fs::create_dir_all(dir.join("k/solves")).unwrap();
    std::fs::write(dir.join("k/solves/.asperity-Xy12Ab.partial"), "{\"asperi").unwrap();
    succeeds(&run(dir, "study.toml", "k", &[]));
    let whole = table(&dir.join("k/results.csv"));
    assert_eq!(whole.len(), 4);
    std::fs::create_dir_all(dir.join("f/solves")).unwrap();
    std::fs::write(dir.join("f/solves/.asperity-Xy12Ab.partial"), "").unwrap();
    succeeds(&run(dir, "study.toml", "f", &["--fresh"]));

    // Killed at every moment of its first milliseconds, then run to the end.
    for i in 0..24 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["run", "study.toml", "--out", "again"])
            .args(if i % 3 == 2 { &["--fresh"][..] } else { &[] })
            .current_dir(dir)
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_micros(250 * i));
        child.kill().unwrap();
        child.wait().unwrap();
    }
    succeeds(&run(dir, "study.toml", "again", &[]));
    assert_eq!(table(&dir.join("again/results.csv")), whole);
    succeeds(&run(dir, "study.toml", "again", &["--fresh"]));
    assert_eq!(table(&dir.join("again/results.csv")), whole);
}

#[test]
fn a_dir_whose_records_an_earlier_asperity_named_by_load_index_is_refused_until_fresh() {
    let tmp = study_dir();
    let dir = tmp.path();
    succeeds(&run(dir, "study.toml", "out", &[]));
    // A fingerprint as an earlier asperity kept it (the whole study's, without the naming of
    // the records), in the place of the run's own: its length and time kept, as the ledger
    // recorded them.
    let path = dir.join("out/solves/fingerprint.json");
    let (length, time) =
        (std::fs::metadata(&path).unwrap().len() as usize, std::fs::metadata(&path).unwrap().modified().unwrap());
    let old = r#"{"study":{},"heights":[]}"#;
    std::fs::write(&path, format!("{old:length$}")).unwrap();
    File::options().write(true).open(&path).unwrap().set_modified(time).unwrap();
    let before = files_below(&dir.join("out"));
    let e = refusal(&run(dir, "study.toml", "out", &[]));
    assert!(e.contains("named its records by load index: rerun with --fresh"), "{e}");
    assert_eq!(files_below(&dir.join("out")), before);
    let o = run(dir, "study.toml", "out", &["--fresh"]);
    succeeds(&o);
    assert!(stderr(&o).contains("4 solved, 0 resumed"), "{}", stderr(&o));
}

#[test]
fn topography_names_never_meet_the_runs_own_files() {
    let tmp = study_dir();
    let dir = tmp.path();
    succeeds(&run(dir, "study.toml", "out", &[]));
    let o = run(dir, "study.toml", "out", &[]);
    succeeds(&o);
    assert!(stderr(&o).contains("0 solved, 4 resumed"), "{}", stderr(&o));
    assert_eq!(
        names(&dir.join("out/solves")),
        ["claim.lock", "fingerprint.json", "results.lock", "study.lock", "topographies", "written.jsonl"]
    );
    assert_eq!(names(&dir.join("out/solves/topographies")), ["fingerprint.json", "study.lock"]);
}

#[test]
fn one_writer_per_solve_and_two_studies_share_a_dir() {
    let tmp = study_dir();
    let dir = tmp.path();
    succeeds(&run(dir, "study.toml", "out", &[]));
    std::fs::write(dir.join("out/notes.txt"), "mine").unwrap();

    // Another process works on a solve (this test holds its lock).
    let solves = dir.join("out/solves/topographies/study.lock");
    let unit = File::create(solves.join(solve_file(&solves, "1e-4", ".lock"))).unwrap();
    unit.lock().unwrap();
    let e = refusal(&run(dir, "study.toml", "out", &[]));
    assert!(e.contains("out is busy") && e.contains("topography \"study.lock\"") && e.contains("--wait"), "{e}");
    // --wait waits for it.
    let mut waiting = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", "out", "--wait"])
        .current_dir(dir)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    assert!(waiting.try_wait().unwrap().is_none(), "it did not wait");
    drop(unit);
    succeeds(&waiting.wait_with_output().unwrap());

    // Another study grows DIR: its new load is solved, the one it shares is not; the table is
    // its own. With --fresh while a run works there: busy.
    let o = run(dir, "other.toml", "out", &[]);
    succeeds(&o);
    assert!(stderr(&o).contains(": 2 solved, 2 resumed"), "{}", stderr(&o));
    assert_eq!(loads(&dir.join("out/results.csv")), ["0.0001", "0.002", "0.0001", "0.002"]);
    succeeds(&run(dir, "study.toml", "out", &[]));
    let results = std::fs::read(dir.join("out/results.csv")).unwrap();
    let study = File::open(dir.join("out/solves/study.lock")).unwrap();
    study.lock_shared().unwrap();
    let e = refusal(&run(dir, "other.toml", "out", &["--fresh"]));
    assert!(e.contains("is busy"), "{e}");
    assert_eq!(std::fs::read(dir.join("out/results.csv")).unwrap(), results);
    drop(study);
    // --fresh discards the run's files, never the user's.
    succeeds(&run(dir, "other.toml", "out", &["--fresh"]));
    assert_eq!(std::fs::read_to_string(dir.join("out/notes.txt")).unwrap(), "mine");
    assert_eq!(loads(&dir.join("out/results.csv")), ["0.0001", "0.002", "0.0001", "0.002"]);

    // Two studies started at once into one new DIR: each runs, or is refused while the other
    // works on a solve both ask for; the table is one study's whole.
    for _ in 0..3 {
        let _ = std::fs::remove_dir_all(dir.join("race"));
        let spawn = |study: &str| {
            Command::new(env!("CARGO_BIN_EXE_asperity"))
                .args(["run", study, "--out", "race"])
                .current_dir(dir)
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (spawn("study.toml"), spawn("other.toml"));
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        assert!(a.status.success() || b.status.success(), "{a:?} {b:?}");
        for lost in [&a, &b].into_iter().filter(|o| !o.status.success()) {
            let e = refusal(lost);
            assert!(e.contains("is busy"), "{e}");
        }
        let loads = loads(&dir.join("race/results.csv"));
        assert!(
            [["0.0001", "0.001"], ["0.0001", "0.002"]].iter().any(|l| loads == [l[0], l[1], l[0], l[1]]),
            "{loads:?}"
        );
    }
}

#[test]
fn files_follow_the_umask() {
    let tmp = study_dir();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 8);
    for (umask, file, folder) in [("022", 0o644, 0o755), ("077", 0o600, 0o700)] {
        let sh = |command: &str| {
            let o = Command::new("sh")
                .args(["-c", &format!("umask {umask}; exec \"$0\" {command}"), env!("CARGO_BIN_EXE_asperity")])
                .current_dir(dir)
                .output()
                .unwrap();
            succeeds(&o);
        };
        let out = format!("c{umask}");
        sh(&format!("contact s.npy --size 1e-6 --load 1e-6 --out {out}"));
        sh(&format!("topo convert s.npy --size 1e-6 t{umask}.gsf"));
        sh(&format!("run study.toml --out r{umask}"));
        let mode = |p: &str| std::fs::metadata(dir.join(p)).unwrap().permissions().mode() & 0o777;
        for f in [format!("{out}/contact.json"), format!("{out}/pressure-000.npy"), format!("t{umask}.gsf")] {
            assert_eq!(mode(&f), file, "{f} under umask {umask}");
        }
        for f in ["results.csv", "results.json", "study.toml", "index.html"] {
            assert_eq!(mode(&format!("r{umask}/{f}")), file, "{f} under umask {umask}");
        }
        assert_eq!(mode(&out), folder);
        assert_eq!(mode(&format!("r{umask}/solves")), folder);
    }
}

#[test]
fn a_study_never_writes_over_a_users_file_of_a_name_it_writes_fresh_or_not() {
    let tmp = study_dir();
    let dir = tmp.path();
    succeeds(&run(dir, "study.toml", "R", &[]));
    let r = dir.join("R");
    std::fs::write(r.join("resolution.csv"), "mine").unwrap();
    // The study now asks for the figure whose table has that name.
    let study = STUDY.replace("figures = []", "figures = [\"resolution\"]");
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    let before = files_below(&r);
    for fresh in [&["--fresh"][..], &[]] {
        let o = run(dir, "study.toml", "R", fresh);
        let e = refusal(&o);
        assert!(e.contains("R/resolution.csv: is a file asperity did not write"), "{e}");
        // Refused before solving: nothing solved, nothing changed.
        assert!(!stderr(&o).contains("solved"), "{}", stderr(&o));
        assert_eq!(files_below(&r), before);
        assert_eq!(std::fs::read_to_string(r.join("resolution.csv")).unwrap(), "mine");
    }
    // Its own file, rewritten since by the user, is the user's now.
    std::fs::remove_file(r.join("resolution.csv")).unwrap();
    let mut results = std::fs::read(r.join("results.json")).unwrap();
    results.extend_from_slice(b"\n");
    std::fs::write(r.join("results.json"), &results).unwrap();
    let e = refusal(&run(dir, "study.toml", "R", &[]));
    assert!(e.contains("R/results.json: is a file asperity did not write (or one changed since)"), "{e}");
    assert_eq!(std::fs::read(r.join("results.json")).unwrap(), results);
}

#[test]
fn an_input_of_a_study_among_its_outputs_is_refused_before_anything_changes() {
    let tmp = study_dir();
    let dir = tmp.path();
    let study = STUDY.replace("figures = []", "figures = []\npressure_maps = true");
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    succeeds(&run(dir, "study.toml", "R", &[]));
    let r = dir.join("R");
    // A third topography read from the study's own pressure map: --fresh would remove it, a
    // run rewrite it; also through a hard link.
    let map = format!("pressure/study.lock/{}", solve_file(&r.join("pressure/study.lock"), "1e-4", ".npy"));
    std::fs::hard_link(r.join(&map), dir.join("map.npy")).unwrap();
    for input in [&format!("R/{map}")[..], "map.npy"] {
        let third = format!(
            "[[topography]]\nname = \"map\"\nfile = \"{input}\"\nsize = [\"1 cm\", \"1 cm\"]\nheight_unit = \"pm\"\n\n"
        );
        std::fs::write(dir.join("study.toml"), format!("{third}{study}")).unwrap();
        let before = files_below(&r);
        for fresh in [&["--fresh"][..], &[]] {
            let e = refusal(&run(dir, "study.toml", "R", fresh));
            // The path shortened in the message, its end kept.
            assert!(
                e.contains(&format!("{}.npy: is an input of the study", &map[map.len() - 16..map.len() - 4])),
                "{input}: {e}"
            );
            assert_eq!(files_below(&r), before);
        }
    }
}

#[test]
fn slide_and_onset_never_replace_a_curve_they_read() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    surface(&dir.join("s.npy"), 64);
    let slide = |extra: &[&str]| {
        let mut args = vec!["slide", "s.npy", "--size", "10um", "--load", "1mN", "--out", "SL"];
        args.extend_from_slice(extra);
        asperity(dir, &args)
    };
    succeeds(&slide(&["--mu-s", "0.6", "--mu-d", "0.4"]));
    let curve = std::fs::read(dir.join("SL/curve.csv")).unwrap();
    let before = names(&dir.join("SL"));
    std::os::unix::fs::symlink("SL/curve.csv", dir.join("link.csv")).unwrap();
    std::fs::hard_link(dir.join("SL/curve.csv"), dir.join("hard.csv")).unwrap();
    for input in ["SL/curve.csv", "link.csv", "hard.csv"] {
        let e = refusal(&slide(&["--curve", input, "--curve-unit", "1nm"]));
        assert!(e.contains("SL holds curve.csv, an input of this command"), "{input}: {e}");
        assert_eq!(names(&dir.join("SL")), before);
        assert_eq!(std::fs::read(dir.join("SL/curve.csv")).unwrap(), curve);
    }
    // onset reads its curve from its own earlier output.
    succeeds(&asperity(dir, &["contact", "s.npy", "--size", "10um", "--load", "1mN", "--out", "C"]));
    succeeds(&asperity(dir, &["onset", "C", "--mu-s", "0.6", "--mu-d", "0.4", "--out", "O"]));
    std::fs::copy(dir.join("SL/curve.csv"), dir.join("O/curve.csv")).unwrap();
    let e = refusal(&asperity(dir, &["onset", "C", "--curve", "O/curve.csv", "--out", "O"]));
    assert!(e.contains("O holds curve.csv, an input of this command"), "{e}");
    assert!(temporaries(dir).is_empty(), "{:?}", temporaries(dir));
}

#[test]
fn an_earlier_output_another_user_may_not_empty_is_refused_before_solving() {
    // SAFETY: no arguments.
    if unsafe { libc::geteuid() } != 0 {
        // Only the superuser can act as another user here; the library's unit test covers a
        // folder its own user may not write.
        eprintln!("skipped: needs root to run as another user");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o777)).unwrap();
    surface(&dir.join("s.npy"), 16);
    let exe = dir.join("asperity");
    std::fs::copy(env!("CARGO_BIN_EXE_asperity"), &exe).unwrap();
    succeeds(&asperity(dir, &["contact", "s.npy", "--size", "1e-6", "--load", "1e-6", "--out", "out"]));
    let before = std::fs::read(dir.join("out/contact.json")).unwrap();
    // Another user, who may write in the parent folder but not in the earlier output.
    let o = Command::new("setpriv")
        .args(["--reuid=65534", "--regid=65534", "--clear-groups", "--"])
        .arg(&exe)
        .args(["contact", "s.npy", "--size", "1e-6", "--load", "2e-6", "--out", "out"])
        .current_dir(dir)
        .output()
        .unwrap();
    let e = refusal(&o);
    assert!(e.contains("out holds an earlier output this user may not remove (Permission denied"), "{e}");
    assert_eq!(std::fs::read(dir.join("out/contact.json")).unwrap(), before);
    let mut left = names(dir);
    left.retain(|n| n != "asperity");
    assert_eq!(left, ["out", "s.npy"]);
}
