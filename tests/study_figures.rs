//! The study's figures, movies and report drawn from a real small computation: a synthetic
//! rough silicon ball on a 128² grid, solved at loads from 0.1 to 100 mN, with the stick-slip
//! model's rows (elastic sharing's at the two lowest loads) and the snapshots a study keeps. Checks what is written, that it decodes and
//! holds something, and that missing data leaves notes instead of failures.

use std::collections::BTreeSet;
use std::path::Path;
use std::sync::OnceLock;

use asperity::contact::{
    summarize, Boundary, ContactSolver, Material, ShearCompliance, SolverOptions, TangentialOptions, TangentialSolver,
};
use asperity::friction::{elastic_onset, ElementLoads, FrictionLaw, Onset, SlipLaw, Weakening, PEAK_TOLERANCE};
use asperity::plot::study::render;
use asperity::plot::FigureInput;
use asperity::shs::ShsPoint;
use asperity::study::adhesion::AdhesionLimit;
use asperity::study::{FigureKind, MapSnapshot, ResolutionRow, Row, SolveFacts, FIGURE_LOADS_N};
use asperity::topography::resample::resample;
use asperity::topography::synth::SyntheticSurface;
use ndarray::Array2;

/// The results of a small study: two topographies × two laws × five loads.
struct Study {
    rows: Vec<Row>,
    /// Elastic sharing's rows at the loads up to [`ELASTIC_UP_TO_N`].
    elastic: Vec<Row>,
    topographies: Vec<String>,
    laws: Vec<FrictionLaw>,
    maps: Vec<MapSnapshot>,
    resolution: Vec<ResolutionRow>,
    parameters: String,
}

const LOADS_N: [f64; 5] = [1e-4, 1e-3, 3e-3, 1e-2, 1e-1];
const ELASTIC_UP_TO_N: f64 = 1e-3;

fn study() -> &'static Study {
    static STUDY: OnceLock<Study> = OnceLock::new();
    STUDY.get_or_init(|| {
        let laws = vec![FrictionLaw::preset("hold 100 s").unwrap(), FrictionLaw::preset("hold 10 s").unwrap()];
        let (mut rows, mut maps, mut topographies, mut resolution) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut elastic = Vec::new();
        for seed in 0..2 {
            // The paper's silicon ball window (31.13 µm) on a coarse grid: 243 nm pixels.
            let surface = SyntheticSurface { grid: (128, 128), seed, ..Default::default() };
            let topo = surface.generate().unwrap();
            let name = format!("ball {seed}");
            // The same ball on pixels twice as large, for the resolution figure.
            let coarse = resample(&topo, 2.0 * surface.size.0 / 128.0, &asperity::limits::Limits::default()).unwrap();
            let heights: Vec<f64> = coarse.heights.iter().copied().collect();
            let e_star = Material::SILICON.plane_strain_modulus();
            let mut solver =
                ContactSolver::new(&heights, (64, 64), surface.size, e_star, Boundary::Free, SolverOptions::default())
                    .unwrap();
            let pixel = surface.size.0 / 64.0;
            for load in LOADS_N {
                let report = solver.solve(load, |_, _| {}).unwrap();
                let pressure = Array2::from_shape_vec((64, 64), solver.pressure().to_vec()).unwrap();
                let summary = summarize(solver.pressure(), (64, 64), surface.size, Boundary::Free, None);
                let facts = SolveFacts::new(&summary, &report);
                let loads = ElementLoads::from_pressure(&pressure, pixel * pixel).unwrap();
                for law in &laws {
                    resolution.push(ResolutionRow::new(
                        2,
                        pixel,
                        &Row::new(&name, load, &facts, &Onset::new(&loads, law)),
                    ));
                }
            }
            let (ny, nx) = topo.heights.dim();
            let heights: Vec<f64> = topo.heights.iter().copied().collect();
            let e_star = Material::SILICON.plane_strain_modulus();
            let mut solver =
                ContactSolver::new(&heights, (ny, nx), surface.size, e_star, Boundary::Free, SolverOptions::default())
                    .unwrap();
            let pixel = (surface.size.0 / nx as f64, surface.size.1 / ny as f64);
            for load in LOADS_N {
                let report = solver.solve(load, |_, _| {}).unwrap();
                let pressure = Array2::from_shape_vec((ny, nx), solver.pressure().to_vec()).unwrap();
                let summary = summarize(solver.pressure(), (ny, nx), surface.size, Boundary::Free, None);
                let facts = SolveFacts::new(&summary, &report);
                let loads = ElementLoads::from_pressure(&pressure, pixel.0 * pixel.1).unwrap();
                for law in &laws {
                    let row = Row::new(&name, load, &facts, &Onset::new(&loads, law));
                    resolution.push(ResolutionRow::new(1, pixel.0, &row));
                    rows.push(row);
                }
                if load <= ELASTIC_UP_TO_N {
                    let compliance = ShearCompliance::of(&[Material::SILICON]);
                    let options = TangentialOptions::default();
                    let mut tangential = TangentialSolver::new(
                        solver.pressure(),
                        (ny, nx),
                        surface.size,
                        compliance,
                        Boundary::Free,
                        options,
                    )
                    .unwrap();
                    for law in &laws {
                        let slip = SlipLaw { mu_s: law.mu_s, mu_d: law.mu_d, weakening: Weakening::Instant };
                        let onset = elastic_onset(&mut tangential, &slip, PEAK_TOLERANCE, |_| {}).unwrap();
                        elastic.push(Row::elastic(&name, load, &facts, law, &slip, &onset, 0.0));
                    }
                }
                if seed == 0 && FIGURE_LOADS_N.contains(&load) {
                    maps.push(MapSnapshot::crop(&name, load, &pressure, pixel, 3).unwrap());
                }
            }
            topographies.push(name);
        }
        let parameters =
            "[material]\nyoungs = 130000000000.0\npoisson = 0.26\n\n[contact]\nboundary = \"free\"\n".to_string();
        Study { rows, elastic, topographies, laws, maps, resolution, parameters }
    })
}

fn point(load_n: f64, friction_drop: f64, std: Option<f64>, hold_s: f64) -> ShsPoint {
    ShsPoint {
        load_n,
        load_n_std: None,
        friction_drop,
        friction_drop_std: std,
        static_coefficient: None,
        static_coefficient_std: None,
        dynamic_coefficient: None,
        dynamic_coefficient_std: None,
        hold_s,
        hold_s_std: None,
        n_restarts: 3,
    }
}

fn input<'a>(
    s: &'a Study,
    maps: &'a [MapSnapshot],
    experiments: &'a [ShsPoint],
    figures: &'a [FigureKind],
    fractions: &'a [f64],
) -> FigureInput<'a> {
    FigureInput {
        rows: &s.rows,
        weakening_rows: &[],
        elastic_rows: &s.elastic,
        band_rows: &[],
        adhesive_rows: &[],
        cohesive_law: None,
        topographies: &s.topographies,
        laws: &s.laws,
        hold_times: &[Some(100.0), Some(10.0)],
        modulus_ratios: &[130.0 / 127.0, 130.0 / 133.0],
        counterface: Some(("the same material, E* = 69.7 GPa", 2.0)),
        // Summits of 30 µm: a pull-off of 18.85 µN (19 µN as shown), the limit at 188.5 µN (190 µN),
        // above the lowest load.
        adhesion: Some(AdhesionLimit::new(30e-6)),
        resolution: &s.resolution,
        hold_time_loads: &[1e-4, 1e-3, 1e-2],
        log_density: false,
        hardness_pa: None,
        slip_distance_m: 0.0,
        slip_distance_band: &[],
        grid: None,
        maps,
        experiments,
        figures,
        snapshot_fractions: fractions,
        parameters: &s.parameters,
    }
}

/// Width, height and the fraction of pixels that are not white, of a PNG.
fn png_facts(path: &Path) -> (u32, u32, f64) {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let pixels = buf[..info.buffer_size()].chunks_exact(3);
    let total = pixels.len() as f64;
    let inked = pixels.filter(|p| p != &[255, 255, 255]).count() as f64;
    (info.width, info.height, inked / total)
}

/// Width, height and frame count of a GIF.
fn gif_facts(path: &Path) -> (u16, u16, usize) {
    let mut decoder = gif::Decoder::new(std::fs::File::open(path).unwrap()).unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    (w, h, frames)
}

/// Every file under `dir`, relative to it.
fn files_in(dir: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            let sub = path.file_name().unwrap().to_string_lossy().to_string();
            out.extend(files_in(&path).into_iter().map(|f| format!("{sub}/{f}")));
        } else {
            out.insert(path.file_name().unwrap().to_string_lossy().to_string());
        }
    }
    out
}

#[test]
fn every_figure_movie_and_the_report() {
    let s = study();
    let experiments = [
        point(2.4e-4, 1.4, Some(0.03), 100.4),
        point(2.4e-2, 1.1, None, 99.0),
        point(1e-3, 1.15, Some(0.02), 10.0),
        point(5e-3, 1.2, Some(0.05), 30.0), // no law of a 30 s hold: drawn neutral
    ];
    let dir = tempfile::tempdir().unwrap();
    let input = input(s, &s.maps, &experiments, &FigureKind::ALL, &[0.25, 0.5, 0.75, 1.0]);
    let files = render(dir.path(), &input).unwrap();

    // (name, width, height) of each figure.
    let figures = [
        ("friction-drop", 1800, 850),
        ("friction-drop-sharing", 1800, 850),
        ("static-dynamic-coefficients", 1400, 850),
        ("resolution", 1400, 850),
        ("hold-time", 1800, 850),
        ("stress-ratio-histograms", 1500, 1100),
        ("pressure-distribution", 1200, 800),
        ("contact-maps", 1400, 1600),
        ("class-map", 1400, 1060),
        ("class-fractions", 1450, 1500),
        ("friction-curve", 1200, 800),
        ("stress-ratio-snapshots", 150 + 3 * 400 + 20, 60 + 60 + 4 * 400 + 150),
    ];
    let movies = ["movie-0.1mN", "movie-1mN", "movie-10mN"];
    let mut expected: BTreeSet<String> = BTreeSet::from(["index.html".to_string()]);
    for (name, w, h) in figures {
        let png = dir.path().join(format!("figures/{name}.png"));
        let (pw, ph, inked) = png_facts(&png);
        assert_eq!((pw, ph), (w, h), "{name}");
        // The class map inks only its contact pixels, a small share of the window.
        let least = if name == "class-map" { 0.01 } else { 0.02 };
        assert!(inked > least && inked < 0.9, "{name}: {inked} of the pixels drawn");
        let svg = std::fs::read_to_string(dir.path().join(format!("figures/{name}.svg"))).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("</svg>") && svg.contains("<text"), "{name}");
        expected.extend([format!("figures/{name}.png"), format!("figures/{name}.svg")]);
    }
    for name in movies {
        let path = dir.path().join(format!("figures/{name}.gif"));
        assert_eq!(gif_facts(&path), (760, 1080, 49), "{name}");
        let bytes = std::fs::metadata(&path).unwrap().len();
        assert!(bytes < 2_000_000, "{name}: {bytes} bytes");
        expected.insert(format!("figures/{name}.gif"));
    }
    // Exactly the returned files were written, and nothing half-written is left.
    let returned: BTreeSet<String> =
        files.iter().map(|f| f.strip_prefix(dir.path()).unwrap().to_string_lossy().to_string()).collect();
    assert_eq!(returned, expected);
    assert_eq!(files_in(dir.path()), expected);

    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    for file in expected.iter().filter(|f| f.starts_with("figures/")) {
        assert!(html.contains(&format!("\"{file}\"")), "index.html links {file}");
    }
    for text in [
        "Fig. 2",
        "Fig. S1",
        "Fig. 3",
        "Fig. S4",
        "Fig. 4b–e",
        "Fig. 4f",
        "Fig. 4g",
        "Fig. 4a",
        "Fig. S6",
        "supplemental movie",
        "the limit the paper names",
    ] {
        assert!(html.contains(text), "index.html names {text}");
    }
    // The parameters, the laws with the placeholder warning, a results row per load.
    assert!(
        html.contains("boundary = &quot;free&quot;") && html.contains("youngs = 130000000000.0"),
        "TOML parameters"
    );
    assert!(html.contains("Limits of the model") && html.contains("Mindlin"));
    // Measured points join the law of their hold time; the 30 s one matches none.
    let svg = std::fs::read_to_string(dir.path().join("figures/friction-drop.svg")).unwrap();
    for label in ["hold 100 s: measured", "hold 10 s: measured", "measured, other hold times"] {
        assert!(svg.contains(label), "friction drop legend: {label}");
    }
    // The other counterface, by the scaling of linear elasticity.
    assert!(svg.contains("hold 100 s: model, on the same material, E* = 69.7 GPa"), "counterface legend");
    assert!(html.contains("(the drop at N is the study&#39;s at 2 N)"), "counterface caption");
    let svg = std::fs::read_to_string(dir.path().join("figures/friction-drop-sharing.svg")).unwrap();
    for label in ["hold 100 s: equal sharing, 2 topographies", "hold 10 s: elastic sharing, 2 topographies"] {
        assert!(svg.contains(label), "sharing legend: {label}");
    }
    assert!(html.contains("<th>hold 100 s, elastic sharing</th>"), "the elastic drop in the results table");
    // The caption states the weakening elastic sharing used (here the instant drop).
    assert!(
        html.contains("(dashed, squares; the same pressure maps, the body displaced rigidly along x, μ_s until an element first slips, then μ_d at once)"),
        "the sharing figure's weakening"
    );
    assert!(html.contains("illustrative placeholder") && html.contains("hold 10 s"));
    for load in ["100 µN", "1 mN", "3 mN", "10 mN", "100 mN"] {
        assert!(html.contains(&format!("<tr><td>{load}</td>")), "results row at {load}");
    }
    assert!(!html.contains("not drawn") && !html.contains("http"), "self-contained, everything drawn");
}

#[test]
fn the_hardness_is_marked_on_the_pressure_distribution_when_set() {
    let s = study();
    let figures = [FigureKind::PressureDistribution];
    let draw = |hardness: Option<f64>| {
        let dir = tempfile::tempdir().unwrap();
        let mut input = input(s, &s.maps, &[], &figures, &[]);
        input.hardness_pa = hardness;
        render(dir.path(), &input).unwrap();
        std::fs::read_to_string(dir.path().join("figures/pressure-distribution.svg")).unwrap()
    };
    assert!(!draw(None).contains("hardness"));
    // Far above every pressure of the maps: the stress axis reaches it.
    let marked = draw(Some(12e9));
    assert!(marked.contains("hardness H = 12 GPa"), "no hardness line in the legend");
}

#[test]
fn missing_data_and_a_subset_leave_notes() {
    let s = study();
    // No experiments, no snapshot near 1 mN nor 100 mN, three figures asked for.
    let maps: Vec<MapSnapshot> = s.maps.iter().filter(|m| m.load_n == 1e-4 || m.load_n == 1e-2).cloned().collect();
    let figures = [FigureKind::Movies, FigureKind::FrictionDrop, FigureKind::ContactMaps];
    let dir = tempfile::tempdir().unwrap();
    let files = render(dir.path(), &input(s, &maps, &[], &figures, &[0.5, 1.0])).unwrap();
    let names: BTreeSet<String> = files.iter().map(|f| f.file_name().unwrap().to_string_lossy().to_string()).collect();
    let expected = [
        "friction-drop.png",
        "friction-drop.svg",
        "contact-maps.png",
        "contact-maps.svg",
        "movie-0.1mN.gif",
        "movie-10mN.gif",
        "index.html",
    ];
    assert_eq!(names, expected.iter().map(|s| s.to_string()).collect());
    let (_, _, inked) = png_facts(&dir.path().join("figures/contact-maps.png"));
    assert!(inked > 0.02, "two panels with data, two saying there is none");
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(html.contains("movie-1mN: no pressure map near 1 mN"), "{html}");
    assert!(html.contains("no pressure map near 100 mN"));
    assert!(html.contains("No measured points were given"));
    assert!(html.contains("Not requested by the study") && html.contains("Contact maps"));
    assert!(!html.contains("class-map.png"));
}

#[test]
fn nothing_to_draw_is_no_failure() {
    let s = study();
    let laws: Vec<FrictionLaw> = Vec::new();
    let input = FigureInput {
        rows: &[],
        weakening_rows: &[],
        elastic_rows: &[],
        band_rows: &[],
        adhesive_rows: &[],
        cohesive_law: None,
        topographies: &s.topographies,
        laws: &laws,
        hold_times: &[],
        modulus_ratios: &[],
        counterface: None,
        adhesion: None,
        resolution: &[],
        hold_time_loads: &[],
        log_density: false,
        hardness_pa: None,
        slip_distance_m: 2e-9,
        slip_distance_band: &[],
        grid: None,
        maps: &[],
        experiments: &[],
        figures: &FigureKind::ALL,
        snapshot_fractions: &[0.0, 1.5],
        parameters: "",
    };
    let dir = tempfile::tempdir().unwrap();
    let files = render(dir.path(), &input).unwrap();
    assert_eq!(files, vec![dir.path().join("index.html")]);
    let html = std::fs::read_to_string(&files[0]).unwrap();
    assert_eq!(html.matches("not drawn").count(), FigureKind::ALL.len());
    assert!(html.contains("No result rows"));
}

#[test]
fn bad_snapshot_fractions_are_left_out_with_a_note() {
    let s = study();
    let dir = tempfile::tempdir().unwrap();
    let figures = [FigureKind::StressRatioSnapshots];
    render(dir.path(), &input(s, &s.maps, &[], &figures, &[0.0, 0.5, 1.5, 1.0])).unwrap();
    let (_, h, _) = png_facts(&dir.path().join("figures/stress-ratio-snapshots.png"));
    assert_eq!(h, 60 + 60 + 2 * 400 + 150, "two rows");
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(html.contains("outside (0, 1] left out: [0.0, 1.5]"), "{html}");
}

/// What a referee reads in each figure: labels that say what is drawn, a key for
/// every colour, no literal markup, one entry for the friction drop's figure-load ticks.
#[test]
fn figures_say_what_they_show() {
    let s = study();
    let dir = tempfile::tempdir().unwrap();
    let input = input(s, &s.maps, &[], &FigureKind::ALL, &[0.5, 1.0]);
    render(dir.path(), &input).unwrap();
    let svg = |name: &str| std::fs::read_to_string(dir.path().join(format!("figures/{name}.svg"))).unwrap();

    let drop = svg("friction-drop");
    assert!(drop.contains("mean over the topographies") && drop.contains("range over 2 topographies"));
    assert!(!drop.contains("p(σ) at"), "the p(σ) loads are named in the caption, not in the legend");
    assert_eq!(drop.matches("ticks along the top: the loads of the p(σ) figure").count(), 1, "the ticks are keyed");
    assert!(!drop.contains("μ_S/μ_D") && !drop.contains(">μ<"), "one notation for the drop");

    // Both preset laws have μ^D = 0.4: one dynamic line, said to be every law's.
    let coefficients = svg("static-dynamic-coefficients");
    assert_eq!(coefficients.matches("every law: dynamic").count(), 1);
    assert!(!coefficients.contains("hold 100 s: dynamic"));

    let histograms = svg("stress-ratio-histograms");
    for key in ["critical: stuck at μ", "pre-sliding: slipped, at μ", "subcritical: stuck below μ"] {
        assert!(histograms.contains(key), "the colour key names {key:?}");
    }
    assert!(histograms.contains("fraction of the elements") && !histograms.contains(">tot<"));
    assert!(histograms.contains("critical (▲)"), "the few critical elements' bar is marked");
    assert!(histograms.contains("(a) one element") && !histograms.contains("(e) N ="), "panels lettered from (a)");

    assert!(!svg("stress-ratio-snapshots").contains("μ^S"), "the colour bar's μ^S is typeset");
    assert!(svg("pressure-distribution").contains("ball 0"), "p(σ) names its topography");
    let fractions = svg("class-fractions");
    assert!(fractions.contains("mean over 2 topographies") && fractions.contains("normal force N"));
    // Elastic sharing's classes below equal sharing's.
    assert!(fractions.contains("elastic sharing, instant drop") && fractions.contains("weakening: normal force"));
    // The loads where one summit's pull-off exceeds a tenth of the load are shaded and keyed
    // in both friction-drop figures, and said with the estimate's inputs in the report.
    for name in ["friction-drop", "friction-drop-sharing"] {
        let drawn = svg(name);
        assert_eq!(drawn.matches("outside a non-adhesive model: N &lt; 190 µN").count(), 1, "{name}");
    }
    assert!(svg("class-map").contains("the stress ratio of a stuck element"), "μ^0 is defined");

    let report = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(report.contains("every topography solved on its own grid"));
    let adhesion = "Below N = 190 µN (shaded grey) a non-adhesive model does not describe the contact: there the \
                    DMT pull-off force 2πRw of a single contacting summit, 19 µN for a work of adhesion w = 0.1 J/m²";
    assert!(report.contains(adhesion), "{report}");
    assert!(report.contains("a summit radius R = 30 µm"), "{report}");
    let full_size = r#"<a href="figures/friction-drop.png"><img src="figures/friction-drop.png""#;
    assert!(report.contains(full_size), "a click shows a figure at full size");
    assert!(report.contains("lifts this"), "the limits say what elastic sharing lifts");
    assert!(report.contains("The lowest load with more than one element on some topography, per resolution"));
}

/// The hold-time figure samples the aging law through the study's two laws, between and beyond
/// them, and marks the laws (two hold times alone would draw a straight segment).
#[test]
fn hold_time_samples_the_aging_law() {
    let s = study();
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), &input(s, &s.maps, &[], &[FigureKind::HoldTime], &[1.0])).unwrap();
    let svg = std::fs::read_to_string(dir.path().join("figures/hold-time.svg")).unwrap();
    // 1 s to 10⁴ s at 12 per decade: one polyline of 49 vertices per load (the old figure's
    // longest line had 2).
    let vertices = |line: &str| {
        line.split("points=\"").nth(1).map_or(0, |p| p.split('"').next().unwrap().split_whitespace().count())
    };
    let curves = svg.split("<polyline").skip(1).filter(|l| vertices(l) == 49).count();
    assert_eq!(curves, 3, "an aging curve at each of the three loads");
    for label in ["aging law at", "ball 0", "hold 100 s", "t = 100 s", "hold 10 s", "t = 10 s", "laws at"] {
        assert!(svg.contains(label), "the legend names {label:?}");
    }
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(html.contains("one aging law") && html.contains("49 hold times from 1 s to 10000 s"), "{html}");
}

/// Files of one study need not share a pixel: the resolution figure names each topography's
/// own (it named every one by the first's).
#[test]
fn the_resolution_figure_names_each_topographys_pixel() {
    let s = study();
    // The second ball as if scanned over a window four times as wide: pixels four times as large.
    let resolution: Vec<ResolutionRow> = s
        .resolution
        .iter()
        .map(|r| {
            let scale = if r.topography == "ball 1" { 4.0 } else { 1.0 };
            ResolutionRow { pixel_size_m: r.pixel_size_m * scale, ..r.clone() }
        })
        .collect();
    let figures = [FigureKind::Resolution];
    let mut input = input(s, &s.maps, &[], &figures, &[1.0]);
    input.resolution = &resolution;
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), &input).unwrap();
    let svg = std::fs::read_to_string(dir.path().join("figures/resolution.svg")).unwrap();
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let pixel = |ball: &str, factor: usize| {
        let r = resolution.iter().find(|r| r.topography == ball && r.coarsening == factor).unwrap();
        format!("{} nm on {ball}", asperity::plot::tick_label(&(r.pixel_size_m * 1e9)))
    };
    // (The SVG and the page escape the apostrophe of "the study's pixel".)
    for (factor, what) in [(1, "pixel"), (2, "2× coarser")] {
        let label = format!("{what}: {}, {}", pixel("ball 0", factor), pixel("ball 1", factor));
        assert!(svg.contains(&label), "the legend reads {label:?}");
        assert!(html.contains(&label), "the caption reads {label:?}");
    }
    // The two balls' pixels differ, as labelled.
    assert_ne!(pixel("ball 0", 1).split(' ').next(), pixel("ball 1", 1).split(' ').next());
}
