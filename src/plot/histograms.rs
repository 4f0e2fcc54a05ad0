//! Fig. 4b–e: the distribution of the local stress ratio over the elements at the critical
//! state, for one element, for the paper's two two-element scenarios, and for the interface at
//! the load nearest 10 mN.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use super::figure::{Axis, Grid, LegendPosition, Panel};
use super::maps::load_label;
use super::series::{Marker, Series};
use super::style;
use super::ticks::tick_label;
use crate::error::Result;
use crate::friction::{ElementClass, ElementLoads, FrictionLaw, Onset};
use crate::study::MapSnapshot;
use plotters::style::RGBColor;

/// Bins of the subcritical ratios of a many-element interface between 0 and mu_s.
const BINS: usize = 40;

/// The fraction of the elements at each local stress ratio μ at the critical state, by class:
/// (class, μ, fraction); subcritical ratios binned (bin centre) when `binned`; subcritical
/// first, so that the few critical elements are drawn over their neighbours.
fn ratios(loads: &ElementLoads, onset: &Onset, binned: bool) -> Vec<(ElementClass, f64, f64)> {
    let law = &onset.law;
    let m = loads.len() as f64;
    let mut out = Vec::new();
    let sub: Vec<f64> = loads
        .sorted()
        .iter()
        .filter(|n| onset.class_of(**n) == ElementClass::Subcritical)
        .map(|n| onset.stress_ratio_of(*n, 1.0))
        .collect();
    if binned {
        let width = law.mu_s / BINS as f64;
        let mut counts = [0usize; BINS];
        for mu in &sub {
            counts[((mu / width) as usize).min(BINS - 1)] += 1;
        }
        out.extend(
            counts
                .iter()
                .enumerate()
                .filter(|(_, c)| **c > 0)
                .map(|(k, c)| (ElementClass::Subcritical, (k as f64 + 0.5) * width, *c as f64 / m)),
        );
    } else {
        out.extend(sub.iter().map(|mu| (ElementClass::Subcritical, *mu, 1.0 / m)));
    }
    for (class, mu, count) in [
        (ElementClass::PreSliding, law.mu_d, onset.pre_sliding.count),
        (ElementClass::Critical, law.mu_s, onset.critical.count),
    ] {
        if count > 0 {
            out.push((class, mu, count as f64 / m));
        }
    }
    out
}

/// The colour and legend name of a class.
fn key(class: ElementClass) -> (RGBColor, &'static str) {
    match class {
        ElementClass::Critical => (style::CRITICAL, "critical: stuck at μ^S"),
        ElementClass::PreSliding => (style::PRE_SLIDING, "pre-sliding: slipped, at μ^D"),
        _ => (style::SUBCRITICAL, "subcritical: stuck below μ^S"),
    }
}

/// One panel of bars at the stress ratios of `loads` at its critical state.
fn panel(title: String, loads: &ElementLoads, law: &FrictionLaw, binned: bool) -> Panel {
    let onset = Onset::new(loads, law);
    let width = law.mu_s / BINS as f64 * if binned { 0.9 } else { 1.5 };
    let bars = ratios(loads, &onset, binned);
    // A fraction runs to 1 at most. On the logarithmic axis of a many-element interface, bars
    // rise from below the rarest; that panel has no legend (the other panels' legends name the
    // colours), so none can cover a bar, such as the pre-sliding one at μ_d that can hold nine
    // elements in ten.
    let least = bars.iter().map(|b| b.2).fold(1.0, f64::min);
    let (lo, hi) = if binned { (least / 3.0, 1.0) } else { (0.0, 1.25) };
    let y = Axis::dimensionless("fraction of the elements").range(lo, hi);
    let mut panel = Panel::new(
        Axis::dimensionless("local stress ratio μ").range(0.0, law.mu_s * 1.12),
        if binned { y.log() } else { y },
    )
    .title(title);
    if !binned {
        panel = panel.legend(LegendPosition::UpperLeft);
    }
    for mu in [law.mu_d, law.mu_s] {
        panel.push(Series::line(vec![(mu, lo), (mu, hi)], style::GREY).dotted().width(1));
    }
    // The colour key: each class present named once, in the legend.
    let mut named = Vec::new();
    for (class, mu, fraction) in bars {
        let (colour, name) = key(class);
        let bar =
            Series::band(vec![mu - width / 2.0, mu + width / 2.0], vec![lo; 2], vec![fraction; 2], colour).opacity(1.0);
        panel.push(if named.contains(&class) { bar } else { bar.label(name) });
        named.push(class);
    }
    // A handful of critical elements among hundreds is a bar too thin to see beside the
    // subcritical ones: a marker above it says where it is.
    if binned && onset.critical.count > 0 {
        let fraction = onset.critical.count as f64 / loads.len() as f64;
        panel.push(Series::scatter(vec![(law.mu_s, (fraction * 2.5).min(1.0))], Marker::Triangle, style::CRITICAL));
    }
    panel
}

/// The four panels of Fig. 4b–e for `law`, the last from `snap` (the map nearest 10 mN).
pub(super) fn stress_ratio_histograms(snap: Option<&MapSnapshot>, law: &FrictionLaw) -> Result<(Grid, String)> {
    let two = |a: f64, b: f64| ElementLoads::from_forces(&[a, b]);
    let mut panels = vec![
        panel("(a) one element".into(), &ElementLoads::from_forces(&[1.0])?, law, false),
        panel("(b) two elements, n₂ = 3 n₁: the weaker pre-slides".into(), &two(1.0, 3.0)?, law, false),
        panel("(c) two elements, n₂ = 1.2 n₁: the stronger is subcritical".into(), &two(1.0, 1.2)?, law, false),
    ];
    if let Some(snap) = snap {
        let loads = ElementLoads::from_pressure(&snap.pressure, snap.pixel_area())?;
        let critical = Onset::new(&loads, law).critical.count;
        let title = format!("(d) N = {}, {} elements, {critical} critical (▲)", load_label(snap.load_n), loads.len());
        panels.push(panel(title, &loads, law, true));
    }
    let caption = format!(
        "The distribution of the local stress ratio μ = τ/σ over the contact elements at the critical state (the \
         paper's Fig. 4b–e, law μ_s = {}, μ_d = {}): the bars give the fraction of the elements at ratio μ (the \
         paper's n^μ/n^tot), coloured by class; the dotted lines mark μ_d and μ_s. (a) A single \
         element is critical at μ_s. (b) Two elements of very different normal force: the weaker has slipped \
         (pre-sliding, amber, at μ_d) when the stronger reaches μ_s (critical, brown). (c) Two elements of similar \
         force: the weaker is critical and its slip sets off the stronger, still below μ_s (subcritical, green, at \
         μ_0 = μ_s n₁/n₂). (d) The interface at the load nearest 10 mN{}, subcritical ratios in {BINS} bins, on a \
         logarithmic axis up to 1 (all the elements), in the colours of (a)–(c); a triangle marks the critical \
         elements' bar.",
        tick_label(&law.mu_s),
        tick_label(&law.mu_d),
        if snap.is_none() { " (no map near 10 mN in this study: left out)" } else { "" }
    );
    let n = panels.len();
    let columns = if n == 4 { 2 } else { n };
    let size = if n == 4 { (1500, 1100) } else { (500 * n as u32, 560) };
    Ok((Grid::new(panels, columns, size), caption))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::draw::Draw;
    use crate::plot::figure::Figure;
    use plotters::prelude::*;

    /// The fill colour of a class as the SVG writes it.
    fn hex(c: RGBColor) -> String {
        format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
    }

    /// Fig. 4e: a legend box covered the pre-sliding bar at μ_d, nine elements in ten, and the
    /// fraction axis ran to 10³ to make room for it. The panel has no legend, its axis ends at 1.
    #[test]
    fn the_fraction_axis_ends_at_one_and_no_legend_covers_a_bar() {
        let law = FrictionLaw::new(0.6, 0.3).unwrap();
        // Most elements weak (they slip first, at μ_d), a few strong ones, one the strongest.
        let mut forces = vec![1.0; 900];
        forces.extend((0..99).map(|k| 60.0 + 0.3 * k as f64));
        forces.push(100.0);
        let loads = ElementLoads::from_forces(&forces).unwrap();
        let onset = Onset::new(&loads, &law);
        let pre = ratios(&loads, &onset, true).iter().find(|b| b.0 == ElementClass::PreSliding).map(|b| b.2);
        assert!(pre.is_some_and(|f| f > 0.5), "pre-sliding fraction {pre:?}");
        let (w, h) = (750, 550);
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
            crate::plot::style::register_fonts();
            Figure::new(panel("(d) N = 10 mN".into(), &loads, &law, true)).with_size(w, h).draw(&root).unwrap();
            root.present().unwrap();
        }
        let legend = svg.split('<').any(|t| t.starts_with("rect") && t.contains("opacity=\"0.88"));
        assert!(!legend, "no legend box");
        let ticks: Vec<&str> =
            svg.split("<text").skip(1).filter_map(|t| Some(t.split('>').nth(1)?.split('<').next()?.trim())).collect();
        assert!(ticks.contains(&"1") && ticks.contains(&"0.1"), "{ticks:?}");
        assert!(!ticks.iter().any(|t| ["10", "100", "1000"].contains(t)), "no fraction above 1: {ticks:?}");
        let colours: Vec<String> = [style::SUBCRITICAL, style::PRE_SLIDING, style::CRITICAL].map(hex).into();
        let bars = svg
            .split('<')
            .filter(|t| t.starts_with("polygon") && colours.iter().any(|c| t.contains(&format!("fill=\"{c}\""))))
            .count();
        assert!(bars >= 3, "{bars} bars drawn");
    }
}
