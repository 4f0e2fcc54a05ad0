//! A study split into shards (`asperity run --shard I/N`) run at once into one DIR, then
//! assembled by a run without a shard, gives the unsharded run's results; and the same through
//! a real Slurm (`asperity slurm --submit`, the ignored test that `.ci/run` runs after starting
//! one with `tools/slurm-local.sh`). A study grown load by load in its DIR gives them too,
//! solving only what is new.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Two balls, elastic and plastic, with the resolution figure's coarser copies: 8 sweeps.
const STUDY: &str = r#"
[[topography]]
name = "ball-1"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 1, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }

[[topography]]
name = "ball-2"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 2, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }

[material]
youngs = "130 GPa"
poisson = 0.26
hardness = "12 GPa"

[contact]
boundary = "periodic"
tolerance = 1e-8
max_iterations = 20000
plastic = [false, true]

[loads]
min = "0.1 mN"
max = "100 mN"
count = 9

[output]
figures = ["friction-drop", "resolution"]
"#;

/// The study's solver tolerance.
const TOLERANCE: f64 = 1e-8;
/// Sweeps: 2 balls × (elastic, plastic) + 2 balls × 2 coarser copies (elastic).
const SWEEPS: usize = 8;
const ROWS: usize = 2 * 2 * 9 * 2;

fn asperity(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn succeeds(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

/// The shards 1..=n of the study run at once as processes into `out`; their outputs in order.
fn shards_at_once(dir: &Path, out: &str, n: usize) -> Vec<Output> {
    let children: Vec<_> = (1..=n)
        .map(|i| {
            Command::new(env!("CARGO_BIN_EXE_asperity"))
                .args(["run", "study.toml", "--out", out, "--shard", &format!("{i}/{n}")])
                .current_dir(dir)
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    children.into_iter().map(|c| c.wait_with_output().unwrap()).collect()
}

/// A results table by column: (header, values).
fn columns(path: &Path) -> Vec<(String, Vec<String>)> {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    header.iter().enumerate().map(|(i, h)| (h.clone(), rows.iter().map(|r| r[i].to_string()).collect())).collect()
}

/// Compare two results tables column by column: every column equal but the timings and the
/// iteration counts, numbers within `relative` (a piece of a load chain that starts cold
/// converges to the warm-started solution within the solver's tolerance, not bit for bit).
/// Returns the largest relative difference of a number.
fn same_results(sharded: &Path, whole: &Path, relative: f64) -> f64 {
    let (a, b) = (columns(sharded), columns(whole));
    assert_eq!(a.iter().map(|c| &c.0).collect::<Vec<_>>(), b.iter().map(|c| &c.0).collect::<Vec<_>>());
    let mut worst = 0.0f64;
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert_eq!(x.len(), y.len(), "{name}");
        if name == "seconds" || name == "iterations" {
            continue;
        }
        for (row, (u, v)) in x.iter().zip(y).enumerate() {
            if u == v {
                continue;
            }
            // Counts, names and flags are equal; only real numbers may differ, and little.
            let (p, q): (f64, f64) = match (u.parse::<i64>(), u.parse(), v.parse()) {
                (Err(_), Ok(p), Ok(q)) => (p, q),
                _ => panic!("{name}, row {row}: {u} sharded against {v} whole"),
            };
            let d = (p - q).abs() / p.abs().max(q.abs());
            assert!(d <= relative, "{name}, row {row}: {u} sharded against {v} whole ({d:.1e} apart)");
            worst = worst.max(d);
        }
    }
    worst
}

/// The closing line's counts: (solved, resumed).
fn solved_resumed(o: &Output) -> (usize, usize) {
    let e = stderr(o);
    let line = e.lines().find(|l| l.contains(" solved, ")).unwrap_or_else(|| panic!("{e}"));
    let count = |before: &str| line.split(before).next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
    (count(" solved,"), count(" resumed"))
}

/// The solve records of `out`'s first topography at `load` [N] (`1e-3N-<digest>.json`).
fn records_at(out: &Path, load: f64) -> usize {
    let folder = out.join("solves/topographies/ball-1");
    walk(&folder).iter().filter(|n| n.starts_with(&format!("{load:e}N-")) && n.ends_with(".json")).count()
}

/// One ball, elastic, at the loads `loads`, with the table and one figure.
fn one_ball(loads: &[&str]) -> String {
    let (balls, rest) = STUDY.split_at(STUDY.find("[[topography]]\nname = \"ball-2\"").unwrap());
    let rest = &rest[rest.find("[material]").unwrap()..];
    let quoted: Vec<String> = loads.iter().map(|l| format!("\"{l}\"")).collect();
    let study = format!("{balls}{rest}")
        .replace("plastic = [false, true]\n", "")
        .replace("[\"friction-drop\", \"resolution\"]", "[\"friction-drop\"]");
    let (head, tail) = study.split_at(study.find("min = ").unwrap());
    format!("{head}values = [{}]{}", quoted.join(", "), &tail[tail.find("\n\n").unwrap()..])
}

const NINE: [&str; 9] = ["0.1 mN", "0.2 mN", "0.5 mN", "1 mN", "2 mN", "5 mN", "10 mN", "20 mN", "50 mN"];

#[test]
fn a_study_grown_by_a_load_solves_it_alone_and_a_removed_one_stays_until_fresh() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("nine.toml"), one_ball(&NINE)).unwrap();
    let mut ten = NINE.to_vec();
    ten.insert(5, "3 mN");
    std::fs::write(dir.join("ten.toml"), one_ball(&ten)).unwrap();
    let o = asperity(dir, &["run", "nine.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (9, 0));

    // A load between two recorded ones: it alone is solved (cold, its neighbours' maps being
    // gone), and the table is the fresh ten-load study's within 100 times the solver's
    // tolerance.
    let o = asperity(dir, &["run", "ten.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (1, 9));
    succeeds(&asperity(dir, &["run", "ten.toml", "--out", "whole"]));
    same_results(&dir.join("out/results.csv"), &dir.join("whole/results.csv"), 100.0 * TOLERANCE);

    // The load removed again: left out of the table, its record kept until --fresh.
    let o = asperity(dir, &["run", "nine.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (0, 9));
    let loads = &columns(&dir.join("out/results.csv"))[0];
    // Two laws × nine loads.
    assert!(loads.0 == "load_n" && loads.1.len() == 18 && !loads.1.contains(&"0.003".to_string()), "{loads:?}");
    assert_eq!(records_at(&dir.join("out"), 3e-3), 1);
    let o = asperity(dir, &["run", "nine.toml", "--out", "out", "--fresh"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (9, 0));
    assert_eq!(records_at(&dir.join("out"), 3e-3), 0);
}

#[test]
fn an_output_option_solves_nothing_and_the_material_solves_everything() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let study = one_ball(&NINE[..4]);
    std::fs::write(dir.join("study.toml"), &study).unwrap();
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "out"]));
    let output = study.replace("[output]\n", "[output]\nlog_density = true\nhold_time_loads = [\"0.2 mN\"]\n");
    std::fs::write(dir.join("output.toml"), output).unwrap();
    let o = asperity(dir, &["run", "output.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (0, 4));

    // Another Young's modulus: every solve is new; the earlier ones stay on disk, and are
    // found again with their material.
    std::fs::write(dir.join("stiffer.toml"), study.replace("youngs = \"130 GPa\"", "youngs = \"160 GPa\"")).unwrap();
    let o = asperity(dir, &["run", "stiffer.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (4, 0));
    assert_eq!(records_at(&dir.join("out"), 1e-4), 2);
    let o = asperity(dir, &["run", "study.toml", "--out", "out"]);
    succeeds(&o);
    assert_eq!(solved_resumed(&o), (0, 4));
}

/// The records of `out` whose solve started cold.
fn cold_records(out: &Path) -> usize {
    let mut cold = 0;
    let mut folders = vec![out.join("solves/topographies")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "json") {
                let record: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
                cold += usize::from(record["cold"].as_bool().unwrap());
            }
        }
    }
    cold
}

#[test]
fn three_shards_at_once_then_assembled_give_the_unsharded_results() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    let whole = asperity(dir, &["run", "study.toml", "--out", "whole"]);
    succeeds(&whole);
    assert_eq!(cold_records(&dir.join("whole")), SWEEPS);

    // Started at once into a new DIR: every one claims it.
    let shards = shards_at_once(dir, "sharded", 3);
    let mut solved = 0;
    for (i, o) in shards.iter().enumerate() {
        succeeds(o);
        let e = stderr(o);
        let summary =
            e.lines().find(|l| l.starts_with(&format!("shard {}/3 ", i + 1))).unwrap_or_else(|| panic!("{e}"));
        solved += summary.split(" solved").next().unwrap().rsplit(' ').next().unwrap().parse::<usize>().unwrap();
        assert!(e.contains("wrote the solve records only"), "{e}");
    }
    assert_eq!(solved, SWEEPS * 9);
    assert!(!dir.join("sharded/results.csv").exists() && !dir.join("sharded/figures").exists());
    // Each sweep's first load, and at most one more per cut between shards, started cold.
    let cold = cold_records(&dir.join("sharded"));
    assert!((SWEEPS..=SWEEPS + 2).contains(&cold), "{cold} cold starts");

    // The run without a shard solves nothing and writes the table and figures.
    let o = asperity(dir, &["run", "study.toml", "--out", "sharded"]);
    succeeds(&o);
    assert!(stderr(&o).contains(": 0 solved, 72 resumed"), "{}", stderr(&o));
    assert!(dir.join("sharded/figures/friction-drop.png").is_file());
    assert_eq!(columns(&dir.join("sharded/results.csv"))[0].1.len(), ROWS);
    // Within 100 times the solver's tolerance (measured: 2e-8 on the peak pressure, 1.5e-9 on
    // the friction drop); a wrong load or topography would be off by far more.
    let worst = same_results(&dir.join("sharded/results.csv"), &dir.join("whole/results.csv"), 100.0 * TOLERANCE);
    assert!(worst > 0.0, "a cold start gave the warm-started numbers bit for bit: is the piece cold?");
    same_results(&dir.join("sharded/resolution.csv"), &dir.join("whole/resolution.csv"), 100.0 * TOLERANCE);
    // No map is left once every chain is done.
    let warm = walk(&dir.join("sharded/solves")).into_iter().filter(|n| n.ends_with("-warm.npy")).count();
    assert_eq!(warm, 0);
}

fn walk(dir: &Path) -> Vec<String> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            names.extend(walk(&path));
        } else {
            names.push(path.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    names
}

#[test]
fn a_missing_shard_is_solved_by_the_assembling_run_and_overlapping_pieces_exclude_each_other() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    let mut shares = Vec::new();
    for shard in ["1/3", "3/3"] {
        let o = asperity(dir, &["run", "study.toml", "--out", "out", "--shard", shard]);
        succeeds(&o);
        let e = stderr(&o);
        // The closing line: "shard 1/3 of …: N solves, …".
        let closing = e.lines().find(|l| l.starts_with("shard ")).unwrap();
        shares.push(closing.split(" solves,").next().unwrap().rsplit(' ').next().unwrap().parse::<usize>().unwrap());
    }
    // A solve held by "another process" (this test): a run that needs it is refused, naming
    // the topography, until it goes.
    let folder = dir.join("out/solves/topographies/ball-1");
    let unit = walk(&folder).into_iter().find(|n| n.ends_with(".lock")).unwrap();
    let held = std::fs::File::create(folder.join(unit)).unwrap();
    held.lock().unwrap();
    let o = asperity(dir, &["run", "study.toml", "--out", "out"]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(e.contains("out is busy") && e.contains("topography \"ball-1\"") && e.lines().count() == 1, "{e}");
    drop(held);

    let o = asperity(dir, &["run", "study.toml", "--out", "out"]);
    succeeds(&o);
    let e = stderr(&o);
    let missing = SWEEPS * 9 - shares.iter().sum::<usize>();
    assert!(e.contains(&format!(": {missing} solved, {} resumed", SWEEPS * 9 - missing)), "{e}");
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "whole"]));
    same_results(&dir.join("out/results.csv"), &dir.join("whole/results.csv"), 100.0 * TOLERANCE);
}

#[test]
fn shards_racing_into_a_new_dir_all_claim_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Few loads and no figures: the claims are what races.
    let study = STUDY.replace("count = 9", "count = 2").replace("[\"friction-drop\", \"resolution\"]", "[]");
    std::fs::write(dir.join("study.toml"), study).unwrap();
    for round in 0..6 {
        let out = format!("race-{round}");
        for o in shards_at_once(dir, &out, 4) {
            succeeds(&o);
        }
        let o = asperity(dir, &["run", "study.toml", "--out", &out]);
        succeeds(&o);
        assert!(stderr(&o).contains(": 0 solved, 8 resumed"), "{}", stderr(&o));
    }
}

#[test]
fn bad_shards_are_refused_in_one_line_naming_the_option() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    for bad in ["0/3", "4/3", "1/0", "x", "-1/3", "2"] {
        let o = asperity(dir, &["run", "study.toml", "--out", "out", "--shard", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let e = stderr(&o);
        assert!(e.starts_with("error: --shard: ") && e.lines().count() == 1, "{bad}: {e}");
    }
    let o = asperity(dir, &["run", "study.toml", "--out", "out", "--shard", "1/2", "--fresh"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.join("out").exists());
    for (args, says) in [
        (&["--shards", "0"][..], "--shards"),
        (&["--shards", "100000000"], "--shards"),
        (&["--shards", "2", "--time", "1 h"], "--time"),
    ] {
        let o = asperity(dir, &[&["slurm", "study.toml", "--out", "out"][..], args].concat());
        assert!(!o.status.success());
        let e = stderr(&o);
        assert!(e.starts_with(&format!("error: {says}: ")) && e.lines().count() == 1, "{e}");
        assert!(!dir.join("out").exists());
    }
}

#[test]
fn slurm_values_are_refused_whole_in_slurms_forms() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    for (args, line, code) in [
        (
            &["--partition", "a\nb"][..],
            "error: --partition: 'a\\nb' cannot go in an #SBATCH line (no spaces, quotes or special characters)",
            1,
        ),
        (
            &["--time", "forever"],
            "error: --time: 'forever' is not a Slurm time limit: give minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, \
             D-HH:MM:SS or UNLIMITED",
            2,
        ),
        (
            &["--mem", "lots"],
            "error: --mem: 'lots' is not a Slurm memory size: give a whole number with an optional K, M, G or T \
             (4G, 500M)",
            2,
        ),
    ] {
        let o = asperity(dir, &[&["slurm", "study.toml", "--out", "out", "--shards", "2"][..], args].concat());
        assert_eq!(o.status.code(), Some(code), "{args:?}");
        assert_eq!(stderr(&o).trim_end(), line);
        assert!(!dir.join("out").exists());
    }
    let o =
        asperity(dir, &["slurm", "study.toml", "--out", "out", "--shards", "2", "--time", "1-12:00", "--mem", "4G"]);
    succeeds(&o);
    let script = std::fs::read_to_string(dir.join("out/slurm/shards.sh")).unwrap();
    assert!(script.contains("#SBATCH --time=1-12:00\n#SBATCH --mem=4G\n"), "{script}");
}

/// `scontrol show job ID`'s JobState of every job (or array task) `id` names.
fn job_states(id: &str) -> Vec<String> {
    let o = Command::new("scontrol").args(["show", "job", id]).output().unwrap();
    assert!(o.status.success(), "scontrol show job {id}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout)
        .split_whitespace()
        .filter_map(|w| w.strip_prefix("JobState="))
        .map(String::from)
        .collect()
}

/// Through a real Slurm: `.ci/run` starts one (tools/slurm-local.sh) and runs this test.
#[test]
#[ignore = "needs a running Slurm: .ci/run starts one with tools/slurm-local.sh"]
fn a_study_on_slurm_as_three_shards_gives_the_unsharded_results() {
    let started = Instant::now();
    match Command::new("sinfo").args(["-h", "-o", "%T"]).output() {
        Ok(o) if o.status.success() && String::from_utf8_lossy(&o.stdout).contains("idle") => {}
        Ok(o) => {
            let why = stderr(&o).lines().next().unwrap_or("no node idle").to_string();
            panic!("Slurm is not ready here (sinfo: {why}): start it with tools/slurm-local.sh")
        }
        Err(e) => panic!("Slurm is not here (sinfo: {e}): start it with tools/slurm-local.sh"),
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), STUDY).unwrap();
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "whole"]));

    let o = asperity(dir, &["slurm", "study.toml", "--shards", "3", "--out", "cluster", "--time", "10", "--submit"]);
    succeeds(&o);
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    let ids: Vec<&str> = stdout.lines().filter_map(|l| l.split("job ").nth(1)?.split(' ').next()).collect();
    assert_eq!(ids.len(), 2, "{stdout}");
    let deadline = Instant::now() + Duration::from_secs(300);
    for id in &ids {
        loop {
            let states = job_states(id);
            if states.iter().all(|s| s == "COMPLETED") {
                break;
            }
            let failed = states
                .iter()
                .any(|s| !["PENDING", "RUNNING", "CONFIGURING", "COMPLETING", "COMPLETED"].contains(&s.as_str()));
            let logs: Vec<String> =
                walk(&dir.join("cluster/slurm")).into_iter().filter(|n| n.ends_with(".log")).collect();
            assert!(!failed, "job {id}: {states:?} (logs: {logs:?} in {})", dir.join("cluster/slurm").display());
            assert!(Instant::now() < deadline, "job {id} not done after 5 minutes: {states:?}");
            std::thread::sleep(Duration::from_millis(500));
        }
    }
    let assembled = std::fs::read_to_string(dir.join("cluster/slurm/assemble.log")).unwrap();
    assert!(assembled.contains(": 0 solved, 72 resumed"), "{assembled}");
    for i in 1..=3 {
        let log = std::fs::read_to_string(dir.join(format!("cluster/slurm/shard-{i}.log"))).unwrap();
        assert!(log.contains(&format!("shard {i}/3 ")) && log.contains("solve records only"), "{log}");
    }
    same_results(&dir.join("cluster/results.csv"), &dir.join("whole/results.csv"), 100.0 * TOLERANCE);
    eprintln!("the Slurm study took {:.1} s", started.elapsed().as_secs_f64());
}

/// Elastic sharing: one ball at 48², four loads, one law.
const ELASTIC: &str = r#"
[[topography]]
name = "ball-1"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [48, 48], seed = 3, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }

[loads]
values = ["0.1 mN", "0.3 mN", "1 mN", "3 mN"]

[[law]]
preset = "hold 100 s"

[model]
sharing = ["equal", "elastic"]

[output]
figures = []
"#;

#[test]
fn sharded_elastic_sharing_equals_the_unsharded_run_bit_for_bit() {
    // An elastic onset follows its solve's pressure to the last bit: sharded and unsharded runs
    // solve every load of an elastic study from the same (cold) start, so every column but
    // the timings and iteration counts is equal, to the digit.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("study.toml"), ELASTIC).unwrap();
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "whole"]));
    for shard in ["1/3", "2/3", "3/3"] {
        succeeds(&asperity(dir, &["run", "study.toml", "--out", "sharded", "--shard", shard]));
    }
    succeeds(&asperity(dir, &["run", "study.toml", "--out", "sharded"]));
    let (sharded, whole) = (columns(&dir.join("sharded/results.csv")), columns(&dir.join("whole/results.csv")));
    assert_eq!(sharded.len(), whole.len());
    for ((name, a), (_, b)) in sharded.iter().zip(&whole) {
        // Timings only: every solve started cold, so even the iteration counts agree.
        if !name.ends_with("seconds") {
            assert_eq!(a, b, "{name}");
        }
    }
    let sharing = &whole.iter().find(|c| c.0 == "sharing").unwrap().1;
    assert_eq!(sharing.iter().filter(|s| *s == "elastic").count(), 4, "{sharing:?}");
    assert_eq!(cold_records(&dir.join("whole")), 4);
}
