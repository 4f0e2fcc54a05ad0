//! The default study's stand-in balls against the paper's description of its interface
//! (Fig. S4): at 0.1 mN each touches in 30–100 contact elements in at most 4 patches lying
//! within a few µm; at the study's lowest load one element carries the whole load, and the
//! friction drop is the single-element value mu_s/mu_d. One solve per ball at each of the two
//! loads on the paper's grid (1500², a few seconds).

use asperity::study::config::{Force, LoadsSpec, StudyConfig};
use asperity::study::run::Study;
use asperity::study::MapSnapshot;

#[test]
fn the_default_balls_touch_as_the_papers_at_0_1_mn_and_in_one_element_at_the_lowest_load() {
    let mut config = StudyConfig::default_study();
    let lowest = config.load_values()[0];
    assert!(lowest < 1e-6, "the default loads start in the single-element regime: {lowest} N");
    config.loads = LoadsSpec { values: Some(vec![Force(lowest), Force(1e-4)]), min: None, max: None, count: None };
    config.output.figures = Vec::new();
    let study = Study::prepare(config, "default study").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let outcome = study.run(&out, false, &|_| ()).unwrap();
    assert_eq!(outcome.rows.len(), 3 * 2 * 2);
    for row in &outcome.rows {
        let at = format!("{} at {} N, law {}", row.topography, row.load_n, row.law);
        if row.load_n == lowest {
            assert_eq!((row.contact_points, row.patches), (1, 1), "{at}");
            assert!((row.friction_drop - row.mu_s / row.mu_d).abs() < 1e-12, "{at}: drop {}", row.friction_drop);
            assert_eq!(row.critical_normal_fraction, 1.0, "{at}");
        } else {
            assert!((30..=100).contains(&row.contact_points), "{at}: {} elements", row.contact_points);
            assert!((1..=4).contains(&row.patches), "{at}: {} patches", row.patches);
            assert!(row.friction_drop < row.mu_s / row.mu_d, "{at}: drop {}", row.friction_drop);
        }
    }
    // The first ball's contact at 0.1 mN lies within a box of at most 3 µm (its snapshot is
    // cropped to the contact points).
    // Named by its load and the digest of its solve.
    let stem = std::fs::read_dir(out.join("snapshots"))
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().into_string().unwrap().strip_suffix(".json").map(str::to_owned))
        .find(|s| s.starts_with("ball-1-1e-4N-"))
        .expect("the first ball's snapshot at 0.1 mN");
    let snap = MapSnapshot::load(&out.join("snapshots"), &stem).unwrap();
    assert_eq!(snap.load_n, 1e-4);
    let (rows, cols) = snap.pressure.dim();
    let margin = 2.0 * 8.0; // pixels kept around the contact on each side
    let extent = ((rows as f64 - margin) * snap.pixel_size.1).max((cols as f64 - margin) * snap.pixel_size.0);
    assert!(extent < 3e-6, "the contact spans {extent} m");
    let peak = snap.pressure.iter().copied().fold(0.0, f64::max);
    assert!(peak < 12e9, "peak pressure {peak} Pa at 0.1 mN, above silicon's hardness");
}
