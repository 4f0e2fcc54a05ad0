//! A slide-hold-slide trace as a figure, with what the analysis found marked on it.

use super::{prefixed, style, tick_label, Axis, Figure, LegendPosition, Marker, Panel, Series};
use crate::shs::{Analysis, Group, ShsOptions, Trace};

/// Three panels: the whole trace (friction against time, measured holds shaded, each static
/// peak F_S circled, each hold found but not measured — shorter than the minimum duration, or
/// without a complete restart — shaded in its own colour and marked by a cross below it, however
/// short); every restart overlaid against sliding distance since its restart, with its peak
/// and its mean F_D drawn across its window, coloured by hold-time group; the normal force
/// against time. Forces are shown with the SI prefix that suits them (mN, µN, …).
pub fn trace_figure(trace: &Trace, analysis: &Analysis, options: &ShsOptions) -> Figure {
    let (t, f) = (trace.time(), trace.friction());
    let biggest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (f_scale, f_unit) = prefixed(biggest(f), "N");
    let (n_scale, n_unit) = prefixed(biggest(trace.normal()), "N");
    let name =
        trace.source().file_name().map_or_else(|| trace.source().display().to_string(), |n| n.to_string_lossy().into());
    let index = |time: f64| t.partition_point(|&x| x < time).min(t.len() - 1);
    let group_of = |hold: f64| {
        let distance = |g: &Group| (g.hold_s.mean / hold).ln().abs();
        (0..analysis.groups.len())
            .min_by(|&a, &b| distance(&analysis.groups[a]).total_cmp(&distance(&analysis.groups[b])))
    };
    let colour = |hold: f64| style::PALETTE[group_of(hold).unwrap_or(0) % style::PALETTE.len()];
    // Headroom above the data keeps the legends clear of the curves.
    let top = 1.3 * biggest(f) * f_scale;

    let skipped = match analysis.skipped.len() {
        0 => String::new(),
        n => format!(", {n} hold{} not measured (crossed)", if n == 1 { "" } else { "s" }),
    };
    // Room below zero for the crosses of skipped holds.
    let bottom = if analysis.skipped.is_empty() { -0.05 * top } else { -0.12 * top };
    let mut whole = Panel::new(Axis::new("time", "s"), Axis::new("friction force", &f_unit).range(bottom, top))
        .title(format!("{name}: {} restarts after holds{skipped}", analysis.cycles.len()))
        .legend(LegendPosition::UpperRight);
    let mut restarts = Panel::new(
        Axis::new("sliding distance since the restart", "µm"),
        Axis::new("friction force", &f_unit).range(-0.05 * top, top),
    )
    .legend(LegendPosition::UpperRight);
    // From zero: a nearly constant normal force on an axis fitted to it read "1, 1, 1, 1, 1".
    let (n_lo, n_hi) = trace.normal().iter().fold((0.0f64, 0.0f64), |(a, b), &n| (a.min(n), b.max(n)));
    let mut normal_axis = Axis::new("normal force", &n_unit);
    if n_hi > n_lo {
        normal_axis = normal_axis.range(1.15 * n_lo * n_scale, 1.15 * n_hi * n_scale);
    }
    let mut normal = Panel::new(Axis::new("time", "s"), normal_axis);

    let label_once = |s: Series, first: bool, label: String| if first { s.label(label) } else { s };
    let mut labelled = vec![false; analysis.groups.len().max(1)];
    // Restarts in group order, so that the legend lists hold times in increasing order.
    let mut order: Vec<usize> = (0..analysis.cycles.len()).collect();
    order.sort_by_key(|&i| group_of(analysis.cycles[i].hold_s));
    for (i, c) in order.into_iter().map(|i| (i, &analysis.cycles[i])) {
        whole.push(label_once(
            Series::span(c.hold_start_s, c.restart_s, style::GREY).opacity(0.25),
            i == 0,
            "hold".into(),
        ));
        normal.push(Series::span(c.window_start_s, c.window_end_s, style::PALETTE[2]).opacity(0.15));

        let (r, end) = (index(c.restart_s), index(c.window_end_s));
        let distance = |j: usize| match trace.displacement() {
            Some(x) => x[j] - x[r],
            None => options.speed * (t[j] - t[r]),
        };
        let last = (end + (end - r) / 3).min(t.len() - 1);
        let curve = (r..=last).map(|j| (distance(j) * 1e6, f[j] * f_scale)).collect();
        let g = group_of(c.hold_s).unwrap_or(0);
        let first = !std::mem::replace(&mut labelled[g], true);
        let hold = analysis.groups.get(g).map_or(c.hold_s, |g| g.hold_s.mean);
        restarts.push(label_once(
            Series::line(curve, colour(c.hold_s)).width(1),
            first,
            format!("hold {} s", tick_label(&hold)),
        ));
        let (peak, stop) = (distance(index(c.peak_s)) * 1e6, distance(end) * 1e6);
        let level = c.dynamic_force_n * f_scale;
        restarts.push(Series::line(vec![(peak, level), (stop, level)], colour(c.hold_s)).width(4));
        restarts
            .push(Series::scatter(vec![(peak, c.static_force_n * f_scale)], Marker::Circle, colour(c.hold_s)).hollow());
    }
    // A skipped hold may last a fraction of a screen pixel: its span alone would not show.
    for h in &analysis.skipped {
        whole.push(Series::span(h.start_s, h.end_s, style::PALETTE[3]).opacity(0.35));
    }
    if !analysis.skipped.is_empty() {
        let marks = analysis.skipped.iter().map(|h| (0.5 * (h.start_s + h.end_s), -0.06 * top)).collect();
        whole.push(Series::scatter(marks, Marker::Cross, style::PALETTE[3]).label("hold not measured (see stderr)"));
    }
    let line = |v: &[f64], scale: f64| t.iter().zip(v).map(|(&t, &v)| (t, v * scale)).collect();
    whole.push(Series::line(line(f, f_scale), style::PALETTE[0]).width(1).label("friction"));
    let peaks = analysis.cycles.iter().map(|c| (c.peak_s, c.static_force_n * f_scale)).collect();
    whole.push(Series::scatter(peaks, Marker::Circle, style::PALETTE[1]).hollow().label("peak F_S"));
    normal.push(Series::line(line(trace.normal(), n_scale), style::GREY).width(1));
    restarts.title = Some(format!(
        "restarts: peak F_S (circle), mean F_D over the {} µm window (bar)",
        tick_label(&(options.window * 1e6))
    ));

    Figure::stack(vec![(whole, 5), (restarts, 5), (normal, 3)]).with_size(1400, 1500)
}
