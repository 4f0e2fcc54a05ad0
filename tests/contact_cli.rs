//! `asperity contact` as users run it: the output contract and one-line errors on bad input.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use ndarray::Array2;
use ndarray_npy::{read_npy, write_npy};

fn asperity(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).output().unwrap()
}

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas/heights.npy")
}

/// Runs `contact` on the fixture with `loads` into `out`, expects success, returns contact.json.
fn contact(loads: &[&str], out: &Path) -> serde_json::Value {
    let surface = fixture();
    let mut args = vec!["contact", surface.to_str().unwrap(), "--size", "8e-6,6e-6"];
    args.extend_from_slice(loads);
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let o = asperity(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(out.join("contact.json")).unwrap()).unwrap()
}

#[test]
fn writes_contact_json_and_one_pressure_map_per_load() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let json = contact(&["--load", "2e-3", "--load", "2e-4"], &out);
    assert_eq!(json["grid"], serde_json::json!([96, 128]));
    assert_eq!(json["physical_size_m"], serde_json::json!([8e-6, 6e-6]));
    assert_eq!(json["boundary"], "periodic");
    let e_star = json["effective_modulus_pa"].as_f64().unwrap();
    assert!((e_star - 130e9 / (1.0 - 0.26 * 0.26)).abs() < 1.0);
    let loads = json["loads"].as_array().unwrap();
    assert_eq!(loads.len(), 2);
    for (entry, load) in loads.iter().zip([2e-3, 2e-4]) {
        for key in
            ["mean_pressure_pa", "contact_fraction", "contact_points", "patches", "iterations", "residual", "seconds"]
        {
            assert!(entry[key].is_number(), "{key} missing in {entry}");
        }
        assert_eq!(entry["load_n"].as_f64().unwrap(), load);
        let p: Array2<f64> = read_npy(out.join(entry["pressure_file"].as_str().unwrap())).unwrap();
        assert_eq!(p.dim(), (96, 128));
        let force = p.sum() * 8e-6 * 6e-6 / (96.0 * 128.0);
        assert!((force / load - 1.0).abs() < 1e-10);
        assert_eq!(p.iter().filter(|v| **v > 0.0).count() as u64, entry["contact_points"].as_u64().unwrap());
    }
    // The loads keep the user's numbering: the second (smaller) load is pressure-001.
    assert_eq!(loads[1]["pressure_file"], "pressure-001.npy");
    assert!(loads[1]["contact_points"].as_u64() < loads[0]["contact_points"].as_u64());
}

/// Runs `contact` with `args`, expects a failure with a one-line message containing `needle`,
/// and no output directory.
fn refused(args: &[&str], needle: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut all = vec!["contact"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--out", out.to_str().unwrap()]);
    let o = asperity(&all);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: not one line: {stderr}");
    assert!(stderr.contains(needle), "{args:?}: '{needle}' not in: {stderr}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "{args:?} left files behind");
}

#[test]
fn bad_input_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let f = fixture();
    let good = f.to_str().unwrap();
    let nan = dir.path().join("nan.npy");
    let mut h: Array2<f64> = read_npy(&f).unwrap();
    h[[3, 4]] = f64::NAN;
    write_npy(&nan, &h).unwrap();
    let inf = dir.path().join("inf.npy");
    h[[3, 4]] = f64::INFINITY;
    write_npy(&inf, &h).unwrap();
    let thin = dir.path().join("thin.npy");
    write_npy(&thin, &Array2::<f64>::zeros((1, 16))).unwrap();

    let size = ["--size", "8e-6,6e-6"];
    refused(&[nan.to_str().unwrap(), size[0], size[1], "--load", "1e-3"], "nan.npy");
    refused(&[inf.to_str().unwrap(), size[0], size[1], "--load", "1e-3"], "inf.npy");
    refused(&[good, size[0], size[1], "--load", "0"], "--load");
    refused(&[good, size[0], size[1], "--load", "1e-3,-2e-3"], "--load");
    refused(&[good, size[0], size[1], "--load", "1e-3", "--youngs", "-1e9"], "Young's modulus");
    refused(&[good, size[0], size[1], "--load", "1e-3", "--youngs", "0"], "Young's modulus");
    refused(&[good, size[0], size[1], "--load", "1e-3", "--poisson", "0.5"], "Poisson");
    refused(&[good, size[0], size[1], "--load", "1e-3", "--poisson", "-1"], "Poisson");
    // A tolerance the uniform start (residual 0.82) passes returned it after 0 iterations:
    // contact fraction 1 where the solution's is 0.02.
    refused(
        &[good, size[0], size[1], "--load", "2e-3", "--tolerance", "1"],
        "--tolerance: must lie in (0, 0.01), got 1",
    );
    refused(&[good, size[0], size[1], "--load", "2e-3", "--tolerance", "1e-2"], "--tolerance: must lie in (0, 0.01)");
    refused(&[thin.to_str().unwrap(), size[0], size[1], "--load", "1e-3"], "too small");
    refused(&[good, "--load", "1e-3"], "--size");
    // A cohesive law without a work of adhesion would be solved without adhesion.
    refused(&[good, size[0], size[1], "--load", "1e-3", "--adhesion-law", "exponential"], "--adhesion-work");
    refused(&[good, size[0], "abc", "--load", "1e-3"], "--size");
    refused(&[good, "--size", "8e-6,-6e-6", "--load", "1e-3"], "--size");
    let gsf = common::sample("wafer-roughness.gsf");
    refused(&[gsf.to_str().unwrap(), "--size", "1e-6,1e-6", "--load", "1e-3"], "does not match");
    refused(&[dir.path().join("absent.npy").to_str().unwrap(), size[0], size[1], "--load", "1e-3"], "absent.npy");
    // The fixture's heights in nanometres (rms 14 nm), taken as metres: 78 m over an 8 µm
    // window. Solved, one pixel carried the whole load at 512 GPa, without a word.
    let nm = dir.path().join("nm.npy");
    write_npy(&nm, &read_npy::<_, Array2<f64>>(&f).unwrap().mapv(|h| h * 1e9)).unwrap();
    let nm = nm.to_str().unwrap();
    refused(&[nm, size[0], size[1], "--load", "1e-3"], "nm.npy: the heights span 7.823e1 m, more than the 8.000e-6");
    refused(&[nm, size[0], size[1], "--load", "1e-3"], "give their unit with --height-unit");
    // With their unit they are the fixture.
    let out = dir.path().join("with-unit");
    let o = asperity(&[
        "contact",
        nm,
        size[0],
        size[1],
        "--height-unit",
        "nm",
        "--load",
        "1e-3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
/// 6 N on 8 × 6 µm is 0.9 E*, the most a contact of this kind is pressed (above E* a unit mistake is refused).
fn full_contact_is_a_result() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("full");
    let json = contact(&["--load", "6"], &out);
    assert_eq!(json["loads"][0]["contact_fraction"].as_f64(), Some(1.0));
}

/// `--plastic` caps the pressure at `--hardness` (here below the elastic peak of 7.4 GPa) and
/// says so in contact.json; without
/// `--hardness`, or with a hardness the window cannot carry the load at, it is refused.
#[test]
fn plastic_caps_the_pressure_at_the_hardness() {
    let dir = tempfile::tempdir().unwrap();
    let elastic = contact(&["--load", "2e-3"], &dir.path().join("elastic"));
    let out = dir.path().join("plastic");
    let json = contact(&["--load", "2e-3", "--hardness", "3GPa", "--plastic"], &out);
    assert_eq!(json["plastic"], true);
    assert_eq!(json["hardness_pa"].as_f64(), Some(3e9));
    assert_eq!(elastic["plastic"], false);
    let p: Array2<f64> = read_npy(out.join("pressure-000.npy")).unwrap();
    let saturated = p.iter().filter(|v| **v == 3e9).count();
    assert!(p.iter().all(|v| *v <= 3e9) && saturated > 0, "{saturated} points at the hardness");
    assert!((p.sum() * 8e-6 * 6e-6 / (96.0 * 128.0) / 2e-3 - 1.0).abs() < 1e-10);
    // More points carry the load than in the elastic solve.
    assert!(json["loads"][0]["contact_points"].as_u64() > elastic["loads"][0]["contact_points"].as_u64());

    let f = fixture();
    let good = f.to_str().unwrap();
    let size = ["--size", "8e-6,6e-6"];
    refused(&[good, size[0], size[1], "--load", "1e-3", "--plastic"], "--hardness");
    refused(&[good, size[0], size[1], "--load", "1e-3", "--hardness", "-1e9"], "--hardness");
    refused(&[good, size[0], size[1], "--load", "1", "--hardness", "12GPa", "--plastic"], "--hardness");
}

/// The one line a failed command prints on stderr, with its exit code 1.
fn refusal(o: &std::process::Output) -> String {
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr).trim_end().to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

#[test]
fn a_long_input_path_keeps_its_reason_on_every_command() {
    let tmp = tempfile::tempdir().unwrap();
    let long = format!("{}/{}.npy", tmp.path().display(), "x".repeat(5000));
    let out = tmp.path().join("out");
    let out = out.to_str().unwrap();
    let converted = format!("{out}.npy");
    let commands: [&[&str]; 9] = [
        &["contact", &long, "--size", "10um", "--load", "1mN", "--out", out],
        &["onset", &long, "--mu-s", "0.5", "--mu-d", "0.3"],
        &["slide", &long, "--size", "10um", "--load", "1mN", "--mu-s", "0.5", "--mu-d", "0.3", "--out", out],
        &["topo", "info", &long],
        &["topo", "psd", &long],
        &["topo", "convert", &long, "--size", "10um", &converted],
        &["shs", &long],
        &["run", &long, "--out", out],
        &["slurm", &long, "--shards", "1", "--out", out],
    ];
    for args in commands {
        let line = refusal(&asperity(args));
        assert!(line.chars().count() <= 400, "{}: {} characters", args[0], line.chars().count());
        // The path keeps its start and its end; the operating system's reason stays whole.
        assert!(line.contains("xxx…xxx"), "{line}");
        assert!(line.ends_with("File name too long (os error 36)"), "{}: {line}", args[0]);
    }
}

#[test]
fn an_empty_output_path_is_no_folder() {
    let o = asperity(&["contact", fixture().to_str().unwrap(), "--size", "8e-6,6e-6", "--load", "1mN", "--out", ""]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        "error: --out: an empty path is no folder: give the folder's path"
    );
}

#[test]
fn a_flat_map_is_in_full_contact_at_uniform_pressure_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let (n, l) = (64, 10e-6);
    // A constant height, and heights a rounding error apart (1e-30 m).
    let flat = tmp.path().join("flat.npy");
    write_npy(&flat, &Array2::<f64>::from_elem((n, n), 3e-7)).unwrap();
    let rounding = tmp.path().join("rounding.npy");
    write_npy(&rounding, &Array2::from_shape_fn((n, n), |(i, j)| 1e-30 * ((i * 7 + j * 13) % 17) as f64)).unwrap();
    for (map, name) in [(&flat, "flat"), (&rounding, "rounding")] {
        let out = tmp.path().join(name);
        let started = std::time::Instant::now();
        let o = asperity(&[
            "contact",
            map.to_str().unwrap(),
            "--size",
            "10um",
            "--load",
            "1mN",
            "--load",
            "10mN",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(started.elapsed().as_secs_f64() < 5.0, "{name}: {:?}", started.elapsed());
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("contact.json")).unwrap()).unwrap();
        for (k, load) in [1e-3, 10e-3].into_iter().enumerate() {
            let solve = &json["loads"][k];
            assert!(solve["iterations"].as_u64().unwrap() <= 3, "{name}: {solve}");
            let p: Array2<f64> = read_npy(out.join(solve["pressure_file"].as_str().unwrap())).unwrap();
            let expected = load / (l * l);
            assert!(p.iter().all(|&p| ((p - expected) / expected).abs() <= 1e-12), "{name} at {load} N");
        }
    }
    // Over a free window a flat map is a flat punch: refused in one line that says so.
    let o = asperity(&[
        "contact",
        flat.to_str().unwrap(),
        "--size",
        "10um",
        "--load",
        "1mN",
        "--free",
        "--out",
        tmp.path().join("free").to_str().unwrap(),
    ]);
    let line = refusal(&o);
    assert!(line.starts_with("error: surface: the map is flat (heights within 0e0 m of each other)"), "{line}");
}

#[test]
fn heights_a_rounding_apart_are_refused_as_no_surface() {
    // A constant 5 nm with one point raised by less than any instrument measures (the solve
    // never converged: 20 000 iterations, then "raise --max-iter", which did not help).
    let tmp = tempfile::tempdir().unwrap();
    let n = 64;
    for (name, bump, span) in [("bump-15", 1e-15, "1 fm"), ("bump-14", 1e-14, "10 fm")] {
        let mut h = Array2::<f64>::from_elem((n, n), 5e-9);
        h[[10, 20]] += bump;
        let map = tmp.path().join(format!("{name}.npy"));
        write_npy(&map, &h).unwrap();
        let out = tmp.path().join(name);
        let started = std::time::Instant::now();
        let line = refusal(&asperity(&[
            "contact",
            map.to_str().unwrap(),
            "--size",
            "10um",
            "--load",
            "1mN",
            "--out",
            out.to_str().unwrap(),
        ]));
        assert!(started.elapsed().as_secs_f64() < 5.0, "{name}: {:?}", started.elapsed());
        assert!(line.contains(&format!("{name}.npy: the heights span ")) && line.contains("below 0.1 pm"), "{line}");
        assert!(line.contains("a flat map has equal heights") && !out.exists(), "{span}: {line}");
    }
}
