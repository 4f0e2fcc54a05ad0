//! A study killed midway and run again continues where it stopped, and ends with the results
//! of an uninterrupted run.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const STUDY: &str = r#"
[[topography]]
name = "ball-1"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [192, 192], seed = 1, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }
wafer = { synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [192, 192], seed = 101, roughness = { hurst = 0.8, rms_height_m = "0.2 nm" } } }

[[topography]]
name = "ball-2"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [192, 192], seed = 2, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }

[loads]
min = "0.1 mN"
max = "100 mN"
count = 40
"#;

const TOTAL: usize = 80;

fn records(out: &Path) -> usize {
    ["ball-1", "ball-2"]
        .iter()
        .filter_map(|t| std::fs::read_dir(out.join("solves/topographies").join(t)).ok())
        .flat_map(|d| d.map(|e| e.unwrap().file_name().into_string().unwrap()))
        .filter(|n| n.ends_with(".json") && !n.starts_with('.'))
        .count()
}

fn run(dir: &Path, out: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", out])
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Rows of a results.csv without the column of timings.
fn table(path: &Path) -> Vec<Vec<String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    let seconds = header.iter().position(|h| h == "seconds").unwrap();
    let mut rows = vec![header.iter().map(String::from).collect::<Vec<_>>()];
    for r in reader.records() {
        rows.push(r.unwrap().iter().enumerate().filter(|(i, _)| *i != seconds).map(|(_, v)| v.to_string()).collect());
    }
    rows
}

#[test]
fn a_killed_run_resumes_to_the_uninterrupted_results() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), STUDY).unwrap();
    let killed = dir.path().join("killed");

    let mut child = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", "killed"])
        .current_dir(dir.path())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while records(&killed) < 6 {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be killed");
        assert!(start.elapsed() < Duration::from_secs(120), "no solve finished in 2 minutes");
        std::thread::sleep(Duration::from_millis(1));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let done = records(&killed);
    assert!(done < TOTAL, "the run finished before it was killed");
    assert!(!killed.join("results.csv").exists());

    let o = run(dir.path(), "killed");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let resumed: usize = stderr.split(" resumed").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    assert!(resumed >= done && resumed < TOTAL, "{stderr} (killed after {done} records)");

    let o = run(dir.path(), "whole");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (a, b) = (table(&killed.join("results.csv")), table(&dir.path().join("whole/results.csv")));
    assert_eq!(a.len(), 2 * TOTAL + 1);
    assert_eq!(a, b);
    // The same in results.json, bit for bit apart from the timings.
    let json = |p: &Path| {
        let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        v["rows"].as_array_mut().unwrap().iter_mut().for_each(|r| r["seconds"] = 0.into());
        v
    };
    assert_eq!(json(&killed.join("results.json")), json(&dir.path().join("whole/results.json")));
    // The warm-start maps are gone once the sweeps are done.
    for t in ["ball-1", "ball-2"] {
        let names: Vec<_> = std::fs::read_dir(killed.join("solves/topographies").join(t))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with("warm"))
            .collect();
        assert!(names.is_empty(), "{names:?}");
    }
}
