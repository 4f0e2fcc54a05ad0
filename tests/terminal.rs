//! What asperity prints and how it treats the terminal and the machine around it: a full
//! standard output is an error in one line, never a panic; a file's content, a path or an
//! option's value never reaches the terminal with its control characters; the worker threads
//! and a Slurm job's CPUs are bounded; the `asperity slurm` hint and scripts quote every path.

use std::fs::File;
use std::path::Path;
use std::process::{Command, Output, Stdio};

use ndarray::Array2;

fn asperity(dir: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_asperity"));
    c.current_dir(dir);
    c
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The one line of a refusal (exit 1, no panic).
fn refusal(o: &Output) -> String {
    // A study's warnings (a load unusually high for its small window) come before its error.
    let e: String = stderr(o).lines().filter(|l| !l.starts_with("warning: ")).map(|l| format!("{l}\n")).collect();
    assert_eq!(o.status.code(), Some(1), "expected a refusal, got {o:?}");
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

/// A small map [m] as .npy (no physical size of its own) and a pressure map [Pa] in `dir`.
fn inputs(dir: &Path) {
    let h = Array2::from_shape_fn((8, 8), |(i, j)| 1e-9 * ((i * 7 + j * 13) % 5) as f64);
    ndarray_npy::write_npy(dir.join("s.npy"), &h).unwrap();
    let p = Array2::from_shape_fn((8, 8), |(i, j)| if (i + j) % 3 == 0 { 1e6 * (1 + i) as f64 } else { 0.0 });
    ndarray_npy::write_npy(dir.join("p.npy"), &p).unwrap();
}

#[test]
fn a_full_standard_output_is_a_one_line_error() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    inputs(dir);
    let generate = ["topo", "generate", "--size", "1e-6", "--grid", "8", "--hurst", "0.8", "--rms", "1e-9"];
    for args in [
        &["topo", "info", "s.npy", "--size", "1e-6"][..],
        &["topo", "info", "s.npy", "--size", "1e-6", "--json"],
        &["topo", "psd", "s.npy", "--size", "1e-6"],
        &["topo", "convert", "s.npy", "--size", "1e-6", "c.npy"],
        &[&generate[..], &["--seed", "1", "g.npy"]].concat(),
        &["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4"],
        &["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--json"],
        &["run", "--print-default"],
        &["--help"],
        &["--version"],
        &["contact", "--help"],
    ] {
        let full = File::options().write(true).open("/dev/full").unwrap();
        let o = asperity(dir).args(args).stdout(full).output().unwrap();
        let e = refusal(&o);
        assert_eq!(e, "error: standard output: No space left on device (os error 28)\n", "{args:?}");
    }
}

#[test]
fn worker_threads_are_bounded_by_the_machine() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    inputs(dir);
    let info = ["topo", "info", "s.npy", "--size", "1e-6"];
    for (value, says) in [("100000", "100000 threads is more than the"), ("many", "'many' is not a number of threads")]
    {
        for args in [&info[..], &["run", "--print-default"], &["onset", "p.npy", "--mu-s", "0.6", "--mu-d", "0.4"]] {
            let o = asperity(dir).args(args).env("RAYON_NUM_THREADS", value).output().unwrap();
            let e = refusal(&o);
            assert!(e.starts_with("error: RAYON_NUM_THREADS: ") && e.contains(says), "{args:?}: {e}");
            assert!(o.stdout.is_empty());
        }
    }
    for value in ["2", "0", " 3"] {
        let o = asperity(dir).args(info).env("RAYON_NUM_THREADS", value).output().unwrap();
        assert!(o.status.success(), "RAYON_NUM_THREADS={value}: {}", stderr(&o));
    }
}

#[test]
fn control_characters_never_reach_the_terminal() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // A file's content, in the error that quotes it.
    std::fs::write(dir.join("t.txt"), b"1 2\n3 4\x1b[2J\rX\n").unwrap();
    let o = asperity(dir).args(["topo", "info", "t.txt"]).output().unwrap();
    let e = refusal(&o);
    assert!(e.starts_with("error: t.txt: ") && e.contains("'4\\x1b[2J'"), "{e}");
    // An option's value, C1 controls and bidirectional overrides included.
    inputs(dir);
    let o =
        asperity(dir).args(["topo", "info", "s.npy", "--size", "1e-6", "--channel", "a\u{9b}2J\u{202e}b\rc"]).output();
    let e = refusal(&o.unwrap());
    assert!(e.contains("a\\u{9b}2J\\u{202e}b\\rc"), "{e}");
    // A path, in the readable output on stdout.
    std::fs::copy(dir.join("s.npy"), dir.join("a\x1b]0;title\x07\rb.npy")).unwrap();
    let o = asperity(dir).args(["topo", "info", "a\x1b]0;title\x07\rb.npy", "--size", "1e-6"]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(out.starts_with("file         a\\x1b]0;title\\x07\\rb.npy (npy)\n"), "{out}");
    for (text, what) in [(&out, "stdout"), (&stderr(&o), "stderr")] {
        assert!(!text.chars().any(|c| c.is_control() && c != '\n'), "{what}: {text:?}");
    }
    // In JSON, as JSON's own escapes: the output parses back to the very name.
    let name = "c\x7f\u{9b}2J\u{202e}d.npy";
    std::fs::copy(dir.join("s.npy"), dir.join(name)).unwrap();
    let o = asperity(dir).args(["topo", "info", name, "--size", "1e-6", "--json"]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.contains(r#""file": "c\u007f\u009b2J\u202ed.npy""#), "{out}");
    let info: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(info["file"], name);
}

/// A tiny study: one small synthetic topography, two loads, no figures.
const STUDY: &str = r#"
[[topography]]
name = "ball"
synthetic = { size_m = ["1 µm", "1 µm"], grid = [16, 16], seed = 1, roughness = { hurst = 0.8, rms_height_m = "2 nm" }, cap = { radius_m = "10 µm" } }

[loads]
values = ["0.1 mN", "1 mN"]

[[law]]
preset = "hold 100 s"

[output]
figures = []
"#;

#[test]
fn the_slurm_hint_and_scripts_quote_every_path() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    let out = "h;touch>PWNED;x%j";
    let o = asperity(dir).args(["slurm", "study.toml", "--shards", "2", "--out", out]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    let hint = e.lines().find_map(|l| l.strip_prefix("submit: ")).unwrap_or_else(|| panic!("no hint: {e}"));

    // Pasted into a shell, the hint runs sbatch on the two scripts and nothing else.
    let bin = dir.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let sbatch = bin.join("sbatch");
    std::fs::write(&sbatch, "#!/bin/sh\nprintf '%s\\n' \"$@\" >> \"$SBATCH_LOG\"\necho 42\n").unwrap();
    std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let shell = Command::new("sh")
        .args(["-c", hint])
        .current_dir(dir)
        .env("PATH", path)
        .env("SBATCH_LOG", dir.join("sbatch.log"))
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(shell.status.success(), "{hint}: {}", stderr(&shell));
    assert!(!dir.join("PWNED").exists(), "the hint ran a command of the folder's name: {hint}");
    let folder = dir.join(out).join("slurm");
    let logged = std::fs::read_to_string(dir.join("sbatch.log")).unwrap();
    let want = format!(
        "--parsable\n{}\n--dependency=afterok:42\n{}\n",
        folder.join("shards.sh").display(),
        folder.join("assemble.sh").display()
    );
    assert_eq!(logged, want);

    // Slurm expands `%` in a log's path: the folder's own `%` is written `%%`, the task's `%a` kept.
    let script = std::fs::read_to_string(folder.join("shards.sh")).unwrap();
    let escaped = folder.display().to_string().replace('%', "%%");
    assert!(script.lines().any(|l| l == format!("#SBATCH --output={escaped}/shard-%a.log")), "{script}");
    let assemble = std::fs::read_to_string(folder.join("assemble.sh")).unwrap();
    assert!(assemble.lines().any(|l| l == format!("#SBATCH --output={escaped}/assemble.log")), "{assemble}");
}

#[test]
fn a_jobs_cpus_are_bounded() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    for cpus in ["100000", "0"] {
        let o = asperity(dir).args(["slurm", "study.toml", "--shards", "2", "--out", "out", "--cpus", cpus]).output();
        let e = refusal(&o.unwrap());
        assert!(e.starts_with(&format!("error: --cpus: {cpus} CPUs: a job runs 1 to 4096 threads")), "{e}");
        assert!(!dir.join("out").exists());
    }
    let o = asperity(dir).args(["slurm", "study.toml", "--shards", "2", "--out", "out", "--cpus", "4096"]).output();
    assert!(o.unwrap().status.success());
    let script = std::fs::read_to_string(dir.join("out/slurm/shards.sh")).unwrap();
    assert!(script.contains("#SBATCH --cpus-per-task=4096\nexport RAYON_NUM_THREADS=4096\n"), "{script}");
}
