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
    let e = refusal(&["topo", "psd", &data("xy-1.txt"), "--height-unit", "um"], dir.path());
    assert!(e.contains("xy-1.txt") && e.contains("not uniform"), "{e}");
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
        assert_eq!((&copy["points"], &copy["uniform"]), (&source["points"], &source["uniform"]), "{out}");
        // The grid's positions as written, to their last digit: the step read back from them
        // is the same to rounding.
        for key in ["length_m", "step_m", "mean_m", "rms_m", "rms_slope", "min_m", "max_m"] {
            let (a, b) = (copy[key].as_f64().unwrap(), source[key].as_f64().unwrap());
            assert!((a / b - 1.0).abs() < 1e-12, "{out}: {key} {a:e} vs {b:e}");
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
    let e = refusal(&["topo", "convert", &data("dektak-1.csv"), "q.csv", "--detrend", "sphere"], d);
    assert!(e.starts_with("error: --detrend: ") && e.contains("line profile"), "{e}");
    let e = refusal(&["topo", "convert", &data("dektak-1.csv"), "q.csv", "--crop", "0:2,0:2"], d);
    assert!(e.starts_with("error: --crop: ") && e.contains("prepares 2-D maps"), "{e}");
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
    assert!(e.starts_with("error: --height-unit: ") && e.contains("states the unit of its heights"), "{e}");
    let e = refusal(&["topo", "info", "b.csv", "--position-unit", "mm"], d);
    assert!(e.starts_with("error: --position-unit: ") && e.contains("states the unit of its positions"), "{e}");
}

/// `--position-unit` gives the positions' unit beside `--height-unit`, which gives the heights'
/// (and the positions' when alone); a map refuses it.
#[test]
fn positions_and_heights_take_units_of_their_own() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("p.txt"), "0 1\n1 3\n2 1\n3 3\n").unwrap();
    let info = |args: &[&str]| -> Value {
        let (ok, out, err) = asperity(&[&["topo", "info", "--json", "p.txt"], args].concat(), d);
        assert!(ok, "{args:?}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    let close = |v: &Value, want: f64| (v.as_f64().unwrap() / want - 1.0).abs() < 1e-12;
    // Positions in mm, heights in nm: 4 mm long, heights 1 and 3 nm, rms slope 2 nm / 1 mm.
    let both = info(&["--position-unit", "mm", "--height-unit", "nm"]);
    assert!(close(&both["length_m"], 4e-3) && close(&both["mean_m"], 2e-9), "{both}");
    assert!(close(&both["rms_slope"], 2e-6) && both["position_unit"] == "mm", "{both}");
    // --height-unit alone is the unit of both (SurfaceTopography's one unit of a line scan).
    let one = info(&["--height-unit", "um"]);
    assert!(close(&one["length_m"], 4e-6) && close(&one["rms_slope"], 2.0), "{one}");
    // --position-unit alone leaves the heights as stored, their unit unknown.
    let x_only = info(&["--position-unit", "mm"]);
    assert!(close(&x_only["length_m"], 4e-3) && x_only["rms_m"].is_null() && close(&x_only["rms"], 1.0), "{x_only}");
    let e = refusal(&["topo", "psd", "p.txt", "--position-unit", "mm"], d);
    assert!(e.contains("no unit for the heights") && e.contains("--height-unit"), "{e}");
    let e = refusal(&["topo", "info", "p.txt", "--position-unit", "furlong"], d);
    assert!(e.starts_with("error: --position-unit: 'furlong' is not a length unit"), "{e}");
    let e = refusal(&["topo", "info", &data("matrix-6.txt"), "--position-unit", "mm"], d);
    assert!(e.starts_with("error: --position-unit: ") && e.contains("2-D map"), "{e}");
}

/// The export rounds its positions to 0.1 µm and states 0.156 µm per sample: the positions
/// agree with a grid of their mean step to their rounding, and the profile is read on it.
#[test]
fn a_stated_step_the_positions_agree_with_makes_the_profile_uniform() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (ok, out, err) = asperity(&["topo", "info", "--json", &data("dektak-1.csv")], d);
    assert!(ok, "{err}");
    let info: Value = serde_json::from_str(&out).unwrap();
    // The mean step (1499.8 − 0) / 9599 µm.
    let step = 1499.8e-6 / 9599.0;
    assert_eq!(info["uniform"], true);
    assert!((info["step_m"].as_f64().unwrap() / step - 1.0).abs() < 1e-12, "{info}");
    assert!((info["length_m"].as_f64().unwrap() / (9600.0 * step) - 1.0).abs() < 1e-12, "{info}");
    // Its spectrum: the Hann-windowed PSD from q = 2π/(9600 step), one row a wavenumber.
    let (ok, out, err) = asperity(&["topo", "psd", &data("dektak-1.csv")], d);
    assert!(ok, "{err}");
    let rows: Vec<&str> = out.lines().collect();
    assert_eq!((rows[0], rows.len()), ("q_rad_per_m,psd_m3", 1 + 9600 / 2));
    let q1: f64 = rows[1].split(',').next().unwrap().parse().unwrap();
    assert!((q1 / (2.0 * std::f64::consts::PI / (9600.0 * step)) - 1.0).abs() < 1e-12, "{q1}");
    // The same export with a step its positions do not agree with, or a position moved by a
    // step: non-uniform, and the spectrum's refusal says why.
    let text = std::fs::read(common::sample("dektak-1.csv")).unwrap();
    let text = String::from_utf8_lossy(&text).into_owned();
    std::fs::write(d.join("other-step.csv"), text.replace("Resolution,0.156 um", "Resolution,0.150 um")).unwrap();
    let e = refusal(&["topo", "psd", "other-step.csv"], d);
    assert!(e.contains("not uniform") && e.contains("the header states a step of 0.15,"), "{e}");
    std::fs::write(d.join("moved.csv"), text.replace("\n1.1,0.00044", "\n1.2,0.00044")).unwrap();
    let e = refusal(&["topo", "psd", "moved.csv"], d);
    assert!(e.contains("not uniform") && e.contains("point 8 lies"), "{e}");
}

/// `--detrend` levels a profile as one scan line: numpy's `polyfit` residuals on dektak-1.csv's
/// grid, and a tilt removed exactly.
#[test]
fn a_profile_is_levelled_by_its_polynomial() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let json = |args: &[&str]| -> Value {
        let (ok, out, err) = asperity(&[&["topo", "info", "--json"], args].concat(), d);
        assert!(ok, "{args:?}: {err}");
        serde_json::from_str(&out).unwrap()
    };
    // numpy 2.4.6: h − polyval(polyfit(x, h, N), x) on the grid i · 1499.8/9599 µm, in metres:
    // its RMS (np.std), and the RMS of its forward differences over the step (N = 1).
    let dektak = data("dektak-1.csv");
    for (mode, rms) in [
        ("line:1", 9.424304890540356e-08),
        ("plane", 9.424304890540356e-08),
        ("poly:2", 3.844722287848323e-08),
        ("line:3", 1.9146848711605317e-08),
    ] {
        let got = json(&[&dektak, "--detrend", mode]);
        let r = got["rms_m"].as_f64().unwrap();
        assert!((r / rms - 1.0).abs() < 1e-9, "{mode}: {r:e} vs numpy's {rms:e}");
        assert!(got["mean_m"].as_f64().unwrap().abs() < 1e-12 * rms, "{mode}: {got}");
    }
    let slope = json(&[&dektak, "--detrend", "line:1"])["rms_slope"].as_f64().unwrap();
    assert!((slope / 0.009459698088292527 - 1.0).abs() < 1e-9, "{slope}");
    // A tilt of 1 µm over 4 µm on a roughness of ±1 nm in the pattern +, −, −, + (orthogonal to
    // a line on every four points): line:1 leaves the roughness, rms 1 nm, exactly.
    let rows: String = (0..400)
        .map(|i| {
            let x = 0.01 * f64::from(i);
            let r = [1.0, -1.0, -1.0, 1.0][(i % 4) as usize];
            format!("{x:.2} {}\n", 0.25 * x + r * 1e-3 + 7.0)
        })
        .collect();
    std::fs::write(d.join("tilted.txt"), rows).unwrap();
    let tilted = json(&["tilted.txt", "--height-unit", "um"]);
    assert!(tilted["rms_m"].as_f64().unwrap() > 100e-9, "{tilted}");
    let level = json(&["tilted.txt", "--height-unit", "um", "--detrend", "line:1"]);
    let r = level["rms_m"].as_f64().unwrap();
    assert!((r - 1e-9).abs() < 1e-9 * 1e-9, "rms {r:e} m, not 1 nm");
    // line:median shifts by the median only: the rms stays, the median becomes 0.
    let median = json(&["tilted.txt", "--height-unit", "um", "--detrend", "line:median"]);
    let (m, t) = (median["rms_m"].as_f64().unwrap(), tilted["rms_m"].as_f64().unwrap());
    assert!((m / t - 1.0).abs() < 1e-12, "{m:e} vs {t:e}");
    // The levelled profile is what topo convert writes and topo psd transforms.
    let (ok, _, err) =
        asperity(&["topo", "convert", "tilted.txt", "l.csv", "--height-unit", "um", "--detrend", "line:1"], d);
    assert!(ok, "{err}");
    assert!((json(&["l.csv"])["rms_m"].as_f64().unwrap() - 1e-9).abs() < 1e-9 * 1e-9);
    let (ok, _, err) = asperity(&["topo", "psd", "tilted.txt", "--height-unit", "um", "--detrend", "poly:2"], d);
    assert!(ok, "{err}");
    let e = refusal(&["topo", "info", "tilted.txt", "--height-unit", "um", "--detrend", "sphere"], d);
    assert!(e.starts_with("error: --detrend: ") && e.contains("a line profile is levelled by"), "{e}");
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
