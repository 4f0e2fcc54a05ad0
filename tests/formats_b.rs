//! The FRT, WSxM, BCR, TrueMap and Park Systems TIFF readers against real files of SurfaceTopography's examples
//! (`tests/data`): grid, physical size, heights (mean, rms, min, max) and the four corners (the
//! orientation) to 1e-9 relative of what SurfaceTopography 1.27.1 reports, as the manifest
//! records it; the files cut short or with a header that lies are refused in one line naming
//! the file. (The HFM profile's entry is checked by `topo_info`, to 1e-9 relative.)

mod common;

use asperity::topography::io::{read, read_any, ReadOptions};
use asperity::topography::AnyTopography;
use serde_json::Value;

/// The manifest entries of these formats, with the format each must be detected as.
const FILES: &[(&str, &str)] = &[
    ("frt-2.frt", "frt"),
    ("stp-1.stp", "wsxm"),
    ("top-1.top", "wsxm"),
    ("bcrf-1.bcrf", "bcr"),
    ("tmd-1.tmd", "tmd"),
    ("example_ps.tiff", "ps"),
];

fn entry(file: &str) -> Value {
    let manifest: Value = serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).unwrap()).unwrap();
    manifest["files"].as_array().unwrap().iter().find(|e| e["file"] == file).unwrap_or_else(|| panic!("{file}")).clone()
}

fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= 1e-9 * want.abs() || (got.is_nan() && want.is_nan())
}

#[test]
fn samples_match_surface_topography() {
    for (file, format) in FILES {
        let e = entry(file);
        let t = read(&common::sample(file), &ReadOptions::default()).unwrap_or_else(|err| panic!("{file}: {err}"));
        assert_eq!(t.provenance.format, *format, "{file}: detected format");
        assert_eq!(t.channel, e["default_channel"].as_str().unwrap(), "{file}: channel");
        assert_eq!(t.provenance.height_unit.as_deref(), e["height_unit_in_file"].as_str(), "{file}: height unit");
        assert_eq!((t.nx() as u64, t.ny() as u64), (e["nx"].as_u64().unwrap(), e["ny"].as_u64().unwrap()), "{file}");
        let (lx, ly) = t.physical_size.unwrap();
        let size = &e["physical_sizes_m"];
        assert!(close(lx, size[0].as_f64().unwrap()) && close(ly, size[1].as_f64().unwrap()), "{file}: {lx} x {ly}");
        assert_eq!(t.missing_points() > 0, e["has_missing_points"].as_bool().unwrap(), "{file}: missing points");

        let defined: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
        let n = defined.len() as f64;
        let mean = defined.iter().sum::<f64>() / n;
        let rms = (defined.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
        let min = defined.iter().copied().fold(f64::INFINITY, f64::min);
        let max = defined.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        for (what, got) in [("mean_m", mean), ("rms_m", rms), ("min_m", min), ("max_m", max)] {
            let want = e[what].as_f64().unwrap();
            // A mean of zero (a levelled image) is round-off: it is compared on the scale of the rms.
            let scale = if what == "mean_m" { want.abs().max(e["rms_m"].as_f64().unwrap()) } else { want.abs() };
            assert!((got - want).abs() <= 1e-9 * scale, "{file}: {what} {got:e} vs {want:e}");
        }
        let (r, c) = (t.ny() - 1, t.nx() - 1);
        let corners = [t.heights[[0, 0]], t.heights[[0, c]], t.heights[[r, 0]], t.heights[[r, c]]];
        for (got, want) in corners.iter().zip(e["corners_m"].as_array().unwrap()) {
            assert!(
                close(*got, want.as_f64().unwrap_or(f64::NAN)),
                "{file}: corners {corners:?} vs {}",
                e["corners_m"]
            );
        }
    }
}

#[test]
fn the_hfm_profile_is_a_profile_in_millimetres() {
    let (any, names) = read_any(&common::sample("hfm-1.hfm"), &ReadOptions::default()).unwrap();
    assert_eq!(names, ["Y"]);
    let AnyTopography::Profile(p) = any else { panic!("hfm-1.hfm must read as a line profile") };
    assert_eq!((p.provenance.format.as_str(), p.points()), ("hfm", 9600));
    assert!((p.length() - 4.8e-3).abs() <= 1e-9 * 4.8e-3, "length {}", p.length());
    // A map reader refuses it, naming it a profile.
    let e = read(&common::sample("hfm-1.hfm"), &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("a line profile"), "{e}");
}

/// Each sample cut in its header, in its data and by one byte, and with a grid declared larger
/// than the file holds: refused in one line that names the file and says it is truncated or
/// inconsistent.
#[test]
fn damaged_samples_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for (file, _) in FILES {
        let bytes = std::fs::read(common::sample(file)).unwrap();
        // The TIFF's preview image comes last and is not read: its cut end is no damage.
        let last = if file.ends_with(".tiff") { 1_051_196 } else { bytes.len() - 1 };
        for cut in [100, bytes.len() / 2, last] {
            let path = dir.path().join(file);
            std::fs::write(&path, &bytes[..cut]).unwrap();
            let err = read(&path, &ReadOptions::default()).expect_err(file).to_string();
            assert!(!err.contains('\n') && err.contains(file), "{file} cut at {cut}: {err}");
            assert!(err.contains("truncated") || err.contains("holds"), "{file} cut at {cut}: {err}");
        }
    }
}
