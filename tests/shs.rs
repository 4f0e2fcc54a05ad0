//! Slide-hold-slide analysis on synthetic traces with known answers, through the library and
//! through the `asperity shs` command.

use std::path::{Path, PathBuf};
use std::process::Command;

use asperity::shs::{self, ShsOptions, Trace, TraceFormat};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

const RATE: f64 = 20.0; // samples per second, as in the paper
const SPEED: f64 = 0.3e-6; // m/s
const NORMAL: f64 = 24e-3; // N
const DYNAMIC: f64 = 9.0e-3; // N, steady sliding friction
const RISE: f64 = 0.3e-6; // m from restart to peak
const DECAY: f64 = 60e-9; // m, Gaussian decay length from the peak to steady sliding
const STROKE: f64 = 4e-6; // m per slide
const WINDOW: f64 = 1e-6; // m
/// Friction sensor noise (standard deviation) relative to F_D: 27 µN on 9 mN.
const NOISE: f64 = 0.003;

/// One hold and the restart after it, as generated.
#[derive(Clone, Copy, Debug)]
struct Restart {
    hold: f64,
    peak: f64,
}

impl Restart {
    /// The mean of the noise-free friction over the window after the peak, as the continuous
    /// integral: steady sliding plus the Gaussian tail of the peak.
    fn dynamic(&self) -> f64 {
        DYNAMIC + (self.peak - DYNAMIC) * DECAY * std::f64::consts::PI.sqrt() / (2.0 * WINDOW)
    }
}

/// Friction at `d` metres into a slide whose peak is `peak`: a parabolic rise to the peak,
/// then a Gaussian decay to steady sliding.
fn slide_friction(d: f64, peak: f64) -> f64 {
    if d <= RISE {
        peak * (1.0 - (1.0 - d / RISE).powi(2))
    } else {
        DYNAMIC + (peak - DYNAMIC) * (-((d - RISE) / DECAY).powi(2)).exp()
    }
}

/// A sampled trace with its true displacement.
struct Synthetic {
    time: Vec<f64>,
    friction: Vec<f64>,
    normal: Vec<f64>,
    displacement: Vec<f64>,
}

/// An initial slide (with its own peak, not a restart), then each hold and a slide, sampled
/// at 20 Hz, with Gaussian noise of `noise` × F_D on friction and 0.3 % on the normal force.
fn synthetic(restarts: &[Restart], noise: f64, seed: u64) -> Synthetic {
    synthetic_protocol(restarts, noise, seed, Protocol::Released { relax: 0.0 })
}

/// How the rheometer holds (synthetic, known answers): the shear force released, falling to
/// zero with time constant `relax` [s] after the stage stops, or held, relaxing by `fraction` of
/// the sliding friction with time constant 5 s and rising from there at the restart.
#[derive(Clone, Copy)]
enum Protocol {
    Released { relax: f64 },
    Held { fraction: f64 },
}

fn synthetic_protocol(restarts: &[Restart], noise: f64, seed: u64, protocol: Protocol) -> Synthetic {
    // Phases in continuous time: (start, end, Some(peak) for a slide / None for a hold).
    let slide_time = STROKE / SPEED;
    let mut phases = vec![(0.0, slide_time, Some(1.3 * DYNAMIC))];
    let mut now = slide_time;
    for r in restarts {
        phases.push((now, now + r.hold, None));
        now += r.hold;
        phases.push((now, now + slide_time, Some(r.peak)));
        now += slide_time;
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let friction_noise = Normal::new(0.0, noise * DYNAMIC).unwrap();
    let normal_noise = Normal::new(0.0, 0.003 * NORMAL).unwrap();
    let mut s = Synthetic { time: vec![], friction: vec![], normal: vec![], displacement: vec![] };
    let (mut phase, mut slid_before) = (0, 0.0);
    // Start off the sample grid so that no event falls on a sample.
    let mut k = 0;
    loop {
        let t = 0.0137 + k as f64 / RATE;
        if t >= now {
            break;
        }
        while t >= phases[phase].1 {
            if phases[phase].2.is_some() {
                slid_before += STROKE;
            }
            phase += 1;
        }
        let (start, _, peak) = phases[phase];
        // The friction at a time `dt` into a hold that follows steady sliding.
        let held = |dt: f64| match protocol {
            Protocol::Released { relax } if relax > 0.0 => DYNAMIC * (-dt / relax).exp(),
            Protocol::Released { .. } => 0.0,
            Protocol::Held { fraction } => DYNAMIC * (1.0 - fraction * (1.0 - (-dt / 5.0).exp())),
        };
        let (f, x) = match peak {
            Some(peak) => {
                let d = SPEED * (t - start);
                let f = match (protocol, phase) {
                    (Protocol::Held { .. }, 1..) if d <= RISE => {
                        let f0 = held(phases[phase - 1].1 - phases[phase - 1].0);
                        f0 + (peak - f0) * (1.0 - (1.0 - d / RISE).powi(2))
                    }
                    _ => slide_friction(d, peak),
                };
                (f, slid_before + d)
            }
            None => (held(t - start), slid_before),
        };
        s.time.push(t);
        s.friction.push(f + friction_noise.sample(&mut rng));
        s.normal.push(NORMAL + normal_noise.sample(&mut rng));
        s.displacement.push(x);
        k += 1;
    }
    s
}

/// Three holds each of 10 s, 30 s and 100 s, interleaved; the static peak grows with the
/// hold (aging) and varies by 1 % from restart to restart.
fn paper_like() -> Vec<Restart> {
    let holds = [100.0, 10.0, 30.0, 10.0, 100.0, 30.0, 30.0, 10.0, 100.0];
    let peak = |k: usize, hold: f64| DYNAMIC * (1.25 + 0.2 * (hold / 10.0f64).log10()) * (1.0 + 0.01 * k as f64);
    // Holds off the 50 ms sample grid, so that their two ends fall at different phases.
    let jitter = |k: usize| 0.013 * k as f64;
    holds.iter().enumerate().map(|(k, &hold)| Restart { hold: hold + jitter(k), peak: peak(k, hold) }).collect()
}

fn close(got: f64, want: f64, what: &str) {
    assert!((got / want - 1.0).abs() < 0.01, "{what}: got {got:.6e}, want {want:.6e} (within 1 %)");
}

fn check_cycles(analysis: &shs::Analysis, restarts: &[Restart]) {
    assert_eq!(analysis.cycles.len(), restarts.len(), "skipped: {:?}", analysis.skipped);
    for (k, (c, r)) in analysis.cycles.iter().zip(restarts).enumerate() {
        close(c.hold_s, r.hold, &format!("restart {k} hold"));
        close(c.static_force_n, r.peak, &format!("restart {k} F_S"));
        close(c.dynamic_force_n, r.dynamic(), &format!("restart {k} F_D"));
        close(c.normal_force_n, NORMAL, &format!("restart {k} N"));
        close(c.static_coefficient, r.peak / NORMAL, &format!("restart {k} mu_s"));
        close(c.dynamic_coefficient, r.dynamic() / NORMAL, &format!("restart {k} mu_d"));
        close(c.friction_drop, r.peak / r.dynamic(), &format!("restart {k} drop"));
    }
    assert_eq!(analysis.groups.len(), 3);
    for (g, hold) in analysis.groups.iter().zip([10.0, 30.0, 100.0]) {
        assert_eq!(g.n_restarts, 3);
        let drops: Vec<f64> =
            restarts.iter().filter(|r| r.hold.round() == hold).map(|r| r.peak / r.dynamic()).collect();
        let mean = drops.iter().sum::<f64>() / 3.0;
        let std = (drops.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
        close(g.hold_s.mean, hold, "group hold");
        close(g.friction_drop.mean, mean, "group drop");
        close(g.normal_force_n.mean, NORMAL, "group N");
        // The spread comes from the restart-to-restart peaks; noise adds a little.
        let got = g.friction_drop.std.unwrap();
        assert!((got - std).abs() < 0.3 * std, "group drop std {got} vs {std}");
    }
}

fn trace(s: &Synthetic, with_displacement: bool) -> Trace {
    let x = with_displacement.then(|| s.displacement.clone());
    Trace::new("synthetic.csv", s.time.clone(), s.friction.clone(), s.normal.clone(), x).unwrap()
}

#[test]
fn known_restarts_from_friction_and_time_alone() {
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 1);
    let analysis = shs::analyse(&trace(&s, false), &ShsOptions::default()).unwrap();
    check_cycles(&analysis, &restarts);
    assert!(analysis.skipped.is_empty(), "{:?}", analysis.skipped);
}

#[test]
fn known_restarts_with_measured_displacement() {
    let restarts = paper_like();
    let mut s = synthetic(&restarts, NOISE, 2);
    // Encoder noise of 1 nm on the displacement.
    let mut rng = StdRng::seed_from_u64(3);
    let encoder = Normal::new(0.0, 1e-9).unwrap();
    s.displacement.iter_mut().for_each(|x| *x += encoder.sample(&mut rng));
    let analysis = shs::analyse(&trace(&s, true), &ShsOptions::default()).unwrap();
    check_cycles(&analysis, &restarts);
}

#[test]
fn steady_noisy_slide_has_no_hold() {
    // 10 minutes of sliding with 2 % noise and a slow 20 % drift: no hold, no restart.
    let mut rng = StdRng::seed_from_u64(4);
    let noise = Normal::new(0.0, 0.02 * DYNAMIC).unwrap();
    let time: Vec<f64> = (0..12_000).map(|i| i as f64 / RATE).collect();
    let friction: Vec<f64> = time.iter().map(|t| DYNAMIC * (0.9 + 0.2 * t / 600.0) + noise.sample(&mut rng)).collect();
    let normal = vec![NORMAL; time.len()];
    let trace = Trace::new("steady.csv", time, friction, normal, None).unwrap();
    let e = shs::analyse(&trace, &ShsOptions::default()).unwrap_err().to_string();
    assert!(e.starts_with("steady.csv: no hold found"), "{e}");
}

#[test]
fn dips_and_spikes_do_not_fake_holds_or_restarts() {
    let restarts = paper_like();
    let mut s = synthetic(&restarts, NOISE, 5);
    let at = |t: f64| s.time.iter().position(|&x| x >= t).unwrap();
    let first_hold = STROKE / SPEED;
    // 0.4 s dips to zero in the initial slide and in the middle of the first restart's slide,
    // and single-sample spikes to the sliding level inside the first (100 s) hold.
    let dips = [at(5.0), at(first_hold + 100.0 + 8.0)];
    let spikes = [at(first_hold + 20.0), at(first_hold + 50.0), at(first_hold + 50.1)];
    for start in dips {
        s.friction[start..start + 8].iter_mut().for_each(|f| *f = 0.0);
    }
    for i in spikes {
        s.friction[i] = 1.2 * DYNAMIC;
    }
    let analysis = shs::analyse(&trace(&s, false), &ShsOptions::default()).unwrap();
    assert_eq!(analysis.cycles.len(), restarts.len(), "{:?}", analysis.skipped);
    close(analysis.cycles[0].hold_s, 100.0, "hold with spikes");
}

#[test]
fn creeping_stage_is_no_hold() {
    // Friction drops near zero for 20 s while the stage keeps going at half speed: with the
    // displacement recorded, only the second (true) hold counts.
    let restarts = [Restart { hold: 20.0, peak: 1.5 * DYNAMIC }, Restart { hold: 20.0, peak: 1.5 * DYNAMIC }];
    let mut s = synthetic(&restarts, NOISE, 6);
    let (a, b) = (STROKE / SPEED, STROKE / SPEED + 20.0);
    let mut shift = 0.0;
    for (t, x) in s.time.iter().zip(s.displacement.iter_mut()) {
        if *t > a && *t <= b {
            shift = 0.5 * SPEED * (t - a);
        }
        *x += shift;
    }
    let analysis = shs::analyse(&trace(&s, true), &ShsOptions::default()).unwrap();
    assert_eq!((analysis.holds_from, analysis.holds_found, analysis.cycles.len()), ("displacement", 1, 1));
    close(analysis.cycles[0].hold_s, 20.0, "the stage's hold");
}

/// Both protocols of a rheometer (synthetic traces, known answers): the holds are found on the
/// stage and last as long as the stage stood, to 20 ms (an encoder noise of 1 nm is 3 ms at the
/// sliding speed; friction-based holds were 1.5 s short when the force relaxes in 0.4 s, and
/// found none when it stays loaded).
#[test]
fn both_protocols_from_the_stage() {
    let restarts = paper_like();
    for (k, protocol) in [Protocol::Released { relax: 0.4 }, Protocol::Held { fraction: 0.03 }].into_iter().enumerate()
    {
        let mut s = synthetic_protocol(&restarts, NOISE, 20 + k as u64, protocol);
        let mut rng = StdRng::seed_from_u64(30 + k as u64);
        let encoder = Normal::new(0.0, 1e-9).unwrap();
        s.displacement.iter_mut().for_each(|x| *x += encoder.sample(&mut rng));
        let analysis = shs::analyse(&trace(&s, true), &ShsOptions::default()).unwrap();
        assert_eq!((analysis.holds_from, analysis.holds_found), ("displacement", 9));
        check_cycles(&analysis, &restarts);
        for (c, r) in analysis.cycles.iter().zip(&restarts) {
            assert!((c.hold_s - r.hold).abs() < 0.02, "hold {} s for {} s", c.hold_s, r.hold);
        }
        if let Protocol::Held { .. } = protocol {
            let e = shs::analyse(&trace(&s, false), &ShsOptions::default()).unwrap_err().to_string();
            assert!(e.contains("no hold found") && e.contains("displacement column"), "{e}");
        }
    }
}

#[test]
fn short_holds_are_reported() {
    // A 0.6 s stop of the stage between the first and second holds: too short, said so.
    let mut restarts = paper_like()[..3].to_vec();
    restarts.insert(1, Restart { hold: 0.6, peak: 1.3 * DYNAMIC });
    let s = synthetic(&restarts, NOISE, 40);
    let analysis = shs::analyse(&trace(&s, true), &ShsOptions::default()).unwrap();
    assert_eq!(
        (analysis.holds_found, analysis.cycles.len(), analysis.skipped.len()),
        (4, 3, 1),
        "{:?}",
        analysis.skipped
    );
    let skipped = &analysis.skipped[0];
    // The stop begins at 126.67 s (13.33 s slides around the first 100 s hold).
    assert!(
        skipped.reason.starts_with("hold from 126.")
            && skipped.reason.contains("s at rest, shorter than the minimum duration 1 s"),
        "{skipped:?}"
    );
    assert!(
        (skipped.start_s - 126.67).abs() < 0.1 && (skipped.end_s - skipped.start_s - 0.6).abs() < 0.1,
        "{skipped:?}"
    );
    // --json (and Python) keep a list of reasons.
    assert_eq!(serde_json::to_value(&analysis).unwrap()["skipped"][0], skipped.reason.as_str());

    // The figure marks it too: a hold shorter than --min-duration is crossed below the trace.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("trace.png");
    let figure = asperity::plot::trace_figure(&trace(&s, true), &analysis, &ShsOptions::default());
    let svg = std::fs::read_to_string(asperity::plot::write_figure(&png, &figure).unwrap()).unwrap();
    assert!(svg.contains("3 restarts after holds, 1 hold not measured (crossed)"), "the title counts it");
    assert_eq!(svg.matches("hold not measured").count(), 2, "the legend names its cross");
}

/// The trace figure states friction and normal force in one unit (on a 1.5 N load the normal
/// force read in N beside friction in mN), and keys the shaded windows where F_D and N are
/// averaged.
#[test]
fn the_trace_figure_keys_what_it_draws_in_one_unit() {
    let s = synthetic(&paper_like()[..2], NOISE, 42);
    let normal: Vec<f64> = s.normal.iter().map(|n| n * 1.5 / NORMAL).collect();
    let trace =
        Trace::new("heavy.csv", s.time.clone(), s.friction.clone(), normal, Some(s.displacement.clone())).unwrap();
    let analysis = shs::analyse(&trace, &ShsOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let figure = asperity::plot::trace_figure(&trace, &analysis, &ShsOptions::default());
    let svg =
        std::fs::read_to_string(asperity::plot::write_figure(&dir.path().join("t.png"), &figure).unwrap()).unwrap();
    assert!(svg.contains("friction force [mN]") && svg.contains("normal force [mN]"), "one unit");
    let texts: Vec<&str> =
        svg.split("<text").skip(1).filter_map(|t| Some(t.split('>').nth(1)?.split('<').next()?.trim())).collect();
    assert!(texts.contains(&"window of F") && texts.contains(&"normal force"), "keyed: {texts:?}");
    assert!(!svg.contains("F_S") && !svg.contains("F_D"), "no literal markup");
}

#[test]
fn absurd_coefficients_are_refused() {
    // Forces in the wrong unit or column: mu_s infinite, or 50.
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 41);
    for (friction, normal, want) in [(6.9e299 / DYNAMIC, 1e-10 / NORMAL, "= inf"), (1.0, 0.01, "is not a friction")] {
        let f = s.friction.iter().map(|v| v * friction).collect();
        let n = s.normal.iter().map(|v| v * normal).collect();
        let trace = Trace::new("absurd.csv", s.time.clone(), f, n, None).unwrap();
        let e = shs::analyse(&trace, &ShsOptions::default()).unwrap_err().to_string();
        assert!(e.starts_with("absurd.csv: row ") && e.contains(want) && e.contains("at most 10"), "{e}");
    }
}

/// The window can start past the peak: F_D over [0, 1] µm after it is the mean of those over
/// [0, 0.5] and [0.5, 1] µm, which `window_start` gives (the mean integrates the samples
/// piecewise linearly, so this holds to rounding).
#[test]
fn the_window_can_start_past_the_peak() {
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 1);
    let t = trace(&s, false);
    let run = |window_start: f64, window: f64| {
        shs::analyse(&t, &ShsOptions { window, window_start, ..ShsOptions::default() }).unwrap().cycles
    };
    let (whole, first, second) = (run(0.0, 1e-6), run(0.0, 0.5e-6), run(0.5e-6, 0.5e-6));
    assert_eq!(whole.len(), restarts.len());
    for ((w, a), b) in whole.iter().zip(&first).zip(&second) {
        let halves = 0.5 * (a.dynamic_force_n + b.dynamic_force_n);
        assert!((w.dynamic_force_n / halves - 1.0).abs() < 1e-12, "{} {halves}", w.dynamic_force_n);
        assert_eq!((a.peak_s, a.window_start_s), (b.peak_s, a.peak_s));
        assert!(b.window_start_s > b.peak_s && b.window_start_s < b.window_end_s && b.window_end_s == w.window_end_s);
    }
    let e = shs::analyse(&t, &ShsOptions { window_start: -1e-9, ..ShsOptions::default() }).unwrap_err();
    assert!(e.to_string().contains("--window-start: -0.000000001 m must be ≥ 0"), "{e}");
}

#[test]
fn restart_too_short_for_the_window_is_skipped() {
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 7);
    let options = ShsOptions { window: 3.9e-6, ..ShsOptions::default() };
    let e = shs::analyse(&trace(&s, false), &options).unwrap_err().to_string();
    assert!(
        e.contains("no complete restart after 9 hold(s)") && e.contains("before the 3.900e-6 m window ends"),
        "{e}"
    );
}

// ---------------------------------------------------------------- files and the command

fn write_csv(path: &Path, header: &str, rows: impl Iterator<Item = String>) {
    let mut text = format!("{header}\n");
    for row in rows {
        text += &row;
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

fn write_trace(dir: &Path, s: &Synthetic) -> PathBuf {
    let path = dir.join("trace.csv");
    let rows = (0..s.time.len()).map(|i| format!("{},{},{}", s.time[i], s.friction[i], s.normal[i]));
    write_csv(&path, "time_s,friction_n,normal_n", rows);
    path
}

#[test]
fn renamed_columns_and_units() {
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 8);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rheometer.csv");
    let rows = (0..s.time.len()).map(|i| {
        format!("{},{},{},{},7", s.time[i] * 1e3, s.friction[i] * 1e3, s.normal[i] * 1e3, s.displacement[i] * 1e6)
    });
    write_csv(&path, "# exported by a rheometer\nt,F,N,x,temperature", rows);
    let format = TraceFormat {
        time_column: "t".into(),
        friction_column: "F".into(),
        normal_column: "N".into(),
        displacement_column: Some("x".into()),
        time_unit: shs::seconds_per("ms").unwrap(),
        friction_unit: asperity::quantity::newtons_per("mN").unwrap(),
        normal_unit: asperity::quantity::newtons_per("mN").unwrap(),
        displacement_unit: 1e-6,
    };
    let trace = shs::read_trace(&path, &format).unwrap();
    assert!(trace.displacement().is_some());
    check_cycles(&shs::analyse(&trace, &ShsOptions::default()).unwrap(), &restarts);
    // The same exported with semicolons or tabs, as spreadsheets in many locales do.
    let text = std::fs::read_to_string(&path).unwrap();
    for delimiter in [";", "\t"] {
        let other = dir.path().join("rheometer-other.csv");
        let lines: Vec<String> =
            text.lines().map(|l| if l.starts_with('#') { l.to_string() } else { l.replace(',', delimiter) }).collect();
        std::fs::write(&other, lines.join("\n")).unwrap();
        let again = shs::read_trace(&other, &format).unwrap();
        assert_eq!(
            (again.time(), again.friction(), again.displacement()),
            (trace.time(), trace.friction(), trace.displacement())
        );
    }
}

#[test]
fn bad_files_get_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("time_s,friction_n,normal_n\n0,1,2\n0.05,abc,2\n", "line 3, column 'friction_n': 'abc' is not a number"),
        ("time_s,friction_n,normal_n\n0,1,2\n0.05,1\n", "line 3: 2 fields where the header has 3"),
        ("time_s,normal_n\n0,2\n0.05,2\n", "no column 'friction_n' (columns: time_s, normal_n)"),
        ("time_s,friction_n,normal_n\n0,1,2\n0.05,1,2\n0.05,1,2\n", "line 4: time 0.05 s does not increase"),
        ("time_s,friction_n,normal_n\n0,1,2\n0.05,NaN,2\n", "line 3, column 'friction_n': 'NaN' is not finite"),
        ("", "empty file"),
    ];
    for (k, (text, want)) in cases.into_iter().enumerate() {
        let path = dir.path().join(format!("bad{k}.csv"));
        std::fs::write(&path, text).unwrap();
        let e = shs::read_trace(&path, &TraceFormat::default()).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()) && e.contains(want) && !e.contains('\n'), "{e}");
    }
    let missing = shs::read_trace(&dir.path().join("absent.csv"), &TraceFormat::default()).unwrap_err().to_string();
    assert!(missing.contains("absent.csv") && !missing.contains('\n'), "{missing}");
}

fn asperity(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_asperity")).args(args).output().unwrap()
}

#[test]
fn command_reports_json_points_and_plot() {
    let restarts = paper_like();
    let s = synthetic(&restarts, NOISE, 9);
    let dir = tempfile::tempdir().unwrap();
    let path = write_trace(dir.path(), &s);
    let (points, png) = (dir.path().join("points.csv"), dir.path().join("trace.png"));
    let (trace_arg, points_arg, png_arg) = (path.to_str().unwrap(), points.to_str().unwrap(), png.to_str().unwrap());
    let out = asperity(&["shs", trace_arg, "--json", "--out", points_arg, "--plot", png_arg]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let cycles = json["cycles"].as_array().unwrap();
    assert_eq!(cycles.len(), 9);
    let keys = ["hold_s", "static_force_n", "dynamic_force_n", "normal_force_n"];
    let more = ["static_coefficient", "dynamic_coefficient", "friction_drop"];
    for key in keys.into_iter().chain(more) {
        assert!(cycles[0][key].is_f64(), "{key} missing in {}", cycles[0]);
    }
    close(cycles[1]["friction_drop"].as_f64().unwrap(), restarts[1].peak / restarts[1].dynamic(), "JSON drop");
    assert_eq!(json["groups"].as_array().unwrap().len(), 3);
    assert_eq!(json["groups"][2]["n_restarts"], 3);

    let points = shs::read_points(&points).unwrap();
    assert_eq!(points.iter().map(|p| p.n_restarts).collect::<Vec<_>>(), vec![3, 3, 3]);
    close(points[2].hold_s, 100.0, "point hold");
    close(points[2].load_n, NORMAL, "point load");
    assert!(points.iter().all(|p| p.friction_drop_std.is_some_and(|s| s > 0.0)));

    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (1400, 1500));
    let drawn = buf[..info.buffer_size()].chunks(3).filter(|p| p.iter().any(|&c| c < 200)).count();
    assert!(drawn > 20_000, "{drawn} drawn pixels");
    assert!(std::fs::metadata(png.with_extension("svg")).unwrap().len() > 10_000);

    let table = asperity(&["shs", trace_arg]);
    let text = String::from_utf8(table.stdout).unwrap();
    assert!(
        table.status.success()
            && text.contains("9 holds found on the friction, 0 skipped; 9 restarts after holds, 3 hold-time groups"),
        "{text}"
    );
}

#[test]
fn command_fails_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let steady = dir.path().join("steady.csv");
    let wobble = |i: usize| DYNAMIC * (1.0 + 0.01 * ((i * 7919) % 13) as f64);
    write_csv(
        &steady,
        "time_s,friction_n,normal_n",
        (0..2000).map(|i| format!("{},{},{NORMAL}", i as f64 / RATE, wobble(i))),
    );
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time_s,friction_n,normal_n\n0,1,2\n0.05,abc,2\n").unwrap();
    let (steady, bad) = (steady.to_str().unwrap(), bad.to_str().unwrap());
    let cases: [(Vec<&str>, &str); 4] = [
        (vec!["shs", steady], "steady.csv: no hold found"),
        (vec!["shs", bad], "bad.csv: line 3, column 'friction_n'"),
        (vec!["shs", steady, "--window=-1"], "--window"),
        (vec!["shs", steady, "--friction-unit", "lbf"], "--friction-unit"),
    ];
    for (args, want) in cases {
        let out = asperity(&args);
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.starts_with("error: ") && err.contains(want) && err.trim_end().lines().count() == 1, "{err}");
        assert!(out.stdout.is_empty());
    }
}
