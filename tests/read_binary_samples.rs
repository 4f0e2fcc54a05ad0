//! The binary instrument readers against the real files of `tests/data`: every
//! manifest entry in a binary format (NanoScope, Igor, Nanosurf, PicoView, Gwyddion, x3p)
//! is reproduced, and the files marked `expect: error` are refused with a one-line reason.

mod common;

use std::path::Path;

use asperity::topography::io::{read, read_channels, ReadOptions};
use serde_json::Value;

/// File endings of the binary formats, with the registry name each must be detected as.
const BINARY: &[(&str, &str)] =
    &[("di", "nanoscope"), ("ibw", "ibw"), ("nid", "nid"), ("mi", "mi"), ("gwy", "gwy"), ("x3p", "x3p")];

/// The manifest entries of binary files, with the format each must be detected as.
fn binary_entries() -> Vec<(Value, &'static str)> {
    let manifest: Value = serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).unwrap()).unwrap();
    manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| {
            let ext = Path::new(e["file"].as_str()?).extension()?.to_str()?.to_ascii_lowercase();
            BINARY.iter().find(|(x, _)| *x == ext).map(|(_, f)| (e.clone(), *f))
        })
        .collect()
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs().max(f64::MIN_POSITIVE)
}

#[test]
fn manifest_entries_are_reproduced() {
    let entries = binary_entries();
    let readable: Vec<_> = entries.iter().filter(|(e, _)| e["expect"] != "error").collect();
    // di-1..4, the ibw, nid, x3p, mi and gwy samples: the test must not pass on an empty list.
    assert_eq!(readable.len(), 9, "binary samples in the manifest");
    for (e, format) in readable {
        let file = e["file"].as_str().unwrap();
        let path = common::sample(file);
        let (fmt, channels) = read_channels(&path, None).unwrap_or_else(|err| panic!("{file}: {err}"));
        assert_eq!(fmt, *format, "{file}: detected format");
        let names: Vec<&str> = channels.iter().map(|c| c.name.as_str()).collect();
        let want: Vec<&str> = e["channels"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
        assert_eq!(names, want, "{file}: channels");

        let t = read(&path, &ReadOptions::default()).unwrap_or_else(|err| panic!("{file}: {err}"));
        assert_eq!(t.channel, e["default_channel"].as_str().unwrap(), "{file}: default channel");
        assert_eq!(t.provenance.format, *format);
        assert_eq!(t.nx() as u64, e["nx"].as_u64().unwrap(), "{file}: nx");
        assert_eq!(t.ny() as u64, e["ny"].as_u64().unwrap(), "{file}: ny");
        match e.get("physical_sizes_m") {
            Some(s) => {
                let (lx, ly) = t.physical_size.unwrap_or_else(|| panic!("{file}: no physical size"));
                assert!(close(lx, s[0].as_f64().unwrap(), 1e-6), "{file}: lx {lx} vs {}", s[0]);
                assert!(close(ly, s[1].as_f64().unwrap(), 1e-6), "{file}: ly {ly} vs {}", s[1]);
            }
            None => assert_eq!(t.physical_size, None, "{file}: the file states no size"),
        }
        assert_eq!(t.provenance.height_unit.as_deref(), e["height_unit_in_file"].as_str(), "{file}: height unit");

        let missing = t.missing_points();
        assert_eq!(missing > 0, e["has_missing_points"].as_bool().unwrap(), "{file}: missing points");
        let defined: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
        let n = defined.len() as f64;
        let mean = defined.iter().sum::<f64>() / n;
        let rms = (defined.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
        let min = defined.iter().copied().fold(f64::INFINITY, f64::min);
        let max = defined.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        for (what, got, key) in
            [("mean", mean, "mean_m"), ("rms", rms, "rms_m"), ("min", min, "min_m"), ("max", max, "max_m")]
        {
            let want = e[key].as_f64().unwrap();
            assert!(close(got, want, 1e-4), "{file}: {what} {got:e} vs {want:e}");
        }
    }
}

#[test]
fn files_marked_error_are_refused_in_one_line() {
    let errors: Vec<_> = binary_entries().into_iter().filter(|(e, _)| e["expect"] == "error").collect();
    assert!(!errors.is_empty());
    for (e, _) in errors {
        let file = e["file"].as_str().unwrap();
        let err = read(&common::sample(file), &ReadOptions::default()).expect_err(file).to_string();
        assert!(!err.contains('\n'), "{file}: multi-line error {err:?}");
        assert!(err.contains(file), "{file}: the error names the file: {err}");
        assert!(err.contains("truncated"), "{file}: the reason says what is wrong: {err}");
    }
}

/// Pixel values at the corners of the default channel, as SurfaceTopography 1.x reads them
/// (its `heights().T`, rows top first as Gwyddion shows them): pins the orientation.
#[test]
fn orientation_matches_gwyddion() {
    let cases: &[(&str, [f64; 4])] = &[
        ("di-1.di", [6.059980111183002e-09, -9.740178655504912e-09, 2.8431591669378123e-09, -3.030637489364063e-08]),
        ("di-3.di", [5.6401630244078e-07, 1.271481837872279e-07, 6.43150486755908e-08, -6.164760426047413e-07]),
        (
            "nid-1.nid",
            [-9.253918035998941e-07, -1.7202278458178043e-06, -1.2321653798371554e-06, -1.982578380569816e-06],
        ),
        ("mi-1.mi", [-4.986900329589845e-07, -5.981623077392578e-07, -5.122423553466797e-07, -6.289871978759767e-07]),
        (
            "si-ball-roughness.gwy",
            [-5.365768854699441e-09, 5.647449179743057e-09, -1.9209035197942668e-09, 4.601261227944038e-09],
        ),
        ("x3p-2.x3p", [6.579781341223288e-08, -4.133318658776711e-08, 9.597611341223287e-08, -3.276918658776711e-08]),
        // Igor stores x fastest: the step between 1 and 2 lies along each row.
        ("10x10-one_channel_without_name.ibw", [1.0, 2.0, 1.0, 2.0]),
    ];
    for (file, [top_left, top_right, bottom_left, bottom_right]) in cases {
        // di-3's default is now its Height channel; SurfaceTopography's first is ZSensor.
        let channel = (*file == "di-3.di").then(|| "ZSensor".to_string());
        let t = read(&common::sample(file), &ReadOptions { channel, ..ReadOptions::default() }).unwrap();
        let (ny, nx) = (t.ny() - 1, t.nx() - 1);
        for (got, want) in [
            (t.heights[[0, 0]], top_left),
            (t.heights[[0, nx]], top_right),
            (t.heights[[ny, 0]], bottom_left),
            (t.heights[[ny, nx]], bottom_right),
        ] {
            assert!(close(got, *want, 1e-9), "{file}: {got:e} vs {want:e}");
        }
    }
}
