//! Line profiles on the command line: never read as a 2-D map. What needs a map (contact, slide,
//! a study) refuses a profile in one line naming the file; `topo psd` gives a uniform profile's
//! 1-D spectrum (SurfaceTopography's values), `topo convert` writes it as two columns; a
//! two-column table too short to tell a profile from a map is refused with a `--format` hint.

mod common;

use std::path::Path;
use std::process::Command;

use serde_json::Value;

/// Exit success, stdout, stderr of `asperity ARGS` run in `dir`.
fn asperity(args: &[&str], dir: &Path) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap();
    (out.status.success(), String::from_utf8(out.stdout).unwrap(), String::from_utf8(out.stderr).unwrap())
}

/// The one-line error of a refused command.
fn refusal(args: &[&str], dir: &Path) -> String {
    let (ok, _, stderr) = asperity(args, dir);
    assert!(!ok, "{args:?} must be refused");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    stderr
}

fn data(name: &str) -> String {
    common::sample(name).to_str().unwrap().to_string()
}

#[test]
fn what_needs_a_map_refuses_a_profile_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for file in ["xy-4.txt", "dektak-1.csv", "csv-2.csv"] {
        let path = data(file);
        for args in [
            vec!["contact", &path, "--load", "1mN", "--out", "c"],
            vec!["contact", &path, "--size", "1e-3", "--height-unit", "um", "--load", "1mN", "--out", "c"],
            vec!["slide", &path, "--load", "1mN", "--mu-s", "0.5", "--mu-d", "0.3", "--out", "s"],
        ] {
            let e = refusal(&args, d);
            assert!(
                e.contains(file)
                    && e.contains("a line profile")
                    && e.contains("contact, slide and a study need a 2-D map"),
                "{e}"
            );
        }
        std::fs::write(
            d.join("study.toml"),
            format!("[[topography]]\nname = \"p\"\nfile = \"{path}\"\n[loads]\nvalues = [\"1 mN\"]\n"),
        )
        .unwrap();
        let e = refusal(&["run", "study.toml", "--quick", "--out", "r"], d);
        assert!(e.contains(file) && e.contains("a line profile"), "{e}");
        // onset starts from pressures: it says the profile is one, and what it needs.
        let e = refusal(&["onset", &path, "--mu-s", "0.5", "--mu-d", "0.3", "--out", "o"], d);
        assert!(e.contains(file) && e.contains("a line profile") && e.contains("not a pressure map"), "{e}");
        assert!(!d.join("o").exists());
        assert!(!d.join("c").exists() && !d.join("s").exists() && !d.join("r").exists());
    }
}

#[test]
fn the_content_decides_and_an_open_case_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Two rows could be a profile of 2 points or a map 2 points wide.
    std::fs::write(d.join("short.txt"), "1 2\n3 4\n").unwrap();
    let e = refusal(&["topo", "info", "short.txt"], d);
    assert!(e.contains("short.txt") && e.contains("--format profile or --format matrix"), "{e}");
    let e = refusal(&["contact", "short.txt", "--size", "1e-6", "--load", "1mN", "--out", "c"], d);
    assert!(e.contains("--format profile or --format matrix"), "{e}");
    let info = |args: &[&str]| -> Value {
        let (ok, out, err) = asperity(&[&["topo", "info", "--json"], args].concat(), d);
        assert!(ok, "{args:?}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    let map = info(&["short.txt", "--format", "matrix"]);
    assert_eq!((&map["kind"], &map["nx"], &map["ny"]), (&Value::from("map"), &Value::from(2), &Value::from(2)));
    let profile = info(&["short.txt", "--format", "profile"]);
    assert_eq!((&profile["kind"], &profile["points"], &profile["length"]), (&"profile".into(), &2.into(), &4.0.into()));
    // A first column that does not increase is no profile: refused, a map with --format matrix.
    std::fs::write(d.join("map.txt"), "0 1\n2 1\n1 1\n4 1\n5 1\n").unwrap();
    let e = refusal(&["topo", "info", "map.txt"], d);
    assert!(e.contains("line 3: x = 1 does not increase") && e.contains("--format matrix"), "{e}");
    assert_eq!(info(&["map.txt", "--format", "matrix"])["ny"], 5);
    // Four rows of increasing x, or a header naming the columns, decide.
    std::fs::write(d.join("four.txt"), "0 1\n1 2\n2 1\n3 2\n").unwrap();
    std::fs::write(d.join("named.csv"), "x [um],z [nm]\n0,1\n1,2\n").unwrap();
    assert_eq!(info(&["four.txt"])["points"], 4);
    let named = info(&["named.csv"]);
    assert_eq!((&named["length_m"], &named["max_m"]), (&Value::from(2e-6), &Value::from(2e-9)));
}

#[test]
fn psd_of_a_uniform_profile_is_surface_topographys() {
    let manifest: Value = serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).unwrap()).unwrap();
    let entry = manifest["files"].as_array().unwrap().iter().find(|e| e["file"] == "xy-4.txt").unwrap();
    let st = &entry["surface_topography"]["power_spectrum_from_profile_no_window"];
    let scale = entry["metres_per_unit"].as_f64().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (ok, out, err) =
        asperity(&["topo", "psd", &data("xy-4.txt"), "--height-unit", "mm", "--window", "none"], dir.path());
    assert!(ok, "{err}");
    let mut lines = out.lines();
    assert_eq!(lines.next(), Some("q_rad_per_m,psd_m3"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (q, c) = l.split_once(',').unwrap();
            (q.parse().unwrap(), c.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 10001 / 2);
    for (i, k) in st["k"].as_array().unwrap().iter().enumerate() {
        let (q, c) = rows[k.as_u64().unwrap() as usize - 1];
        let (want_q, want_c) = (st["q"][i].as_f64().unwrap() / scale, st["C"][i].as_f64().unwrap() * scale.powi(3));
        assert!(
            (q / want_q - 1.0).abs() < 1e-9 && (c / want_c - 1.0).abs() < 1e-9,
            "k = {k}: {q} {c} vs {want_q} {want_c}"
        );
    }
    // A non-uniform profile has no spectrum without an interpolation; a unit must be known.
    let e = refusal(&["topo", "psd", &data("dektak-1.csv")], dir.path());
    assert!(e.contains("dektak-1.csv") && e.contains("not uniform"), "{e}");
    let e = refusal(&["topo", "psd", &data("xy-4.txt")], dir.path());
    assert!(e.contains("states no length unit"), "{e}");
}

#[test]
fn convert_writes_a_profile_as_two_columns_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let info = |file: &str| -> Value {
        let (ok, out, err) = asperity(&["topo", "info", "--json", file], d);
        assert!(ok, "{err}");
        serde_json::from_str(&out).unwrap()
    };
    let source = info(&data("dektak-1.csv"));
    for out in ["p.csv", "p.txt"] {
        let (ok, _, err) = asperity(&["topo", "convert", &data("dektak-1.csv"), out], d);
        assert!(ok, "{err}");
        let copy = info(out);
        for key in ["points", "uniform", "length_m", "mean_m", "rms_m", "rms_slope", "min_m", "max_m"] {
            assert_eq!(copy[key], source[key], "{out}: {key}");
        }
    }
    // The file's positions are kept, not moved to start at 0: xy-1.txt's first x is 13.381669 µm.
    let (ok, _, err) = asperity(&["topo", "convert", &data("xy-1.txt"), "x.csv", "--height-unit", "um"], d);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(d.join("x.csv")).unwrap();
    let first: Vec<f64> = text.lines().nth(1).unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert!((first[0] - 13.381669e-6).abs() < 1e-18 && (first[1] - 17.854970e-6).abs() < 1e-18, "{first:?}");
    let e = refusal(&["topo", "convert", &data("dektak-1.csv"), "p.npy"], d);
    assert!(e.contains("p.npy") && e.contains("line profile") && e.contains("*.csv or *.txt"), "{e}");
    let e = refusal(&["topo", "convert", &data("dektak-1.csv"), "q.csv", "--detrend", "plane"], d);
    assert!(e.starts_with("error: --detrend: ") && e.contains("line profile"), "{e}");
    let e = refusal(&["topo", "convert", &data("matrix-6.txt"), "m.csv"], d);
    assert!(e.contains(".csv and .txt hold line profiles"), "{e}");
    let e = refusal(&["topo", "convert", &data("xy-5.txt"), "m.csv", "--height-unit", "um"], d);
    assert!(e.contains("1 of 4 points are missing"), "{e}");
    assert!(!d.join("p.npy").exists() && !d.join("q.csv").exists() && !d.join("m.csv").exists());
}

/// A file stating its heights' unit only takes `--height-unit` for its positions, as the message
/// says (it was refused: "states its own height unit"); a file stating both refuses it.
#[test]
fn a_profile_stating_only_its_heights_unit_takes_the_positions_unit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("h.csv"), "x,height in nm\n0,1\n1,2\n2,4\n3,1\n4,2\n5,3\n6,1\n7,2\n").unwrap();
    let (ok, out, err) = asperity(&["topo", "info", "--json", "h.csv", "--height-unit", "um"], d);
    assert!(ok, "{err}");
    let info: Value = serde_json::from_str(&out).unwrap();
    assert!((info["length_m"].as_f64().unwrap() - 8e-6).abs() < 1e-18, "{info}");
    assert!((info["mean_m"].as_f64().unwrap() - 2e-9).abs() < 1e-21, "{info}");
    std::fs::write(d.join("b.csv"), "x in um,height in nm\n0,1\n1,2\n2,4\n3,1\n4,2\n5,3\n6,1\n7,2\n").unwrap();
    let e = refusal(&["topo", "info", "b.csv", "--height-unit", "um"], d);
    assert!(e.starts_with("error: --height-unit: ") && e.contains("states its own units"), "{e}");
}

#[test]
fn the_summary_says_it_is_a_profile() {
    let (ok, out, err) = asperity(&["topo", "info", &data("xy-1.txt"), "--height-unit", "um"], Path::new("."));
    assert!(ok, "{err}");
    assert!(out.contains("132 points along x, non-uniform positions (a line profile, not a 2-D map)"), "{out}");
    assert!(out.contains("rms          3.059 µm") && out.contains("rms slope    0.4382"), "{out}");
    let (ok, out, _) = asperity(&["topo", "info", &data("xy-1.txt")], Path::new("."));
    assert!(ok && out.contains("rms slope    unknown"), "{out}");
}

#[test]
fn a_profile_beyond_representable_lengths_is_refused() {
    // Squares of 1e308 overflow: the statistics would be inf and NaN, printed as if measured.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("high.txt"), "0 1e308\n1 -1e308\n2 1e308\n3 5\n4 6\n").unwrap();
    std::fs::write(d.join("long.txt"), "0 1\n1e300 2\n2e300 3\n3e300 5\n4e300 6\n").unwrap();
    let e = refusal(&["topo", "info", "high.txt", "--height-unit", "m"], d);
    assert!(e.contains("high.txt: point 1 has height 1e308, beyond ±1e50"), "{e}");
    let e = refusal(&["topo", "info", "long.txt", "--height-unit", "km"], d);
    assert!(e.contains("long.txt: the length 5e303 m is not between"), "{e}");
}
