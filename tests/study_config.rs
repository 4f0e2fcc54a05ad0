//! `asperity run` on bad study files: one-line errors naming the place, a non-zero exit, and
//! nothing solved or written. And the default study, as `--print-default` shows it.

use std::path::Path;
use std::process::{Command, Output};

use asperity::study::config::{StudyConfig, DEFAULT_STUDY};

fn asperity(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(cwd).output().unwrap()
}

/// A valid small study; each case below breaks one part of it.
const GOOD: &str = r#"
[[topography]]
name = "ball"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [32, 32], seed = 1, roughness = { hurst = 0.8, rms_height_m = "22 nm" }, cap = { radius_m = "1.5 mm" } }

[contact]
boundary = "periodic"
tolerance = 1e-8
max_iterations = 20000

[loads]
min = "0.1 mN"
max = "100 mN"
count = 3

[[law]]
preset = "hold 100 s"
"#;

/// Run `study` (written as study.toml in a fresh folder) and return its stderr, checking the
/// exit status and that nothing was written.
fn refused(study: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), study).unwrap();
    let o = asperity(&["run", "study.toml", "--out", "out"], dir.path());
    let all = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success(), "accepted:\n{study}");
    // The study's unusual values are warned about first (its 10 µm window at 100 mN).
    let stderr: String = all.lines().filter(|l| !l.starts_with("warning: ")).map(|l| format!("{l}\n")).collect();
    assert_eq!(stderr.lines().count(), 1, "{all}");
    assert!(!dir.path().join("out").exists(), "{stderr}");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, ["study.toml"], "{stderr}");
    stderr
}

#[test]
fn the_good_study_runs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), GOOD).unwrap();
    let o = asperity(&["run", "study.toml", "--out", "out"], dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.path().join("out/results.csv").is_file());
}

#[test]
fn bad_study_files_fail_on_one_line_at_their_place() {
    let cases: &[(&str, &str, &str)] = &[
        // An unknown key.
        ("tolerance = 1e-8", "tolerence = 1e-8", "error: study.toml:8:1: contact.tolerence: unknown field `tolerence`"),
        // A wrong unit: a length for a load, a force for a length.
        (
            "min = \"0.1 mN\"",
            "min = \"0.1 mm\"",
            "error: study.toml:12:7: loads.min: '0.1 mm' is a length, not a force",
        ),
        ("\"22 nm\"", "\"22 mN\"", "topography[0].synthetic: roughness.rms_height_m: '22 mN' is a force, not a length"),
        // An empty load list, a non-positive load.
        (
            "min = \"0.1 mN\"\nmax = \"100 mN\"\ncount = 3",
            "values = []",
            "error: study.toml:12:1: loads.values: the load list is empty",
        ),
        (
            "min = \"0.1 mN\"\nmax = \"100 mN\"\ncount = 3",
            "values = [\"1 mN\", 0]",
            "loads.values[1]: 0 N is not positive",
        ),
        ("min = \"0.1 mN\"", "min = \"-0.1 mN\"", "error: study.toml:12:1: loads.min: -0.0001 N is not positive"),
        // Bad laws.
        (
            "preset = \"hold 100 s\"",
            "preset = \"hold 1 s\"",
            "error: study.toml:16:1: law[0]: unknown law \"hold 1 s\"",
        ),
        (
            "preset = \"hold 100 s\"",
            "name = \"x\"\nmu_s = 0.2\nmu_d = 0.4",
            "law[0]: the static friction coefficient 0.2 is below the dynamic one",
        ),
        ("preset = \"hold 100 s\"", "mu_s = 0.6", "law[0]: give exactly one of"),
        // Aging laws: complete, with hold times that keep mu_s above mu_d, listed once.
        (
            "preset = \"hold 100 s\"",
            "mu_s = 0.6\nmu_d = 0.4\naging = 0.1\nhold_times = [\"10 s\"]",
            "law[0]: an aging law needs mu_s (at hold_time), mu_d, hold_time, aging and hold_times",
        ),
        (
            "preset = \"hold 100 s\"",
            "mu_s = 0.6\nmu_d = 0.4\nhold_time = \"100 s\"\naging = 0.1\nhold_times = [\"0.1 s\"]",
            "law[0]: after a hold of 0.1 s: the static friction coefficient",
        ),
        (
            "preset = \"hold 100 s\"",
            "mu_s = 0.6\nmu_d = 0.4\nhold_time = \"100 s\"\naging = 0.1\nhold_times = [\"1 min\", \"60 s\"]",
            "law[0]: hold_times: 60 s is listed twice",
        ),
        (
            "preset = \"hold 100 s\"",
            "mu_s = 0.6\nmu_d = 0.4\nhold_time = \"100 mN\"\naging = 0.1\nhold_times = [\"10 s\"]",
            "'100 mN' is a force, not a time",
        ),
        (
            "preset = \"hold 100 s\"",
            "preset = \"hold 100 s\"\n[[law]]\nmu_s = 0.6\nmu_d = 0.4\nhold_time = \"100 s\"\naging = 0.1\nhold_times = [\"100 s\"]",
            "law[1]: the name \"hold 100 s\" is used twice",
        ),
        // An uncertainty of Young's modulus that would draw the E band through E ≤ 0.
        (
            "[contact]",
            "[material]\nyoungs = \"130 GPa\"\nyoungs_uncertainty = \"130 GPa\"\n\n[contact]",
            "material.youngs_uncertainty: 130 GPa must lie in [0, youngs) = [0, 130 GPa)",
        ),
        (
            "[contact]",
            "[material]\nyoungs_uncertainty = \"-1 GPa\"\n\n[contact]",
            "material.youngs_uncertainty: -1 GPa must lie in [0, youngs) = [0, 130 GPa)",
        ),
        // A boundary that does not exist, a cap too small for its window.
        ("\"periodic\"", "\"periodical\"", "error: study.toml:7:12: contact.boundary: 'periodical' is not"),
        (
            "\"1.5 mm\"",
            "\"10 µm\"",
            "topography[0].synthetic: cap.radius_m: 0.00001 m is smaller than the window's half-diagonal",
        ),
    ];
    // 10 000 snapshot rows aborted on a 16 GB figure, after the solves.
    let fractions = format!("{}\n[output]\nsnapshot_fractions = [{}]\n", GOOD, vec!["0.5"; 10_000].join(", "));
    let stderr = refused(&fractions);
    assert!(stderr.contains("output.snapshot_fractions: 10000 fractions: at most 12"), "{stderr}");
    for (from, to, expected) in cases {
        assert!(GOOD.contains(from), "{from}");
        let stderr = refused(&GOOD.replacen(from, to, 1));
        assert!(stderr.contains(expected), "expected {expected:?} in {stderr}");
        assert!(stderr.starts_with("error: study.toml:"), "{stderr}");
    }
}

#[test]
fn files_are_read_before_anything_is_solved() {
    // A missing topography file, after a topography that would run: refused before solving.
    let missing = format!("{GOOD}\n[[topography]]\nname = \"ball-2\"\nfile = \"scans/ball.npy\"\nsize = \"30 µm\"\n");
    let stderr = refused(&missing);
    assert!(stderr.starts_with("error: study.toml: topography \"ball-2\": "), "{stderr}");
    assert!(stderr.contains("scans/ball.npy") && stderr.contains("No such file"), "{stderr}");
    // A wafer file, a friction curve, measured points.
    let wafer = GOOD.replace(
        "cap = { radius_m = \"1.5 mm\" } }",
        "cap = { radius_m = \"1.5 mm\" } }\nwafer = { file = \"w.npy\" }",
    );
    let stderr = refused(&wafer);
    assert!(stderr.starts_with("error: study.toml: topography \"ball\": ") && stderr.contains("w.npy"), "{stderr}");
    let curve = GOOD.replace("preset = \"hold 100 s\"", "curve = \"afm.csv\"");
    let stderr = refused(&curve);
    assert!(stderr.starts_with("error: study.toml: law \"afm.csv\": ") && stderr.contains("afm.csv"), "{stderr}");
    let points = format!("{GOOD}\n[output]\nexperiments = \"points.csv\"\n");
    let stderr = refused(&points);
    assert!(stderr.starts_with("error: study.toml: output.experiments: "), "{stderr}");
    // A bare array without its size.
    let dir = tempfile::tempdir().unwrap();
    ndarray_npy::write_npy(dir.path().join("h.npy"), &ndarray::Array2::<f64>::zeros((8, 8))).unwrap();
    let bare = GOOD.replace(
        "synthetic = { size_m = [\"31.13 µm\", \"31.13 µm\"], grid = [32, 32], seed = 1, roughness = { hurst = 0.8, rms_height_m = \"22 nm\" }, cap = { radius_m = \"1.5 mm\" } }",
        "file = \"h.npy\"",
    );
    std::fs::write(dir.path().join("study.toml"), bare).unwrap();
    let o = asperity(&["run", "study.toml", "--out", "out"], dir.path());
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success() && stderr.lines().count() == 1 && stderr.contains("physical size"), "{stderr}");
    assert!(!dir.path().join("out").exists());
}

/// A study refuses what `contact` and `slide` refuse, before any solve: a synthetic surface
/// whose heights span more than its window (rms_slope = 1e6 gives ±1.7 m on a 10 µm window), a
/// tolerance its solver's start passes, and a subnormal coefficient (5e-324 would write NaN
/// into a solve record that no later run could read).
#[test]
fn implausible_surfaces_loose_tolerances_and_subnormal_laws_are_refused() {
    let steep = GOOD.replace("rms_height_m = \"22 nm\"", "rms_slope = 1e6").replace("31.13 µm", "10 µm");
    let stderr = refused(&steep);
    assert!(
        stderr.starts_with("error: study.toml: topography \"ball\": synthetic topography: the heights span ")
            && stderr.contains("more than the 1.000e-5 × 1.000e-5 m window is wide: no rough surface looks like that"),
        "{stderr}"
    );
    let loose = GOOD.replace("tolerance = 1e-8", "tolerance = 0.5");
    let stderr = refused(&loose);
    assert!(
        stderr.starts_with("error: study.toml:") && stderr.contains("contact.tolerance: must lie in (0, 0.01)"),
        "{stderr}"
    );
    let tiny = GOOD.replace("preset = \"hold 100 s\"", "name = \"tiny\"\nmu_s = 5e-324\nmu_d = 5e-324");
    let stderr = refused(&tiny);
    assert!(
        stderr.contains("law[0]: the dynamic friction coefficient must be positive, finite and at least"),
        "{stderr}"
    );
}

#[test]
fn a_missing_study_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let o = asperity(&["run", "nowhere.toml", "--out", "out"], dir.path());
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success() && stderr.starts_with("error: nowhere.toml: ") && stderr.lines().count() == 1);
}

#[test]
fn print_default_is_the_default_study_and_explains_it() {
    let dir = tempfile::tempdir().unwrap();
    let o = asperity(&["run", "--print-default"], dir.path());
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    assert_eq!(text, DEFAULT_STUDY);
    assert_eq!(StudyConfig::parse(&text, "default").unwrap(), StudyConfig::default_study());
    for key in [
        "size_m",
        "grid",
        "seed",
        "hurst",
        "rms_height_m",
        "rolloff_wavelength_m",
        "radius_m",
        "file",
        "format",
        "channel",
        "size",
        "height_unit",
        "crop",
        "fill_missing",
        "detrend",
        "pixel_size",
        "wafer",
        "youngs",
        "poisson",
        "counterface",
        "boundary",
        "tolerance",
        "max_iterations",
        "values",
        "count",
        "preset",
        "mu_s",
        "curve",
        "window",
        "pressure_maps",
        "experiments",
        "figures",
        "snapshot_fractions",
        "hold_time_loads",
        "log_density",
        "youngs_uncertainty",
        "hold_time",
        "aging",
        "hold_times",
        "resolution",
        "PLACEHOLDERS",
    ] {
        assert!(text.contains(key), "{key} is not explained");
    }
    let o = asperity(&["run", "--help"], dir.path());
    let help = String::from_utf8(o.stdout).unwrap();
    assert!(help.contains("PLACEHOLDERS") && help.contains("--print-default") && help.contains("--quick"), "{help}");
}

/// A measured scan takes a cap (with units) and the material a hardness; a synthetic surface
/// has its cap in `synthetic`, and a file with no height unit is refused before any solve.
#[test]
fn file_caps_hardness_and_unknown_units() {
    let study = GOOD
        .replace(
            r#"synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [32, 32], seed = 1, roughness = { hurst = 0.8, rms_height_m = "22 nm" }, cap = { radius_m = "1.5 mm" } }"#,
            "file = \"scan.txt\"\nsize = \"10 µm\"\ndetrend = \"plane\"\ncap = { radius_m = \"1.5 mm\" }",
        )
        .replace("[contact]", "[material]\nyoungs = \"130 GPa\"\npoisson = 0.26\nhardness = \"12 GPa\"\n\n[contact]");
    let config = StudyConfig::parse(&study, "study.toml").unwrap();
    assert_eq!(config.topographies[0].cap.map(|c| c.radius), Some(1.5e-3));
    assert_eq!(config.hardness(), Some(12e9));

    let synthetic_cap = GOOD.replace("\n\n[contact]", "\ncap = { radius_m = 1e-3 }\n\n[contact]");
    let e = refused(&synthetic_cap);
    assert!(e.contains("cap: applies to a `file` only"), "{e}");

    // A 4 × 4 matrix without a height unit: refused, naming the topography and the key.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scan.txt"), "1 2 3 4\n5 6 7 8\n9 1 2 3\n4 5 6 7\n").unwrap();
    std::fs::write(dir.path().join("study.toml"), &study).unwrap();
    let o = asperity(&["run", "study.toml", "--out", "out"], dir.path());
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert!(!o.status.success() && stderr.trim_end().lines().count() == 1, "{stderr}");
    assert!(stderr.contains("topography \"ball\"") && stderr.contains("height_unit"), "{stderr}");
    assert!(!dir.path().join("out").exists());
}

/// An aging law gives one law per hold time; the study as run keeps the laws as given — an
/// aging law's parameters, a curve law's file (made absolute) and window.
#[test]
fn laws_expand_and_are_written_back_as_given() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("afm.csv"), "0,0.1\n1,0.6\n2,0.4\n3,0.4\n4,0.3\n").unwrap();
    let laws =
        "[[law]]\nmu_s = 0.6\nmu_d = 0.4\nhold_time = \"100 s\"\naging = 0.1\nhold_times = [\"10 s\", \"1000 s\"]\n\
                [[law]]\ncurve = \"afm.csv\"\nwindow = [0.5, 1.5]\n";
    let study = GOOD
        .replace("[[law]]\npreset = \"hold 100 s\"\n", laws)
        .replace("min = \"0.1 mN\"\nmax = \"100 mN\"\ncount = 3", "values = [\"0.1 mN\"]");
    std::fs::write(dir.path().join("study.toml"), &study).unwrap();
    let config = StudyConfig::from_file(&dir.path().join("study.toml")).unwrap();
    let prepared = asperity::study::run::Study::prepare(config, "study.toml").unwrap();
    let names: Vec<(String, f64, f64)> =
        prepared.laws().iter().map(|l| (l.name.clone().unwrap(), l.mu_s, l.mu_d)).collect();
    assert_eq!(names.len(), 3);
    assert_eq!(names[0].0, "hold 10 s");
    assert!((names[0].1 - 0.5).abs() < 1e-12 && (names[1].1 - 0.7).abs() < 1e-12 && names[1].0 == "hold 1000 s");
    assert_eq!((names[2].1, names[2].2), (0.6, 0.4));
    let o = asperity(&["run", "study.toml", "--out", "out"], dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let written = std::fs::read_to_string(dir.path().join("out/study.toml")).unwrap();
    let again = StudyConfig::parse(&written, "written").unwrap();
    let curve = &again.laws[1];
    assert_eq!(curve.curve.as_deref(), Some(dir.path().join("afm.csv").as_path()));
    assert_eq!(curve.window, Some((0.5, 1.5)));
    assert_eq!(again.laws[0].hold_times.as_ref().map(Vec::len), Some(2));
    assert_eq!(again.laws[0].aging, Some(0.1));
}

/// The default study lists every levelling a study takes, each of which it takes (`sphere`
/// was missing from the list).
#[test]
fn the_default_study_lists_every_detrend() {
    use asperity::topography::detrend::Detrend;
    let line = DEFAULT_STUDY.lines().find(|l| l.contains("detrend      =")).expect("the detrend key is explained");
    let listed: Vec<&str> = line.split('"').skip(3).step_by(2).collect();
    assert_eq!(
        listed,
        ["none", "mean", "plane", "poly:N", "sphere", "line:N", "line:median", "line:1,plane", "plane"],
        "{line}"
    );
    for value in &listed[..8] {
        let value = value.replace('N', "2");
        assert!(value.parse::<Detrend>().is_ok(), "{value}");
    }
}

#[test]
fn a_figure_that_would_be_skipped_without_a_word_is_refused() {
    // No fraction to draw the stress-ratio snapshots at.
    let e = refused(&format!("{GOOD}\n[output]\nsnapshot_fractions = []\n"));
    assert!(
        e.contains("study.toml:")
            && e.contains("output.snapshot_fractions: an empty list draws no stress-ratio snapshots"),
        "{e}"
    );
    // Without the figure, an empty list is fine.
    let study = format!("{GOOD}\n[output]\nsnapshot_fractions = []\nfigures = [\"friction-drop\"]\n");
    StudyConfig::parse(&study, "study.toml").unwrap();
    // The sharing figure, named, without elastic sharing.
    let e = refused(&format!("{GOOD}\n[output]\nfigures = [\"friction-drop\", \"friction-drop-sharing\"]\n"));
    assert!(e.contains("output.figures: \"friction-drop-sharing\" compares equal with elastic sharing"), "{e}");
    // By the default list of every figure it is only left out, as the report says.
    StudyConfig::parse(GOOD, "study.toml").unwrap();
    let study = format!(
        "{GOOD}\n[model]\nsharing = [\"equal\", \"elastic\"]\n\n[output]\nfigures = [\"friction-drop-sharing\"]\n"
    );
    StudyConfig::parse(&study, "study.toml").unwrap();
}
