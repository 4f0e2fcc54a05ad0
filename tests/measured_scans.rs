//! A user's own scans through `asperity contact`: a tilted measured window solved as read is
//! flagged (load at the edges), levelled and capped it is not; a height unit the file does not
//! state is never taken as metres; the hardness reports the load above it.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use ndarray::Array2;
use ndarray_npy::read_npy;
use serde_json::Value;

fn asperity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `contact FILE extra… --out DIR`, expected to succeed: contact.json and stderr.
fn contact(file: &Path, extra: &[&str], out: &Path) -> (Value, String) {
    let mut args = vec!["contact", file.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let o = asperity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    (serde_json::from_str(&std::fs::read_to_string(out.join("contact.json")).unwrap()).unwrap(), stderr(&o))
}

/// The share of the load within the edge band (2 % of the points along each axis, at least
/// 2), from the pressure map itself.
fn edge_share(p: &Array2<f64>) -> f64 {
    let (ny, nx) = p.dim();
    let band = |n: usize| ((0.02 * n as f64).round() as usize).max(2);
    let (bx, by) = (band(nx), band(ny));
    let edge: f64 = p
        .indexed_iter()
        .filter(|((j, i), _)| *i < bx || *i >= nx - bx || *j < by || *j >= ny - by)
        .map(|(_, v)| *v)
        .sum();
    edge / p.sum()
}

/// `contact` at 1 mN: the edge load fraction as reported (checked against the pressure map)
/// and the warnings printed.
fn edge_fraction(file: &Path, extra: &[&str], out: &Path) -> (f64, Vec<String>) {
    let (json, err) = contact(file, &[&["--load", "1mN"][..], extra].concat(), out);
    let load = &json["loads"][0];
    let p: Array2<f64> = read_npy(out.join(load["pressure_file"].as_str().unwrap())).unwrap();
    let edge = load["edge_load_fraction"].as_f64().unwrap();
    assert!((edge - edge_share(&p)).abs() < 1e-12, "{edge} vs {}", edge_share(&p));
    assert_eq!(load["max_pressure_pa"].as_f64().unwrap(), p.iter().copied().fold(0.0, f64::max));
    let warnings: Vec<String> = err.lines().filter(|l| l.starts_with("warning: ")).map(String::from).collect();
    assert_eq!(json["warnings"].as_array().unwrap().len(), warnings.len(), "{err}");
    (edge, warnings)
}

#[test]
fn tilted_scans_are_flagged_and_clear_once_levelled_and_capped() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name);
    let level = ["--detrend", "plane", "--cap-radius", "1.5e-3"];

    // A tilted Nanosurf scan (20 µm): as read, its contact sits at an edge.
    let nid = common::sample("nid-1.nid");
    let (edge, warnings) = edge_fraction(&nid, &[], &out("nid"));
    assert!(edge > 0.01, "{edge}");
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("of the load sits within 2 % of the window's edges"), "{warnings:?}");
    assert!(warnings[0].contains("--free"), "the warning says what to do: {warnings:?}");
    for extra in [&level[..], &[&level[..], &["--free"]].concat()] {
        let (edge, warnings) = edge_fraction(&nid, extra, &out("nid-capped"));
        assert_eq!((edge, warnings.len()), (0.0, 0), "{extra:?}");
    }

    // The tilted NanoScope scan (10 µm, its Height channel) is flagged as read, and still once
    // levelled and capped: a 300 nm bump at its top-right corner outgrows the 17 nm the cap
    // lowers the corners by. Cropping the bump away clears it.
    let di = common::sample("di-3.di");
    let (edge, warnings) = edge_fraction(&di, &[], &out("di"));
    assert!(edge > 0.01 && warnings.len() == 1, "{edge}");
    let (edge, warnings) = edge_fraction(&di, &level, &out("di-capped"));
    assert!(edge > 0.01 && warnings.len() == 1, "{edge}");
    let (edge, warnings) = edge_fraction(&di, &[&level[..], &["--crop", "16:240,16:240"]].concat(), &out("di-cropped"));
    assert_eq!((edge, warnings.len()), (0.0, 0));
}

#[test]
fn hardness_reports_the_load_above_it() {
    let scan = common::sample("nid-1.nid");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hard");
    let base = ["--load", "1mN", "--detrend", "plane", "--cap-radius", "1.5mm"];
    let (json, _) = contact(&scan, &base, &dir.path().join("soft"));
    let load = &json["loads"][0];
    assert!(load.get("load_above_hardness_fraction").is_none(), "no hardness, no fraction: {load}");
    let max = load["max_pressure_pa"].as_f64().unwrap();
    // A hardness at half the largest pressure: the share of the load at p ≥ H, from the map.
    let h = format!("{}", max / 2.0);
    let (json, err) = contact(&scan, &[&base[..], &["--hardness", &h]].concat(), &out);
    let load = &json["loads"][0];
    let p: Array2<f64> = read_npy(out.join(load["pressure_file"].as_str().unwrap())).unwrap();
    let want = p.iter().filter(|v| **v >= max / 2.0).sum::<f64>() / p.sum();
    let got = load["load_above_hardness_fraction"].as_f64().unwrap();
    assert!(want > 0.0 && (got - want).abs() < 1e-12, "{got} vs {want}");
    assert_eq!(json["hardness_pa"].as_f64(), Some(max / 2.0));
    assert!(err.contains("of the load is carried at pressures at or above the material's hardness"), "{err}");
    // Above every pressure: nothing to report.
    let (json, err) = contact(&scan, &[&base[..], &["--hardness", "90GPa"]].concat(), &dir.path().join("x"));
    assert_eq!(json["loads"][0]["load_above_hardness_fraction"].as_f64(), Some(0.0));
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn an_unknown_height_unit_is_never_solved_as_metres() {
    let dir = tempfile::tempdir().unwrap();
    let matrix = dir.path().join("bare.txt");
    let rows: Vec<String> =
        (0..16).map(|j| (0..16).map(|i| format!("{}", (i * j) % 7)).collect::<Vec<_>>().join(" ")).collect();
    std::fs::write(&matrix, rows.join("\n")).unwrap();
    let out = dir.path().join("out");
    let o = asperity(&[
        "contact",
        matrix.to_str().unwrap(),
        "--size",
        "1e-6",
        "--load",
        "1e-6",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(!o.status.success() && err.trim_end().lines().count() == 1, "{err}");
    assert!(
        err.contains("bare.txt") && err.contains("states no height unit") && err.contains("--height-unit"),
        "{err}"
    );
    assert!(!out.exists());
    let (json, _) = contact(&matrix, &["--size", "1e-6", "--height-unit", "nm", "--load", "1e-6", "--free"], &out);
    assert_eq!(json["grid"], serde_json::json!([16, 16]));

    // Values in radians with no factor to metres are refused; with one they are heights.
    let phase = dir.path().join("phase.txt");
    std::fs::write(&phase, format!("h=16 w=16\npixel size=1e-007 m\ndata unit=rad\n{}", rows.join("\n"))).unwrap();
    let o = asperity(&["contact", phase.to_str().unwrap(), "--load", "1e-6", "--out", out.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(!o.status.success() && err.contains("no channel holds heights (a length unit): 'default' (rad)"), "{err}");
    // Named, the channel is read as stored, its unit kept and marked as no length.
    let info = asperity(&["topo", "info", phase.to_str().unwrap(), "--channel", "default", "--json"]);
    let info: Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!((info["height_unit"].as_str(), info["height_unit_known"].as_bool()), (Some("rad"), Some(false)));
    assert!(info.get("rms_m").is_none() && info["rms"].is_number(), "{info}");
    let converted = dir.path().join("converted.txt");
    std::fs::write(
        &converted,
        format!(
            "h=16 w=16\npixel size=1e-007 m\ndata unit=rad\nheight conversion factor (-> m)=5e-008\n{}",
            rows.join("\n")
        ),
    )
    .unwrap();
    let info = asperity(&["topo", "info", converted.to_str().unwrap(), "--json"]);
    let info: Value = serde_json::from_slice(&info.stdout).unwrap();
    for l in info["physical_size_m"].as_array().unwrap() {
        assert!((l.as_f64().unwrap() / 1.6e-6 - 1.0).abs() < 1e-15, "{info}");
    }
    assert_eq!(info["max_m"].as_f64(), Some(6.0 * 5e-8));
}
