//! Bare numbers in the wrong unit are refused with the unit meant, `onset` runs every
//! load of a contact folder, `contact` prints a line per load, and study sections partially
//! given keep the default's other keys.

use std::path::Path;
use std::process::{Command, Output};

use asperity::study::config::StudyConfig;

fn asperity(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// A 31.13 µm ball of 64 × 64 points, written as s.npy into a fresh folder.
fn ball(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("asperity-units-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = asperity(
        &[
            "topo",
            "generate",
            "--size",
            "31.13um",
            "--grid",
            "64",
            "--hurst",
            "0.8",
            "--rms",
            "20nm",
            "--sphere-radius",
            "1.5mm",
            "--seed",
            "1",
            "s.npy",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    dir
}

#[test]
fn bare_numbers_in_the_wrong_unit_are_refused_naming_the_option_and_the_unit_meant() {
    let dir = ball("refused");
    let cases: [(&[&str], &str); 4] = [
        (
            &["--size", "31.13um", "--youngs", "130", "--load", "1mN"],
            "error: --youngs: 130 Pa is not a solid's Young's modulus (1 MPa to 2000 GPa); did you mean 130GPa?",
        ),
        (
            &["--size", "31.13", "--load", "1mN"],
            "error: --size: 31.13 m is not the size of a measured window (1 nm to 1 m); did you mean 31.13um?",
        ),
        (
            &["--size", "31.13um", "--load", "1mN", "--hardness", "12"],
            "error: --hardness: 12 Pa is not a solid's hardness (1 MPa to 200 GPa); did you mean 12GPa?",
        ),
        (&["--size", "31.13um", "--load", "1kN"], "error: --load: 1000 N on the 31.13 µm × 31.13 µm window"),
    ];
    for (args, expected) in cases {
        let mut all = vec!["contact", "s.npy", "--out", "o"];
        all.extend_from_slice(args);
        let out = asperity(&all, &dir);
        let err = stderr(&out);
        assert!(!out.status.success() && err.starts_with(expected) && err.lines().count() == 1, "{all:?}: {err}");
        assert!(!dir.join("o").exists());
    }
    // 1 N (meant 1 mN) solves, with a warning that says so.
    let out = asperity(&["contact", "s.npy", "--size", "31.13um", "--load", "1", "--out", "o"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).lines().any(|l| l.starts_with("warning: --load: 1 N") && l.ends_with("did you mean 1mN?")));
    // Friction coefficients above 10 (a percentage, or 1e300) are refused, never printed as inf.
    for (mu_s, mu_d, expected) in [
        (
            "60",
            "40",
            "error: --mu-s: a friction coefficient of 60 is above 10, higher than any measured one; did you mean 0.6",
        ),
        ("1e300", "0.4", "error: --mu-s: a friction coefficient of 1e300 is above 10"),
    ] {
        let out = asperity(&["onset", "o", "--mu-s", mu_s, "--mu-d", mu_d], &dir);
        assert!(!out.status.success() && stderr(&out).starts_with(expected), "{}", stderr(&out));
        assert!(!String::from_utf8_lossy(&out.stdout).contains("inf"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn onset_runs_every_load_of_a_contact_folder_and_contact_prints_a_line_per_load() {
    let dir = ball("loads");
    let out = asperity(&["contact", "s.npy", "--size", "31.13um", "--load", "1e-4,1e-3", "--out", "c"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(lines[0].starts_with("load") && lines[0].contains("contact points") && lines[0].contains("edge load"));
    assert!(lines[1].starts_with("100 µN ") && lines[2].starts_with("1 mN "), "{text}");

    let out = asperity(&["onset", "c", "--mu-s", "0.6", "--mu-d", "0.4"], &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("100 µN") || l.starts_with("1 mN")).collect();
    assert_eq!(rows.len(), 2, "{text}");
    let out = asperity(&["onset", "c", "--mu-s", "0.6", "--mu-d", "0.4", "--json"], &dir);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = json.as_array().expect("a list, one report per load");
    assert_eq!(rows.len(), 2);
    for (i, (row, load)) in rows.iter().zip([1e-4, 1e-3]).enumerate() {
        assert_eq!(row["load_index"], i);
        assert_eq!(row["imposed_load_n"], load);
        let mu = row["static_coefficient"].as_f64().unwrap();
        assert!((0.4..=0.6).contains(&mu), "{mu}");
    }
    // The same row as the one load asked for alone.
    let one = asperity(&["onset", "c", "--mu-s", "0.6", "--mu-d", "0.4", "--json", "--load-index", "1"], &dir);
    let one: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
    assert_eq!(one, rows[1]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn study_sections_partially_given_keep_the_defaults_other_keys() {
    let default = StudyConfig::default_study();
    let c = StudyConfig::parse("[contact]\nboundary = \"free\"\n", "s.toml").unwrap();
    assert_eq!(c.contact.boundary, asperity::contact::Boundary::Free);
    assert_eq!(
        (c.contact.tolerance, c.contact.max_iterations),
        (default.contact.tolerance, default.contact.max_iterations)
    );
    let c = StudyConfig::parse("[material]\npoisson = 0.3\n", "s.toml").unwrap();
    assert_eq!((c.material.youngs, c.material.poisson), (default.material.youngs, 0.3));
    let c = StudyConfig::parse("[loads]\ncount = 7\n", "s.toml").unwrap();
    assert_eq!((c.loads.min, c.loads.max, c.loads.count), (default.loads.min, default.loads.max, Some(7)));
    let c = StudyConfig::parse("[loads]\nvalues = [\"1 mN\"]\n", "s.toml").unwrap();
    assert_eq!(c.load_values(), [1e-3]);
    let c = StudyConfig::parse("[limits]\n", "s.toml").unwrap();
    assert_eq!(c.limits, default.limits);
    let c = StudyConfig::parse("[output]\nlog_density = true\n", "s.toml").unwrap();
    assert_eq!(c.output.figures, default.output.figures);
    // The study's checks speak the study file's language.
    let e = StudyConfig::parse("[material]\nyoungs = 130\n", "s.toml").unwrap_err().to_string();
    assert_eq!(e, "s.toml:2:1: material.youngs: 130 Pa is not a solid's Young's modulus (1 MPa to 2000 GPa); did you mean \"130 GPa\"?");
    let e = StudyConfig::parse("[[law]]\nname = \"x\"\nmu_s = 60\nmu_d = 40\n", "s.toml").unwrap_err().to_string();
    assert!(e.starts_with("s.toml:1:1: law[0]: mu_s: a friction coefficient of 60 is above 10"), "{e}");
    // Edge warnings name the remedies left, in the study's words.
    assert!(
        default.edge_remedies("ball-1") == ["boundary = \"free\" in [contact]"],
        "{:?}",
        default.edge_remedies("ball-1")
    );
}
