//! `asperity topo convert | generate | psd`, run as the user runs them.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use asperity::output::write_npy;
use asperity::topography::io::{read, ReadOptions};
use asperity::topography::stats::{psd, Window};
use asperity::topography::synth::{Amplitude, Cap, CapShape, SelfAffine, SyntheticSurface};
use ndarray::Array2;

fn asperity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).output().expect("the binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn read_npy(path: &Path, size: (f64, f64)) -> Array2<f64> {
    read(path, &ReadOptions { physical_size: Some(size), ..Default::default() }).unwrap().heights
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn generate_writes_the_library_surface_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball.npy");
    // The library's surface as the command line gives it.
    let args = |seed: &'static str, out: &Path| {
        asperity(&[
            "topo",
            "generate",
            "--size",
            "2e-5,1.5e-5",
            "--grid",
            "96,80",
            "--hurst",
            "0.8",
            "--rms",
            "5e-9",
            "--rolloff",
            "4e-6",
            "--cutoff",
            "5e-7",
            "--sphere-radius",
            "1e-3",
            "--seed",
            seed,
            s(out),
        ])
    };
    let o = args("42", &out);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains(
            "96 × 80 points (nx × ny), physical size 2e-5 × 1.5e-5 m, which a .npy does not hold: read it back with \
             --size 2e-5,1.5e-5"
        ),
        "{}",
        stdout(&o)
    );
    let surface = SyntheticSurface {
        size: (2e-5, 1.5e-5),
        grid: (96, 80),
        roughness: Some(SelfAffine {
            hurst: 0.8,
            rolloff_wavelength: Some(4e-6),
            short_cutoff_wavelength: Some(5e-7),
            long_cutoff_wavelength: None,
            amplitude: Amplitude::RmsHeight(5e-9),
        }),
        cap: Some(Cap { radius: 1e-3, shape: CapShape::Sphere }),
        seed: 42,
    };
    let expected = surface.generate().unwrap().heights;
    let written = read_npy(&out, surface.size);
    let bits = |a: &Array2<f64>| a.iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&written), bits(&expected));

    // The same command again gives the same file; another seed another one.
    let again = dir.path().join("again.npy");
    let other = dir.path().join("other.npy");
    assert!(args("42", &again).status.success() && args("43", &other).status.success());
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    assert_ne!(std::fs::read(&out).unwrap(), std::fs::read(&other).unwrap());
}

#[test]
fn generate_to_gsf_keeps_the_size_and_float32_heights() {
    let dir = tempfile::tempdir().unwrap();
    let (npy, gsf) = (dir.path().join("s.npy"), dir.path().join("s.gsf"));
    for out in [&npy, &gsf] {
        let o = asperity(&[
            "topo",
            "generate",
            "--size",
            "3e-6,2e-6",
            "--grid",
            "48,40",
            "--hurst",
            "0.6",
            "--rms",
            "2e-9",
            "--seed",
            "5",
            s(out),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let exact = read_npy(&npy, (3e-6, 2e-6));
    // The .gsf carries its own size and unit: no options needed.
    let back = read(&gsf, &ReadOptions::default()).unwrap();
    assert_eq!(back.physical_size, Some((3e-6, 2e-6)));
    let bits = |a: &Array2<f64>| a.iter().map(|h| h.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&back.heights), bits(&exact.mapv(|h| f64::from(h as f32))));
}

#[test]
fn generate_rejects_bad_arguments_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.npy");
    let base = ["topo", "generate", "--size", "1e-5", "--grid", "32", "--seed", "1"];
    let run = |extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        asperity(&args)
    };
    // Both amplitudes: a usage error (exit 2).
    let o = run(&["--hurst", "0.8", "--rms", "1e-9", "--rms-slope", "0.1", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(stderr(&o).trim().lines().count(), 1, "{}", stderr(&o));
    for (extra, expected) in [
        (vec!["--rms", "1e-9", "--hurst", "1.5"], "error: --hurst: must lie in (0, 1], got 1.5"),
        (vec!["--hurst", "0.8", "--rms", "1e-9", "--sphere-radius", "1e-6"], "error: --sphere-radius: "),
        (vec!["--hurst", "0.8", "--rms=-1e-9"], "error: --rms: must be positive"),
    ] {
        let mut args = extra.clone();
        args.push(s(&out));
        let o = run(&args);
        assert_eq!(o.status.code(), Some(1), "{extra:?}");
        let err = stderr(&o);
        assert!(err.starts_with(expected) && err.trim().lines().count() == 1, "{extra:?}: {err}");
    }
    let o = run(&["--hurst", "0.8", "--rms", "1e-9", s(&dir.path().join("x.txt"))]);
    assert!(stderr(&o).contains("name a 2-D map *.npy"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "no output after an error");
}

/// A 40 × 30 map [nm]: a tilted plane with two missing points.
fn tilted_plane_with_holes(dir: &Path) -> PathBuf {
    let mut h = Array2::from_shape_fn((30, 40), |(j, i)| 5.0 + 0.2 * i as f64 - 0.1 * j as f64);
    h[(10, 10)] = f64::NAN;
    h[(20, 31)] = f64::NAN;
    let path = dir.join("plane.npy");
    write_npy(&path, &h).unwrap();
    path
}

#[test]
fn convert_refuses_or_fills_missing_points_and_detrends() {
    let dir = tempfile::tempdir().unwrap();
    let input = tilted_plane_with_holes(dir.path());
    let out = dir.path().join("out.npy");
    let common = ["topo", "convert", s(&input), s(&out), "--size", "4e-6,3e-6", "--height-unit", "nm"];
    let o = asperity(&common);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("plane.npy: 2 of 1200 points are missing") && err.trim().lines().count() == 1, "{err}");
    assert!(!out.exists());

    let mut args = common.to_vec();
    args.extend(["--fill-missing", "--detrend", "plane"]);
    let o = asperity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains(
            "physical size 4e-6 × 3e-6 m, which a .npy does not hold: read it back with --size 4e-6,3e-6, or write \
             .gsf, which keeps it"
        ),
        "{}",
        stdout(&o)
    );
    let h = read_npy(&out, (4e-6, 3e-6));
    assert_eq!(h.dim(), (30, 40));
    // Filled from the plane, then the plane (of order 10 nm) removed.
    assert!(h.iter().all(|v| v.abs() < 1e-20), "{h}");
}

#[test]
fn convert_crops_by_length_and_resamples() {
    let dir = tempfile::tempdir().unwrap();
    let input = tilted_plane_with_holes(dir.path());
    let out = dir.path().join("out.npy");
    // x from 1 µm to 3 µm is pixels 10..30, y from 0.3 µm to 0.9 µm rows 3..9: no hole inside.
    let o = asperity(&[
        "topo",
        "convert",
        s(&input),
        s(&out),
        "--size",
        "4e-6,3e-6",
        "--height-unit",
        "nm",
        "--crop",
        "1um:3um,300nm:900nm",
        "--pixel-size",
        "5e-8",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("40 × 12 points (nx × ny), physical size 2e-6 × 6e-7 m"), "{}", stdout(&o));
    let h = read_npy(&out, (2e-6, 6e-7));
    // The plane, resampled exactly: h(x, y) = 5 + 0.2 (x/0.1 µm) − 0.1 (y/0.1 µm) nm, from x = 1 µm, y = 0.3 µm.
    for ((j, i), v) in h.indexed_iter() {
        let expected = 1e-9 * (5.0 + 0.2 * (10.0 + 0.5 * i as f64) - 0.1 * (3.0 + 0.5 * j as f64));
        assert!((v - expected).abs() < 1e-21, "({j}, {i}): {v} vs {expected}");
    }
    let o = asperity(&["topo", "convert", s(&input), s(&out), "--size", "4e-6", "--crop", "0:10,0um:1um"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("mixes pixel indices and lengths"), "{}", stderr(&o));
}

#[test]
fn convert_reads_a_real_bare_array() {
    // The sample: a 2 × 2 float64 array with mean 3.025, here in nm.
    let sample = common::sample("example-2d.npy");
    let raw = read_npy(&sample, (1.0, 1.0));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let o = asperity(&[
        "topo",
        "convert",
        s(&sample),
        s(&out),
        "--size",
        "1e-6",
        "--height-unit",
        "nm",
        "--detrend",
        "mean",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let h = read_npy(&out, (1e-6, 1e-6));
    for (a, b) in h.iter().zip(raw.iter()) {
        assert!((a - (b - 3.025) * 1e-9).abs() < 1e-24, "{a} from {b}");
    }
    // Without a size the reader says what is missing.
    let o = asperity(&["topo", "convert", s(&sample), s(&out)]);
    assert!(stderr(&o).contains("--size"), "{}", stderr(&o));
}

#[test]
fn psd_prints_the_library_spectrum_as_csv() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.npy");
    let o = asperity(&[
        "topo",
        "generate",
        "--size",
        "1e-5",
        "--grid",
        "64",
        "--hurst",
        "0.5",
        "--rms-slope",
        "0.1",
        "--seed",
        "9",
        "--sphere-radius",
        "1e-4",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = asperity(&["topo", "psd", s(&out), "--size", "1e-5", "--window", "none"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("q_rad_per_m,psd_m4"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (q, c) = l.split_once(',').unwrap();
            (q.parse().unwrap(), c.parse().unwrap())
        })
        .collect();
    let topo = read(&out, &ReadOptions { physical_size: Some((1e-5, 1e-5)), ..Default::default() }).unwrap();
    let p = psd(&topo, Window::None).unwrap();
    assert_eq!(rows, p.q.iter().copied().zip(p.c.iter().copied()).collect::<Vec<_>>());
    // --detrend sphere reports its fit on stderr, keeping stdout CSV.
    let o = asperity(&["topo", "psd", s(&out), "--size", "1e-5", "--detrend", "sphere"]);
    assert!(o.status.success() && stderr(&o).starts_with("sphere fit: radius"), "{}", stderr(&o));
    assert!(stdout(&o).starts_with("q_rad_per_m,psd_m4\n"));
}

#[test]
fn a_crop_past_the_map_a_pixel_past_the_window_and_an_implausible_rms_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.npy");
    write_npy(&input, &Array2::from_shape_fn((16, 16), |(j, i)| 1e-9 * (i + 2 * j) as f64)).unwrap();
    let out = dir.path().join("out.npy");
    for (extra, expected) in [
        (
            &["--crop", "0um:12um,0um:5um"][..],
            "error: --crop: x1 = 1.2e-5 m lies past the map's end at 1e-5 m: give bounds within the map",
        ),
        (
            &["--pixel-size", "20um"],
            "error: --pixel-size: 2e-5 m on a 1e-5 × 1e-5 m window leaves fewer than 2 points along an axis: give \
             at most 5e-6 m",
        ),
    ] {
        let o = asperity(&[&["topo", "convert", s(&input), s(&out), "--size", "10um"][..], extra].concat());
        assert_eq!(o.status.code(), Some(1), "{extra:?}");
        assert_eq!(stderr(&o).trim_end(), expected);
        assert!(!out.exists());
    }
    // The whole map by lengths is still a crop.
    let o = asperity(&["topo", "convert", s(&input), s(&out), "--size", "10um", "--crop", "0um:10um,0um:10um"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = asperity(&[
        "topo",
        "generate",
        "--size",
        "1e-5",
        "--grid",
        "32",
        "--seed",
        "1",
        "--hurst",
        "0.8",
        "--rms",
        "1m",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).starts_with("error: --rms: "), "{}", stderr(&o));
    assert_eq!(stderr(&o).trim_end().lines().count(), 1);
}
