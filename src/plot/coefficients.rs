//! The study's curves of friction against a control parameter: the friction drop against the
//! load (Fig. 2, with the band over topographies and Young's modulus; under equal and elastic
//! sharing), the static and dynamic
//! coefficients against the load (Fig. S1), the friction drop at coarser pixels (resolution)
//! and against the AFM hold time (aging).
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use super::figure::{Axis, Figure, LegendPosition, Panel};
use super::maps::load_label;
use super::series::{Marker, Series};
use super::shared::{by_load, signed, spread, FigureInput, LOAD_COLOURS};
use super::style;
use super::ticks::tick_label;
use crate::contact::CohesiveLaw;
use crate::friction::{ElementLoads, FrictionLaw, Onset};
use crate::plausible::MAX_FRICTION_COEFFICIENT;
use crate::quantity::{show, FORCE, LENGTH, PRESSURE, SURFACE_ENERGY};
use crate::shs::ShsPoint;
use crate::study::adhesion::{AdhesionLimit, ADHESION_SHARE};
use crate::study::{law_name, ResolutionRow, Row, Sharing, COARSENING};
use plotters::style::RGBColor;

/// A measured point belongs to the law of its hold time when the two agree within this factor.
const HOLD_MATCH: f64 = 1.25;

/// The colour of the law at `index`: black, red, … as the paper's 100 s and 10 s hold times.
pub(super) fn law_colour(index: usize) -> RGBColor {
    style::PALETTE[index % style::PALETTE.len()]
}

/// The index of the law whose hold time matches `point`'s, if any.
fn law_of(input: &FigureInput, point: &ShsPoint) -> Option<usize> {
    input
        .hold_times
        .iter()
        .enumerate()
        .filter_map(|(i, h)| h.map(|h| (i, (point.hold_s / h).ln().abs())))
        .filter(|(_, d)| *d <= HOLD_MATCH.ln())
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// `value(row)` against the load, per topography, in increasing load.
fn per_topography(rows: &[Row], law: &str, value: impl Fn(&Row) -> f64) -> Vec<Vec<(f64, f64)>> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows.iter().filter(|r| r.law == law) {
        if !names.contains(&r.topography.as_str()) {
            names.push(&r.topography);
        }
    }
    names
        .iter()
        .map(|t| {
            let mut curve: Vec<(f64, f64)> =
                rows.iter().filter(|r| r.law == law && r.topography == *t).map(|r| (r.load_n, value(r))).collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            curve
        })
        .collect()
}

/// The value of `curve` (ascending loads) at `load`, linear in log(load) between its points;
/// `None` outside its loads.
pub(super) fn interpolate(curve: &[(f64, f64)], load: f64) -> Option<f64> {
    let k = curve.iter().position(|p| p.0 >= load * (1.0 - 1e-12))?;
    if (curve[k].0 / load - 1.0).abs() < 1e-12 {
        return Some(curve[k].1);
    }
    let (a, b) = (curve.get(k.checked_sub(1)?)?, curve[k]);
    let t = (load / a.0).ln() / (b.0 / a.0).ln();
    Some(a.1 + t * (b.1 - a.1))
}

/// The lowest load [N] at which some topography of `law` has more than one contact element.
fn first_multi_element_load(rows: &[Row], law: &str) -> Option<f64> {
    rows.iter().filter(|r| r.law == law && r.contact_points > 1).map(|r| r.load_n).min_by(f64::total_cmp)
}

/// The x range [mN] of the load axis: the study's loads and the measured ones.
fn load_range(input: &FigureInput) -> (f64, f64) {
    let xs = input.rows.iter().map(|r| r.load_n).chain(input.experiments.iter().map(|p| p.load_n));
    let (lo, hi) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x * 1e3), b.max(x * 1e3)));
    (lo / 1.5, hi * 1.5)
}

/// What the shaded span of the loads outside a non-adhesive model stands for, with the
/// estimate's inputs: one sentence for the report and the figures' captions.
pub(super) fn adhesion_sentence(limit: &AdhesionLimit) -> String {
    format!(
        "Below N = {} (shaded grey) a non-adhesive model does not describe the contact: there the DMT pull-off \
         force 2πRw of a single contacting summit, {} for a work of adhesion w = {} J/m² (assumed: of the order of a \
         water film's capillary adhesion on silicon oxide) and a summit radius R = {} (1/κ, κ the RMS mean \
         curvature of the topography; the largest over the topographies), exceeds {}% of the load, which a solve \
         without adhesion leaves out.",
        show(estimate(limit.load_n), &FORCE),
        show(estimate(limit.pull_off_n), &FORCE),
        tick_label(&limit.work_of_adhesion),
        show(estimate(limit.summit_radius_m), &LENGTH),
        tick_label(&(ADHESION_SHARE * 100.0))
    )
}

/// Adhesion moves the drop by more than this fraction in the load ranges the report states.
pub(super) const ADHESION_MOVES: f64 = 0.01;

/// A range of loads \[N] where adhesion moves the mean drop of a law by more than
/// [`ADHESION_MOVES`]: from `from` to `to`, each `None` where the range reaches the study's
/// lowest or highest load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AdhesionRange {
    pub from: Option<f64>,
    pub to: Option<f64>,
}

/// Where adhesion moves the mean drop (over the applied load, over the topographies) by more
/// than [`ADHESION_MOVES`]: from the curves without (`plain`) and with adhesion (`adhesive`),
/// (load \[N], mean drop) in increasing load, compared at the loads both have. Each range's
/// ends are where the relative difference of the two, linear in log load between the study's
/// loads, crosses the threshold; none when it never exceeds it. At the lowest loads a contact
/// of a pixel or two may catch no cohesive tension at all, so the ranges need not start there.
pub(super) fn adhesion_reach(plain: &[(f64, f64)], adhesive: &[(f64, f64)]) -> Vec<AdhesionRange> {
    let excess: Vec<(f64, f64)> = adhesive
        .iter()
        .filter_map(|&(load, with)| {
            let without = plain.iter().find(|p| (p.0 / load - 1.0).abs() < 1e-9)?.1;
            Some((load, (with / without - 1.0).abs() - ADHESION_MOVES))
        })
        .collect();
    let crossing = |(l0, d0): (f64, f64), (l1, d1): (f64, f64)| {
        let t = d0 / (d0 - d1);
        (l0.ln() + t * (l1.ln() - l0.ln())).exp()
    };
    let mut ranges = Vec::new();
    let mut open: Option<Option<f64>> = excess.first().filter(|e| e.1 > 0.0).map(|_| None);
    for w in excess.windows(2) {
        match (w[0].1 > 0.0, w[1].1 > 0.0) {
            (false, true) => open = Some(Some(crossing(w[0], w[1]))),
            (true, false) => {
                let from = open.take().expect("a range is open while the excess is positive");
                ranges.push(AdhesionRange { from, to: Some(crossing(w[0], w[1])) });
            }
            _ => {}
        }
    }
    if let Some(from) = open {
        ranges.push(AdhesionRange { from, to: None });
    }
    ranges
}

/// The ranges of [`adhesion_reach`] in words.
fn reach_phrase(ranges: &[AdhesionRange]) -> String {
    let at = |load: f64| show(estimate(load), &FORCE);
    let each: Vec<String> = ranges
        .iter()
        .map(|r| match (r.from, r.to) {
            (None, None) => "at every load of the range".to_string(),
            (None, Some(to)) => format!("below N = {}", at(to)),
            (Some(from), None) => format!("above N = {}", at(from)),
            (Some(from), Some(to)) => format!("from N = {} to {}", at(from), at(to)),
        })
        .collect();
    if each.is_empty() {
        "none in the range".to_string()
    } else {
        each.join(" and ")
    }
}

/// The cohesive law of the adhesive solves and, per law, where adhesion moves the mean drop by
/// more than [`ADHESION_MOVES`], as a phrase for the report and the caption; `None` without
/// adhesive rows.
pub(super) fn adhesion_solved(input: &FigureInput) -> Option<String> {
    let law = input.cohesive_law.filter(|_| !input.adhesive_rows.is_empty())?;
    let cohesive = match law {
        CohesiveLaw::Maugis { work, stress } => format!(
            "the Maugis–Dugdale law, w = {}, σ₀ = {}, h₀ = {}",
            show(work, &SURFACE_ENERGY),
            show(stress, &PRESSURE),
            show(law.range(), &LENGTH)
        ),
        CohesiveLaw::Exponential { work, range } => {
            format!("the exponential law, w = {}, ρ = {}", show(work, &SURFACE_ENERGY), show(range, &LENGTH))
        }
    };
    let mean = |rows: &[Row], name: &str| -> Vec<(f64, f64)> {
        by_load(rows, name).iter().map(|g| (g.0, spread(g.1.iter().map(|r| r.friction_drop)).1)).collect()
    };
    let reach: Vec<String> = input
        .laws
        .iter()
        .map(|law| {
            let name = law_name(law);
            let found = reach_phrase(&adhesion_reach(&mean(input.rows, &name), &mean(input.adhesive_rows, &name)));
            format!("\"{name}\": {found}")
        })
        .collect();
    Some(format!(
        "{cohesive}; adhesion moves the mean drop over the applied load by more than {}% — {}",
        tick_label(&(ADHESION_MOVES * 100.0)),
        reach.join("; ")
    ))
}

/// `x` to the two significant digits an order-of-magnitude estimate has.
fn estimate(x: f64) -> f64 {
    format!("{x:.1e}").parse().expect("a formatted float parses")
}

/// The shaded span of the loads [mN] below the adhesion limit, within the axis `x` [mN].
fn adhesion_span(limit: Option<AdhesionLimit>, (x0, x1): (f64, f64)) -> Option<Series> {
    let to = limit?.load_n * 1e3;
    (to > x0).then(|| {
        Series::span(x0, to.min(x1), style::GREY)
            .opacity(0.2)
            .label(format!("outside a non-adhesive model: N < {}", show(estimate(to * 1e-3), &FORCE)))
    })
}

/// y range fitting `levels` with a little room.
fn fit(levels: &[f64]) -> (f64, f64) {
    let (lo, hi) = levels.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let pad = ((hi - lo) * 0.06).max(0.005);
    (lo - pad, hi + pad)
}

/// Measured points as a scatter series with error bars where given; extends `levels`.
fn measured(xy: Vec<(f64, f64)>, err: Vec<f64>, marker: Marker, colour: RGBColor, levels: &mut Vec<f64>) -> Series {
    levels.extend(xy.iter().zip(&err).flat_map(|(p, e)| [p.1 - e, p.1 + e]));
    Series::scatter(xy, marker, colour).errors(err)
}

/// The panel of the friction drop against the load [mN] over `x` and `y`, its legend beside the
/// axes: the bands span the height at low loads and the ticks line the top.
fn drop_vs_load(x: (f64, f64), y: (f64, f64), title: &str) -> Panel {
    Panel::new(
        Axis::new("normal load N", "mN").log().range(x.0, x.1),
        Axis::dimensionless("friction drop F_S/(μ^D N)").range(y.0, y.1),
    )
    .title(title)
    .legend_beside(480)
}

/// Friction drop vs load (Fig. 2): per law a band over the topographies — and over E ± ΔE when
/// the study gives ΔE, by drop(N; E*) = drop(N·E*₀/E*; E*₀) — their mean, the single-element
/// value mu_s/mu_d dotted below the first load carried by more than one element, the measured
/// points of the law's hold time, and the loads of the p(σ) figure.
pub(super) fn friction_drop(input: &FigureInput) -> Option<(Figure, String)> {
    let (x0, x1) = load_range(input);
    let mut series = Vec::new();
    let mut levels: Vec<f64> = Vec::new();
    let topographies = input.topographies.len();
    let mut matched = vec![false; input.experiments.len()];
    for (i, law) in input.laws.iter().enumerate() {
        let name = law_name(law);
        let curves = per_topography(input.rows, &name, |r| r.friction_drop);
        let groups = by_load(input.rows, &name);
        if groups.is_empty() {
            continue;
        }
        let colour = law_colour(i);
        let loads: Vec<f64> = groups.iter().map(|g| g.0).collect();
        let x: Vec<f64> = loads.iter().map(|l| l * 1e3).collect();
        let mut ratios = vec![1.0];
        ratios.extend_from_slice(input.modulus_ratios);
        let (lower, upper): (Vec<f64>, Vec<f64>) = loads
            .iter()
            .map(|&n| {
                let values = curves.iter().flat_map(|c| ratios.iter().filter_map(|r| interpolate(c, n * r)));
                let (lo, _, hi) = spread(values);
                (lo, hi)
            })
            .unzip();
        levels.extend(lower.iter().chain(&upper));
        let mean: Vec<(f64, f64)> =
            x.iter().zip(&groups).map(|(&x, g)| (x, spread(g.1.iter().map(|r| r.friction_drop)).1)).collect();
        let band = if topographies > 1 { format!("{topographies} topographies") } else { "1 topography".into() };
        let modulus = if input.modulus_ratios.is_empty() { String::new() } else { ", E ± ΔE".to_string() };
        series.push(
            Series::band(x.clone(), lower, upper, colour).label(format!("{name}: model, range over {band}{modulus}")),
        );
        series.push(Series::line(mean, colour).label(format!("{name}: model, mean over the topographies")));
        if let Some((other, ratio)) = input.counterface {
            // The mean drop against the other counterface, from the same solves.
            let means: Vec<(f64, f64)> = loads
                .iter()
                .filter_map(|&n| {
                    let values: Vec<f64> = curves.iter().filter_map(|c| interpolate(c, n * ratio)).collect();
                    (values.len() == curves.len()).then(|| (n * 1e3, spread(values.into_iter()).1))
                })
                .collect();
            levels.extend(means.iter().map(|m| m.1));
            series.push(Series::line(means, colour).width(1).dashed().label(format!("{name}: model, on {other}")));
        }
        let adhesive = by_load(input.adhesive_rows, &name);
        if !adhesive.is_empty() {
            // The same solves with adhesion: the drop over the applied load and over the total
            // normal force (the paper's AFM definition), each the mean over the topographies.
            let mean = |value: fn(&Row) -> f64| -> Vec<(f64, f64)> {
                adhesive.iter().map(|g| (g.0 * 1e3, spread(g.1.iter().map(|r| value(r))).1)).collect()
            };
            let (applied, total) =
                (mean(|r| r.friction_drop), mean(|r| r.friction_drop_total_load.unwrap_or(f64::NAN)));
            levels.extend(applied.iter().chain(&total).map(|p| p.1));
            series.push(
                Series::line(applied.clone(), colour)
                    .width(3)
                    .dashed()
                    .label(format!("{name}: with adhesion, F_S/(μ^D N)")),
            );
            series.push(Series::scatter(applied, Marker::Triangle, colour).hollow());
            series.push(
                Series::line(total.clone(), colour)
                    .width(1)
                    .label(format!("{name}: with adhesion, F_S/(μ^D (N + N_a))")),
            );
            series.push(Series::scatter(total, Marker::Square, colour).hollow());
        }
        let limit = law.drop();
        levels.push(limit);
        series.push(single_element_line(input.rows, &name, limit, (x0, x1), colour));
        let mine: Vec<&ShsPoint> = input
            .experiments
            .iter()
            .zip(matched.iter_mut())
            .filter(|(p, _)| law_of(input, p) == Some(i))
            .map(|(p, m)| {
                *m = true;
                p
            })
            .collect();
        if !mine.is_empty() {
            let xy = mine.iter().map(|p| (p.load_n * 1e3, p.friction_drop)).collect();
            let err = mine.iter().map(|p| p.friction_drop_std.unwrap_or(0.0)).collect();
            series.push(measured(xy, err, Marker::Circle, colour, &mut levels).label(format!("{name}: measured")));
        }
    }
    if series.is_empty() {
        return None;
    }
    let others: Vec<&ShsPoint> = input.experiments.iter().zip(&matched).filter(|(_, m)| !**m).map(|(p, _)| p).collect();
    if !others.is_empty() {
        let xy = others.iter().map(|p| (p.load_n * 1e3, p.friction_drop)).collect();
        let err = others.iter().map(|p| p.friction_drop_std.unwrap_or(0.0)).collect();
        series.push(
            measured(xy, err, Marker::Square, style::GREY, &mut levels).label("measured, other hold times".to_string()),
        );
    }
    let (y0, y1) = fit(&levels);
    // The loads of the p(σ) figure: short ticks along the top, not lines like axes; one legend
    // entry says what they are, the caption names each load.
    let top = y1 - (y1 - y0) * 0.08;
    let mut marked = Vec::new();
    for (k, &target) in crate::study::FIGURE_LOADS_N[..3].iter().enumerate() {
        if let Some(load) = nearest_load(input.rows, target) {
            let tick = Series::line(vec![(load * 1e3, top), (load * 1e3, y1)], LOAD_COLOURS[k]).width(4);
            series.push(if marked.is_empty() {
                tick.label("ticks along the top: the loads of the p(σ) figure")
            } else {
                tick
            });
            marked.push(load_label(load));
        }
    }
    series.extend(adhesion_span(input.adhesion, (x0, x1)));
    let mut panel = drop_vs_load((x0, x1), (y0, y1), "Friction drop vs normal load");
    panel.series = series;
    let experiments = if input.experiments.is_empty() {
        " No measured points were given.".to_string()
    } else {
        " Points: measured friction drops F_S/F_D (mean ± standard deviation where given), coloured as the law of \
         their hold time; grey squares match no law's hold time."
            .to_string()
    };
    let modulus = if input.modulus_ratios.is_empty() {
        String::new()
    } else {
        " and over Young's modulus E ± ΔE (from the same solves: by linear elasticity the drop at load N for a \
         modulus E* is the drop at N·E*₀/E* for the study's E*₀)"
            .to_string()
    };
    let counterface = match input.counterface {
        Some((other, ratio)) => format!(
            " The thin dashed line is the mean drop on {other} instead of the study's counterface, from the same \
             solves by the same scaling (the drop at N is the study's at {} N), where the loads allow.",
            tick_label(&ratio)
        ),
        None => String::new(),
    };
    let adhesive = match adhesion_solved(input) {
        Some(found) => format!(
            " The band and its line are the solves without adhesion. With adhesion ({found}), the thick dashed line \
             with triangles is the mean drop over the applied load, F_S/(μ_d N), and the thin line with squares the \
             mean over the total normal force, F_S/(μ_d (N + N_a)) with N_a the adhesive force (the paper's AFM \
             definition); the friction model sees the compressive pressure only."
        ),
        None => String::new(),
    };
    let caption = format!(
        "The friction drop F_S/(μ_d N) as a function of normal load (the paper's Fig. 2): per friction law, the \
         shaded band spans the values over the {topographies} topograph{}{modulus}, the line is the mean over the \
         topographies, and the dotted line is the single-element value μ_s/μ_d, drawn below the lowest load carried \
         by more than one element.{adhesive}{counterface}{experiments} Short ticks along the top mark the loads of \
         the p(σ) figure ({}), coloured as its curves.{}",
        if topographies == 1 { "y" } else { "ies" },
        marked.join(", "),
        input.adhesion.map_or(String::new(), |a| {
            let curve = if input.adhesive_rows.is_empty() { "" } else { " (for the solves without adhesion)" };
            format!(" {}{curve}", adhesion_sentence(&a))
        })
    );
    Some((Figure::new(panel).with_size(1800, 850), caption))
}

/// Elastic sharing lowers the drop where its excess over 1 (drop − 1) lies this fraction below
/// equal sharing's under the same weakening: well above the solvers' tolerances, and
/// meaningful as both drops near 1.
const LOWERED: f64 = 0.1;

/// Friction drop vs load under equal sharing (the paper's), equal sharing with elastic
/// sharing's slip weakening, and elastic sharing: per law a band over the topographies and
/// their mean for each (solid, thin solid, dashed), and the single-element value mu_s/mu_d.
/// With a band of d_c the two weakening models' bands span its ends too, as the friction-drop
/// figure's band spans E ± ΔE. `None` without elastic-sharing rows.
pub(super) fn friction_drop_sharing(input: &FigureInput) -> Option<(Figure, String)> {
    if input.elastic_rows.is_empty() {
        return None;
    }
    let xs = input.rows.iter().chain(input.weakening_rows).chain(input.elastic_rows).map(|r| r.load_n * 1e3);
    let (x0, x1) = xs.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    let (x0, x1) = (x0 / 1.5, x1 * 1.5);
    let mut series = Vec::new();
    let mut levels: Vec<f64> = Vec::new();
    let (mut findings, mut weakened) = (Vec::new(), Vec::new());
    let at_band_ends =
        |sharing: Sharing| -> Vec<Row> { input.band_rows.iter().filter(|r| r.sharing == sharing).cloned().collect() };
    let (equal_ends, elastic_ends) = (at_band_ends(Sharing::Equal), at_band_ends(Sharing::Elastic));
    let dc_range = match input.slip_distance_band {
        [low, high] => format!("d_c {} to {}", show(*low, &LENGTH), show(*high, &LENGTH)),
        _ => String::new(),
    };
    for (i, law) in input.laws.iter().enumerate() {
        let name = law_name(law);
        let colour = law_colour(i);
        let mut means = Vec::new();
        // Each model's rows, the rows at the ends of the band of d_c, its band's opacity (with
        // a band of d_c, and without it) and its marker.
        let sharings = [
            (input.rows, &[][..], (0.25, 0.25), Marker::Circle, "equal sharing"),
            (input.weakening_rows, &equal_ends[..], (0.1, 0.0), Marker::Triangle, "equal sharing, weakening"),
            (input.elastic_rows, &elastic_ends[..], (0.12, 0.12), Marker::Square, "elastic sharing"),
        ];
        for (s, (rows, ends, (widened, opacity), marker, what)) in sharings.into_iter().enumerate() {
            let groups = by_load(rows, &name);
            if groups.is_empty() {
                means.push(Vec::new());
                continue;
            }
            let x: Vec<f64> = groups.iter().map(|g| g.0 * 1e3).collect();
            let stats: Vec<(f64, f64, f64)> =
                groups.iter().map(|g| spread(g.1.iter().map(|r| r.friction_drop))).collect();
            let ends = by_load(ends, &name);
            // The band: over the topographies, and at the ends of the band of d_c where the law
            // has rows there.
            let (lower, upper): (Vec<f64>, Vec<f64>) = groups
                .iter()
                .map(|(load, rows)| {
                    let more = ends.iter().filter(|e| (e.0 / load - 1.0).abs() < 1e-9).flat_map(|e| &e.1);
                    let (lo, _, hi) = spread(rows.iter().chain(more).map(|r| r.friction_drop));
                    (lo, hi)
                })
                .unzip();
            levels.extend(lower.iter().chain(&upper));
            let topographies = groups.iter().map(|g| g.1.len()).max().unwrap_or(0);
            let band =
                if topographies == 1 { "1 topography".to_string() } else { format!("{topographies} topographies") };
            if !ends.is_empty() {
                series.push(
                    Series::band(x.clone(), lower, upper, colour)
                        .opacity(widened)
                        .label(format!("{name}: {what}, range over {band} and {dc_range}")),
                );
            } else if opacity > 0.0 {
                series.push(Series::band(x.clone(), lower, upper, colour).opacity(opacity));
            }
            let mean: Vec<(f64, f64)> = x.iter().copied().zip(stats.iter().map(|s| s.1)).collect();
            let line = Series::line(mean.clone(), colour).label(format!("{name}: {what}, {band}"));
            series.push(match s {
                0 => line.width(3),
                1 => line.width(1),
                _ => line.width(3).dashed(),
            });
            series.push(Series::scatter(mean.clone(), marker, colour).hollow());
            means.push(groups.iter().map(|g| g.0).zip(stats.iter().map(|s| s.1)).collect::<Vec<_>>());
        }
        let limit = law.drop();
        levels.push(limit);
        series.push(single_element_line(input.rows, &name, limit, (x0, x1), colour));
        let at =
            |means: &[(f64, f64)], load: f64| means.iter().find(|(l, _)| (l / load - 1.0).abs() < 1e-9).map(|m| m.1);
        // The interaction alone: elastic against equal sharing under the same weakening (the
        // paper's equal sharing where the laws drop at once).
        let like = if means[1].is_empty() { &means[0] } else { &means[1] };
        // The lowest load from which on the mean elastic drop's excess stays clearly below the
        // mean equal one's, at every load both have.
        let lowered: Vec<(f64, bool)> = means[2]
            .iter()
            .filter_map(|(load, elastic)| Some((*load, elastic - 1.0 < (1.0 - LOWERED) * (at(like, *load)? - 1.0))))
            .collect();
        // The weakening alone: equal sharing with it against the paper's.
        let moves: Vec<f64> = means[1].iter().filter_map(|(load, weak)| Some(weak - at(&means[0], *load)?)).collect();
        if let (Some(low), Some(high)) =
            (moves.iter().copied().reduce(f64::min), moves.iter().copied().reduce(f64::max))
        {
            weakened.push(format!("for \"{name}\" by {} to {}", signed(low), signed(high)));
        }
        let from = (0..lowered.len()).find(|&k| lowered[k..].iter().all(|p| p.1));
        findings.push(match from {
            Some(k) => format!("for \"{name}\" from N = {} on", load_label(lowered[k].0)),
            None => format!("for \"{name}\" not at the highest load"),
        });
    }
    let (y0, y1) = fit(&levels);
    series.extend(adhesion_span(input.adhesion, (x0, x1)));
    let mut panel = drop_vs_load((x0, x1), (y0, y1), "Friction drop vs normal load: equal and elastic sharing");
    panel.series = series;
    let weakening = if input.slip_distance_m > 0.0 {
        format!(
            "μ_s until an element first slips, then falling to μ_d over a slip of d_c = {} (a law from a measured \
             curve follows its own)",
            show(input.slip_distance_m, &LENGTH)
        )
    } else {
        "μ_s until an element first slips, then μ_d at once".to_string()
    };
    let weakening_alone = if weakened.is_empty() {
        String::new()
    } else {
        format!(
            " The weakening alone (equal sharing, with it against the instant drop) moves the mean drop {}.",
            weakened.join(", ")
        )
    };
    let dc_band = match input.slip_distance_band {
        [low, high] if !input.band_rows.is_empty() => format!(
            " The bands of elastic sharing and of equal sharing with the weakening span the slip-weakening distance \
             too, from d_c = {} to {} (the lines stay at d_c = {}).",
            show(*low, &LENGTH),
            show(*high, &LENGTH),
            show(input.slip_distance_m, &LENGTH)
        ),
        _ => String::new(),
    };
    let caption = format!(
        "The friction drop F_S/(μ_d N) against the normal load with the tangential force shared equally among the \
         stuck elements (the paper's model, μ_d from an element's first slip; thick solid, circles), shared equally \
         under elastic sharing's slip weakening (each element a spring–slider of the contact's stuck stiffness K_t/n; \
         thin solid, triangles), and through the elastic half-space (dashed, squares; the same pressure maps, the body \
         displaced rigidly along x, {weakening}): per law, the band spans the values over the topographies (paler for \
         elastic sharing) and the line joins their mean; dotted: the single-element value μ_s/μ_d, drawn below the \
         lowest load carried by more than one element. The interaction alone (elastic against equal sharing under the \
         same weakening) lowers the mean excess drop − 1 by more than {}% at every load {}.{weakening_alone}{dc_band}{}",
        tick_label(&(LOWERED * 100.0)),
        findings.join(", "),
        input.adhesion.map_or(String::new(), |a| format!(" {}", adhesion_sentence(&a)))
    );
    Some((Figure::new(panel).with_size(1800, 850), caption))
}

/// The swept load nearest `target` in log scale, if within half a decade.
fn nearest_load(rows: &[Row], target: f64) -> Option<f64> {
    rows.iter()
        .map(|r| r.load_n)
        .filter(|l| (l / target).log10().abs() <= 0.5)
        .min_by(|a, b| (a / target).ln().abs().total_cmp(&(b / target).ln().abs()))
}

/// Static and dynamic friction coefficients vs load (Fig. S1): per law the band of F_S/N over
/// the topographies and the constant mu_d, with the measured points of its hold time.
pub(super) fn static_dynamic(input: &FigureInput) -> Option<(Figure, String)> {
    let (x0, x1) = load_range(input);
    let mut series = Vec::new();
    let mut levels = Vec::new();
    // Laws of one μ^D share one dynamic line: drawn per law, each would hide the others.
    let shared_mu_d = input.laws.len() > 1 && input.laws.iter().all(|l| l.mu_d == input.laws[0].mu_d);
    let (mut d0, mut d1) = (f64::INFINITY, 0.0f64);
    for (i, law) in input.laws.iter().enumerate() {
        let name = law_name(law);
        let groups = by_load(input.rows, &name);
        if groups.is_empty() {
            continue;
        }
        let colour = law_colour(i);
        let x: Vec<f64> = groups.iter().map(|g| g.0 * 1e3).collect();
        let stats: Vec<(f64, f64, f64)> =
            groups.iter().map(|g| spread(g.1.iter().map(|r| r.static_coefficient))).collect();
        levels.extend(stats.iter().flat_map(|s| [s.0, s.2]));
        levels.push(law.mu_d);
        series.push(
            Series::band(x.clone(), stats.iter().map(|s| s.0).collect(), stats.iter().map(|s| s.2).collect(), colour)
                .label(format!("{name}: static μ_S = F_S/N (model)")),
        );
        series.push(Series::line(x.iter().copied().zip(stats.iter().map(|s| s.1)).collect(), colour));
        // The dynamic line spans the loads solved, not the whole axis.
        let (first, last) = (x[0], x[x.len() - 1]);
        (d0, d1) = (d0.min(first), d1.max(last));
        if !shared_mu_d {
            series.push(
                Series::line(vec![(first, law.mu_d), (last, law.mu_d)], colour)
                    .dashed()
                    .label(format!("{name}: dynamic μ_D = μ^D = {}", tick_label(&law.mu_d))),
            );
        }
        let mine: Vec<&ShsPoint> = input.experiments.iter().filter(|p| law_of(input, p) == Some(i)).collect();
        let pick = |f: fn(&ShsPoint) -> (Option<f64>, Option<f64>)| -> (Vec<(f64, f64)>, Vec<f64>) {
            mine.iter()
                .filter_map(|p| {
                    let (v, e) = f(p);
                    v.map(|v| ((p.load_n * 1e3, v), e.unwrap_or(0.0)))
                })
                .unzip()
        };
        let (xy, err) = pick(|p| (p.static_coefficient, p.static_coefficient_std));
        if !xy.is_empty() {
            series.push(measured(xy, err, Marker::Circle, colour, &mut levels).label(format!("{name}: measured μ_S")));
        }
        let (xy, err) = pick(|p| (p.dynamic_coefficient, p.dynamic_coefficient_std));
        if !xy.is_empty() {
            series.push(
                measured(xy, err, Marker::Square, colour, &mut levels).hollow().label(format!("{name}: measured μ_D")),
            );
        }
    }
    if series.is_empty() {
        return None;
    }
    if shared_mu_d {
        let mu_d = input.laws[0].mu_d;
        series.push(
            Series::line(vec![(d0, mu_d), (d1, mu_d)], style::GREY)
                .dashed()
                .label(format!("every law: dynamic μ_D = μ^D = {}", tick_label(&mu_d))),
        );
    }
    let (y0, y1) = fit(&levels);
    let mut panel = Panel::new(
        Axis::new("normal load N", "mN").log().range(x0, x1),
        Axis::dimensionless("friction coefficient").range(y0, y1),
    )
    .title("Static and dynamic friction coefficients vs normal load")
    .legend(LegendPosition::UpperRight);
    panel.series = series;
    let shared = if shared_mu_d { " (one grey line: every law has the same μ_d)" } else { "" };
    let caption = format!(
        "The static friction coefficient μ_S = F_S/N (band over the topographies, line their mean) and the dynamic \
         one μ_D (dashed{shared}: the model's is the local μ_d at every load) against the normal load (the paper's \
         Fig. S1); filled circles and open squares: measured μ_S and μ_D of the law's hold time, where the study \
         gives measured points."
    );
    Some((Figure::new(panel).with_size(1400, 850), caption))
}

/// Colours of the pixel sizes: the study's, 2× and 4× coarser.
const RESOLUTION_COLOURS: [RGBColor; 3] = [RGBColor(20, 20, 20), RGBColor(30, 100, 200), RGBColor(230, 120, 0)];

/// Friction drop vs load for the first law at the study's pixel size and [`COARSENING`] times
/// coarser: a band over the topographies and their mean per pixel size.
pub(super) fn resolution(input: &FigureInput) -> Option<(Figure, String)> {
    let law = input.laws.first()?;
    let name = law_name(law);
    let mut series = Vec::new();
    let mut levels = vec![law.drop()];
    let mut pixels = Vec::new();
    // Per pixel size: its name and the lowest load with more than one element on some
    // topography, which the caption states as the data have it.
    let mut first_multi = Vec::new();
    for (k, factor) in std::iter::once(1).chain(COARSENING).enumerate() {
        let rows: Vec<&ResolutionRow> =
            input.resolution.iter().filter(|r| r.coarsening == factor && r.law == name).collect();
        if rows.is_empty() {
            continue;
        }
        let mut loads: Vec<f64> = rows.iter().map(|r| r.load_n).collect();
        loads.sort_by(f64::total_cmp);
        loads.dedup();
        let stats: Vec<(f64, f64, f64)> =
            loads.iter().map(|&l| spread(rows.iter().filter(|r| r.load_n == l).map(|r| r.friction_drop))).collect();
        levels.extend(stats.iter().flat_map(|s| [s.0, s.2]));
        let x: Vec<f64> = loads.iter().map(|l| l * 1e3).collect();
        // Each topography's own pixel: files of one study need not share theirs.
        let nm = |m: f64| format!("{} nm", tick_label(&(m * 1e9)));
        let mut own: Vec<(&str, f64)> = Vec::new();
        for r in &rows {
            if !own.iter().any(|(t, _)| *t == r.topography) {
                own.push((&r.topography, r.pixel_size_m));
            }
        }
        let one = own.iter().all(|(_, p)| (p / own[0].1 - 1.0).abs() < 1e-9);
        let pixel = if one {
            nm(own[0].1)
        } else {
            own.iter().map(|(t, p)| format!("{} on {t}", nm(*p))).collect::<Vec<_>>().join(", ")
        };
        let what = if factor == 1 { "the study's pixel".to_string() } else { format!("{factor}× coarser") };
        pixels.push(format!("{what}: {pixel}"));
        let multi = rows.iter().filter(|r| r.contact_points > 1).min_by(|a, b| a.load_n.total_cmp(&b.load_n));
        first_multi.push(match multi {
            Some(r) => format!(
                "{what}: {} ({} elements on {}, pixel {})",
                load_label(r.load_n),
                r.contact_points,
                r.topography,
                nm(r.pixel_size_m)
            ),
            None => format!("{what}: none"),
        });
        let colour = RESOLUTION_COLOURS[k];
        series.push(
            Series::band(x.clone(), stats.iter().map(|s| s.0).collect(), stats.iter().map(|s| s.2).collect(), colour)
                .label(format!("{what}: {pixel}")),
        );
        series.push(Series::line(x.into_iter().zip(stats.iter().map(|s| s.1)).collect(), colour));
    }
    if pixels.len() < 2 {
        return None;
    }
    let (x0, x1) = load_range(input);
    series.push(
        Series::line(vec![(x0, law.drop()), (x1, law.drop())], style::GREY)
            .dotted()
            .label(format!("one element: μ^S/μ^D = {}", tick_label(&law.drop()))),
    );
    let (y0, y1) = fit(&levels);
    let mut panel = Panel::new(
        Axis::new("normal load N", "mN").log().range(x0, x1),
        Axis::dimensionless("friction drop F_S/(μ^D N)").range(y0, y1),
    )
    .title(format!("Friction drop vs load at {} resolutions ({name})", pixels.len()))
    .legend(LegendPosition::LowerLeft);
    panel.series = series;
    let caption = format!(
        "The friction drop against the normal load for the law \"{name}\" with the same topographies resampled to \
         coarser pixels ({}; band over the topographies, line their mean). The pixel is the model's element: a coarser \
         pixel carries more load per element, so on the whole the drop at a given load is higher; but resampling \
         also splits and merges contact spots, so a coarser grid need not stay single-element longer. The lowest \
         load with more than one element on some topography, per resolution: {}. Results of the model hold for one \
         pixel size; a study on another grid (such as `asperity run --quick`) gives other numbers.",
        pixels.join("; "),
        first_multi.join("; ")
    );
    Some((Figure::new(panel).with_size(1400, 850), caption))
}

/// The aging law through the laws with a hold time (`laws`: (t [s], law), at least two), when
/// they share mu_d and lie on one line mu_s(t) = mu_s(t₀) + β·log10(t/t₀): (t₀, mu_s(t₀), β, mu_d),
/// t₀ the first law's hold time. The default study's two laws are such a law.
fn aging_law(laws: &[(f64, &FrictionLaw)]) -> Option<(f64, f64, f64, f64)> {
    let (t0, first) = laws[0];
    let (t1, last) = laws[laws.len() - 1];
    let beta = (last.mu_s - first.mu_s) / (t1 / t0).log10();
    let on_line = |&(t, law): &(f64, &FrictionLaw)| {
        let mu_s = first.mu_s + beta * (t / t0).log10();
        law.mu_d == first.mu_d && (law.mu_s - mu_s).abs() <= 1e-9 * law.mu_s
    };
    (t1 > t0 && beta.is_finite() && laws.iter().all(on_line)).then_some((t0, first.mu_s, beta, first.mu_d))
}

/// Hold times [s] at which the aging curve is drawn: 12 per decade from 1 s to 10⁴ s, widened
/// to a decade beyond the hold times `(lo, hi)` [s] of the laws and the measured points.
fn aging_samples((lo, hi): (f64, f64)) -> Vec<f64> {
    let (a, b) = ((lo / 10.0).min(1.0).log10().floor(), (hi * 10.0).max(1e4).log10().ceil());
    let n = ((b - a) * 12.0).round() as i32;
    (0..=n).map(|k| 10f64.powf(a + (b - a) * f64::from(k) / f64::from(n))).collect()
}

/// Friction drop vs hold time at the chosen loads (aging): the laws of the study with a hold
/// time, each at its hold time (mean over the topographies, their range as a bar); when the
/// laws are one aging law, that law sampled over hold times from 1 s to 10⁴ s on the first
/// topography's kept pressure map at each load; measured points at their hold time.
pub(super) fn hold_time(input: &FigureInput) -> Option<(Figure, String)> {
    let mut laws: Vec<(f64, &FrictionLaw)> =
        input.laws.iter().zip(input.hold_times).filter_map(|(l, h)| h.map(|h| (h, l))).collect();
    laws.sort_by(|a, b| a.0.total_cmp(&b.0));
    if laws.len() < 2 {
        return None;
    }
    let aging = aging_law(&laws);
    let times: Vec<f64> = laws.iter().map(|l| l.0).collect();
    let hold_xs = times.iter().copied().chain(input.experiments.iter().map(|p| p.hold_s));
    let (t_lo, t_hi) = hold_xs.fold((f64::INFINITY, 0.0f64), |(a, b), t| (a.min(t), b.max(t)));
    let samples = if aging.is_some() { aging_samples((t_lo, t_hi)) } else { Vec::new() };
    let mut series = Vec::new();
    let mut levels = Vec::new();
    let mut chosen = Vec::new();
    let mut sampled = Vec::new();
    for (k, &target) in input.hold_time_loads.iter().enumerate() {
        let Some(load) = nearest_load(input.rows, target) else { continue };
        chosen.push(load);
        let colour = LOAD_COLOURS[k % LOAD_COLOURS.len()];
        // The aging law on the first topography's map at this load, where the study kept one.
        let map = input.maps.iter().find(|m| (m.load_n / load - 1.0).abs() < 1e-9);
        let loads = map.and_then(|m| ElementLoads::from_pressure(&m.pressure, m.pixel_area()).ok());
        if let (Some((t0, mu_s0, beta, mu_d)), Some(loads), Some(map)) = (aging, loads, map) {
            let curve: Vec<(f64, f64)> = samples
                .iter()
                .filter_map(|&t| {
                    // At μ_s = μ_d (t = 1 s for the default law) a rounding error must not drop the point.
                    let mu_s = mu_s0 + beta * (t / t0).log10();
                    let mu_s = if (mu_s - mu_d).abs() <= 1e-12 * mu_d { mu_d } else { mu_s };
                    let law = FrictionLaw::new(mu_s, mu_d).ok().filter(|_| mu_s <= MAX_FRICTION_COEFFICIENT)?;
                    Some((t, Onset::new(&loads, &law).friction_drop()))
                })
                .collect();
            levels.extend(curve.iter().map(|p| p.1));
            series.push(Series::line(curve, colour).label(format!(
                "aging law at {}, {}",
                load_label(load),
                map.topography
            )));
            sampled.push(load_label(load));
        }
        let marks = laws.iter().map(|(t, law)| {
            let name = law_name(law);
            let drops = input.rows.iter().filter(|r| r.law == name && (r.load_n / load - 1.0).abs() < 1e-9);
            (*t, spread(drops.map(|r| r.friction_drop)))
        });
        let mut means = Vec::new();
        for (t, (lo, mean, hi)) in marks {
            levels.extend([lo, hi]);
            series.push(Series::line(vec![(t, lo), (t, hi)], colour).width(4));
            means.push((t, mean));
        }
        let topographies = input.topographies.len();
        series.push(
            Series::scatter(means, Marker::Circle, colour)
                .hollow()
                .label(format!("the study's laws at {} (mean, range over {topographies})", load_label(load))),
        );
    }
    if chosen.is_empty() {
        return None;
    }
    // Measured points at the chosen load nearest theirs (within half a decade), else grey.
    // Per load: (hold time [s], drop) and the drop's standard deviation.
    type Measured = (Vec<(f64, f64)>, Vec<f64>);
    let mut by_load: Vec<Measured> = vec![(Vec::new(), Vec::new()); chosen.len() + 1];
    for p in input.experiments {
        let k = chosen
            .iter()
            .enumerate()
            .filter(|(_, l)| (p.load_n / **l).log10().abs() <= 0.5)
            .min_by(|a, b| (p.load_n / a.1).ln().abs().total_cmp(&(p.load_n / b.1).ln().abs()))
            .map_or(chosen.len(), |(k, _)| k);
        by_load[k].0.push((p.hold_s, p.friction_drop));
        by_load[k].1.push(p.friction_drop_std.unwrap_or(0.0));
    }
    for (k, (xy, err)) in by_load.into_iter().enumerate() {
        if xy.is_empty() {
            continue;
        }
        let (colour, label) = match chosen.get(k) {
            Some(load) => (LOAD_COLOURS[k % LOAD_COLOURS.len()], format!("measured near {}", load_label(*load))),
            None => (style::GREY, "measured at other loads".to_string()),
        };
        series.push(measured(xy, err, Marker::Square, colour, &mut levels).hollow().label(label));
    }
    let (y0, y1) = fit(&levels);
    // Each law of the study marked at its hold time across the panel.
    for (t, law) in &laws {
        let label = format!("law \"{}\": t = {} s", law_name(law), tick_label(t));
        series.push(Series::line(vec![(*t, y0), (*t, y1)], style::GREY).dotted().width(1).label(label));
    }
    let (t0, t1) = samples.iter().fold((t_lo, t_hi), |(a, b), &t| (a.min(t), b.max(t)));
    let mut panel = Panel::new(
        Axis::new("hold time t", "s").log().range(t0 / 1.5, t1 * 1.5),
        Axis::dimensionless("friction drop F_S/(μ^D N)").range(y0, y1),
    )
    .title("Friction drop vs hold time")
    // Beside the axes: the curves span the panel.
    .legend_beside(560);
    panel.series = series;
    let names: Vec<String> =
        laws.iter().map(|(t, l)| format!("\"{}\" (t = {} s)", law_name(l), tick_label(t))).collect();
    let curve = match aging {
        Some((t0, mu_s0, beta, mu_d)) if !sampled.is_empty() => format!(
            " The laws are one aging law, μ_s(t) = {} + {}·log10(t/{} s) with μ_d = {}: its curves (lines) are its \
             friction drop at {} hold times from {} s to {} s on the first topography's pressure map at {} (where \
             μ_s(t) ≥ μ_d).",
            tick_label(&mu_s0),
            tick_label(&beta),
            tick_label(&t0),
            tick_label(&mu_d),
            samples.len(),
            tick_label(&samples[0]),
            tick_label(&samples[samples.len() - 1]),
            sampled.join(", ")
        ),
        Some(_) => " No pressure map was kept at these loads, so the aging law is not sampled between them.".into(),
        None => {
            " The laws are not one aging law (a shared μ_d, μ_s linear in log t), so nothing is drawn between them."
                .into()
        }
    };
    let caption = format!(
        "The friction drop against the AFM hold time t of the local law at the swept loads nearest {}: the study's \
         laws {} at their hold times (dotted; circle the mean over the topographies, bar their range).{curve} \
         Measured points sit at their hold time, coloured as the nearest of these loads.",
        chosen.iter().map(|l| load_label(*l)).collect::<Vec<_>>().join(", "),
        names.join(", ")
    );
    Some((Figure::new(panel).with_size(1800, 850), caption))
}

/// The single-element limit mu_s/mu_d of law `name`, dotted from `x0` up to its first load
/// [mN] with more than one element (or `x1`).
fn single_element_line(rows: &[Row], name: &str, limit: f64, (x0, x1): (f64, f64), colour: RGBColor) -> Series {
    let end = first_multi_element_load(rows, name).map_or(x1, |l| l * 1e3);
    Series::line(vec![(x0, limit), (end, limit)], colour)
        .dotted()
        .label(format!("{name}: one element, μ^S/μ^D = {}", tick_label(&limit)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 1 % crossings of the two curves, linear in log load: 3 % at 1 mN and 0 % at 100 mN
    /// cross at 2/3 of the way, 10^(−3 + 4/3) N; none, every load, and a range that starts
    /// above the lowest load (a contact catching no tension there) are told apart.
    #[test]
    fn adhesion_reach_interpolates_in_log_load() {
        let plain = [(1e-3, 1.0), (1e-1, 1.0)];
        let reach = adhesion_reach(&plain, &[(1e-3, 1.03), (1e-1, 1.0)]);
        let [AdhesionRange { from: None, to: Some(load) }] = reach[..] else { panic!("{reach:?}") };
        assert!((load / 10f64.powf(-3.0 + 4.0 / 3.0) - 1.0).abs() < 1e-12, "{load}");
        assert_eq!(reach_phrase(&reach), "below N = 22 mN");
        assert!(adhesion_reach(&plain, &[(1e-3, 1.009), (1e-1, 0.995)]).is_empty());
        assert_eq!(adhesion_reach(&plain, &[(1e-3, 1.2), (1e-1, 0.98)]), [AdhesionRange { from: None, to: None }]);
        let plain = [(1e-7, 1.5), (1e-6, 1.5), (1e-5, 1.0), (1e-4, 1.0)];
        let reach = adhesion_reach(&plain, &[(1e-7, 1.5), (1e-6, 1.53), (1e-5, 1.1), (1e-4, 1.0)]);
        let [AdhesionRange { from: Some(from), to: Some(to) }] = reach[..] else { panic!("{reach:?}") };
        assert!((from / 10f64.powf(-6.5) - 1.0).abs() < 1e-9, "{from}");
        assert!((to / 10f64.powf(-5.0 + 0.9) - 1.0).abs() < 1e-9, "{to}");
        assert_eq!(reach_phrase(&reach), "from N = 320 nN to 79 µN");
    }

    #[test]
    fn interpolation_is_linear_in_log_load() {
        let curve = [(1e-3, 1.0), (1e-2, 2.0), (1e-1, 4.0)];
        assert_eq!(interpolate(&curve, 1e-2), Some(2.0));
        assert!((interpolate(&curve, 10f64.powf(-2.5)).unwrap() - 1.5).abs() < 1e-12);
        assert!((interpolate(&curve, 10f64.powf(-1.5)).unwrap() - 3.0).abs() < 1e-12);
        assert_eq!(interpolate(&curve, 1e-4), None);
        assert_eq!(interpolate(&curve, 1.0), None);
        assert_eq!(interpolate(&curve, 1e-3), Some(1.0));
    }
}
