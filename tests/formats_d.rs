//! The Digital Surf Mountains `.mnt` and Bruker Dektak `.opdx` readers on real files of
//! SurfaceTopography's examples (`tests/data`): grid, physical size in metres, points not
//! measured, heights (mean, rms, min, max) and single points (the orientation) to 1e-9 relative
//! of what SurfaceTopography 1.27.1 reports, as the manifest records it; damaged and hostile
//! files refused in one line naming the file; and the stylus profile of `container-2.zip`,
//! whose positions are printed with six decimals, uniform as SurfaceTopography reads it.

mod common;

use std::path::{Path, PathBuf};

use asperity::topography::io::{read, read_any, ReadOptions};
use asperity::topography::stats::{profile_height, profile_rms_slope};
use asperity::topography::AnyTopography;
use serde_json::Value;

fn entry(file: &str) -> Value {
    let manifest: Value = serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).unwrap()).unwrap();
    manifest["files"].as_array().unwrap().iter().find(|e| e["file"] == file).unwrap_or_else(|| panic!("{file}")).clone()
}

fn close(got: f64, want: f64) -> bool {
    (got - want).abs() <= 1e-9 * want.abs() || (got.is_nan() && want.is_nan())
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// An error on one line that names the file.
fn refused(path: &Path) -> String {
    let e = read_any(path, &ReadOptions::default()).map(|_| ()).expect_err(&path.display().to_string()).to_string();
    assert!(!e.contains('\n') && e.contains(&*path.file_name().unwrap().to_string_lossy()), "{e}");
    e
}

#[test]
fn mountains_documents_match_surface_topography() {
    for file in ["mnt-1.mnt", "mnt-2.mnt"] {
        let e = entry(file);
        let t = read(&common::sample(file), &ReadOptions::default()).unwrap_or_else(|err| panic!("{file}: {err}"));
        assert_eq!(t.provenance.format, "mnt", "{file}");
        assert_eq!(t.channel, e["default_channel"].as_str().unwrap(), "{file}");
        assert_eq!(t.provenance.height_unit.as_deref(), Some("µm"), "{file}");
        assert!(t.height_unit_known, "{file}");
        assert_eq!((t.nx() as u64, t.ny() as u64), (e["nx"].as_u64().unwrap(), e["ny"].as_u64().unwrap()), "{file}");
        let (lx, ly) = t.physical_size.unwrap();
        let size = &e["physical_sizes_m"];
        assert!(close(lx, size[0].as_f64().unwrap()) && close(ly, size[1].as_f64().unwrap()), "{file}: {lx} x {ly}");
        assert_eq!(t.missing_points() as u64, e["missing_points"].as_u64().unwrap(), "{file}: points not measured");

        let defined: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
        let n = defined.len() as f64;
        let mean = defined.iter().sum::<f64>() / n;
        let rms = (defined.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
        let min = defined.iter().copied().fold(f64::INFINITY, f64::min);
        let max = defined.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        for (what, got) in [("mean_m", mean), ("rms_m", rms), ("min_m", min), ("max_m", max)] {
            let want = e[what].as_f64().unwrap();
            assert!(close(got, want), "{file}: {what} {got:e} vs {want:e}");
        }
        let (r, c) = (t.ny() - 1, t.nx() - 1);
        let corners = [t.heights[[0, 0]], t.heights[[0, c]], t.heights[[r, 0]], t.heights[[r, c]]];
        for (got, want) in corners.iter().zip(e["corners_m"].as_array().unwrap()) {
            assert!(close(*got, want.as_f64().unwrap_or(f64::NAN)), "{file}: corners {corners:?}");
        }
        for p in e["points_m"].as_array().unwrap() {
            let (row, col) = (p[0].as_u64().unwrap() as usize, p[1].as_u64().unwrap() as usize);
            let (got, want) = (t.heights[[row, col]], p[2].as_f64().unwrap_or(f64::NAN));
            assert!(close(got, want), "{file}: ({row}, {col}) {got:e} vs {want:e}");
        }
    }
}

#[test]
fn a_dektak_opdx_profile_matches_surface_topography() {
    let path = common::sample("opdx-3.opdx");
    let st = &entry("opdx-3.opdx")["surface_topography"];
    let (any, names) = read_any(&path, &ReadOptions::default()).unwrap();
    assert_eq!(names, ["Height"]);
    let AnyTopography::Profile(p) = any else { panic!("opdx-3.opdx must read as a line profile") };
    assert_eq!((p.provenance.format.as_str(), p.provenance.height_unit.as_deref()), ("opdx", Some("µm")));
    assert!(p.position_unit_known && p.height_unit_known);
    assert_eq!((p.points() as u64, p.step().is_some()), (st["nb_grid_pts"][0].as_u64().unwrap(), true));
    let (mean, rms) = profile_height(&p).unwrap();
    for (what, got, want) in [
        ("length", p.length(), st["physical_sizes"][0].as_f64().unwrap() * 1e-6),
        ("mean", mean, st["mean"].as_f64().unwrap() * 1e-6),
        ("rms", rms, st["rms_height_from_profile"].as_f64().unwrap() * 1e-6),
        ("rms slope", profile_rms_slope(&p).unwrap(), st["rms_slope_from_profile"].as_f64().unwrap()),
    ] {
        assert!(close(got, want), "{what}: {got:e} vs SurfaceTopography's {want:e}");
    }
    // Its first and last heights, as SurfaceTopography gives them [µm].
    let h = p.heights();
    assert!(close(h[0], 0.0013718305790923332e-6) && close(h[3000], 0.014412930733025379e-6), "{} {}", h[0], h[3000]);
    // Contact's gate refuses a profile by name.
    assert!(read(&path, &ReadOptions::default()).unwrap_err().to_string().contains("line profile"));
}

#[test]
fn damaged_files_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for file in ["mnt-1.mnt", "mnt-2.mnt", "opdx-3.opdx"] {
        let bytes = std::fs::read(common::sample(file)).unwrap();
        for cut in [100, 600, bytes.len() / 2] {
            let e = refused(&write(dir.path(), file, &bytes[..cut]));
            assert!(e.contains("truncated"), "{file} cut at {cut}: {e}");
        }
    }
    // A compound file without the stream of a Mountains document (a Word file, say).
    let mut bytes = std::fs::read(common::sample("mnt-1.mnt")).unwrap();
    let name: Vec<u8> = "ScopedContents".encode_utf16().flat_map(u16::to_le_bytes).collect();
    // The directory's entry (sector 2, at 12544; an earlier copy of the name is not read).
    let at = bytes.windows(name.len()).rposition(|w| w == name).unwrap();
    assert_eq!(at, 12544);
    bytes[at] = b'X';
    let e = refused(&write(dir.path(), "other.mnt", &bytes));
    assert!(e.contains("without the stream ScopedContents"), "{e}");
    // Containers nested 40 deep: refused at the depth no Vision64 file reaches, not by the stack.
    let mut bytes = b"VCA DATA\x01\x00\x00\x55".to_vec();
    for _ in 0..40 {
        bytes.extend_from_slice(b"\x01\x00\x00\x00a\x7d\x01\x00");
    }
    let e = refused(&write(dir.path(), "deep.opdx", &bytes));
    assert!(e.contains("nested deeper"), "{e}");
}

/// Every truncation (in steps) and byte flips all along the file: a profile or a one-line error.
#[test]
fn opdx_survives_mutation() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read(common::sample("opdx-3.opdx")).unwrap();
    let mut cases = Vec::new();
    for n in (0..original.len()).step_by(97) {
        cases.push(original[..n].to_vec());
    }
    for at in (0..original.len()).step_by(53) {
        for x in [0x01, 0x80, 0xff] {
            let mut b = original.clone();
            b[at] ^= x;
            cases.push(b);
        }
    }
    for (i, bytes) in cases.iter().enumerate() {
        let path = write(dir.path(), "case.opdx", bytes);
        if let Err(e) = read_any(&path, &ReadOptions::default()) {
            let e = e.to_string();
            assert!(!e.contains('\n') && e.contains("case.opdx"), "case {i}: {e}");
        }
    }
}

#[test]
fn the_stylus_profile_printed_to_six_decimals_is_uniform() {
    // Positions 0.000000, 0.000100, 0.000199…: one grid of 0.298684 / 3000 as printed, the
    // length SurfaceTopography gives (3001 steps), not the last position.
    let path =
        PathBuf::from(format!("{}#uncd_stylus_300um_5mar_3_k0HpKJt.txt", common::sample("container-2.zip").display()));
    let opts = ReadOptions { height_unit: Some("m".into()), ..ReadOptions::default() };
    let (any, _) = read_any(&path, &opts).unwrap();
    let AnyTopography::Profile(p) = any else { panic!("a profile") };
    assert!(p.step().is_some());
    assert!(close(p.length(), 0.29878356133333334), "{}", p.length());
    let (mean, rms) = profile_height(&p).unwrap();
    assert!(close(mean, 1.4995001666117043e-08) && close(rms, 0.00032216820243188013), "{mean:e} {rms:e}");
}

/// A Gwyddion file from another project's test suite (gwyfile's), read as that project's test
/// asserts: the channel 'Test', 128 × 128, data[0][0] ≈ 0.00082494 and data[44][33] ≈
/// 0.00085301 (row, column). Its units are empty strings, so neither size nor height unit is
/// taken as metres without being told.
#[test]
fn a_gwyddion_file_of_another_project_reads_as_its_tests_assert() {
    let path = common::sample("gwyfile-test.gwy");
    let bare = read(&path, &ReadOptions::default()).unwrap();
    assert_eq!((bare.physical_size, bare.height_unit_known), (None, false));
    let options =
        ReadOptions { physical_size: Some((1e-6, 1e-6)), height_unit: Some("m".into()), ..Default::default() };
    let t = read(&path, &options).unwrap();
    assert_eq!((t.ny(), t.nx()), (128, 128));
    assert_eq!(t.channel, "Test");
    assert!((t.heights[[0, 0]] / 0.00082494 - 1.0).abs() < 1e-5, "{}", t.heights[[0, 0]]);
    assert!((t.heights[[44, 33]] / 0.00085301 - 1.0).abs() < 1e-5, "{}", t.heights[[44, 33]]);
}
