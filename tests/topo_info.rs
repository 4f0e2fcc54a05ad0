//! `asperity topo info` reproduces every entry of the instrument samples' manifest: sizes to
//! 1e-6 relative, statistics to 1e-4 relative, channels, default channel, height unit, missing
//! points; files marked `expect: error` are refused with one line naming the file; line
//! profiles' length, RMS height and RMS slope to 1e-9 relative of SurfaceTopography's.
//!
//! Every entry is checked and every failure reported together.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn topo_info(file: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "info"])
        .arg(file)
        .args(extra)
        .arg("--json")
        .output()
        .expect("the asperity binary runs")
}

/// Differences between `got` and `want` within relative `tol`, as messages.
fn compare_number(what: &str, got: &Value, want: &Value, tol: f64, errors: &mut Vec<String>) {
    match (got.as_f64(), want.as_f64()) {
        (Some(g), Some(w)) if (g - w).abs() <= tol * w.abs() => {}
        _ => errors.push(format!("{what}: got {got}, want {want} (to {tol:e} relative)")),
    }
}

fn compare_equal(what: &str, got: &Value, want: &Value, errors: &mut Vec<String>) {
    if got != want {
        errors.push(format!("{what}: got {got}, want {want}"));
    }
}

/// Run `topo info` and check its JSON against the statistics the manifest gives.
fn check_read(file: &Path, extra: &[&str], errors: &mut Vec<String>) -> Option<Value> {
    let out = topo_info(file, extra);
    if !out.status.success() {
        errors.push(format!("refused: {}", String::from_utf8_lossy(&out.stderr).trim()));
        return None;
    }
    match serde_json::from_slice::<Value>(&out.stdout) {
        Ok(v) => Some(v),
        Err(e) => {
            errors.push(format!("stdout is not JSON: {e}"));
            None
        }
    }
}

/// A line profile's entry: what SurfaceTopography reports for it, in the file's length unit,
/// reproduced to 1e-9 relative in metres (read with the entry's `read_with` options) and, for a
/// file that states no unit, as stored without them.
fn check_profile(entry: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    let file = common::sample(entry["file"].as_str().expect("entries name their file"));
    let st = &entry["surface_topography"];
    let scale = entry["metres_per_unit"].as_f64().expect("profile entries give their unit");
    let options: Vec<&str> = entry["read_with"].as_array().unwrap().iter().map(|o| o.as_str().unwrap()).collect();
    let scaled = |v: &Value, s: f64| v.as_f64().map_or(Value::Null, |v| Value::from(v * s));
    let compare = |what: &str, got: &Value, want: &Value, errors: &mut Vec<String>| match want {
        Value::Null => compare_equal(what, got, want, errors),
        _ => compare_number(what, got, want, 1e-9, errors),
    };
    let Some(got) = check_read(&file, &options, &mut errors) else { return errors };
    compare_equal("kind", &got["kind"], &Value::from("profile"), &mut errors);
    compare_equal("points", &got["points"], &st["nb_grid_pts"][0], &mut errors);
    compare_equal("height_unit_known", &got["height_unit_known"], &Value::Bool(true), &mut errors);
    let grid = &entry["on_stated_grid"];
    if grid.is_object() {
        // Read on the grid its header states, where SurfaceTopography takes the rounded positions.
        compare_equal("uniform", &got["uniform"], &Value::Bool(true), &mut errors);
        compare("step_m", &got["step_m"], &scaled(&grid["step"], scale), &mut errors);
        compare("length_m", &got["length_m"], &scaled(&grid["length"], scale), &mut errors);
        compare("mean_m", &got["mean_m"], &scaled(&grid["mean"], scale), &mut errors);
        compare("rms_m", &got["rms_m"], &scaled(&grid["rms_height"], scale), &mut errors);
        compare("rms_slope", &got["rms_slope"], &grid["rms_slope"], &mut errors);
        return errors;
    }
    compare_equal("uniform", &got["uniform"], &st["is_uniform"], &mut errors);
    compare("length_m", &got["length_m"], &scaled(&st["physical_sizes"][0], scale), &mut errors);
    compare("mean_m", &got["mean_m"], &scaled(&st["mean"], scale), &mut errors);
    compare("rms_m", &got["rms_m"], &scaled(&st["rms_height_from_profile"], scale), &mut errors);
    compare("rms_slope", &got["rms_slope"], &st["rms_slope_from_profile"], &mut errors);
    if entry["position_unit_in_file"].is_null() && entry["height_unit_in_file"].is_null() {
        // Without a unit: the values as stored, and no slope (the two units might differ).
        let Some(got) = check_read(&file, &[], &mut errors) else { return errors };
        compare("length", &got["length"], &st["physical_sizes"][0], &mut errors);
        compare("rms", &got["rms"], &st["rms_height_from_profile"], &mut errors);
        for key in ["length_m", "rms_m", "rms_slope"] {
            compare_equal(key, &got[key], &Value::Null, &mut errors);
        }
    }
    errors
}

fn check_entry(entry: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    let name = entry["file"].as_str().expect("entries name their file");
    let file = common::sample(name);
    if entry["kind"] == "profile" {
        return check_profile(entry);
    }

    if entry["expect"] == "error" {
        let out = topo_info(&file, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        if out.status.success() {
            errors.push("read, but must be refused".into());
        } else if stderr.trim_end().lines().count() != 1 || !stderr.contains(name) {
            errors.push(format!("refusal is not one line naming the file: {stderr:?}"));
        }
        return errors;
    }

    if let Some(shape) = entry.get("array_shape") {
        // A bare array: refused without a size, read with one.
        let out = topo_info(&file, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        if out.status.success() || stderr.trim_end().lines().count() != 1 || !stderr.contains(name) {
            errors.push(format!("without --size: not refused in one line naming the file: {stderr:?}"));
        }
        if let Some(got) = check_read(&file, &["--size", "1e-6,2e-6"], &mut errors) {
            compare_equal("nx", &got["nx"], &shape[1], &mut errors);
            compare_equal("ny", &got["ny"], &shape[0], &mut errors);
            for (key, want) in [("mean_m", "mean"), ("rms_m", "std"), ("min_m", "min"), ("max_m", "max")] {
                compare_number(key, &got[key], &entry[want], 1e-4, &mut errors);
            }
            compare_number("physical_size_m[1]", &got["physical_size_m"][1], &Value::from(2e-6), 1e-12, &mut errors);
        }
        return errors;
    }

    let Some(got) = check_read(&file, &[], &mut errors) else { return errors };
    compare_equal("nx", &got["nx"], &entry["nx"], &mut errors);
    compare_equal("ny", &got["ny"], &entry["ny"], &mut errors);
    match entry.get("physical_sizes_m") {
        Some(want) => {
            for i in 0..2 {
                let what = format!("physical_size_m[{i}]");
                compare_number(&what, &got["physical_size_m"][i], &want[i], 1e-6, &mut errors);
            }
        }
        None => compare_equal("physical_size_m", &got["physical_size_m"], &Value::Null, &mut errors),
    }
    compare_equal("channels", &got["channels"], &entry["channels"], &mut errors);
    compare_equal("channel", &got["channel"], &entry["default_channel"], &mut errors);
    compare_equal("height_unit", &got["height_unit"], &entry["height_unit_in_file"], &mut errors);
    let missing = got["missing_points"].as_u64().is_some_and(|n| n > 0);
    compare_equal("has missing points", &Value::from(missing), &entry["has_missing_points"], &mut errors);
    // A file that states no height unit is never read as metres: its statistics are the
    // values as stored, without the `_m`.
    let known = !entry["height_unit_in_file"].is_null();
    compare_equal("height_unit_known", &got["height_unit_known"], &Value::from(known), &mut errors);
    for key in ["mean_m", "rms_m", "min_m", "max_m"] {
        let got_key = if known { key } else { key.trim_end_matches("_m") };
        compare_number(got_key, &got[got_key], &entry[key], 1e-4, &mut errors);
        if !known && !got[key].is_null() {
            errors.push(format!("{key} given although the height unit is unknown"));
        }
    }
    errors
}

#[test]
fn every_manifest_entry_is_reproduced() {
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).expect("manifest.json is readable"))
            .expect("manifest.json is JSON");
    let entries = manifest["files"].as_array().expect("the manifest lists files");
    assert!(entries.len() >= 20, "the manifest lists {} files", entries.len());
    let failures: Vec<String> = entries
        .iter()
        .filter_map(|entry| {
            let errors = check_entry(entry);
            (!errors.is_empty()).then(|| format!("{}:\n    {}", entry["file"], errors.join("\n    ")))
        })
        .collect();
    assert!(failures.is_empty(), "{} of {} entries fail:\n{}", failures.len(), entries.len(), failures.join("\n"));
}

#[test]
fn options_act_as_documented() {
    let run = |file: &str, extra: &[&str]| {
        let out = topo_info(&common::sample(file), extra);
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        (out.status.success(), serde_json::from_slice::<Value>(&out.stdout).unwrap_or(Value::Null), stderr)
    };
    // A unit for a file that states none scales its heights; one that states its own refuses it.
    let (ok, got, _) = run("xyz-1.txt", &["--height-unit", "nm", "--size", "4e-6"]);
    assert!(ok);
    assert_eq!(got["height_unit"], "nm");
    assert_eq!(got["max_m"].as_f64(), Some(2e-9));
    assert_eq!(got["physical_size_m"], serde_json::json!([4e-6, 4e-6]));
    let (ok, _, stderr) = run("matrix-6.txt", &["--height-unit", "nm"]);
    assert!(!ok && stderr.starts_with("error: --height-unit: ") && stderr.contains("matrix-6.txt states its own"));
    // A size contradicting the file's, an unknown channel, a forced format.
    let (ok, _, stderr) = run("sdf-1.sdf", &["--size", "1e-6"]);
    assert!(!ok && stderr.contains("does not match the size 0.000007,0.000004 m"), "{stderr}");
    let (ok, _, stderr) = run("wafer-roughness.gsf", &["--channel", "Phase"]);
    assert!(!ok && stderr.contains("no channel 'Phase' (channels: 'Height')"), "{stderr}");
    let (ok, got, _) = run("matrix-3.txt", &["--format", "matrix"]);
    assert!(ok && got["format"] == "matrix" && got["nx"] == 256);
    let (ok, _, stderr) = run("matrix-3.txt", &["--format", "xyz"]);
    assert!(!ok && stderr.lines().count() == 1 && stderr.contains("not the 3 of an x y z point"), "{stderr}");
}

#[test]
fn summary_states_units() {
    let out = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "info"])
        .arg(common::sample("matrix-3.txt"))
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("256 × 256 points"), "{text}");
    assert!(text.contains("10.00 µm × 10.00 µm (pixel 39.06 nm × 39.06 nm)"), "{text}");
    assert!(text.contains("rms          35.22 nm"), "{text}");
}

#[test]
fn line_levelling_gives_the_statistics_of_the_surface_without_its_lines_offsets_and_tilts() {
    let dir = tempfile::tempdir().unwrap();
    let (nx, ny) = (64, 48);
    let surface = ndarray::Array2::from_shape_fn((ny, nx), |(j, i)| {
        1e-9 * ((0.37 * i as f64).sin() * (0.21 * j as f64).cos() + 0.4 * (0.11 * (i + 2 * j) as f64).sin())
    });
    // Each scan line with an offset and a tilt of its own, a hundred times the roughness.
    let scanned = ndarray::Array2::from_shape_fn((ny, nx), |(j, i)| {
        let (a, b) = ((j as f64 * 1.7).sin() * 1e-7, (j as f64 * 0.9).cos() * 2e-9);
        surface[[j, i]] + a + b * i as f64
    });
    let write = |name: &str, a: &ndarray::Array2<f64>| {
        let path = dir.path().join(name);
        ndarray_npy::write_npy(&path, a).unwrap();
        path
    };
    let (flat, lines) = (write("flat.npy", &surface), write("lines.npy", &scanned));
    let rms = |file: &Path, detrend: &str| {
        let out = topo_info(file, &["--size", "1e-6", "--detrend", detrend]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<Value>(&out.stdout).unwrap()["rms_m"].as_f64().unwrap()
    };
    for mode in ["line:1", "line:1,plane", "line:2"] {
        let (got, want) = (rms(&lines, mode), rms(&flat, mode));
        assert!((got - want).abs() <= 1e-12 * want, "{mode}: {got:e} vs {want:e}");
    }
    // Without it the offsets dominate; a plane alone leaves them.
    assert!(rms(&lines, "none") > 50.0 * rms(&flat, "line:1"));
    assert!(rms(&lines, "plane") > 50.0 * rms(&flat, "line:1"));
    // A line profile is levelled as one scan line; a whole-map step after it is refused in one line.
    let out = topo_info(&common::sample("xy-1.txt"), &["--height-unit", "um", "--detrend", "line:1,plane"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.lines().count() == 1 && stderr.contains("whole-map step"), "{stderr}");
}
