//! Adhesion in the study: the `[contact] adhesion` key and its refusals, the adhesive solves
//! beside the non-adhesive ones (the friction model on the compressive pressure, both drops in
//! the table), and a DIR that grows from the non-adhesive study to the adhesive one.

use std::path::Path;
use std::process::Command;

use asperity::friction::{ElementLoads, FrictionLaw, Onset};
use asperity::study::config::StudyConfig;

/// A 1.5 mm sphere on a 16 µm window of 64² pixels (250 nm) against a wafer of 0.2 nm RMS,
/// from 10 µN to 10 mN; an exponential law of 1 mJ/m² and 1 nm range, whose tension spans
/// several pixels round the contact (the gap there grows by a fraction of a nanometre per
/// pixel), so that no load falls in a jump. `{boundary}` and `{adhesion}` are filled in.
const STUDY: &str = r#"
[[topography]]
name = "ball"
synthetic = { size_m = ["16 µm", "16 µm"], grid = [64, 64], seed = 1, cap = { radius_m = "1.5 mm" } }
wafer = { synthetic = { size_m = ["16 µm", "16 µm"], grid = [64, 64], seed = 101, roughness = { hurst = 0.8, rms_height_m = "0.2 nm" } } }

[contact]
boundary = "{boundary}"
{adhesion}

[loads]
values = ["10 µN", "100 µN", "1 mN", "10 mN"]

[[law]]
name = "pair"
mu_s = 0.6
mu_d = 0.4

[output]
figures = ["friction-drop"]
pressure_maps = true
"#;

const ADHESION: &str = r#"adhesion = { work = "1 mJ/m2", range = "1 nm", law = "exponential" }"#;

fn study(boundary: &str, adhesion: &str) -> String {
    STUDY.replace("{boundary}", boundary).replace("{adhesion}", adhesion)
}

fn run(dir: &Path, file: &str, text: &str) -> std::process::Output {
    std::fs::write(dir.join(file), text).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["run", file, "--out", "out"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// The rows of `results.csv` as (header → value) maps.
fn table(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| header.iter().map(String::from).zip(r.unwrap().iter().map(String::from)).collect())
        .collect()
}

fn number(row: &std::collections::HashMap<String, String>, column: &str) -> f64 {
    row[column].parse().unwrap_or_else(|_| panic!("{column} = {:?}", row[column]))
}

fn parse_err(adhesion: &str) -> String {
    let text = format!("[contact]\nadhesion = {adhesion}\n");
    StudyConfig::parse(&text, "study.toml").unwrap_err().to_string()
}

#[test]
fn the_adhesion_key_reads_as_the_command_lines_options_and_refuses_in_one_line() {
    let parse = |t: &str| StudyConfig::parse(&format!("[contact]\nadhesion = {t}\n"), "s.toml").unwrap();
    let c = parse(r#"{ work = "50 mJ/m2", stress = "100 MPa" }"#);
    let law = c.contact.adhesion.as_ref().unwrap().cohesive_law().unwrap();
    assert_eq!(law, asperity::contact::CohesiveLaw::Maugis { work: 0.05, stress: 1e8 });
    let c = parse(r#"{ work = 0.05, range = "2 nm", law = "exponential" }"#);
    let law = c.contact.adhesion.as_ref().unwrap().cohesive_law().unwrap();
    assert_eq!(law, asperity::contact::CohesiveLaw::Exponential { work: 0.05, range: 2e-9 });
    // The Maugis–Dugdale law by its range: σ₀ = w/h₀.
    let c = parse(r#"{ work = "50 mJ/m2", range = "0.5 nm" }"#);
    let law = c.contact.adhesion.as_ref().unwrap().cohesive_law().unwrap();
    assert_eq!(law, asperity::contact::CohesiveLaw::Maugis { work: 0.05, stress: 0.05 / 0.5e-9 });
    assert!(StudyConfig::default_study().contact.adhesion.is_none());

    let e = parse_err(r#"{ work = "50 J/m2", stress = "100 MPa" }"#);
    assert!(
        e.starts_with("study.toml:2:") && e.contains("contact.adhesion.work: 50 J/m² is not a work of adhesion"),
        "{e}"
    );
    assert!(e.contains("did you mean"), "{e}");
    // The key's form and a sign, in the study file's words and units.
    let e = parse_err("true");
    assert!(e.ends_with("contact.adhesion: invalid type: boolean `true`, expected a table such as { work = \"50 mJ/m2\", range = \"0.3 nm\" }"), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2", range = -1e-9 }"#);
    assert!(e.ends_with("contact.adhesion.range: must be positive, got -1 nm"), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2", stress = "100 MPa", range = "1 nm" }"#);
    assert!(e.contains("contact.adhesion.stress: give the law's strength `stress` or its `range`, not both"), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2" }"#);
    assert!(e.contains("contact.adhesion.work: needs `stress` or `range`"), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2", range = "1 nm", law = "jkr" }"#);
    assert!(e.contains("contact.adhesion.law: 'jkr' is not \"maugis\" or \"exponential\""), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2", range = "-1 nm" }"#);
    assert!(e.contains("contact.adhesion.range: must be positive"), "{e}");
    // A range or stress typed without its unit lands decades away: refused with the unit meant.
    let e = parse_err(r#"{ work = 0.05, range = 0.3 }"#);
    assert!(
        e.contains("contact.adhesion.range: 300 mm is not the range of a cohesive law") && e.contains("\"0.3 nm\""),
        "{e}"
    );
    let e = parse_err(r#"{ work = 0.05, stress = 1 }"#);
    assert!(e.contains("contact.adhesion.stress: 1 Pa is not a cohesive stress") && e.contains("\"1 GPa\""), "{e}");
    let e = parse_err(r#"{ work = "50 mJ/m2", range = "1 nm", tension = 1 }"#);
    assert!(e.contains("unknown field `tension`"), "{e}");
    let e = StudyConfig::parse(
        "[material]\nhardness = \"12 GPa\"\n[contact]\nplastic = true\nadhesion = { work = 0.05, range = 1e-9 }\n",
        "study.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("contact.plastic: is not solved with adhesion"), "{e}");
    assert!(!e.contains('\n'), "one line: {e}");
    // Without a hardness too: the adhesion is what refuses it, not the missing hardness.
    let e = StudyConfig::parse("[contact]\nplastic = true\nadhesion = { work = 0.05, range = 1e-9 }\n", "study.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("contact.plastic: is not solved with adhesion"), "{e}");
}

/// The ball on its wafer, free boundary: each adhesive solve carries its load (N_c − N_a = N),
/// the friction model's elements are its compressive pressure (the paper's equal sharing on
/// that map gives the AFM-definition drop to rounding), the two drops are related by
/// N/(N + N_a) row by row, and at 10 mN, where N_a/N is below a percent, the drops with and
/// without adhesion agree within 1 %.
#[test]
fn adhesive_solves_feed_the_friction_model_their_compressive_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(dir.path(), "study.toml", &study("free", ADHESION));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("adhesive"), "the summary shows the adhesive rows apart: {stdout}");
    let out = dir.path().join("out");
    let rows = table(&out.join("results.csv"));
    assert_eq!(rows.len(), 8);
    let (plain, adhesive): (Vec<_>, Vec<_>) = rows.iter().partition(|r| r["adhesive_force_n"].is_empty());
    assert_eq!((plain.len(), adhesive.len()), (4, 4));
    assert!(plain.iter().all(|r| r["friction_drop_total_load"].is_empty()));
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    let pixel = 16e-6 / 64.0;
    let maps = out.join("pressure/ball/adhesive");
    let mut names: Vec<String> =
        std::fs::read_dir(&maps).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names.len(), 4, "{names:?}");
    for (r, p) in adhesive.iter().zip(&plain) {
        let (load, na) = (number(r, "load_n"), number(r, "adhesive_force_n"));
        assert_eq!(load, number(p, "load_n"));
        assert!(na > 0.0, "an adhesive force at {load} N: {na}");
        let (drop, total) = (number(r, "friction_drop"), number(r, "friction_drop_total_load"));
        assert!((total / (drop * load / (load + na)) - 1.0).abs() < 1e-12, "{load} N: {total} against {drop}");
        // The map of this load: its name starts with the load.
        let name = names.iter().find(|n| n.starts_with(&format!("{load:e}N-"))).unwrap();
        let bytes = std::fs::read(maps.join(name)).unwrap();
        let pressure = asperity::topography::io::npy::read_f64(&bytes).unwrap();
        assert!(pressure.iter().all(|p| *p >= 0.0), "a compressive map");
        let compressive = pressure.sum() * pixel * pixel;
        // Load control reaches the load (its steps impose it inside their conjugate gradient).
        assert!((compressive - na - load).abs() < 1e-9 * load, "{load} N: N_c {compressive}, N_a {na}");
        let onset = Onset::new(&ElementLoads::from_pressure(&pressure, pixel * pixel).unwrap(), &law);
        assert!((onset.friction_drop() / total - 1.0).abs() < 1e-12, "{load} N");
        assert_eq!(number(r, "contact_points") as usize, pressure.iter().filter(|p| **p > 0.0).count());
    }
    let (heaviest, without) = (adhesive[3], plain[3]);
    let share = number(heaviest, "adhesive_force_n") / number(heaviest, "load_n");
    assert!(share < 0.01, "N_a/N at 10 mN: {share}");
    let moved = number(heaviest, "friction_drop") / number(without, "friction_drop") - 1.0;
    assert!(moved.abs() < 0.01, "adhesion moves the drop at 10 mN by {moved}");
    // At 10 µN the adhesive force is not small beside the load: the two drops differ.
    let lightest = number(adhesive[0], "adhesive_force_n") / number(adhesive[0], "load_n");
    assert!(lightest > 0.1, "N_a/N at 10 µN: {lightest}");
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(report.contains("also solved with adhesion, the exponential law"), "the report names the law");
    assert!(report.contains("by more than 1%"), "the report states the 1 % load");
}

/// A finished study without adhesion, run again with it into the same DIR, resumes every
/// non-adhesive solve and solves the adhesive ones; its non-adhesive rows are the first run's.
#[test]
fn adding_adhesion_to_a_finished_study_resumes_its_solves() {
    let dir = tempfile::tempdir().unwrap();
    run(dir.path(), "plain.toml", &study("periodic", ""));
    let first = table(&dir.path().join("out/results.csv"));
    let o = run(dir.path(), "adhesive.toml", &study("periodic", ADHESION));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("each with and without adhesion, × 4 loads: 4 solved, 4 resumed"), "{stderr}");
    let second = table(&dir.path().join("out/results.csv"));
    assert_eq!(second.len(), 8);
    for (a, b) in first.iter().zip(&second) {
        for (column, value) in a {
            if column != "seconds" {
                assert_eq!(value, &b[column], "{column}");
            }
        }
    }
    // And back: the study without adhesion finds all its solves.
    let o = run(dir.path(), "plain.toml", &study("periodic", ""));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("0 solved, 4 resumed"), "{stderr}");
}

/// Elastic sharing on the adhesive solves: the tangential solver runs on each one's compressive
/// map, its rows carry both drops with their relation, and the equal-sharing rows under the
/// same weakening beside them.
#[test]
fn elastic_sharing_runs_on_the_adhesive_solves() {
    let dir = tempfile::tempdir().unwrap();
    let text =
        study("periodic", ADHESION).replace("[output]", "[model]\nsharing = [\"equal\", \"elastic\"]\n\n[output]");
    run(dir.path(), "study.toml", &text);
    let rows = table(&dir.path().join("out/results.csv"));
    // Per load: the paper's equal sharing, equal sharing under d_c, elastic sharing; with and
    // without adhesion.
    assert_eq!(rows.len(), 4 * 3 * 2);
    let elastic: Vec<_> =
        rows.iter().filter(|r| r["sharing"] == "elastic" && !r["adhesive_force_n"].is_empty()).collect();
    assert_eq!(elastic.len(), 4);
    for r in elastic {
        let (load, na) = (number(r, "load_n"), number(r, "adhesive_force_n"));
        let (drop, total) = (number(r, "friction_drop"), number(r, "friction_drop_total_load"));
        assert!((total / (drop * load / (load + na)) - 1.0).abs() < 1e-12, "{load} N");
        // Any interface's drop over the force its elements carry lies between 1 and μ_s/μ_d.
        assert!(total > 1.0 && total <= 0.6 / 0.4 + 1e-9, "{load} N: {total}");
    }
}

/// A study with adhesion split into two shards, the second run first, then assembled, gives
/// the unsharded rows: the second shard's first solve without adhesion starts cold rather than
/// from the load before it, and its adhesive solve, which starts from that one, reaches the
/// same equilibrium (the load decides it, not where the chain was cut).
#[test]
fn shards_give_the_unsharded_adhesive_rows() {
    let dir = tempfile::tempdir().unwrap();
    run(dir.path(), "study.toml", &study("periodic", ADHESION));
    let whole = table(&dir.path().join("out/results.csv"));
    for args in [&["--shard", "2/2"][..], &["--shard", "1/2"], &[]] {
        let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["run", "study.toml", "--out", "sharded"])
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let sharded = table(&dir.path().join("sharded/results.csv"));
    assert_eq!((whole.len(), sharded.len()), (8, 8));
    let mut largest: f64 = 0.0;
    for (a, b) in whole.iter().zip(&sharded) {
        for (column, value) in a {
            if ["seconds", "iterations"].contains(&column.as_str()) {
                continue;
            }
            match (value.parse::<f64>(), b[column].parse::<f64>()) {
                (Ok(x), Ok(y)) => {
                    let relative = (x - y).abs() / x.abs().max(f64::MIN_POSITIVE);
                    largest = largest.max(relative);
                    assert!(relative < 1e-6 || (x - y).abs() < 1e-15, "{column} at {}: {x} against {y}", a["load_n"]);
                }
                _ => assert_eq!(value, &b[column], "{column}"),
            }
        }
    }
    // Not the same bits: the cut is real.
    assert!(largest > 0.0, "the shards reproduce the unsharded run to the last bit");
}

/// A run stopped after each of its records in turn, then run again, ends with the rows of an
/// uninterrupted run to the last bit: an adhesive solve is recorded before the solve without
/// adhesion it starts from, so a stop between the two solves that one again from the start it
/// had (the map of the load before it), not from another.
#[test]
fn a_run_stopped_after_any_record_resumes_to_the_same_bits() {
    use asperity::study::run::{Progress, Study};
    use std::ops::ControlFlow;
    let text = study("periodic", ADHESION);
    let prepare = || Study::prepare(StudyConfig::parse(&text, "study.toml").unwrap(), "study.toml").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let rows = |out: &Path| {
        let mut rows = prepare().run(out, false, &|_| ControlFlow::Continue(())).unwrap().rows;
        rows.iter_mut().for_each(|r| r.seconds = 0.0);
        rows
    };
    let expected = rows(&whole);
    assert_eq!(expected.len(), 8);
    for stop in 1..8 {
        let out = dir.path().join(format!("stopped-{stop}"));
        let solved = std::sync::atomic::AtomicUsize::new(0);
        let stopped = prepare().run(&out, false, &|e| match e {
            Progress::Solved { .. } if solved.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1 == stop => {
                ControlFlow::Break(())
            }
            _ => ControlFlow::Continue(()),
        });
        assert!(stopped.is_err(), "stopped after {stop} records");
        assert_eq!(rows(&out), expected, "stopped after {stop} records");
    }
}

/// Where a contact of one pixel catches no tension (the `--quick` balls at their lightest
/// loads, a Maugis–Dugdale law of 0.3 nm range on 122 nm pixels), the adhesive force is zero,
/// not a rounding below it, and no drop on the total load exceeds the drop on the load.
#[test]
fn an_adhesive_force_is_never_negative() {
    let dir = tempfile::tempdir().unwrap();
    let asperity = env!("CARGO_BIN_EXE_asperity");
    let default = Command::new(asperity).args(["run", "--print-default"]).output().unwrap();
    let text = String::from_utf8(default.stdout).unwrap().replacen(
        "[contact]\n",
        "[contact]\nadhesion = { work = \"50 mJ/m2\", range = \"0.3 nm\" }\n",
        1,
    );
    assert!(text.contains("adhesion = {"), "the default study has a [contact] table");
    std::fs::write(dir.path().join("s.toml"), text).unwrap();
    let o = Command::new(asperity)
        .args(["run", "s.toml", "--quick", "--out", "out"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = table(&dir.path().join("out/results.csv"));
    let adhesive: Vec<_> = rows.iter().filter(|r| !r["adhesive_force_n"].is_empty()).collect();
    assert_eq!(adhesive.len(), 42);
    for r in &adhesive {
        let (load, na) = (number(r, "load_n"), number(r, "adhesive_force_n"));
        assert!(na >= 0.0, "{} at {load} N: N_a = {na}", r["topography"]);
        assert!(number(r, "friction_drop_total_load") <= number(r, "friction_drop"), "{} at {load} N", r["topography"]);
    }
    assert!(adhesive.iter().any(|r| number(r, "adhesive_force_n") == 0.0), "a contact that catches no tension");
}
