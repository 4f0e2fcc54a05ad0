//! `asperity onset` end to end: inputs (bare map, contact directory), outputs, and errors.

use std::path::Path;
use std::process::{Command, Output};

use asperity::friction::{ElementLoads, FrictionLaw, Onset};
use ndarray::Array2;
use ndarray_npy::{read_npy, write_npy};

fn asperity(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap()
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Whether a JSON number equals `b` but for the last bits (JSON parsing rounds).
fn close(a: &serde_json::Value, b: f64) -> bool {
    let a = a.as_f64().unwrap();
    (a - b).abs() <= 1e-14 * b.abs()
}

/// The one line a failed command prints.
fn error_line(out: &Output) -> String {
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(err.lines().count(), 1, "{err}");
    err.trim_end().to_string()
}

/// A 12×10 map with contact on about two thirds of it, pressures 0.1–2 GPa.
fn pressure_map() -> Array2<f64> {
    Array2::from_shape_fn((12, 10), |(i, j)| {
        let k = (i * 10 + j) as u64;
        let h = k.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 40;
        if h.is_multiple_of(3) {
            0.0
        } else {
            1e8 + (h % 1000) as f64 * 1.9e6
        }
    })
}

fn write_contact_dir(dir: &Path, maps: &[Array2<f64>]) {
    std::fs::create_dir_all(dir).unwrap();
    let loads: Vec<_> = maps
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let file = format!("pressure_{i}.npy");
            write_npy(dir.join(&file), p).unwrap();
            // The load the map carries, as `asperity contact` writes it.
            let load = p.sum() * (2e-6 / 10.0) * (3e-6 / 12.0);
            serde_json::json!({"load_n": load, "mean_pressure_pa": 1e7, "contact_fraction": 0.6,
                "contact_points": 80, "patches": 5, "iterations": 30, "residual": 1e-10, "seconds": 0.01,
                "pressure_file": file})
        })
        .collect();
    let contact = serde_json::json!({"grid": [12, 10], "physical_size_m": [2e-6, 3e-6],
        "effective_modulus_pa": 7.6e10, "boundary": "periodic", "loads": loads});
    std::fs::write(dir.join("contact.json"), contact.to_string()).unwrap();
}

#[test]
fn contact_directory_to_json_and_output_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let p = pressure_map();
    write_contact_dir(&tmp.path().join("contact"), &[p.mapv(|x| x * 0.5), p.clone()]);
    let out = asperity(
        &["onset", "contact", "--load-index", "1", "--mu-s", "0.6", "--mu-d", "0.4", "--json", "--out", "res"],
        tmp.path(),
    );
    let j = json(&out);

    // The same numbers as the library on the same map, with a = 2 µm · 3 µm / (10 · 12).
    let area = 2e-6 / 10.0 * (3e-6 / 12.0);
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    let o = Onset::new(&ElementLoads::from_pressure(&p, area).unwrap(), &law);
    assert_eq!(j["elements"].as_u64().unwrap() as usize, o.elements);
    assert!(close(&j["static_coefficient"], o.static_coefficient()));
    assert_eq!(j["dynamic_coefficient"].as_f64().unwrap(), 0.4);
    assert!(close(&j["friction_drop"], o.friction_drop()));
    assert_eq!(j["critical"]["count"].as_u64().unwrap() as usize, o.critical.count);
    assert!(close(&j["subcritical"]["friction_fraction"], o.subcritical.friction_fraction));
    assert!(close(&j["pre_sliding"]["normal_fraction"], o.pre_sliding.normal_fraction));
    assert_eq!(j["load_index"], 1);
    assert!(close(&j["imposed_load_n"], p.sum() * area));
    assert!(close(&j["static_force_n"], o.static_force));
    assert!(o.friction_drop() > 1.0 && o.friction_drop() < 1.5);

    let res = tmp.path().join("res");
    let onset_json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(res.join("onset.json")).unwrap()).unwrap();
    assert_eq!(onset_json, j);
    let classes: Array2<i8> = read_npy(res.join("classes.npy")).unwrap();
    assert_eq!(classes, o.class_map(&p, area));
    assert_eq!(classes.iter().filter(|&&c| c == 0).count(), p.iter().filter(|&&x| x == 0.0).count());
    let ratio: Array2<f64> = read_npy(res.join("stress_ratio.npy")).unwrap();
    let ratio_1: Array2<f64> = read_npy(res.join("stress_ratio_1.npy")).unwrap();
    assert_eq!(ratio.mapv(f64::to_bits), ratio_1.mapv(f64::to_bits));
    for ((&c, &r), &x) in classes.iter().zip(&ratio).zip(&p) {
        match c {
            0 => assert!(r.is_nan() && x == 0.0),
            1 => assert_eq!(r, 0.4),
            2 => assert_eq!(r, 0.6),
            _ => assert!(r > 0.0 && r < 0.6),
        }
    }
    // Snapshots: the library's maps; slipped elements (at mu_d) only grow with δ, nothing exceeds mu_s.
    let mut slipped = 0;
    for f in ["0.25", "0.5", "0.75", "1"] {
        let snap: Array2<f64> = read_npy(res.join(format!("stress_ratio_{f}.npy"))).unwrap();
        let expected = o.stress_ratio_map(&p, area, f.parse().unwrap()).unwrap();
        assert_eq!(snap.mapv(f64::to_bits), expected.mapv(f64::to_bits), "{f}");
        assert!(snap.iter().all(|r| r.is_nan() || *r <= 0.6));
        let now = snap.iter().filter(|&&r| r == 0.4).count();
        assert!(now >= slipped, "{f}");
        slipped = now;
    }
    assert_eq!(slipped, o.pre_sliding.count);

    // curve.csv: both modes, each peaking at δ/δ_peak = 1 with F/N = the static coefficient.
    let text = std::fs::read_to_string(res.join("curve.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "mode,delta_over_peak,delta_m,element_shear_n,force_n,coefficient,stuck");
    for mode in ["equal_load_sharing", "rigid_displacement"] {
        let rows: Vec<Vec<&str>> =
            text.lines().filter(|l| l.starts_with(mode)).map(|l| l.split(',').collect()).collect();
        let peak = rows.iter().map(|r| r[5].parse::<f64>().unwrap()).fold(0.0, f64::max);
        assert!((peak / o.static_coefficient() - 1.0).abs() < 1e-14, "{mode}");
        let at_peak = rows.iter().find(|r| r[5].parse::<f64>().unwrap() == peak).unwrap();
        assert_eq!(at_peak[1], "1.0");
        assert_eq!(at_peak[2], "", "no --shear-stiffness, no delta_m");
        let last = rows.last().unwrap();
        assert_eq!((last[5].parse::<f64>().unwrap(), last[6]), (0.4, "0"));
    }
    // Nothing else was left beside the results.
    let names: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn pixel_area_changes_newtons_only() {
    let tmp = tempfile::tempdir().unwrap();
    write_npy(tmp.path().join("p.npy"), &pressure_map()).unwrap();
    let law = ["--mu-s", "0.5", "--mu-d", "0.3", "--json"];
    let run = |extra: &[&str]| json(&asperity(&[&["onset", "p.npy"], &law[..], extra].concat(), tmp.path()));
    let bare = run(&[]);
    let sized = run(&["--size", "1e-6,2e-6"]);
    let area = run(&["--pixel-area", "1.6666666666666667e-14"]);
    // Forces n_i = p_i·a round differently for each a: equal but for the last bits.
    for other in [&sized, &area] {
        assert_eq!(bare["elements"], other["elements"]);
        for key in ["static_coefficient", "friction_drop"] {
            assert!(close(&other[key], bare[key].as_f64().unwrap()), "{key}");
        }
        for class in ["critical", "pre_sliding", "subcritical"] {
            assert_eq!(bare[class]["count"], other[class]["count"]);
            for key in ["normal_fraction", "friction_fraction"] {
                let b = bare[class][key].as_f64().unwrap();
                assert!((other[class][key].as_f64().unwrap() - b).abs() < 1e-14, "{class} {key}");
            }
        }
    }
    assert!(bare.get("load_n").is_none() && bare.get("static_force_n").is_none());
    let (n1, n2) = (sized["load_n"].as_f64().unwrap(), area["load_n"].as_f64().unwrap());
    assert!((n1 / n2 - 1.0).abs() < 1e-12, "{n1} vs {n2}");
    let expected = pressure_map().sum() * 1e-6 / 10.0 * (2e-6 / 12.0);
    assert!((n1 / expected - 1.0).abs() < 1e-12);
}

#[test]
fn friction_law_from_a_measured_curve_and_presets() {
    let tmp = tempfile::tempdir().unwrap();
    write_npy(tmp.path().join("p.npy"), &pressure_map()).unwrap();
    std::fs::write(tmp.path().join("afm.csv"), "x_nm,mu\n0,0.1\n10,0.7\n20,0.5\n30,0.4\n40,0.42\n").unwrap();
    let j = json(&asperity(&["onset", "p.npy", "--curve", "afm.csv", "--window", "5,25", "--json"], tmp.path()));
    assert_eq!(j["law"]["mu_s"], 0.7);
    assert!((j["law"]["mu_d"].as_f64().unwrap() - 0.45).abs() < 1e-15);
    assert_eq!(j["law"]["name"], "afm.csv");
    let j = json(&asperity(&["onset", "p.npy", "--law", "hold 100 s", "--json"], tmp.path()));
    assert_eq!((j["law"]["name"].as_str(), j["law"]["mu_s"].as_f64()), (Some("hold 100 s"), Some(0.6)));
    let j =
        json(&asperity(&["onset", "p.npy", "--law", "mine", "--mu-s", "0.8", "--mu-d", "0.2", "--json"], tmp.path()));
    assert_eq!((j["law"]["name"].as_str(), j["law"]["mu_s"].as_f64()), (Some("mine"), Some(0.8)));
}

#[test]
fn bad_input_is_one_line_and_leaves_no_output() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write_npy(dir.join("p.npy"), &pressure_map()).unwrap();
    let mut nan = pressure_map();
    nan[[3, 4]] = f64::NAN;
    write_npy(dir.join("nan.npy"), &nan).unwrap();
    let mut neg = pressure_map();
    neg[[5, 1]] = -1e6;
    write_npy(dir.join("neg.npy"), &neg).unwrap();
    write_npy(dir.join("zero.npy"), &Array2::<f64>::zeros((4, 4))).unwrap();
    std::fs::write(dir.join("junk.npy"), b"not numpy").unwrap();
    write_contact_dir(&dir.join("two"), &[pressure_map(), pressure_map()]);
    std::fs::create_dir(dir.join("empty")).unwrap();

    let cases: &[(&[&str], &str)] = &[
        (
            &["p.npy", "--mu-s", "0.6", "--mu-d", "0"],
            "error: --mu-d: the dynamic friction coefficient must be positive",
        ),
        (&["p.npy", "--mu-s", "0.6", "--mu-d", "-0.2"], "error: --mu-d:"),
        (&["p.npy", "--mu-s", "0.3", "--mu-d", "0.4"], "error: --mu-s: the static friction coefficient 0.3 is below"),
        (&["p.npy", "--mu-s", "0.6"], "error: --mu-s: needs --mu-d too"),
        (&["p.npy"], "error: --mu-s: give the local friction law"),
        (&["p.npy", "--law", "hold 5 s"], "error: --law: unknown law"),
        (&["nan.npy", "--mu-s", "0.6", "--mu-d", "0.4"], "error: nan.npy: pressure at row 3, column 4 is NaN"),
        (&["neg.npy", "--mu-s", "0.6", "--mu-d", "0.4"], "error: neg.npy: pressure at row 5, column 1 is -1000000 Pa"),
        (&["zero.npy", "--mu-s", "0.6", "--mu-d", "0.4"], "error: zero.npy: no contact"),
        (&["junk.npy", "--mu-s", "0.6", "--mu-d", "0.4"], "error: junk.npy: not a .npy file"),
        (&["gone.npy", "--mu-s", "0.6", "--mu-d", "0.4"], "error: gone.npy:"),
        (&["p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--pixel-area", "0"], "error: --pixel-area:"),
        (&["p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--size", "-1"], "error: --size:"),
        (&["p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--snapshots", "0.5,2"], "error: --snapshots:"),
        (&["p.npy", "--mu-s", "0.6", "--mu-d", "0.4", "--shear-stiffness", "0"], "error: --shear-stiffness:"),
        // Every load runs without --load-index; --out writes one.
        (
            &["two", "--mu-s", "0.6", "--mu-d", "0.4"],
            "error: --out: writes the maps of one load, and the input two holds 2: choose it with --load-index",
        ),
        (&["two", "--mu-s", "0.6", "--mu-d", "0.4", "--load-index", "2"], "error: --load-index: 2 is out of range"),
        (&["empty", "--mu-s", "0.6", "--mu-d", "0.4"], "error: empty: holds no contact.json: give a contact directory"),
    ];
    for (args, expected) in cases {
        let out = asperity(&[&["onset"], *args, &["--out", "res"]].concat(), dir);
        let line = error_line(&out);
        assert!(line.starts_with(expected), "{args:?}: {line}");
        assert!(!dir.join("res").exists(), "{args:?} left output behind");
    }
    // clap's own usage errors are one line too.
    assert!(error_line(&asperity(&["onset", "p.npy", "--mu-s", "x", "--mu-d", "0.4"], dir)).contains("--mu-s"));
}

#[test]
fn onset_reads_what_contact_writes() {
    // `asperity contact` on the rough sphere of the Tamaas fixture, then `asperity onset` on
    // its output directory: the drops of tests/friction_on_contact.rs at 0.2 and 20 mN.
    let tmp = tempfile::tempdir().unwrap();
    let heights = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas/heights.npy");
    let solve = ["contact", heights.to_str().unwrap(), "--size", "8e-6,6e-6", "--load", "2e-4,2e-2", "--out", "c"];
    let out = asperity(&solve, tmp.path());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for (index, elements, drop) in [("0", 40, 1.09559), ("1", 2132, 1.05779)] {
        let j = json(&asperity(
            &["onset", "c", "--load-index", index, "--mu-s", "0.6", "--mu-d", "0.4", "--json"],
            tmp.path(),
        ));
        assert_eq!(j["elements"], elements);
        assert!((j["friction_drop"].as_f64().unwrap() / drop - 1.0).abs() < 1e-4, "{j}");
        let (n, imposed) = (j["load_n"].as_f64().unwrap(), j["imposed_load_n"].as_f64().unwrap());
        assert!((n / imposed - 1.0).abs() < 1e-9);
    }
    // Every load at once: one table, headed by the directory, a line a load.
    let table = asperity(&["onset", "c", "--mu-s", "0.6", "--mu-d", "0.4"], tmp.path());
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.starts_with("c, 2 loads  (mu_s 0.6, mu_d 0.4)\n"), "{text}");
    assert!(text.contains("\n200 µN ") && text.contains("\n20 mN "), "{text}");
}

#[test]
fn snapshots_are_capped_as_a_studys() {
    let tmp = tempfile::tempdir().unwrap();
    write_npy(tmp.path().join("p.npy"), &pressure_map()).unwrap();
    let many: Vec<String> = (1..=13).map(|k| format!("{}", k as f64 / 13.0)).collect();
    let law = ["onset", "p.npy", "--mu-s", "0.5", "--mu-d", "0.3", "--out", "out", "--snapshots"];
    let o = asperity(&[&law[..], &[many.join(",").as_str()]].concat(), tmp.path());
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        error_line(&o),
        "error: --snapshots: 13 fractions: at most 12, as a study's snapshot_fractions (each is a map of the grid)"
    );
    assert!(!tmp.path().join("out").exists());
    let o = asperity(&[&law[..], &[many[1..].join(",").as_str()]].concat(), tmp.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
