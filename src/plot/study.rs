//! The study's figures, movies and report: [`render`] draws the figures a study asks for from
//! its [`FigureInput`] into `DIR/figures/` and writes `DIR/index.html`, which shows them.
//!
//! The line figures (friction drop, p(σ), class fractions, friction curve) use the plot
//! foundation's [`Figure`]; the maps are drawn in `plot::maps`, the movies in
//! `plot::movie`, the page in `plot::report`. Data a figure needs but the study lacks (no
//! snapshot near a load, no measured points) is said in the figure or in the report; it is
//! never an error.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::contact_maps::{ClassMap, ContactMaps};
use super::draw::write_figure;
use super::figure::{Axis, Figure, LegendPosition, Panel};
use super::maps::{load_label, RatioSnapshots};
use super::movie::{scaled_curve, write_movie};
use super::series::{Marker, Series};
use super::shared::{by_load, spread, stem, Drawn, FigureInput, Image, LOAD_COLOURS};
use super::style;
use super::ticks::tick_label;
use super::{coefficients, histograms};
use crate::error::{Error, Result};
use crate::friction::{displacement, element_stiffness, ElementLoads, FrictionLaw, Loading, Onset};
use crate::study::{law_name, FigureKind, MapSnapshot, Row, FIGURE_LOADS_N, NEAR_DECADES};
use plotters::style::RGBColor;

/// Draw the figures of `input.figures` into `dir/figures/` (`<name>.png` + `.svg`, movies as
/// `.gif`) and write `dir/index.html` showing them with the study's parameters and results.
/// Returns every file written. Figures whose data the study lacks are left out with a note in
/// the report.
pub fn render(dir: &Path, input: &FigureInput) -> Result<Vec<PathBuf>> {
    let figures_dir = dir.join("figures");
    std::fs::create_dir_all(&figures_dir).map_err(|e| Error::io(&figures_dir, e))?;
    let kinds: Vec<FigureKind> = FigureKind::ALL.into_iter().filter(|k| input.figures.contains(k)).collect();
    let drawn: Vec<Drawn> = kinds.par_iter().map(|&kind| draw(dir, input, kind)).collect::<Result<_>>()?;
    let mut files: Vec<PathBuf> = Vec::new();
    for image in drawn.iter().flat_map(|d| &d.images) {
        files.push(dir.join(&image.file));
        files.extend(image.svg.as_ref().map(|s| dir.join(s)));
    }
    let page = dir.join("index.html");
    super::report::write(&page, input, &drawn)?;
    files.push(page);
    Ok(files)
}

/// The snapshot nearest `target` [N] in log scale, if within [`NEAR_DECADES`].
fn nearest(maps: &[MapSnapshot], target: f64) -> Option<&MapSnapshot> {
    let distance = |m: &MapSnapshot| (m.load_n / target).log10().abs();
    maps.iter()
        .filter(|m| m.load_n > 0.0 && distance(m) <= NEAR_DECADES)
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
}

/// The onset of the first law on a snapshot.
fn onset_of(snap: &MapSnapshot, law: &FrictionLaw) -> Result<(ElementLoads, Onset)> {
    let loads = ElementLoads::from_pressure(&snap.pressure, snap.pixel_area())?;
    let onset = Onset::new(&loads, law);
    Ok((loads, onset))
}

fn draw(dir: &Path, input: &FigureInput, kind: FigureKind) -> Result<Drawn> {
    let mut drawn = Drawn { kind, images: Vec::new(), notes: Vec::new() };
    let first_law = input.laws.first();
    let figure = |drawn: &mut Drawn, name: &str, fig: &dyn Fn(&Path) -> Result<PathBuf>, caption: String| {
        let png = format!("figures/{name}.png");
        fig(&dir.join(&png))?;
        drawn.images.push(Image { file: png, svg: Some(format!("figures/{name}.svg")), caption });
        Ok::<(), Error>(())
    };
    let name = stem(kind);
    // A figure drawn from the input alone, or the note of what it lacks.
    let made = |drawn: &mut Drawn, made: Option<(Figure, String)>, lacking: &str| match made {
        Some((fig, caption)) => figure(drawn, name, &|p| write_figure(p, &fig), caption),
        None => {
            drawn.notes.push(lacking.into());
            Ok(())
        }
    };
    match kind {
        FigureKind::FrictionDrop => {
            made(&mut drawn, coefficients::friction_drop(input), "no result rows to draw the friction drop from")?
        }
        FigureKind::FrictionDropSharing => made(
            &mut drawn,
            coefficients::friction_drop_sharing(input),
            "no elastic-sharing rows: list \"elastic\" in [model] sharing",
        )?,
        FigureKind::StaticDynamicCoefficients => {
            made(&mut drawn, coefficients::static_dynamic(input), "no result rows to draw the coefficients from")?
        }
        FigureKind::Resolution => made(&mut drawn, coefficients::resolution(input), "no solves at coarser pixels")?,
        FigureKind::HoldTime => made(
            &mut drawn,
            coefficients::hold_time(input),
            "fewer than two laws with a hold time, or no load near the chosen ones",
        )?,
        FigureKind::StressRatioHistograms => match first_law {
            Some(law) => {
                let (fig, caption) = histograms::stress_ratio_histograms(nearest(input.maps, 1e-2), law)?;
                figure(&mut drawn, name, &|p| write_figure(p, &fig), caption)?;
            }
            None => drawn.notes.push("no friction law".into()),
        },
        FigureKind::PressureDistribution => {
            made(&mut drawn, pressure_distribution(input), "no pressure map near 0.1, 1 or 10 mN")?
        }
        FigureKind::ContactMaps => {
            let panels: Vec<(f64, Option<&MapSnapshot>)> =
                FIGURE_LOADS_N.iter().map(|&t| (t, nearest(input.maps, t))).collect();
            note_missing(&mut drawn, &panels);
            if panels.iter().any(|p| p.1.is_some()) {
                let fig = ContactMaps { panels };
                let caption = "Contact maps at the loads nearest 0.1, 1, 10 and 100 mN (the paper's Fig. S4): the \
                               whole window, contact pixels coloured by their local normal stress on one scale; \
                               where the contact is small beside the window an inset zooms into it (scale bar \
                               inside), its place marked on the map; the inset lies where it hides no contact, \
                               or beside the map where every place on it would."
                    .to_string();
                figure(&mut drawn, name, &|p| write_figure(p, &fig), caption)?;
            }
        }
        FigureKind::ClassMap => match (nearest(input.maps, 1e-2), first_law) {
            (Some(snap), Some(law)) => {
                let (_, onset) = onset_of(snap, law)?;
                let fig = ClassMap { snap, onset, law_name: law_name(law) };
                let caption = format!(
                    "The state of every contact element at the critical state (the peak of the friction force) \
                     at N = {}, for the law \"{}\" (the paper's Fig. 4f): critical elements stuck at μ_s (brown), \
                     pre-sliding elements already slipped, at μ_d (amber), subcritical elements stuck below μ_s, \
                     at μ_0 = μ_s n_c/n for an element of normal force n when the critical ones carry n_c (green); \
                     zoomed to the contact region, the inset on the map where it hides no contact, else below the \
                     legend.",
                    load_label(snap.load_n),
                    law_name(law)
                );
                figure(&mut drawn, name, &|p| write_figure(p, &fig), caption)?;
            }
            (None, _) => drawn.notes.push("no pressure map near 10 mN".into()),
            (_, None) => drawn.notes.push("no friction law".into()),
        },
        FigureKind::ClassFractions => {
            made(&mut drawn, class_fractions(input), "no result rows for the first friction law")?
        }
        FigureKind::FrictionCurve => match (nearest(input.maps, 1e-4), first_law) {
            (Some(snap), Some(law)) => {
                let (fig, caption) = friction_curve(snap, law)?;
                figure(&mut drawn, name, &|p| write_figure(p, &fig), caption)?;
            }
            (None, _) => drawn.notes.push("no pressure map near 0.1 mN".into()),
            (_, None) => drawn.notes.push("no friction law".into()),
        },
        FigureKind::StressRatioSnapshots => {
            let Some(law) = first_law else {
                drawn.notes.push("no friction law".into());
                return Ok(drawn);
            };
            let (fractions, bad): (Vec<f64>, Vec<f64>) =
                input.snapshot_fractions.iter().partition(|f| **f > 0.0 && **f <= 1.0);
            if !bad.is_empty() {
                drawn.notes.push(format!("δ/δ_peak outside (0, 1] left out: {bad:?}"));
            }
            let mut columns = Vec::new();
            let mut panels = Vec::new();
            for &target in &FIGURE_LOADS_N[..3] {
                let snap = nearest(input.maps, target);
                panels.push((target, snap));
                // No empty columns: a load without a map is said in the report only.
                if let Some(s) = snap {
                    columns.push((s, onset_of(s, law)?.1));
                }
            }
            note_missing(&mut drawn, &panels);
            if fractions.is_empty() || columns.is_empty() {
                drawn.notes.push("nothing to show: no snapshot fraction or no map near 0.1, 1 or 10 mN".into());
            } else {
                let list: Vec<String> = fractions.iter().map(tick_label).collect();
                let caption = format!(
                    "The local stress ratio (shear over normal force of each element) at imposed displacements \
                     δ/δ_peak = {} (rows) for the loads nearest 0.1, 1 and 10 mN (columns), law \"{}\" (the \
                     paper's Fig. S6): stuck elements from pale green (unloaded) to brown at μ_s (critical), \
                     slipped elements amber (μ_d). Each map shows the whole contact or, where its pixels would be \
                     too small to see, the most loaded contact patch and its surroundings, grown so that no patch is cut at \
                     the edge.",
                    list.join(", "),
                    law_name(law)
                );
                let fig = RatioSnapshots { columns, fractions, law: law.clone(), law_name: law_name(law) };
                figure(&mut drawn, name, &|p| write_figure(p, &fig), caption)?;
            }
        }
        FigureKind::Movies => {
            let Some(law) = first_law else {
                drawn.notes.push("no friction law".into());
                return Ok(drawn);
            };
            for &target in &FIGURE_LOADS_N[..3] {
                let label = load_label(target).replace(' ', "");
                let Some(snap) = nearest(input.maps, target) else {
                    drawn.notes.push(format!("movie-{label}: no pressure map near {}", load_label(target)));
                    continue;
                };
                let (_, onset) = onset_of(snap, law)?;
                let file = format!("figures/movie-{label}.gif");
                write_movie(&dir.join(&file), snap, &onset, &law_name(law))?;
                let caption = format!(
                    "The local stress ratio as the imposed displacement grows from 0 to 1.2 δ_peak at N = {} \
                     ({} elements, law \"{}\"; the paper's supplemental movie at {}): stuck elements green, \
                     turning brown as they reach μ_s, slipped elements amber; below, the friction coefficient \
                     F/N with the current displacement. The map shows the whole contact or, where its pixels \
                     would be too small to see, the most loaded contact patch and its surroundings, no patch cut at the \
                     edge. The movie holds at the peak (the \
                     critical state) and at total sliding.",
                    load_label(snap.load_n),
                    onset.elements,
                    law_name(law),
                    load_label(target)
                );
                drawn.images.push(Image { file, svg: None, caption });
            }
        }
    }
    Ok(drawn)
}

/// A note for each figure load without a snapshot near it.
fn note_missing(drawn: &mut Drawn, panels: &[(f64, Option<&MapSnapshot>)]) {
    for (target, snap) in panels {
        if snap.is_none() {
            drawn.notes.push(format!("no pressure map near {}: no panel", load_label(*target)));
        }
    }
}

/// p(σ) of the local normal stress at the loads nearest 0.1, 1 and 10 mN (Fig. 3).
fn pressure_distribution(input: &FigureInput) -> Option<(Figure, String)> {
    let maps: Vec<(usize, &MapSnapshot)> =
        FIGURE_LOADS_N[..3].iter().enumerate().filter_map(|(k, &t)| nearest(input.maps, t).map(|m| (k, m))).collect();
    let max = maps.iter().flat_map(|(_, m)| m.pressure.iter()).fold(0.0f64, |a, &b| a.max(b));
    if maps.is_empty() || max <= 0.0 {
        return None;
    }
    // The stress axis reaches the hardness when it is set, so that its line shows.
    let reach = max.max(input.hardness_pa.unwrap_or(0.0));
    let (scale, unit) = super::ticks::prefixed(reach, "Pa");
    let density_axis = Axis::new("probability density p(σ)", &format!("1/{unit}"));
    let mut panel = Panel::new(
        Axis::new("local normal stress σ", &unit).range(0.0, reach * scale * 1.04),
        if input.log_density { density_axis.log() } else { density_axis },
    )
    .title(format!("Distribution of the local normal stress on {}", maps[0].1.topography))
    .legend(LegendPosition::UpperRight);
    // One set of bins for every load, so that the curves compare bin by bin.
    let smallest = maps.iter().map(|(_, m)| m.pressure.iter().filter(|p| **p > 0.0).count()).min().unwrap_or(0);
    let bins = ((smallest as f64).sqrt().round() as usize).clamp(12, 40);
    let width = max / bins as f64;
    let mut top = 0.0f64;
    let topography = maps[0].1.topography.clone();
    for (k, snap) in maps {
        let contact: Vec<f64> = snap.pressure.iter().copied().filter(|p| *p > 0.0).collect();
        let mut counts = vec![0usize; bins];
        for p in &contact {
            counts[((p / width) as usize).min(bins - 1)] += 1;
        }
        let norm = 1.0 / (contact.len() as f64 * width);
        // A histogram's outline: each bin a flat step; on a log axis empty bins are left out.
        let mut outline = vec![(0.0, 0.0)];
        for (i, c) in counts.iter().enumerate() {
            let d = *c as f64 * norm / scale;
            top = top.max(d);
            let (a, b) = (i as f64 * width * scale, (i + 1) as f64 * width * scale);
            outline.extend([(a, d), (b, d)]);
        }
        outline.push((max * scale, 0.0));
        if input.log_density {
            outline.retain(|p| p.1 > 0.0);
        }
        let label = format!("N = {} ({} elements)", load_label(snap.load_n), contact.len());
        panel.push(Series::line(outline, LOAD_COLOURS[k]).width(3).label(label));
    }
    if let Some(h) = input.hardness_pa {
        let bottom = if input.log_density { top * 1e-4 } else { 0.0 };
        panel.push(
            Series::line(vec![(h * scale, bottom), (h * scale, top)], style::GREY)
                .dashed()
                .label(format!("hardness H = {} {unit}", crate::quantity::human(h * scale))),
        );
    }
    let caption = format!(
        "The probability density p(σ) of the local normal stress σ over the contact elements of the topography \
         \"{}\" (the study's first) at the loads nearest 0.1, 1 and 10 mN (the paper's Fig. 3), as histograms on \
         common bins: discrete at low load (a few elements), continuous at high load.",
        topography
    );
    Some((Figure::new(panel).with_size(1200, 800), caption))
}

/// Fractions of N and of F_S carried by each class vs load, first law (Fig. 4g): equal sharing,
/// and below it elastic sharing's four classes when the study has its rows.
fn class_fractions(input: &FigureInput) -> Option<(Figure, String)> {
    let law = input.laws.first()?;
    let name = law_name(law);
    let topographies = input.topographies.len();
    let mean_over = format!("mean over {topographies} topograph{}", if topographies == 1 { "y" } else { "ies" });
    type Pick = fn(&Row) -> f64;
    let classes: [(&str, RGBColor, Pick, Pick); 3] = [
        ("critical", style::CRITICAL, |r| r.critical_normal_fraction, |r| r.critical_friction_fraction),
        ("pre-sliding", style::PRE_SLIDING, |r| r.pre_sliding_normal_fraction, |r| r.pre_sliding_friction_fraction),
        ("subcritical", style::SUBCRITICAL, |r| r.subcritical_normal_fraction, |r| r.subcritical_friction_fraction),
    ];
    let equal = class_panel(input.rows, &name, &classes, format!("equal sharing, {name}; {mean_over}"))?;
    let elastic_classes: [(&str, RGBColor, Pick, Pick); 4] = [
        ("critical", style::CRITICAL, |r| r.critical_normal_fraction, |r| r.critical_friction_fraction),
        (
            "weakening",
            style::WEAKENING,
            |r| r.weakening_normal_fraction.unwrap_or(0.0),
            |r| r.weakening_friction_fraction.unwrap_or(0.0),
        ),
        ("weakened", style::PRE_SLIDING, |r| r.pre_sliding_normal_fraction, |r| r.pre_sliding_friction_fraction),
        ("stuck", style::SUBCRITICAL, |r| r.subcritical_normal_fraction, |r| r.subcritical_friction_fraction),
    ];
    let weakening = if input.slip_distance_m > 0.0 {
        format!("d_c {}", crate::quantity::show(input.slip_distance_m, &crate::quantity::LENGTH))
    } else {
        "instant drop".to_string()
    };
    let elastic =
        class_panel(input.elastic_rows, &name, &elastic_classes, format!("elastic sharing, {weakening}; {mean_over}"));
    let figure = match elastic {
        Some(elastic) => Figure::stack(vec![(equal, 1), (elastic, 1)]).with_size(1450, 1500),
        None => Figure::new(equal).with_size(1450, 800),
    };
    let below = if input.elastic_rows.iter().any(|r| r.law == name) {
        " Below, the same under elastic sharing, whose slip weakening splits the elements that slipped before the \
         peak: weakening (red-orange; slip below d_c, between μ_s and μ_d, the critical ones' part: their further \
         slip lowers the force) and weakened (amber; at μ_d, the paper's pre-sliding); critical (brown) are those on \
         their bound μ_s for the first time at the peak, stuck (green) the paper's subcritical."
    } else {
        ""
    };
    let caption = format!(
        "The fraction of the normal load N (solid) and of the static friction force F_S (dashed) carried by \
         critical (brown), pre-sliding (amber) and subcritical (green) elements at the critical state, against the \
         normal load, for the law \"{name}\" (the paper's Fig. 4g): N^μ and F_S^μ are the normal and the friction \
         force carried by the elements of class μ (the paper's F_f^μ); {mean_over}.{below}"
    );
    Some((figure, caption))
}

/// A panel of the class fractions of `rows` for the law `name`, one pair of lines per class
/// (name, colour, its fraction of N, of F_S), titled "… (`what`)"; `None` without rows.
fn class_panel(
    rows: &[Row],
    name: &str,
    classes: &[(&str, RGBColor, fn(&Row) -> f64, fn(&Row) -> f64)],
    what: String,
) -> Option<Panel> {
    let groups = by_load(rows, name);
    if groups.is_empty() {
        return None;
    }
    let x: Vec<f64> = groups.iter().map(|g| g.0 * 1e3).collect();
    let mut panel = Panel::new(Axis::new("normal load N", "mN").log(), Axis::dimensionless("fraction").range(0.0, 1.0))
        .title(format!("Force carried per element class at the critical state ({what})"))
        .legend_beside(330);
    for &(class, colour, normal, friction) in classes {
        let mean = |pick: fn(&Row) -> f64| -> Vec<(f64, f64)> {
            x.iter().zip(&groups).map(|(&x, g)| (x, spread(g.1.iter().map(|r| pick(r))).1)).collect()
        };
        let n = mean(normal);
        panel.push(Series::scatter(n.clone(), Marker::Circle, colour));
        panel.push(Series::line(n, colour).width(3).label(format!("{class}: normal force N^μ/N")));
        panel.push(
            Series::line(mean(friction), colour).width(3).dashed().label(format!("{class}: friction force F_S^μ/F_S")),
        );
    }
    Some(panel)
}

/// F/N vs δ/δ_peak at the load nearest 0.1 mN, equal load sharing and rigid displacement
/// control (Fig. 4a); δ in metres along the top where the snapshot records its contact's stuck
/// stiffness K_t (the elements' k_t = K_t / n).
fn friction_curve(snap: &MapSnapshot, law: &FrictionLaw) -> Result<(Figure, String)> {
    let (loads, onset) = onset_of(snap, law)?;
    // Both curves run past the peak into sliding; rigid control may need longer to slip all.
    let rigid_end = law.mu_s * loads.sorted()[loads.len() - 1] / onset.critical_shear();
    let end = rigid_end.clamp(1.5, 3.0);
    let els = scaled_curve(&loads, &onset, Loading::EqualLoadSharing, end);
    let rigid = scaled_curve(&loads, &onset, Loading::RigidDisplacement, end);
    let peak = onset.static_coefficient();
    let mut panel = Panel::new(
        Axis::dimensionless("imposed displacement δ/δ_{peak}").range(0.0, end),
        Axis::dimensionless("friction coefficient F/N").range(0.0, law.mu_s * 1.25),
    )
    .title(format!("Friction vs displacement at N = {} ({} elements)", load_label(snap.load_n), onset.elements))
    .legend(LegendPosition::UpperRight);
    // δ = s / k_t, the elements sharing the stuck contact's K_t equally.
    let stiffness = snap.stuck_stiffness.map(|contact| (contact, element_stiffness(contact, onset.elements)));
    let mut length = String::new();
    if let Some((contact, element)) = stiffness {
        let peak_m = displacement(onset.critical_shear(), element);
        let (scale, unit) = super::ticks::prefixed(peak_m * end, "m");
        panel = panel.top_axis(Axis::new("imposed displacement δ", &unit), peak_m * scale);
        length = format!(
            "δ_peak = {} {unit} (top axis: δ in {unit}): δ = s/k_t for an element shear s, the n = {} elements \
             sharing equally the contact's stuck tangential stiffness K_t = {} N/m (the elastic contact's \
             Cerruti operator on this solve's contact set, every point stuck), k_t = K_t/n = {} N/m each, so \
             that the curve's first slope is the elastic contact's.",
            tick_label(&(peak_m * scale)),
            onset.elements,
            tick_label(&contact),
            tick_label(&element)
        );
    }
    // The local coefficients in the colours of the classes that sit at them.
    panel.push(Series::line(vec![(0.0, law.mu_s), (end, law.mu_s)], style::CRITICAL).dotted().label("local μ^S"));
    panel.push(Series::line(vec![(0.0, law.mu_d), (end, law.mu_d)], style::PRE_SLIDING).dashed().label("local μ^D"));
    panel.push(Series::line(rigid, style::PALETTE[2]).width(2).dashed().label("rigid displacement control"));
    panel.push(Series::line(els, style::PALETTE[0]).width(3).label("equal load sharing (the model)"));
    panel.push(
        Series::scatter(vec![(1.0, peak)], Marker::Circle, style::PALETTE[0])
            .hollow()
            .label(format!("critical state: F_S/N = {:.4}", peak)),
    );
    if stiffness.is_none() {
        length = "The study recorded no stuck stiffness K_t with this snapshot (a run before it did), so δ \
                  has no length here and is drawn in units of δ_peak (`asperity onset --shear-stiffness` gives \
                  δ = s/k_t in metres)."
            .into();
    }
    let caption = format!(
        "The macroscopic friction coefficient F/N against the imposed displacement δ (in units of δ_peak, the \
         displacement at the peak) at N = {} for the law \"{}\" (the paper's Fig. 4a): the model's equal load \
         sharing (solid), the peak circled (the critical state, F_S/N = {:.4}), and rigid displacement control \
         without redistribution (dashed, blue), which peaks at the same F_S; the local μ_s (brown, dotted) and μ_d \
         (amber, dashed). {length}",
        load_label(snap.load_n),
        law_name(law),
        peak
    );
    Ok((Figure::new(panel).with_size(1200, 800), caption))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::draw::Draw;
    use plotters::prelude::{IntoDrawingArea, SVGBackend};

    /// Fig. 4a as SVG text, and its caption, on four elements of 1, 2, 3 and 5 × 10⁻⁷ N.
    fn drawn(stuck_stiffness: Option<f64>) -> (String, String) {
        let mut pressure = ndarray::Array2::zeros((4, 4));
        for (k, p) in [1e9, 2e9, 3e9, 5e9].into_iter().enumerate() {
            pressure[[1 + k / 2, 1 + k % 2]] = p;
        }
        let snap = MapSnapshot {
            topography: "ball".into(),
            load_n: 1.1e-6,
            pressure,
            origin: (0, 0),
            grid: (4, 4),
            pixel_size: (1e-8, 1e-8),
            stuck_stiffness,
        };
        let (figure, caption) = friction_curve(&snap, &FrictionLaw::new(0.6, 0.4).unwrap()).unwrap();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
            style::register_fonts();
            figure.draw(&root).unwrap();
            root.present().unwrap();
        }
        (svg, caption)
    }

    /// Every text of `svg` as (y [px], text).
    fn texts(svg: &str) -> Vec<(f64, String)> {
        svg.split("<text")
            .skip(1)
            .map(|t| {
                let y = t.split(" y=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
                let text = t.split_once('>').unwrap().1.split("</text>").next().unwrap();
                (y, text.trim().to_string())
            })
            .collect()
    }

    /// Fig. 4a's δ in metres, not only in units of δ_peak: with the contact's K_t recorded it
    /// reads δ in nm along the top and states δ_peak = n s*/K_t: here the fourth element is the
    /// critical one (F_k = 2.4, 4, 4.8, 5.4 × 10⁻⁷ N), s* = 0.6 · 5e-7 N = 3e-7 N, and with
    /// K_t = 1000 N/m over n = 4 elements, k_t = 250 N/m and δ_peak = 4 · 3e-7 / 1000 m = 1.2 nm.
    #[test]
    fn the_friction_curve_gives_delta_in_nm() {
        let (svg, caption) = drawn(Some(1e3));
        for said in ["δ_peak = 1.2 nm", "n = 4 elements", "K_t = 1000 N/m", "k_t = K_t/n = 250 N/m"] {
            assert!(caption.contains(said), "no \"{said}\" in: {caption}");
        }
        assert!(!caption.contains("no length"), "{caption}");
        // The top axis' name above the plotting area, its ticks at 0.5 nm steps up to 1.5 δ_peak.
        let texts = texts(&svg);
        let name = texts
            .iter()
            .find(|t| t.1 == "imposed displacement δ [nm]")
            .unwrap_or_else(|| panic!("the top axis is not named: {texts:?}"));
        let title = texts.iter().find(|t| t.1.starts_with("Friction vs displacement")).unwrap();
        assert!(title.0 < name.0, "the title at y = {} px, the top axis' name at {} px", title.0, name.0);
        let ticks: Vec<&str> =
            texts.iter().filter(|t| t.0 > name.0 && t.0 < name.0 + 60.0).map(|t| t.1.as_str()).collect();
        assert_eq!(ticks, ["0", "0.5", "1", "1.5"], "the top axis' ticks");

        // A snapshot of an earlier run, without K_t: δ/δ_peak only, as said.
        let (svg, caption) = drawn(None);
        assert!(!svg.contains("δ [nm]") && caption.contains("δ has no length here"), "{caption}");
    }
}
