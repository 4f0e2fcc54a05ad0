//! A study with `[model] sharing = ["equal", "elastic"]`: both sharings' rows, the elastic
//! drop's bounds and its single-element limit, the comparison figure, resume and shards that
//! solve nothing twice; without `[model]`, the results of equal sharing alone.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

/// Two small balls (64², 486 nm pixels): one element at 0.1 µN, 3–5 at 1 mN, 77–86 at 30 mN.
const BALLS: &str = r#"
[[topography]]
name = "a"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 1, roughness = { hurst = 0.8, rms_height_m = "21 nm", rolloff_wavelength_m = "7 µm", short_cutoff_wavelength_m = "1 µm" }, cap = { radius_m = "1.5 mm" } }

[[topography]]
name = "b"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 2, roughness = { hurst = 0.8, rms_height_m = "21 nm", rolloff_wavelength_m = "7 µm", short_cutoff_wavelength_m = "1 µm" }, cap = { radius_m = "1.5 mm" } }
"#;

/// The default laws (hold 100 s: 0.6/0.4, hold 10 s: 0.5/0.4) apply.
const REST: &str = r#"
[loads]
values = ["0.1 µN", "1 mN", "30 mN"]

[model]
sharing = ["equal", "elastic"]

[output]
figures = ["friction-drop", "friction-drop-sharing", "resolution"]
"#;

fn asperity(dir: &Path, args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).current_dir(dir).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The rows of a CSV file as maps from column to value.
fn table(path: &Path) -> Vec<HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    reader.records().map(|r| header.iter().cloned().zip(r.unwrap().iter().map(String::from)).collect()).collect()
}

fn num(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column].parse().unwrap_or_else(|_| panic!("{column} = {:?}", row[column]))
}

#[test]
fn both_sharings_give_their_rows_figure_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), format!("{BALLS}{REST}")).unwrap();
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    // 6 solves of the study's grid and 12 of the resolution figure's coarser copies.
    assert!(stderr(&o).contains("18 solved, 0 resumed"), "{}", stderr(&o));
    // An onset's cost grows with its contact points, unknown before its solve: a batch log
    // counts solves and onsets together and tells no time left.
    let start = "solving: 18 solves (0 done by an earlier run) and 12 elastic onsets (0 done by an earlier run), \
                 counted together, without an estimate of the time left";
    assert!(stderr(&o).contains(start), "{}", stderr(&o));
    assert!(stderr(&o).contains("solving: 30/30 solves and elastic onsets after "), "{}", stderr(&o));
    let out = dir.path().join("r");
    let rows = table(&out.join("results.csv"));
    // 2 topographies × 3 models × 2 laws × 3 loads, model before law: the paper's equal
    // sharing, equal sharing under elastic sharing's slip weakening (2 nm), elastic sharing.
    assert_eq!(rows.len(), 36);
    let order: Vec<(&str, f64)> =
        rows.iter().step_by(3).map(|r| (r["sharing"].as_str(), num(r, "slip_distance_m"))).collect();
    let models =
        [("equal", 0.0), ("equal", 0.0), ("equal", 2e-9), ("equal", 2e-9), ("elastic", 2e-9), ("elastic", 2e-9)];
    assert_eq!(order, [models, models].concat());

    let mut compared = 0;
    let papers = |r: &&HashMap<String, String>| r["sharing"] == "equal" && num(r, "slip_distance_m") == 0.0;
    for equal in rows.iter().filter(papers) {
        assert!(equal["slide_iterations"].is_empty() && equal["slide_seconds"].is_empty());
        let find = |sharing: &str, slip: f64| {
            rows.iter()
                .find(|r| {
                    r["sharing"] == sharing
                        && num(r, "slip_distance_m") == slip
                        && r["topography"] == equal["topography"]
                        && r["law"] == equal["law"]
                        && r["load_n"] == equal["load_n"]
                })
                .expect("a row of each model for every equal one")
        };
        let (elastic, weakening) = (find("elastic", 2e-9), find("equal", 2e-9));
        // The same solve: its contact columns are the equal row's.
        for column in ["contact_points", "patches", "max_pressure_pa", "mu_s", "mu_d", "dynamic_coefficient"] {
            assert_eq!(elastic[column], equal[column], "{column}");
            assert_eq!(weakening[column], equal[column], "{column}");
        }
        assert!(weakening["slide_iterations"].is_empty());
        assert!(num(elastic, "slide_iterations") > 0.0 && num(elastic, "slide_seconds") > 0.0);
        let (limit, points) = (num(equal, "mu_s") / num(equal, "mu_d"), num(equal, "contact_points"));
        let (de, dw, dl) =
            (num(equal, "friction_drop"), num(weakening, "friction_drop"), num(elastic, "friction_drop"));
        for (row, drop) in [(elastic, dl), (weakening, dw)] {
            assert!(drop >= 1.0 - 1e-9 && drop <= limit * (1.0 + 1e-9), "drop {drop} outside [1, {limit}]");
            assert!((num(row, "static_coefficient") - drop * num(row, "mu_d")).abs() < 1e-12);
            // Elastic rows split the slipped elements into the fully weakened (pre-sliding)
            // and the weakening; equal rows leave the weakening columns empty.
            let elastic_row = row["sharing"] == "elastic";
            assert_eq!(row["weakening_count"].is_empty(), !elastic_row);
            let names: &[&str] = if elastic_row {
                &["critical", "pre_sliding", "subcritical", "weakening"]
            } else {
                &["critical", "pre_sliding", "subcritical"]
            };
            let classes: f64 = names.iter().map(|c| num(row, &format!("{c}_count"))).sum();
            assert_eq!(classes, points);
            for share in ["normal", "friction"] {
                let fractions: f64 = names.iter().map(|c| num(row, &format!("{c}_{share}_fraction"))).sum();
                assert!((fractions - 1.0).abs() < 1e-9, "{share} fractions sum to {fractions}");
            }
        }
        if points == 1.0 {
            // One element: every model gives the local law's mu_s/mu_d.
            for d in [de, dw, dl] {
                assert!((d - limit).abs() < 1e-9 * limit, "{d} {limit}");
            }
            assert_eq!(num(elastic, "critical_count"), 1.0);
            assert_eq!(num(weakening, "critical_count"), 1.0);
        }
        // Weakening over a slip only adds to what an element carries when others slip: never
        // below the paper's drop.
        assert!(dw >= de * (1.0 - 1e-12), "{dw} {de}");
        if num(equal, "load_n") == 0.03 {
            // Elastic interaction lowers the drop at the highest load, against equal sharing
            // under the same weakening (by 0.3–3.4 % here).
            assert!(dl < dw, "{}/{}: elastic {dl} not below equal {dw}", equal["topography"], equal["law"]);
            compared += 1;
        }
    }
    assert_eq!(compared, 4);
    assert!(rows.iter().any(|r| r["load_n"] == "1e-7" && r["contact_points"] == "1"));

    // resolution.csv holds the equal rows only, its own pixel's as the study's.
    let resolution = table(&out.join("resolution.csv"));
    assert_eq!(resolution.iter().filter(|r| r["coarsening"] == "1").count(), 12);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["rows"].as_array().unwrap().iter().filter(|r| r["sharing"] == "elastic").count(), 12);

    for f in ["friction-drop-sharing.png", "friction-drop-sharing.svg", "friction-drop.png"] {
        assert!(out.join("figures").join(f).is_file(), "{f}");
    }
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(report.contains("figures/friction-drop-sharing.png"));
    assert!(report.contains("by more than 10% at every load for &quot;hold 100 s&quot; from N = 30 mN on"), "{report}");
    // The interaction and the weakening apart: per law and load, in the figure's caption and a
    // table of the report (on these 486 nm pixels every element snaps: the weakening moves
    // nothing).
    assert!(report.contains("The weakening alone (equal sharing, with it against the instant drop) moves the mean drop for &quot;hold 100 s&quot; by +0.0000 to +0.0000"), "{report}");
    assert!(report.contains("<th>hold 100 s: weakening</th><th>hold 100 s: interaction</th>"), "{report}");

    // Run again: every solve, elastic onsets included, comes from its record.
    let before = std::fs::read(out.join("results.csv")).unwrap();
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    assert!(stderr(&o).contains("0 solved, 18 resumed"), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), before);

    // Without elastic sharing: every solve is recorded already, and the table leaves the
    // elastic rows out (their records keep them).
    std::fs::write(
        dir.path().join("study.toml"),
        format!(
            "{BALLS}{}",
            REST.replace("\"equal\", \"elastic\"", "\"equal\"").replace(", \"friction-drop-sharing\"", "")
        ),
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", "r"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(stderr(&o).contains("0 solved, 18 resumed"), "{}", stderr(&o));
    let table = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(!table.contains(",elastic,") && table.lines().count() == 1 + 12, "{table}");
}

#[test]
fn equal_sharing_alone_is_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let rest = REST.replace("[model]\nsharing = [\"equal\", \"elastic\"]\n", "").replace("\"30 mN\"", "\"10 mN\"");
    // The sharing figure, named, needs elastic sharing.
    std::fs::write(dir.path().join("study.toml"), format!("{BALLS}{rest}")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", "study.toml", "--out", "r"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!o.status.success() && stderr(&o).contains("add \"elastic\" to [model] sharing"), "{}", stderr(&o));
    // In the list of every figure it is left out, and the report says why.
    let every = "figures = [\"friction-drop\", \"friction-drop-sharing\", \"resolution\"]";
    assert!(rest.contains(every));
    std::fs::write(dir.path().join("study.toml"), format!("{BALLS}{}", rest.replace(every, ""))).unwrap();
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    // A batch log counts the solves and tells the time left from their grid points.
    assert!(stderr(&o).contains("solving: 18 solves (0 done by an earlier run)\n"), "{}", stderr(&o));
    assert!(stderr(&o).contains("solving: 18/18 solves, about 0 s left after "), "{}", stderr(&o));
    let out = dir.path().join("r");
    let rows = table(&out.join("results.csv"));
    assert_eq!(rows.len(), 12);
    assert!(rows.iter().all(|r| r["sharing"] == "equal" && r["slide_iterations"].is_empty()));
    assert!(!std::fs::read_to_string(out.join("study.toml")).unwrap().contains("[model]"));
    assert!(!out.join("figures/friction-drop-sharing.png").exists());
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(report.contains("no elastic-sharing rows: list &quot;elastic&quot; in [model] sharing"));
}

#[test]
fn shards_record_the_elastic_onsets() {
    let dir = tempfile::tempdir().unwrap();
    let rest = small_rest();
    std::fs::write(dir.path().join("study.toml"), format!("{BALLS}{rest}")).unwrap();
    for shard in ["1/2", "2/2"] {
        let o = asperity(dir.path(), &["run", "study.toml", "--out", "r", "--shard", shard]);
        // Two laws' onsets per solve.
        assert!(stderr(&o).contains("3 solves, 3 solved, 0 resumed; 6 elastic onsets run, in"), "{}", stderr(&o));
    }
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    assert!(stderr(&o).contains("0 solved, 6 resumed, in"), "{}", stderr(&o));
    let rows = table(&dir.path().join("r/results.csv"));
    assert_eq!(rows.len(), 36);
    assert_eq!(rows.iter().filter(|r| r["sharing"] == "elastic" && !r["slide_iterations"].is_empty()).count(), 12);
}

#[test]
fn a_break_at_an_elastic_onset_interrupts_and_the_run_resumes() {
    use asperity::study::run::Progress;
    use std::ops::ControlFlow;

    let dir = tempfile::tempdir().unwrap();
    let rest = small_rest();
    let study = prepared(&format!("{BALLS}{rest}"));
    let out = dir.path().join("r");
    let stop = |event: Progress| match event {
        Progress::Slid { .. } => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    };
    let e = study.run(&out, false, &stop).unwrap_err();
    assert!(matches!(e, asperity::Error::Interrupted { .. }), "{e}");
    // The onsets run in any order, over all threads: each one finished before the stop is
    // recorded beside its solve's normal part and map (one under way at it stops at its next
    // step, unrecorded), and no solve is.
    let names = |t: &str| {
        let mut n: Vec<String> = std::fs::read_dir(out.join("solves/topographies").join(t))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        n.sort();
        n
    };
    let mut parts = 0;
    for t in ["a", "b"] {
        for name in names(t) {
            if let Some((solve, _)) = name.split_once("-elastic-") {
                assert!(names(t).contains(&format!("{solve}-normal.json")), "{t}: {name}");
                assert!(names(t).contains(&format!("{solve}-warm.npy")), "{t}: {name}");
                parts += 1;
            } else {
                assert!(
                    name.ends_with("-normal.json") || name.ends_with("-warm.npy") || name.ends_with(".lock"),
                    "{name}"
                );
            }
        }
    }
    assert!(parts > 0);

    let slid = std::sync::atomic::AtomicUsize::new(0);
    // Each onset run reports its steps as it goes (their count rising), before it is done.
    let steps = std::sync::Mutex::new(std::collections::HashMap::new());
    let searched = std::sync::Mutex::new(std::collections::HashMap::new());
    let count = |event: Progress| match event {
        Progress::Slid { topography, load_n, law, iterations, .. } => {
            assert!(law.starts_with("hold") && iterations > 0);
            let key = (topography.to_string(), load_n.to_bits(), law.to_string());
            assert!(steps.lock().unwrap().get(&key).is_some_and(|s| *s > 0), "{key:?}");
            slid.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        Progress::Sliding { topography, load_n, law, stage, steps: n, solves, largest_drop, .. } => {
            assert!(solves >= n);
            assert!(largest_drop > 0.0 && largest_drop < 0.6 / 0.4 * (1.0 + 1e-9), "{largest_drop}");
            let key = (topography.to_string(), load_n.to_bits(), law.to_string());
            // The march, then the search: never back.
            let searching = stage == asperity::friction::SlideStage::Search;
            let last = searched.lock().unwrap().insert(key.clone(), searching);
            assert!(searching || last != Some(true), "{key:?} marched after its search");
            let last = steps.lock().unwrap().insert(key, n);
            assert!(last.is_none_or(|last| n > last), "{last:?} then {n}");
        }
        _ => {}
    };
    let outcome = study.run(&out, false, &count).unwrap();
    assert_eq!((outcome.solved, outcome.resumed, outcome.onsets_resumed), (6, 0, parts));
    // Two laws' onsets for each solve run now, but those recorded before the stop.
    assert_eq!(slid.into_inner(), 2 * outcome.solved - parts);
    assert_eq!(outcome.onsets, 2 * outcome.solved - parts);
    assert_eq!(outcome.rows.iter().filter(|r| r.sharing == asperity::study::Sharing::Elastic).count(), 12);
    // The solves' parts gave way to their records: one per load, beside its lock.
    for t in ["a", "b"] {
        let names = names(t);
        let records = names.iter().filter(|n| n.ends_with(".json")).count();
        let locks = names.iter().filter(|n| n.ends_with(".lock")).count();
        assert_eq!((records, locks, names.len()), (3, 3, 6), "{names:?}");
    }
}

/// The study's other sections with 3 mN as the largest load and no resolution figure: a small
/// study that runs in a second or two.
fn small_rest() -> String {
    REST.replace("\"30 mN\"", "\"3 mN\"").replace(", \"resolution\"", "")
}

/// The study of `text`, prepared.
fn prepared(text: &str) -> asperity::study::run::Study {
    let config = asperity::study::config::StudyConfig::parse(text, "study.toml").unwrap();
    asperity::study::run::Study::prepare(config, "study.toml").unwrap()
}

/// The rows without their timings.
fn untimed(rows: &[asperity::study::Row]) -> Vec<asperity::study::Row> {
    let mut rows = rows.to_vec();
    for r in &mut rows {
        r.seconds = 0.0;
        r.slide_seconds = r.slide_seconds.map(|_| 0.0);
    }
    rows
}

#[test]
fn a_break_in_an_onset_under_way_stops_it_there_and_the_run_resumes() {
    use asperity::study::run::Progress;
    use std::ops::ControlFlow;
    use std::sync::Mutex;

    let dir = tempfile::tempdir().unwrap();
    let rest = small_rest();
    let study = prepared(&format!("{BALLS}{rest}"));
    let whole = study.run(&dir.path().join("whole"), false, &|_: Progress| ()).unwrap();
    // Stopped at the fifth step of the first onset to get there.
    let out = dir.path().join("r");
    let stopped = Mutex::new(None);
    let stop = |event: Progress| match event {
        Progress::Sliding { topography, load_n, law, steps, .. } if steps >= 5 => {
            stopped.lock().unwrap().get_or_insert((topography.to_string(), load_n.to_bits(), law.to_string()));
            ControlFlow::Break(())
        }
        _ => ControlFlow::Continue(()),
    };
    let e = study.run(&out, false, &stop).unwrap_err();
    assert!(matches!(e, asperity::Error::Interrupted { .. }), "{e}");
    let stopped = stopped.into_inner().unwrap().expect("an onset took 5 steps");
    // Resumed, it runs that onset again (it was not recorded) and gives the whole run's rows.
    let slid = Mutex::new(Vec::new());
    let resumed = study
        .run(&out, false, &|event: Progress| {
            if let Progress::Slid { topography, load_n, law, .. } = event {
                slid.lock().unwrap().push((topography.to_string(), load_n.to_bits(), law.to_string()));
            }
        })
        .unwrap();
    assert!(slid.into_inner().unwrap().contains(&stopped), "{stopped:?}");
    assert_eq!(untimed(&resumed.rows), untimed(&whole.rows));
}

#[test]
fn an_elastic_onset_finished_before_a_stop_is_not_run_again() {
    use asperity::study::run::Progress;
    use std::ops::ControlFlow;
    use std::sync::Mutex;

    let dir = tempfile::tempdir().unwrap();
    // One ball, three loads, two laws; on one thread, so that the stop falls where asked: the
    // sweep solves its loads, then the onsets run, the largest contact set first.
    let ball = BALLS.split("\n[[topography]]").nth(1).unwrap();
    let rest = small_rest();
    let study = prepared(&format!("[[topography]]{ball}{rest}"));
    let (loads, laws) = (study.loads().to_vec(), study.laws().to_vec());
    assert_eq!((loads.len(), laws.len()), (3, 2));
    let first_law = asperity::study::law_name(&laws[0]);
    let second_law = asperity::study::law_name(&laws[1]);
    // On all threads, in whatever order the onsets end.
    let whole = study.run(&dir.path().join("whole"), false, &|_: Progress| ()).unwrap();
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();

    // Stopped once the first law's onset at the second load is done: the third load's onsets
    // are done and recorded, and so are the three normal solves and that onset; no solve's
    // record (they are written in load order, the first load's onsets not run).
    let out = dir.path().join("stopped");
    let order = Mutex::new(Vec::new());
    let stop = |event: Progress| match event {
        Progress::Slid { load_n, law, .. } => {
            order.lock().unwrap().push((load_n, law.to_string()));
            if load_n == loads[1] && law == first_law {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
        _ => ControlFlow::Continue(()),
    };
    assert!(matches!(one_thread.install(|| study.run(&out, false, &stop)), Err(asperity::Error::Interrupted { .. })));
    let largest_first = [(loads[2], first_law.clone()), (loads[2], second_law.clone()), (loads[1], first_law.clone())];
    assert_eq!(order.into_inner().unwrap(), largest_first);
    let folder = out.join("solves/topographies/a");
    // Each load's files (`<load>N-<digest>…`): its lock, normal solve and map, and the onsets
    // done (none at the first load, one at the second, both at the third); no record.
    let of_load = |k: usize| -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n.starts_with(&format!("{:e}N-", loads[k])))
            .collect();
        names.sort();
        names
    };
    for (k, onsets) in [(0, 0), (1, 1), (2, 2)] {
        let names = of_load(k);
        let count = |end: &str| names.iter().filter(|n| n.ends_with(end)).count();
        let elastic = names.iter().filter(|n| n.contains("-elastic-")).count();
        assert_eq!(
            (count(".lock"), count("-normal.json"), count("-warm.npy"), elastic),
            (1, 1, 1, onsets),
            "{names:?}"
        );
        assert_eq!(names.len(), 3 + onsets, "{names:?}");
    }

    let slid = Mutex::new(Vec::new());
    let solved = Mutex::new(Vec::new());
    let start = Mutex::new(None);
    let resumed = one_thread
        .install(|| {
            study.run(&out, false, &|event: Progress| match event {
                Progress::Slid { load_n, law, .. } => slid.lock().unwrap().push((load_n, law.to_string())),
                Progress::Solved { load_n, .. } => solved.lock().unwrap().push(load_n),
                Progress::Sliding { .. } => {}
                Progress::Start { total, done, onsets, onsets_done, .. } => {
                    *start.lock().unwrap() = Some((total, done, onsets, onsets_done))
                }
            })
        })
        .unwrap();
    assert_eq!((resumed.solved, resumed.resumed, resumed.onsets_resumed), (3, 0, 3));
    // The progress counts 3 solves and their 6 onsets: 3 onsets done.
    assert_eq!(start.into_inner().unwrap(), Some((3, 0, 6, 3)));
    let expected = [(loads[1], second_law.clone()), (loads[0], first_law.clone()), (loads[0], second_law.clone())];
    assert_eq!(slid.into_inner().unwrap(), expected);
    // Recorded in load order once the first load's onsets are done.
    assert_eq!(solved.into_inner().unwrap(), loads);
    // The same results as the uninterrupted run, bit for bit apart from the timings; with
    // elastic sharing every solve starts cold, in the whole run as in the resumed one.
    assert_eq!(untimed(&resumed.rows), untimed(&whole.rows));
    // Each load's record and lock, nothing else.
    for k in 0..3 {
        let names = of_load(k);
        assert!(names.len() == 2 && names[0].ends_with(".json") && names[1].ends_with(".lock"), "{names:?}");
        let record: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(folder.join(&names[0])).unwrap()).unwrap();
        assert_eq!(record["cold"], true);
    }
}

#[test]
fn a_band_of_slip_distances_adds_its_onsets_and_a_dir_grows_and_shrinks_with_it() {
    let dir = tempfile::tempdir().unwrap();
    let ball = BALLS.split("\n[[topography]]").nth(1).unwrap();
    let rest = small_rest();
    let sharing = "sharing = [\"equal\", \"elastic\"]\n";
    let banded = rest.replace(sharing, &format!("{sharing}slip_distance_band = [\"1 nm\", \"5 nm\"]\n"));
    assert_ne!(banded, rest);
    let write =
        |rest: &str| std::fs::write(dir.path().join("study.toml"), format!("[[topography]]{ball}{rest}")).unwrap();
    write(&rest);
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    assert!(stderr(&o).contains("3 solved, 0 resumed; 6 elastic onsets run, in"), "{}", stderr(&o));
    let out = dir.path().join("r");
    let before = table(&out.join("results.csv"));
    assert_eq!(before.len(), 18);

    // The band added: its ends' onsets alone are computed, those at d_c kept from the records
    // (each normal solve is solved again: the records keep no pressure map).
    write(&banded);
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    assert!(
        stderr(&o).contains("3 solved, 0 resumed; 12 elastic onsets run, 6 recorded before kept, in"),
        "{}",
        stderr(&o)
    );
    let rows = table(&out.join("results.csv"));
    // Per law and load: the paper's, and equal and elastic sharing at 2 nm, 1 nm and 5 nm.
    assert_eq!(rows.len(), 3 * 2 * 7);
    // The rows at d_c are those of the run without the band, bit for bit but the timings.
    let untimed = |r: &HashMap<String, String>| {
        let mut r = r.clone();
        for c in ["seconds", "slide_seconds"] {
            r.remove(c);
        }
        r
    };
    let at_dc: Vec<_> = rows.iter().filter(|r| !["1e-9", "5e-9"].contains(&r["slip_distance_m"].as_str())).collect();
    assert_eq!(at_dc.iter().map(|r| untimed(r)).collect::<Vec<_>>(), before.iter().map(untimed).collect::<Vec<_>>());
    let find = |r: &HashMap<String, String>, sharing: &str, d: f64| -> f64 {
        let found: Vec<_> = rows
            .iter()
            .filter(|s| {
                s["sharing"] == sharing
                    && num(s, "slip_distance_m") == d
                    && s["law"] == r["law"]
                    && s["load_n"] == r["load_n"]
            })
            .collect();
        assert_eq!(found.len(), 1, "{sharing} {d} {} {}", r["law"], r["load_n"]);
        num(found[0], "friction_drop")
    };
    let papers = |r: &&HashMap<String, String>| r["sharing"] == "equal" && num(r, "slip_distance_m") == 0.0;
    let mut rising = 0;
    for paper in rows.iter().filter(papers) {
        let limit = num(paper, "mu_s") / num(paper, "mu_d");
        let elastic: Vec<f64> = [1e-9, 2e-9, 5e-9].iter().map(|&d| find(paper, "elastic", d)).collect();
        let equal: Vec<f64> = [1e-9, 2e-9, 5e-9].iter().map(|&d| find(paper, "equal", d)).collect();
        if paper["contact_points"] == "1" {
            // One element: every model gives the local law's mu_s/mu_d at every d_c.
            for d in elastic.iter().chain(&equal) {
                assert!((d - limit).abs() < 1e-9 * limit, "{d} {limit}");
            }
            continue;
        }
        // On 3 and 12 elements: the drops never fall as d_c grows, move by less than 2e-4 from
        // 1 to 2 nm, and the elastic one rises by 0.03–0.09 from 2 to 5 nm.
        for drops in [&elastic, &equal] {
            assert!(drops[0] <= drops[1] * (1.0 + 1e-9) && drops[1] <= drops[2] * (1.0 + 1e-9), "{drops:?}");
            assert!(drops[1] - drops[0] < 2e-4, "{drops:?}");
        }
        assert!(elastic[2] - elastic[1] > 0.02, "{elastic:?}");
        rising += 1;
    }
    assert_eq!(rising, 4);
    // Measured at 3 mN for "hold 100 s": 1.1414, 1.1414, 1.1838 under elastic sharing.
    let at = |d: f64| {
        let r = rows.iter().find(|r| r["law"] == "hold 100 s" && r["load_n"] == "0.003").unwrap();
        find(r, "elastic", d)
    };
    for (d, drop) in [(1e-9, 1.1414), (2e-9, 1.1414), (5e-9, 1.1838)] {
        assert!((at(d) - drop).abs() < 1e-3, "{d}: {}", at(d));
    }
    let svg = std::fs::read_to_string(out.join("figures/friction-drop-sharing.svg")).unwrap();
    // The band's legend entries (d_c typeset with its subscript).
    for model in ["elastic sharing", "equal sharing, weakening"] {
        assert!(svg.contains(&format!("hold 100 s: {model}, range over 1 topography and d")), "legend: {model}");
    }
    assert_eq!(svg.matches("1 nm to 5 nm").count(), 4, "a band per law and model");
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(report.contains("from d_c = 1 nm to 5 nm (the lines stay at d_c = 2 nm)"), "caption");
    assert!(report.contains("<th>elastic, d<sub>c</sub> 1 nm</th><th>elastic, d<sub>c</sub> 2 nm</th>"), "table");

    // The band removed: nothing is solved, the table is the one before.
    write(&rest);
    let o = asperity(dir.path(), &["run", "study.toml", "--out", "r"]);
    assert!(stderr(&o).contains("0 solved, 3 resumed, in"), "{}", stderr(&o));
    let after = table(&out.join("results.csv"));
    assert_eq!(after.iter().map(untimed).collect::<Vec<_>>(), before.iter().map(untimed).collect::<Vec<_>>());
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!report.contains("d<sub>c</sub> 1 nm"), "no band table without the band");
}
