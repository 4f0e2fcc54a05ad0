//! A slide-hold-slide trace as a figure, with what the analysis found marked on it.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use super::figure::{Axis, Figure, Panel};
use super::series::{Marker, Series};
use super::style;
use super::ticks::{prefixed, tick_label};
use crate::shs::{Analysis, Cycle, Group, ShsOptions, Trace};

/// Width [px] of the legends, beside the axes of every panel, so that the time axes line up.
const LEGEND_WIDTH: u32 = 300;

/// Three panels: the whole trace (friction against time, measured holds shaded, each static
/// peak F_S circled, each hold found but not measured — shorter than the minimum duration, or
/// without a complete restart — shaded in its own colour and marked by a cross below it, however
/// short); every restart overlaid against sliding distance since its restart, with its peak
/// and its mean F_D drawn across its window under the curve, coloured by hold-time group, on
/// an axis fitted to the peaks and F_D; the normal force against time, the windows where F_D
/// and N are averaged shaded. Friction and normal force share one unit, with the SI prefix
/// that suits the friction (mN, µN, …).
pub fn trace_figure(trace: &Trace, analysis: &Analysis, options: &ShsOptions) -> Figure {
    let (t, f) = (trace.time(), trace.friction());
    let biggest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let (f_scale, f_unit) = prefixed(biggest(f), "N");
    let name =
        trace.source().file_name().map_or_else(|| trace.source().display().to_string(), |n| n.to_string_lossy().into());
    let index = |time: f64| t.partition_point(|&x| x < time).min(t.len() - 1);
    let group_of = |hold: f64| {
        let distance = |g: &Group| (g.hold_s.mean / hold).ln().abs();
        (0..analysis.groups.len())
            .min_by(|&a, &b| distance(&analysis.groups[a]).total_cmp(&distance(&analysis.groups[b])))
    };
    let colour = |hold: f64| style::PALETTE[group_of(hold).unwrap_or(0) % style::PALETTE.len()];
    let top = 1.05 * biggest(f) * f_scale;

    let skipped = match analysis.skipped.len() {
        0 => String::new(),
        n => format!(", {n} hold{} not measured (crossed)", if n == 1 { "" } else { "s" }),
    };
    // Room below zero for the crosses of skipped holds.
    let bottom = if analysis.skipped.is_empty() { -0.05 * top } else { -0.12 * top };
    let mut whole = Panel::new(Axis::new("time", "s"), Axis::new("friction force", &f_unit).range(bottom, top))
        .title(format!("{name}: {} restarts after holds{skipped}", analysis.cycles.len()))
        .legend_beside(LEGEND_WIDTH);
    let (r_lo, r_hi) = restart_range(&analysis.cycles).map_or((-0.05 * top, top), |(a, b)| (a * f_scale, b * f_scale));
    let mut restarts = Panel::new(
        Axis::new("sliding distance since the restart", "µm"),
        Axis::new("friction force", &f_unit).range(r_lo, r_hi),
    )
    .legend_beside(LEGEND_WIDTH);
    // From zero: a nearly constant normal force on an axis fitted to it read "1, 1, 1, 1, 1".
    let (n_lo, n_hi) = trace.normal().iter().fold((0.0f64, 0.0f64), |(a, b), &n| (a.min(n), b.max(n)));
    let mut normal_axis = Axis::new("normal force", &f_unit);
    if n_hi > n_lo {
        normal_axis = normal_axis.range(1.15 * n_lo * f_scale, 1.15 * n_hi * f_scale);
    }
    let mut normal = Panel::new(Axis::new("time", "s"), normal_axis).legend_beside(LEGEND_WIDTH);

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
        normal.push(label_once(
            Series::span(c.window_start_s, c.window_end_s, style::PALETTE[2]).opacity(0.15),
            i == 0,
            "window of F_D, N".into(),
        ));

        let (r, end) = (index(c.restart_s), index(c.window_end_s));
        let distance = |j: usize| match trace.displacement() {
            Some(x) => x[j] - x[r],
            None => options.speed * (t[j] - t[r]),
        };
        let last = (end + (end - r) / 3).min(t.len() - 1);
        // From the last sample below the axis (the rise from the hold is cut off, not drawn
        // along the axis' bottom edge).
        let first = (r..=last).find(|&j| f[j] * f_scale >= r_lo).map_or(r, |j| j.saturating_sub(1).max(r));
        let curve = (first..=last).map(|j| (distance(j) * 1e6, f[j] * f_scale)).collect();
        let g = group_of(c.hold_s).unwrap_or(0);
        let first = !std::mem::replace(&mut labelled[g], true);
        let hold = analysis.groups.get(g).map_or(c.hold_s, |g| g.hold_s.mean);
        // F_D's bar first and translucent: the curve is drawn over it.
        let (peak, stop) = (distance(index(c.peak_s)) * 1e6, distance(end) * 1e6);
        let level = c.dynamic_force_n * f_scale;
        restarts.push(Series::line(vec![(peak, level), (stop, level)], colour(c.hold_s)).width(5).opacity(0.35));
        restarts.push(label_once(
            Series::line(curve, colour(c.hold_s)).width(1),
            first,
            format!("hold {} s", tick_label(&hold)),
        ));
        restarts
            .push(Series::scatter(vec![(peak, c.static_force_n * f_scale)], Marker::Circle, colour(c.hold_s)).hollow());
    }
    // A skipped hold may last a fraction of a screen pixel: its span alone would not show.
    for h in &analysis.skipped {
        whole.push(Series::span(h.start_s, h.end_s, style::PALETTE[3]).opacity(0.35));
    }
    if !analysis.skipped.is_empty() {
        let marks = analysis.skipped.iter().map(|h| (0.5 * (h.start_s + h.end_s), -0.06 * top)).collect();
        whole.push(Series::scatter(marks, Marker::Cross, style::PALETTE[3]).label("hold not measured"));
    }
    let line = |v: &[f64], scale: f64| t.iter().zip(v).map(|(&t, &v)| (t, v * scale)).collect();
    whole.push(Series::line(line(f, f_scale), style::PALETTE[0]).width(1).label("friction"));
    let peaks = analysis.cycles.iter().map(|c| (c.peak_s, c.static_force_n * f_scale)).collect();
    whole.push(Series::scatter(peaks, Marker::Circle, style::PALETTE[1]).hollow().label("peak F_S"));
    normal.push(Series::line(line(trace.normal(), f_scale), style::GREY).width(1).label("normal force"));
    restarts.title = Some(format!(
        "restarts: static peak (circle), mean dynamic friction over the {} µm window (bar)",
        tick_label(&(options.window * 1e6))
    ));

    Figure::stack(vec![(whole, 5), (restarts, 5), (normal, 3)]).with_size(1400, 1500)
}

/// The friction range [N] of the restarts' panel: the lowest F_D to the highest peak F_S, with
/// 60 % of that span (at least 2 % of the peak) on each side, so that peaks a few percent above
/// F_D on a large force fill the axis; none without a peak above F_D.
fn restart_range(cycles: &[Cycle]) -> Option<(f64, f64)> {
    let (lo, hi) = cycles
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| (a.min(c.dynamic_force_n), b.max(c.static_force_n)));
    (lo < hi).then(|| {
        let pad = (0.6 * (hi - lo)).max(0.02 * hi.abs());
        (lo - pad, hi + pad)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Peaks 10 % above F_D on 0.5 N fill the panel (on an axis from zero they were a sliver).
    #[test]
    fn restarts_are_drawn_on_the_range_of_their_peaks() {
        let cycle = |fs: f64, fd: f64| Cycle {
            hold_s: 10.0,
            hold_start_s: 0.0,
            restart_s: 10.0,
            peak_s: 11.0,
            window_start_s: 11.0,
            window_end_s: 14.0,
            static_force_n: fs,
            dynamic_force_n: fd,
            normal_force_n: 1.0,
            static_coefficient: fs,
            dynamic_coefficient: fd,
            friction_drop: fs / fd,
        };
        let (lo, hi) = restart_range(&[cycle(0.55, 0.5), cycle(0.53, 0.49)]).unwrap();
        assert!((lo - (0.49 - 0.036)).abs() < 1e-12 && (hi - (0.55 + 0.036)).abs() < 1e-12, "{lo} {hi}");
        assert!((hi - lo) < 0.25 * 0.55, "the peaks fill the axis: {lo} to {hi}");
        assert_eq!(restart_range(&[cycle(0.5, 0.5)]), None, "no peak: the axis of the whole trace");
        assert_eq!(restart_range(&[]), None);
    }
}
