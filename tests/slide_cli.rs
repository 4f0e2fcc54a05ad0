//! `asperity slide` as users run it: the output contract, the partial-slip mode, the contact
//! directory as input, and one-line errors.

use std::path::{Path, PathBuf};
use std::process::Command;

use ndarray::Array2;
use ndarray_npy::read_npy;

fn asperity(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).output().unwrap()
}

fn surface() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tamaas/heights.npy")
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn writes_the_onset_its_curve_and_maps() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slide");
    let s = surface();
    let o = asperity(&[
        "slide",
        s.to_str().unwrap(),
        "--size",
        "8e-6,6e-6",
        "--load",
        "2mN",
        "--mu-s",
        "0.6",
        "--mu-d",
        "0.4",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = json(&out.join("slide.json"));
    assert_eq!(j["load_n"].as_f64().unwrap(), 2e-3);
    let (fs, mu_s) = (j["static_coefficient"].as_f64().unwrap(), 0.6);
    // Elastic sharing lies between total sliding at mu_d and every point at mu_s at once.
    assert!(fs > 0.4 && fs <= mu_s + 1e-12, "static coefficient {fs}");
    assert!((j["friction_drop"].as_f64().unwrap() - fs / 0.4).abs() < 1e-12);
    assert!((j["static_force_n"].as_f64().unwrap() - fs * 2e-3).abs() < 1e-9 * 2e-3);
    let eq = &j["equal_sharing"];
    assert!(eq["friction_drop"].as_f64().unwrap() > 1.0 && eq["static_coefficient"].as_f64().unwrap() > 0.4);
    let classes = ["stuck", "critical", "weakening", "weakened"];
    let count: u64 = classes.iter().map(|c| j[c]["count"].as_u64().unwrap()).sum();
    let normal: f64 = classes.iter().map(|c| j[c]["normal_fraction"].as_f64().unwrap()).sum();
    let friction: f64 = classes.iter().map(|c| j[c]["friction_fraction"].as_f64().unwrap()).sum();
    assert_eq!(count, j["contact_points"].as_u64().unwrap());
    assert!((normal - 1.0).abs() < 1e-9 && (friction - 1.0).abs() < 1e-9);
    // The maps at the peak: the shear sums to F_S, the classes mark exactly the contact points.
    let sx: Array2<f64> = read_npy(out.join("shear_x.npy")).unwrap();
    let sy: Array2<f64> = read_npy(out.join("shear_y.npy")).unwrap();
    let cl: Array2<i8> = read_npy(out.join("classes.npy")).unwrap();
    assert_eq!((sx.dim(), sy.dim(), cl.dim()), ((96, 128), (96, 128), (96, 128)));
    let area = 8e-6 * 6e-6 / (96.0 * 128.0);
    assert!((sx.sum() * area / j["static_force_n"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    assert_eq!(cl.iter().filter(|c| **c != 0).count() as u64, count);
    for (class, code) in classes.iter().zip([3, 2, 4, 1]) {
        assert_eq!(cl.iter().filter(|c| **c == code).count() as u64, j[class]["count"].as_u64().unwrap(), "{class}");
    }
    let curve = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    let mut lines = curve.lines();
    assert_eq!(lines.next(), Some("displacement_m,force_n,stick_points,slip_points"));
    let peak = lines.map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap()).fold(0.0, f64::max);
    // The curve holds the settled states: the search's, solved to the tolerance, whose largest
    // is F_S, and the march's, solved to 100 times it (at most 1e-4), which may lie above F_S by
    // about that fraction (here 5.2e-5).
    let fs_n = j["static_force_n"].as_f64().unwrap();
    assert!(peak <= fs_n * (1.0 + 1e-4) && peak >= fs_n, "{peak} vs {fs_n}");
}

#[test]
fn ramps_a_tangential_force_from_a_contact_directory() {
    let dir = tempfile::tempdir().unwrap();
    let (contact, out) = (dir.path().join("contact"), dir.path().join("slide"));
    let s = surface();
    let o = asperity(&[
        "contact",
        s.to_str().unwrap(),
        "--size",
        "8e-6,6e-6",
        "--load",
        "0.2mN,2mN",
        "--out",
        contact.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let args = |q: &str| {
        vec![
            "slide".to_string(),
            contact.to_str().unwrap().to_string(),
            "--load".into(),
            "2mN".into(),
            "--mu-s".into(),
            "0.5".into(),
            "--mu-d".into(),
            "0.5".into(),
            "--tangential-force".into(),
            q.into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let run = |q: &str| {
        let a = args(q);
        asperity(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let o = run("0.5mN");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j = json(&out.join("slide.json"));
    assert!((j["tangential_force_n"].as_f64().unwrap() / 0.5e-3 - 1.0).abs() < 1e-5);
    assert!(j["displacement_m"].as_f64().unwrap() > 0.0);
    let (stick, slip) = (j["stick_points"].as_u64().unwrap(), j["slip_points"].as_u64().unwrap());
    assert!(stick > 0 && slip > 0, "half of μN is partial slip: {stick} stuck, {slip} slipping");
    // Beyond μN there is no partial-slip state: refused in one line, nothing written over.
    let before = std::fs::read(out.join("slide.json")).unwrap();
    let o = run("1.5mN");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--tangential-force") && err.trim().lines().count() == 1, "{err}");
    assert_eq!(std::fs::read(out.join("slide.json")).unwrap(), before);
    // A load the directory does not hold.
    let mut a = args("0.5mN");
    a[3] = "3mN".into();
    let o = asperity(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--load") && err.contains("not among"), "{err}");
    // No load given: the directory's loads are listed to choose from.
    let a: Vec<&str> = a.iter().map(String::as_str).filter(|s| !["--load", "3mN"].contains(s)).collect();
    let err = String::from_utf8_lossy(&asperity(&a).stderr).to_string();
    assert!(err.contains("holds several loads, choose one [N]: 2e-4, 2e-3"), "{err}");
    // A topography's reading options do nothing to a contact directory: refused.
    let mut a = args("0.5mN");
    a.extend(["--size".to_string(), "1e-6".to_string()]);
    let o = asperity(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.starts_with("error: --size: not used with a contact directory"), "{err}");
}

#[test]
fn refuses_a_missing_law_and_a_bad_slip_distance() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slide");
    let s = surface();
    let base = ["slide", s.to_str().unwrap(), "--size", "8e-6,6e-6", "--load", "2mN", "--out", out.to_str().unwrap()];
    for (extra, needle) in [
        (&[][..], "--mu-s"),
        (&["--mu-s", "0.6", "--mu-d", "0.4", "--slip-distance", "-1nm"][..], "--slip-distance"),
        // Finite but too long to weaken within the path's steps: said so, with what to do.
        (
            &["--mu-s", "0.6", "--mu-d", "0.4", "--slip-distance", "1e300"][..],
            "1e300 m is not a slip-weakening distance (1 pm to 1 mm)",
        ),
        (&["--mu-s", "0.3", "--mu-d", "0.4"][..], "--mu-s"),
        // The ramp is under Coulomb friction: a weakening law would do nothing there.
        (
            &["--mu-s", "0.6", "--mu-d", "0.4", "--tangential-force", "0.5mN", "--slip-distance", "1nm"][..],
            "'--tangential-force <Q>' cannot be used with '--slip-distance <DC>'",
        ),
        // A missing required argument is named (clap's first line alone named none).
        (&["--curve", "curve.csv"][..], "error: --curve-unit <LENGTH> must be given"),
    ] {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(extra);
        let o = asperity(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        // One line of error, the last (after the normal solve's line where it ran).
        let last = err.trim().lines().last().unwrap_or_default();
        let errors = err.lines().filter(|l| l.starts_with("error")).count();
        assert!(!o.status.success() && last.contains(needle) && errors == 1, "{extra:?}: {err}");
        assert!(!out.exists());
    }
}

/// A contact folder edited since `asperity contact` wrote it, full contact and an --out that
/// cannot be written are refused, in one line naming the file or option (an --out before the
/// normal solve).
#[test]
fn refuses_an_edited_contact_folder_full_contact_and_a_foreign_out_first() {
    let dir = tempfile::tempdir().unwrap();
    let (contact, out) = (dir.path().join("contact"), dir.path().join("slide"));
    let s = surface();
    let size = ["--size", "8e-6,6e-6"];
    let o = asperity(
        &[&["contact", s.to_str().unwrap()][..], &size, &["--load", "2mN", "--out", contact.to_str().unwrap()]]
            .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let law = ["--mu-s", "0.6", "--mu-d", "0.4", "--out", out.to_str().unwrap()];
    let refused = |input: &Path, extra: &[&str], needle: &str| {
        let o = asperity(&[&["slide", input.to_str().unwrap()][..], extra, &law].concat());
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        // A topography's normal solve says its own lines first.
        let last = err.trim().lines().last().unwrap_or_default();
        assert!(!o.status.success() && last.starts_with("error: ") && last.contains(needle), "{needle}: {err}");
        assert_eq!(err.matches("error").count(), 1, "{err}");
        assert!(!out.exists());
    };
    let map = contact.join("pressure-000.npy");
    let p: Array2<f64> = read_npy(&map).unwrap();
    // Three times the pressure: taken before as a load of 6 mN under the name of 2 mN.
    ndarray_npy::write_npy(&map, &p.mapv(|x| 3.0 * x)).unwrap();
    refused(&contact, &[], "pressure-000.npy: carries 6.0");
    let mut negative = p.clone();
    negative[[0, 0]] = -1e9;
    ndarray_npy::write_npy(&map, &negative).unwrap();
    refused(&contact, &[], "pressure-000.npy: pressure at row 0, column 0 is -1000000000 Pa");
    ndarray_npy::write_npy(&map, &p).unwrap();
    let json = contact.join("contact.json");
    let text = std::fs::read_to_string(&json).unwrap();
    std::fs::write(&json, text.replace("\"pressure-000.npy\"", "\"../contact/pressure-000.npy\"")).unwrap();
    refused(&contact, &[], "must name a file of its own folder");
    std::fs::write(&json, text).unwrap();
    // A study's output folder has no contact.json: said so, with what is wanted instead.
    let study = dir.path().join("study");
    std::fs::create_dir(&study).unwrap();
    std::fs::write(study.join("results.csv"), "topography\n").unwrap();
    refused(&study, &["--load", "2mN"], "holds no contact.json (it is a study's output): give a contact directory");
    // 6 N (0.9 E* over the window) presses the whole periodic window into contact.
    refused(&s, &[&size[..], &["--load", "6N"]].concat(), "full contact");
    // …known from the heights before the normal solve, whose line is never printed.
    let o = asperity(&[&["slide", s.to_str().unwrap()][..], &size, &["--load", "6N"], &law].concat());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && !err.contains("normal solve") && err.contains("full contact"), "{err}");
    // The same load from a contact folder's pressures.
    let full = dir.path().join("full");
    let o = asperity(
        &[&["contact", s.to_str().unwrap()][..], &size, &["--load", "6N", "--out", full.to_str().unwrap()]].concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    refused(&full, &[], "full contact");
    // A folder of the user's: refused before the normal solve, whose line is never printed.
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let o = asperity(
        &[
            &["slide", s.to_str().unwrap()][..],
            &size,
            &["--load", "2mN", "--mu-s", "0.6", "--mu-d", "0.4", "--out", mine.to_str().unwrap()],
        ]
        .concat(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("--out") && !err.contains("normal solve"), "{err}");
    assert_eq!(std::fs::read_to_string(mine.join("notes.txt")).unwrap(), "mine");
}

/// `--help` says what the command takes and writes (the command's long doc, not only its
/// summary line).
#[test]
fn help_states_the_input_and_the_outputs() {
    let o = asperity(&["slide", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{help}");
    for needle in ["<SURFACE|CONTACT_DIR>", "output directory of `asperity contact`", "DIR/slide.json", "Cerruti"] {
        assert!(help.contains(needle), "{needle}: {help}");
    }
    let summary = String::from_utf8_lossy(&asperity(&["--help"]).stdout).to_string();
    let line = summary.lines().find(|l| l.trim_start().starts_with("slide ")).unwrap();
    assert!(line.ends_with("static friction, friction drop, shear maps"), "{line}");
}

/// Results the path cannot stand behind are refused in one line, and nothing is written: a
/// μ(slip) curve whose tail falls below its mean mu_d (an F_S/N of 0.4275 below a mu_d of
/// 0.4333 would be a drop below 1), coefficients whose tractions are not representable
/// (5e-324 would write null), and options checked before the normal solve (--tolerance 0,
/// --max-iter 0, Q ≥ μN after it; a Q of 1e-300 N, whose ramp would end only at the step
/// limit).
#[test]
fn refuses_results_outside_the_law_and_options_before_solving() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slide");
    let curve = dir.path().join("c.csv");
    // Peak 0.6, then 0.45 and a tail at 0.4: its mean after the peak, mu_d, is 0.41667.
    std::fs::write(&curve, "0,0.1\n1,0.6\n2,0.45\n3,0.4\n4,0.4\n").unwrap();
    let s = surface();
    let base = ["slide", s.to_str().unwrap(), "--size", "8e-6,6e-6", "--load", "2mN", "--out", out.to_str().unwrap()];
    let run = |extra: &[&str]| {
        let o = asperity(&[&base[..], extra].concat());
        (o.status.success(), String::from_utf8_lossy(&o.stderr).to_string())
    };
    let law = ["--mu-s", "0.5", "--mu-d", "0.5"];
    let c = curve.to_str().unwrap();
    for (extra, needle, solved) in [
        // At 1 Å every point weakens to the tail at once: F_S/N = 0.41579, the instant drop to
        // 0.4.
        (
            &["--curve", c, "--curve-unit", "1Å"][..],
            "error: --curve: F_S/N = 0.4157",
            true,
        ),
        (&["--mu-s", "5e-324", "--mu-d", "5e-324"][..], "error: --mu-d: the dynamic friction coefficient must be positive, finite and at least 2.2250738585072014e-308", false),
        (&["--mu-s", "1e-200", "--mu-d", "1e-200"][..], "error: --mu-s: the lowest coefficient times the largest pressure would be 7.389e-191 Pa, outside the 1e-140 to 1e140", true),
        (&[&law[..], &["--tolerance", "0"]].concat()[..], "error: --tolerance: must lie in (0, 0.01), got 0", false),
        (&[&law[..], &["--tolerance", "0.05"]].concat()[..], "error: --tolerance: must lie in (0, 0.01), got 0.05", false),
        (&[&law[..], &["--max-iter", "0"]].concat()[..], "error: --max-iter: must be at least 1", false),
        (&[&law[..], &["--peak-tolerance", "0"]].concat()[..], "error: --peak-tolerance: must lie in (0, 0.1), got 0", false),
        (&[&law[..], &["--tangential-force", "1mN"]].concat()[..], "error: --tangential-force: must lie in (0, μN) = (0, 1.000000e-3) N", false),
        (&[&law[..], &["--tangential-force", "1e-300"]].concat()[..], "error: --tangential-force: at 1e-300 N, 1.000e-297 of μN, the displacement step", true),
    ] {
        let (ok, err) = run(extra);
        let last = err.trim().lines().last().unwrap_or_default();
        assert!(!ok && last.starts_with(needle) && err.matches("error").count() == 1, "{extra:?}: {err}");
        // Options are refused before the normal solve, whose line then never shows.
        assert_eq!(err.contains("normal solve"), solved, "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?}");
    }
    // Averaged over its tail, mu_d is the curve's sliding value: F_S/N lies in [mu_d, mu_s].
    let (ok, err) = run(&["--curve", c, "--curve-unit", "1Å", "--window", "2,3"]);
    assert!(ok, "{err}");
    let j = json(&out.join("slide.json"));
    let fs = j["static_coefficient"].as_f64().unwrap();
    assert!(j["law"]["mu_d"].as_f64().unwrap() == 0.4 && fs > 0.4 && fs < 0.6, "{fs}");
    // A force a millionth of a millionth of μN is the fully stuck state, not refused.
    std::fs::remove_dir_all(&out).unwrap();
    let (ok, err) = run(&[&law[..], &["--tangential-force", "1e-12"]].concat());
    assert!(ok, "{err}");
    let j = json(&out.join("slide.json"));
    assert!((j["tangential_force_n"].as_f64().unwrap() / 1e-12 - 1.0).abs() < 1e-5, "{j}");
    assert_eq!((j["slip_points"].as_u64(), j["stick_points"].as_u64()), (Some(0), j["contact_points"].as_u64()));
}

#[test]
fn a_curve_unit_without_a_curve_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let surface = surface();
    let out = tmp.path().join("out");
    let o = asperity(&[
        "slide",
        surface.to_str().unwrap(),
        "--size",
        "8e-6,6e-6",
        "--load",
        "1mN",
        "--mu-s",
        "0.5",
        "--mu-d",
        "0.3",
        "--curve-unit",
        "1nm",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        "error: --curve-unit: is the unit of --curve only: give --curve FILE, or drop --curve-unit"
    );
    assert!(!out.exists());
}
