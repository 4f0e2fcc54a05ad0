//! A small study end to end: the results table against the contact solver and the stick-slip
//! model run directly, the files a run leaves, and how a run treats a DIR it finds.

use asperity::contact::{
    self, Boundary, ContactSolver, Convergence, Material, ShearCompliance, SolverOptions, TangentialOptions,
    TangentialSolver,
};
use asperity::friction::{stuck_stiffness, ElementLoads, FrictionLaw, Onset};
use asperity::study::config::StudyConfig;
use asperity::study::run::{Progress, Study};
use asperity::study::{MapSnapshot, Results, Row, FIGURE_LOADS_N};
use asperity::topography::resample::compound;
use asperity::topography::synth::{SelfAffine, SyntheticSurface};
use ndarray::Array2;

const SMALL: &str = r#"
[[topography]]
name = "ball-1"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 1, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }
wafer = { synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 101, roughness = { hurst = 0.8, rms_height_m = "0.2 nm", rolloff_wavelength_m = "5 µm" } } }

[[topography]]
name = "ball-2"
synthetic = { size_m = ["31.13 µm", "31.13 µm"], grid = [64, 64], seed = 2, roughness = { hurst = 0.8, rms_height_m = "22 nm", rolloff_wavelength_m = "5 µm" }, cap = { radius_m = "1.5 mm" } }

[material]
youngs = "130 GPa"
poisson = 0.26

[contact]
boundary = "periodic"
tolerance = 1e-8
max_iterations = 20000

[loads]
values = ["100 mN", "0.1 mN", "1 mN", "10 mN"]

[[law]]
preset = "hold 100 s"

[[law]]
name = "strong"
mu_s = 0.9
mu_d = 0.3

[output]
pressure_maps = true
"#;

fn study(text: &str) -> Study {
    Study::prepare(StudyConfig::parse(text, "small.toml").unwrap(), "small.toml").unwrap()
}

/// The rows of the study as the solver and the model give them, run here directly.
fn direct_rows() -> Vec<Row> {
    let surface = |seed, rms: f64, cap| SyntheticSurface {
        size: (31.13e-6, 31.13e-6),
        grid: (64, 64),
        seed,
        roughness: Some(SelfAffine {
            hurst: 0.8,
            rolloff_wavelength: Some(5e-6),
            short_cutoff_wavelength: None,
            long_cutoff_wavelength: None,
            amplitude: asperity::topography::synth::Amplitude::RmsHeight(rms),
        }),
        cap,
    };
    let cap = SyntheticSurface::default().cap;
    let ball_1 =
        compound(&surface(1, 22e-9, cap).generate().unwrap(), &surface(101, 0.2e-9, None).generate().unwrap()).unwrap();
    let ball_2 = surface(2, 22e-9, cap).generate().unwrap();
    let laws = [FrictionLaw::preset("hold 100 s").unwrap(), FrictionLaw::new(0.9, 0.3).unwrap().named("strong")];
    let e_star = Material::SILICON.plane_strain_modulus();
    let convergence = Convergence { tolerance: 1e-8, max_iterations: 20_000 };
    let options = SolverOptions { convergence, ..Default::default() };
    let mut rows = Vec::new();
    for (name, topo) in [("ball-1", ball_1), ("ball-2", ball_2)] {
        let size = topo.physical_size.unwrap();
        let heights: Vec<f64> = topo.heights.iter().copied().collect();
        let mut solver = ContactSolver::new(&heights, (64, 64), size, e_star, Boundary::Periodic, options).unwrap();
        let mut per_load = Vec::new();
        for load in [1e-4, 1e-3, 1e-2, 1e-1] {
            let report = solver.solve(load, |_, _| ()).unwrap();
            let summary = contact::summarize(solver.pressure(), (64, 64), size, Boundary::Periodic, None);
            let facts = asperity::study::SolveFacts {
                plastic: false,
                contact_points: summary.contact_points,
                patches: summary.patch_sizes.len(),
                contact_fraction: summary.contact_fraction,
                max_pressure_pa: solver.pressure().iter().copied().fold(0.0, f64::max),
                edge_load_fraction: summary.edge_load_fraction,
                load_above_hardness_fraction: None,
                iterations: report.iterations,
                seconds: 0.0,
                adhesive_force_n: None,
            };
            let p = Array2::from_shape_vec((64, 64), solver.pressure().to_vec()).unwrap();
            let elements = ElementLoads::from_pressure(&p, (size.0 / 64.0) * (size.1 / 64.0)).unwrap();
            per_load
                .push(laws.iter().map(|l| Row::new(name, load, &facts, &Onset::new(&elements, l))).collect::<Vec<_>>());
        }
        for l in 0..laws.len() {
            rows.extend(per_load.iter().map(|r| r[l].clone()));
        }
    }
    rows
}

/// The path of the one file in `folder` named for the solve at `load` [N] (`<load>N-<digest>`,
/// the load as `{:e}` writes it) with the extension `ext`.
fn solve_file(folder: &std::path::Path, load: f64, ext: &str) -> std::path::PathBuf {
    let found: Vec<_> = std::fs::read_dir(folder)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_str().unwrap().starts_with(&format!("{load:e}N-")))
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    assert_eq!(found.len(), 1, "{}: {found:?}", folder.display());
    found[0].clone()
}

fn without_seconds(rows: &[Row]) -> Vec<Row> {
    rows.iter().map(|r| Row { seconds: 0.0, ..r.clone() }).collect()
}

#[test]
fn a_small_study_gives_the_solver_and_models_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let s = study(SMALL);
    let events = std::sync::Mutex::new(Vec::new());
    let outcome = s
        .run(&out, false, &|e| {
            events.lock().unwrap().push(match e {
                Progress::Start { total, done, onsets, .. } => {
                    assert_eq!(onsets, 0, "equal sharing runs no onset");
                    (total, done)
                }
                Progress::Solved { .. } => (0, 1),
                // Equal sharing only: none (the count of events below would show one).
                Progress::Slid { .. } | Progress::Sliding { .. } => (0, 0),
            })
        })
        .unwrap();
    let events = events.into_inner().unwrap();
    // 2 topographies × 4 loads, and their copies 2× and 4× coarser for the resolution figure.
    assert_eq!(events[0], (24, 0));
    assert_eq!(events.len(), 25);
    assert_eq!((outcome.solved, outcome.resumed, outcome.rows.len()), (24, 0, 16));

    // results.json: the rows, which are the solver's and the model's run directly.
    let results: Results = serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!((results.asperity_version.as_str(), results.commit.as_str()), (asperity::VERSION, asperity::COMMIT));
    let json = results.rows;
    assert_eq!(json, outcome.rows);
    assert_eq!(without_seconds(&json), without_seconds(&direct_rows()));
    for r in &json {
        assert!(r.seconds > 0.0 && r.iterations > 0);
        assert!(r.friction_drop >= 1.0 && r.friction_drop <= r.mu_s / r.mu_d + 1e-12, "{r:?}");
        assert!((r.static_coefficient - r.friction_drop * r.mu_d).abs() < 1e-12);
        let normal = r.critical_normal_fraction + r.pre_sliding_normal_fraction + r.subcritical_normal_fraction;
        let friction = r.critical_friction_fraction + r.pre_sliding_friction_fraction + r.subcritical_friction_fraction;
        assert!((normal - 1.0).abs() < 1e-12 && (friction - 1.0).abs() < 1e-12, "{r:?}");
        assert_eq!(r.critical_count + r.pre_sliding_count + r.subcritical_count, r.contact_points);
        assert_eq!(r.contact_fraction, r.contact_points as f64 / 4096.0);
    }
    // Topography × law × load, loads ascending whatever order the file gave them in.
    let order: Vec<_> = json.iter().map(|r| (r.topography.as_str(), r.law.as_str(), r.load_n)).collect();
    assert_eq!(
        order[..5],
        [
            ("ball-1", "hold 100 s", 1e-4),
            ("ball-1", "hold 100 s", 1e-3),
            ("ball-1", "hold 100 s", 1e-2),
            ("ball-1", "hold 100 s", 1e-1),
            ("ball-1", "strong", 1e-4)
        ]
    );

    // results.csv: the same rows, every column.
    let mut csv = csv::Reader::from_path(out.join("results.csv")).unwrap();
    let header: Vec<String> = csv.headers().unwrap().iter().map(String::from).collect();
    for column in [
        "load_n",
        "topography",
        "law",
        "contact_points",
        "patches",
        "contact_fraction",
        "static_coefficient",
        "dynamic_coefficient",
        "friction_drop",
        "critical_count",
        "critical_normal_fraction",
        "critical_friction_fraction",
        "pre_sliding_count",
        "pre_sliding_normal_fraction",
        "pre_sliding_friction_fraction",
        "subcritical_count",
        "subcritical_normal_fraction",
        "subcritical_friction_fraction",
        "iterations",
        "seconds",
    ] {
        assert!(header.iter().any(|h| h == column), "no column {column} in {header:?}");
    }
    let from_csv: Vec<Row> = csv.deserialize().map(|r| r.unwrap()).collect();
    assert_eq!(from_csv, json);

    // The study as run reads back as a study, with its loads explicit and its laws as given.
    let text = std::fs::read_to_string(out.join("study.toml")).unwrap();
    let as_run = StudyConfig::parse(&text, "study.toml").unwrap();
    assert_eq!(&as_run, s.config());
    assert_eq!(as_run.load_values(), [1e-4, 1e-3, 1e-2, 1e-1]);
    assert_eq!(as_run.laws[0].preset.as_deref(), Some("hold 100 s"));
    assert_eq!((as_run.laws[1].mu_s, as_run.laws[1].mu_d), (Some(0.9), Some(0.3)));

    // Snapshots of the first topography at the loads of the figures, and every pressure map.
    for (k, load) in FIGURE_LOADS_N.iter().enumerate() {
        let name = solve_file(&out.join("pressure/ball-1"), *load, "npy");
        let stem = name.file_stem().unwrap().to_str().unwrap();
        let snap = MapSnapshot::load(&out.join("snapshots"), &format!("ball-1-{stem}")).unwrap();
        assert_eq!((snap.load_n, snap.topography.as_str(), snap.grid), (*load, "ball-1", (64, 64)));
        let full: Array2<f64> = ndarray_npy::read_npy(&name).unwrap();
        // The same values summed in another order.
        assert!((snap.pressure.sum() / full.sum() - 1.0).abs() < 1e-13);
        let area = snap.pixel_area();
        assert!((full.sum() * area / load - 1.0).abs() < 1e-10);
        assert_eq!(full.iter().filter(|p| **p > 0.0).count(), json[k].contact_points);
        // The friction curve's snapshot (0.1 mN) holds its contact's stuck stiffness K_t, from
        // the study's material and boundary on this very map; the others none.
        if k == 0 {
            let mut solver = TangentialSolver::new(
                full.as_slice().unwrap(),
                (64, 64),
                (31.13e-6, 31.13e-6),
                ShearCompliance::of(&[Material::SILICON]),
                Boundary::Periodic,
                TangentialOptions::default(),
            )
            .unwrap();
            let (want, _) = stuck_stiffness(&mut solver).unwrap();
            let got = snap.stuck_stiffness.expect("K_t recorded at 0.1 mN");
            assert!((got / want - 1.0).abs() < 1e-9, "K_t {got} N/m recorded, {want} N/m on the map");
        } else {
            assert_eq!(snap.stuck_stiffness, None, "K_t at {load} N");
        }
    }
    // Nothing left over from the sweep but its records and their locks, named by load.
    let solves = out.join("solves/topographies/ball-2");
    for load in [1e-4, 1e-3, 1e-2, 1e-1] {
        solve_file(&solves, load, "json");
        solve_file(&solves, load, "lock");
    }
    assert_eq!(std::fs::read_dir(&solves).unwrap().count(), 8);

    // Run again once the first outcome (which holds DIR's locks) is dropped: everything is
    // found finished, and the results are the same.
    let rows = outcome.rows.clone();
    drop(outcome);
    let again = s.run(&out, false, &|_| ()).unwrap();
    assert_eq!((again.solved, again.resumed), (0, 24));
    assert_eq!(again.rows, rows);
}

#[test]
fn a_dir_grows_with_its_study_and_fresh_starts_over() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let small = SMALL.replace("pressure_maps = true", "pressure_maps = false");
    study(&small).run(&out, false, &|_| ()).unwrap();
    let ball = out.join("solves/topographies/ball-1");

    // 20 mN in place of 10 mN: that load alone is solved, for each of the 6 sweeps (2 balls,
    // each with 2 coarser copies); 10 mN is left out of the table, its records kept.
    let other = study(&small.replace("\"10 mN\"]", "\"20 mN\"]"));
    let outcome = other.run(&out, false, &|_| ()).unwrap();
    assert_eq!((outcome.solved, outcome.resumed), (6, 18));
    let loads: Vec<f64> = outcome.rows.iter().map(|r| r.load_n).collect();
    assert!(loads.contains(&2e-2) && !loads.contains(&1e-2), "{loads:?}");
    solve_file(&ball, 1e-2, "json");
    drop(outcome);
    // Another figure set solves nothing.
    let same = study(&small.replace("pressure_maps = false", "pressure_maps = false\nfigures = [\"friction-drop\"]"));
    assert_eq!(same.run(&out, false, &|_| ()).unwrap().resumed, 8);

    // --fresh solves everything again, and removes the records no longer asked for.
    let outcome = other.run(&out, true, &|_| ()).unwrap();
    assert_eq!((outcome.solved, outcome.resumed), (24, 0));
    assert!(outcome.rows.iter().any(|r| r.load_n == 2e-2));
    assert!(std::fs::read_dir(&ball).unwrap().all(|e| !e.unwrap().file_name().to_str().unwrap().starts_with("1e-2N-")));

    // A folder that holds something else is never a study's.
    let busy = dir.path().join("busy");
    std::fs::create_dir(&busy).unwrap();
    std::fs::write(busy.join("notes.txt"), "mine").unwrap();
    for fresh in [false, true] {
        let e = other.run(&busy, fresh, &|_| ()).unwrap_err().to_string();
        assert!(e.contains("holds no study"), "{e}");
    }
    assert_eq!(std::fs::read_to_string(busy.join("notes.txt")).unwrap(), "mine");
}

#[test]
fn a_warm_start_from_a_saved_pressure_continues_the_sweep_exactly() {
    let topo = SyntheticSurface { grid: (64, 64), ..SyntheticSurface::default() }.generate().unwrap();
    let heights: Vec<f64> = topo.heights.iter().copied().collect();
    let new = || {
        let e_star = Material::SILICON.plane_strain_modulus();
        ContactSolver::new(
            &heights,
            (64, 64),
            topo.physical_size.unwrap(),
            e_star,
            Boundary::Periodic,
            SolverOptions::default(),
        )
        .unwrap()
    };
    let mut sweep = new();
    sweep.solve(1e-3, |_, _| ()).unwrap();
    let saved = sweep.pressure().to_vec();
    let swept = sweep.solve(1e-2, |_, _| ()).unwrap();
    let mut resumed = new();
    resumed.warm_start(&saved).unwrap();
    let report = resumed.solve(1e-2, |_, _| ()).unwrap();
    assert_eq!(report.iterations, swept.iterations);
    assert!(resumed.pressure().iter().zip(sweep.pressure()).all(|(a, b)| a.to_bits() == b.to_bits()));
    assert!(resumed.warm_start(&saved[1..]).is_err());
    let mut negative = saved.clone();
    negative[7] = -1.0;
    assert!(resumed.warm_start(&negative).is_err());
}

/// `plastic = [false, true]`: each topography swept elastic and capped at the hardness, told
/// apart by the `plastic` column; the plastic maps stay below the hardness, spread the load on
/// more points, and change the drop.
#[test]
fn a_study_compares_elastic_and_plastic_solves() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = SMALL
        .replace("poisson = 0.26\n", "poisson = 0.26\nhardness = \"1 GPa\"\n")
        .replace("max_iterations = 20000\n", "max_iterations = 20000\nplastic = [false, true]\n")
        .replace("[[topography]]\nname = \"ball-2\"", "[[unused]]\nname = \"ball-2\"");
    let text = text[..text.find("[[unused]]").unwrap()].to_string() + &text[text.find("[material]").unwrap()..];
    let outcome = study(&text).run(&out, false, &|_| ()).unwrap();
    // Elastic and plastic sweeps, and the elastic coarser copies of the resolution figure.
    assert_eq!((outcome.solved, outcome.rows.len()), (16, 16));
    let (elastic, plastic): (Vec<&Row>, Vec<&Row>) = outcome.rows.iter().partition(|r| !r.plastic);
    assert_eq!((elastic.len(), plastic.len()), (8, 8));
    let mut differ = 0;
    for (e, p) in elastic.iter().zip(&plastic) {
        assert_eq!(
            (e.topography.as_str(), e.law.as_str(), e.load_n),
            (p.topography.as_str(), p.law.as_str(), p.load_n)
        );
        assert!(p.contact_points >= e.contact_points, "{e:?} {p:?}");
        differ += (p.friction_drop != e.friction_drop) as usize;
    }
    assert!(differ > 0, "the cap changed no drop");
    for k in 0..4 {
        let load = [1e-4, 1e-3, 1e-2, 1e-1][k];
        let map: Array2<f64> =
            ndarray_npy::read_npy(solve_file(&out.join("pressure/ball-1/plastic"), load, "npy")).unwrap();
        assert!(map.iter().all(|p| *p <= 1e9));
        let elastic: Array2<f64> =
            ndarray_npy::read_npy(solve_file(&out.join("pressure/ball-1"), load, "npy")).unwrap();
        assert!(k < 2 || elastic.iter().any(|p| *p > 1e9), "load {k}: the elastic peak stays below 1 GPa");
    }
    // Without a hardness, a plastic solve is refused before anything runs.
    let e = StudyConfig::parse(&text.replace("hardness = \"1 GPa\"\n", ""), "s.toml").unwrap_err().to_string();
    assert!(e.contains("contact.plastic") && e.contains("hardness"), "{e}");
}
