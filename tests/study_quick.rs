//! `asperity run --quick`, the CI's smoke study: the default study on a coarse grid, end to end.

use std::collections::BTreeMap;
use std::process::Command;

use asperity::study::{MapSnapshot, Results};

#[test]
fn the_quick_study_shows_the_friction_drop_falling_with_load() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "--quick", "--out", "results"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.path().join("results");
    let results: Results =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(results.asperity_version, env!("CARGO_PKG_VERSION"));
    let rows = results.rows;
    assert_eq!(rows.len(), 3 * 2 * 7);

    let mut curves: BTreeMap<(String, String), Vec<(f64, f64)>> = BTreeMap::new();
    for r in &rows {
        curves.entry((r.topography.clone(), r.law.clone())).or_default().push((r.load_n, r.friction_drop));
    }
    assert_eq!(curves.len(), 6);
    for ((topography, law), curve) in &curves {
        assert_eq!(curve.len(), 7);
        let (first, last) = (curve[0], curve[6]);
        assert_eq!((first.0, last.0), (1e-7, 1e-1));
        // One element at 0.1 µN: the single-element drop mu_s/mu_d.
        let law = if law == "hold 100 s" { 0.6 / 0.4 } else { 0.5 / 0.4 };
        assert!((first.1 - law).abs() < 1e-12, "{topography}: drop {} at 0.1 µN", first.1);
        assert!(first.1 > last.1, "{topography}: drop {} at 0.1 µN, {} at 100 mN", first.1, last.1);
    }
    // The run ends with the table in brief: per law, the drop's range over the balls at 0.1,
    // 1, 10 and 100 mN, as the rows give it.
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.starts_with("friction drop, min–max") && stdout.contains("100 µN"), "{stdout}");
    for law in ["hold 100 s", "hold 10 s"] {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(&format!("{law}, equal sharing")))
            .unwrap_or_else(|| panic!("no line for {law}: {stdout}"));
        let cells: Vec<&str> = line.split_whitespace().rev().take(4).collect();
        for (cell, load) in cells.iter().rev().zip([1e-4, 1e-3, 1e-2, 1e-1]) {
            let drops: Vec<f64> =
                rows.iter().filter(|r| r.law == law && r.load_n == load).map(|r| r.friction_drop).collect();
            assert_eq!(drops.len(), 3);
            let (lo, hi) = (drops.iter().copied().fold(f64::MAX, f64::min), drops.iter().copied().fold(0.0, f64::max));
            assert_eq!(*cell, format!("{lo:.4}–{hi:.4}"), "{law} at {load} N: {line}");
        }
    }
    // The first ball's maps at 0.1, 1, 10 and 100 mN (loads 3 to 6 of 7, one per decade), each
    // named by its load and the digest of its solve.
    let mut stems: Vec<String> = std::fs::read_dir(out.join("snapshots"))
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().into_string().unwrap().strip_suffix(".json").map(str::to_owned))
        .collect();
    stems.sort();
    assert_eq!(stems.len(), 4, "{stems:?}");
    for load in [1e-4, 1e-3, 1e-2, 1e-1] {
        let prefix = format!("ball-1-{load:e}N-");
        let stem = stems.iter().find(|s| s.starts_with(&prefix)).unwrap_or_else(|| panic!("{prefix}: {stems:?}"));
        let snap = MapSnapshot::load(&out.join("snapshots"), stem).unwrap();
        assert_eq!((snap.load_n, snap.grid), (load, (256, 256)));
    }
}
