//! The Zygo MetroPro, Digital Surf, Alicona, Wyko OPD and Sensofar readers on real instrument
//! files (SurfaceTopography's examples, `tests/data`): grid, physical size in metres and height
//! statistics as SurfaceTopography 1.27.1 reports them, to 1e-9 relative (the manifest entries);
//! orientation pinned by single points; the header fields that flip, negate or mask heights
//! acting as the format defines them; truncated files refused in one line.

mod common;

use std::path::Path;

use asperity::topography::io::{read, read_channels, ReadOptions};
use asperity::topography::Topography;
use serde_json::Value;

/// The samples: file, format it must be detected as, points marked not measured.
const SAMPLES: &[(&str, &str, usize)] = &[
    ("metropro-1.dat", "metropro", 0),
    ("sur-2.sur", "sur", 117),
    ("sur-3.sur", "sur", 233_009),
    ("al3d-1.al3d", "al3d", 0),
    ("opd-1.opd", "opd", 116),
    ("plu-1.plu", "plu", 0),
];

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs()
}

fn entry(file: &str) -> Value {
    let manifest: Value = serde_json::from_slice(&std::fs::read(common::sample("manifest.json")).unwrap()).unwrap();
    manifest["files"].as_array().unwrap().iter().find(|e| e["file"] == file).cloned().unwrap_or_else(|| {
        panic!("{file}: no manifest entry");
    })
}

/// Mean, standard deviation, min and max of the defined heights.
fn stats(t: &Topography) -> [f64; 4] {
    let h: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
    let n = h.len() as f64;
    let mean = h.iter().sum::<f64>() / n;
    let rms = (h.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    [mean, rms, h.iter().copied().fold(f64::INFINITY, f64::min), h.iter().copied().fold(f64::NEG_INFINITY, f64::max)]
}

fn read_bytes(name: &str, bytes: &[u8]) -> Result<Topography, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    read(&path, &ReadOptions::default()).map_err(|e| e.to_string())
}

#[test]
fn samples_match_surface_topography() {
    for &(file, format, missing) in SAMPLES {
        let e = entry(file);
        let path = common::sample(file);
        let (fmt, channels) = read_channels(&path, None).unwrap_or_else(|err| panic!("{file}: {err}"));
        assert_eq!(fmt, format, "{file}: detected format");
        let names: Vec<&str> = channels.iter().map(|c| c.name.as_str()).collect();
        let want: Vec<&str> = e["channels"].as_array().unwrap().iter().map(|c| c.as_str().unwrap()).collect();
        assert_eq!(names, want, "{file}: channels");

        let t = read(&path, &ReadOptions::default()).unwrap();
        assert_eq!(t.channel, e["default_channel"].as_str().unwrap(), "{file}");
        assert_eq!((t.nx() as u64, t.ny() as u64), (e["nx"].as_u64().unwrap(), e["ny"].as_u64().unwrap()), "{file}");
        let (lx, ly) = t.physical_size.unwrap();
        let size = &e["physical_sizes_m"];
        assert!(close(lx, size[0].as_f64().unwrap(), 1e-12) && close(ly, size[1].as_f64().unwrap(), 1e-12), "{file}");
        assert_eq!(t.provenance.height_unit.as_deref(), e["height_unit_in_file"].as_str(), "{file}");
        assert!(t.height_unit_known, "{file}");
        assert_eq!(t.missing_points(), missing, "{file}: points not measured");
        for (got, key) in stats(&t).into_iter().zip(["mean_m", "rms_m", "min_m", "max_m"]) {
            let want = e[key].as_f64().unwrap();
            assert!(close(got, want, 1e-9), "{file}: {key} {got:e} vs SurfaceTopography's {want:e}");
        }
    }
}

/// Heights at (row, column) as SurfaceTopography 1.27.1 gives them (`heights().T`, in metres;
/// NaN where it masks the point): pins which way the rows and columns run.
#[test]
fn orientation_matches_surface_topography() {
    let nan = f64::NAN;
    let cases: &[(&str, &[((usize, usize), f64)])] = &[
        (
            "metropro-1.dat",
            &[
                ((0, 0), 5.05753145602552e-05),
                ((0, 639), 5.08308995810728e-05),
                ((479, 0), 5.056755638157932e-05),
                ((160, 320), 5.075044761610435e-05),
            ],
        ),
        (
            "sur-2.sur",
            &[
                ((0, 0), 1.014770011858701e-05),
                ((0, 562), 1.0113900118192021e-05),
                ((483, 0), 1.0127500118350953e-05),
                ((483, 562), nan),
            ],
        ),
        ("sur-3.sur", &[((0, 0), nan), ((256, 170), 0.006954876803302645), ((170, 256), nan)]),
        (
            "al3d-1.al3d",
            &[
                ((0, 0), 0.07635815441608429),
                ((0, 199), 0.07634570449590683),
                ((295, 0), 0.07633679360151291),
                ((98, 100), 0.07634462416172028),
            ],
        ),
        (
            "opd-1.opd",
            &[
                ((0, 0), -2.6550621614908414e-07),
                ((0, 639), -2.5646328900066876e-07),
                ((479, 0), -2.8399285465906725e-07),
                ((160, 320), -2.746491716046585e-07),
            ],
        ),
        (
            "plu-1.plu",
            &[
                ((0, 0), -0.0001112265625),
                ((0, 767), -0.00010144921874999999),
                ((575, 0), -0.00011106640625),
                ((192, 384), -0.00010626171874999999),
            ],
        ),
    ];
    for (file, points) in cases {
        let t = read(&common::sample(file), &ReadOptions::default()).unwrap();
        for &((r, c), want) in *points {
            let got = t.heights[[r, c]];
            assert!(
                got.is_nan() == want.is_nan() && (want.is_nan() || close(got, want, 1e-12)),
                "{file} [{r}, {c}]: {got:e} vs {want:e}"
            );
        }
    }
}

/// Digital Surf's header fields acting on the real sur-2.sur: `inversion` negates (1), mirrors
/// the columns (2) or the rows (3); without `special_points` no value is a missing point.
#[test]
fn sur_inversion_and_special_points() {
    let bytes = std::fs::read(common::sample("sur-2.sur")).unwrap();
    let plain = read(&common::sample("sur-2.sur"), &ReadOptions::default()).unwrap();
    let with = |at: usize, v: u16| {
        let mut b = bytes.clone();
        b[at..at + 2].copy_from_slice(&v.to_le_bytes());
        read_bytes("case.sur", &b).unwrap()
    };
    let (ny, nx) = plain.heights.dim();
    let same = |a: f64, b: f64| (a.is_nan() && b.is_nan()) || a == b;
    for (inversion, map) in [
        (1u16, (|r, c, _, _| (r, c)) as fn(usize, usize, usize, usize) -> (usize, usize)),
        (2, |r, c, _, nx| (r, nx - 1 - c)),
        (3, |r, c, ny, _| (ny - 1 - r, c)),
    ] {
        let t = with(290, inversion);
        for (r, c) in [(0, 0), (0, nx - 1), (ny - 1, 0), (100, 200), (ny - 1, nx - 1)] {
            let (rr, cc) = map(r, c, ny, nx);
            assert!(same(t.heights[[rr, cc]], -plain.heights[[r, c]]), "inversion {inversion} at [{r}, {c}]");
        }
    }
    let t = with(86, 0);
    assert_eq!(t.missing_points(), 0);
    // The 117 points become the stored value zmin − 2, times the height scale.
    let min = stats(&plain)[2];
    assert!(t.heights.iter().filter(|h| **h < min).count() == 117);
}

/// MetroPro's `sign` negates the heights; a phase value of 2147483640 or more is not measured.
#[test]
fn metropro_sign_and_invalid_phase() {
    let mut bytes = std::fs::read(common::sample("metropro-1.dat")).unwrap();
    let plain = read(&common::sample("metropro-1.dat"), &ReadOptions::default()).unwrap();
    bytes[232..234].copy_from_slice(&1i16.to_be_bytes());
    // The phase data start after the 834-byte header and the 640 × 480 16-bit intensities.
    let phase = 834 + 2 * 640 * 480;
    bytes[phase..phase + 4].copy_from_slice(&2_147_483_640i32.to_be_bytes());
    let t = read_bytes("case.dat", &bytes).unwrap();
    assert!(t.heights[[0, 0]].is_nan() && t.missing_points() == 1);
    assert_eq!(t.heights[[0, 1]], -plain.heights[[0, 1]]);
    assert_eq!(t.heights[[479, 639]], -plain.heights[[479, 639]]);
}

/// Detected by content under any name (the Sensofar format, which has no magic, by its
/// extension); a truncated file is refused in one line naming the file.
#[test]
fn detection_and_truncation() {
    for &(file, format, _) in SAMPLES {
        let bytes = std::fs::read(common::sample(file)).unwrap();
        if format != "plu" {
            let t = read_bytes("scan.bin", &bytes).unwrap_or_else(|e| panic!("{file} as scan.bin: {e}"));
            assert_eq!(t.provenance.format, format);
        }
        let name = Path::new(file).file_name().unwrap().to_str().unwrap();
        // The heights end the MetroPro and Digital Surf files; the others go on with images or
        // metadata: a cut inside their heights (opd-1's Raw block spans bytes 24 020–1 252 826).
        let inside = match format {
            "metropro" | "sur" => bytes.len() - 1,
            "opd" => 1_000_000,
            _ => bytes.len() / 2,
        };
        for keep in [inside, 600, 100] {
            let err = read_bytes(name, &bytes[..keep]).expect_err(file);
            assert!(!err.contains('\n') && err.contains(name), "{file} cut at {keep}: {err}");
            assert!(err.contains("truncated") || err.contains("too few"), "{file} cut at {keep}: {err}");
        }
    }
}
