//! The maps that zoom into the contact with an inset: the contact maps at the figure loads
//! (Fig. S4) and the element classes at the critical state (Fig. 4f). They draw with what
//! `maps` draws every map with, and place their insets with `inset`.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::draw::{Draw, DrawResult};
use super::inset::{inset, inset_place};
use super::maps::{
    colour_bar, draw_layer, load_label, map_chart, percent, plot_size, pressure_colour, swatches, text, Layer, MapAxes,
    View, HEADING, LABEL, MAP_MARGIN, TICK, X_LABELS,
};
use super::style;
use super::ticks::{prefixed, tick_label};
use crate::friction::{ElementClass, Onset};
use crate::study::MapSnapshot;

/// Width [px] of the column beside a contact map that takes its inset when no place on the map
/// is free of contact.
const INSET_COLUMN: u32 = 240;

/// Contact maps (Fig. S4): the whole window at each of the figure loads, contact pixels coloured
/// by pressure on one scale; where the contact is small beside the window an inset zooms into it.
pub(super) struct ContactMaps<'a> {
    /// (target load [N], the snapshot nearest it if close enough); loads without one get no
    /// panel.
    pub panels: Vec<(f64, Option<&'a MapSnapshot>)>,
}

impl ContactMaps<'_> {
    /// (columns, rows) of the panels: 2 × 2 for four, else one row.
    fn layout(&self) -> (usize, usize) {
        let n = self.panels.iter().filter(|p| p.1.is_some()).count().max(1);
        if n == 4 {
            (2, 2)
        } else {
            (n, 1)
        }
    }
}

impl Draw for ContactMaps<'_> {
    fn size(&self) -> (u32, u32) {
        let (columns, rows) = self.layout();
        (700 * columns as u32, 56 + 712 * rows as u32 + 120)
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let maps: Vec<&MapSnapshot> = self.panels.iter().filter_map(|p| p.1).collect();
        let (columns, rows) = self.layout();
        let p_max = maps.iter().flat_map(|m| m.pressure.iter()).fold(0.0f64, |a, &b| a.max(b));
        let (p_scale, p_unit) = prefixed(p_max, "Pa");
        let (head, rest) = area.split_vertically(56);
        let topography = maps.first().map_or(String::new(), |m| format!(" of {}", m.topography));
        text(
            &head,
            &format!("Contact maps{topography}: local normal stress on the contact pixels"),
            (head.dim_in_pixel().0 as i32 / 2, 30),
            style::TITLE_SIZE * 0.9,
            (HPos::Center, VPos::Center),
        )?;
        let (grid, bar) = rest.split_vertically(rest.dim_in_pixel().1 - 120);
        let letters = ["a", "b", "c", "d", "e", "f"];
        for (k, (cell, snap)) in grid.split_evenly((rows, columns)).iter().zip(&maps).enumerate() {
            let (title, body) = cell.split_vertically(40);
            let points = snap.pressure.iter().filter(|p| **p > 0.0).count();
            let heading = format!(
                "({}) N = {}: {points} contact pixel{}",
                letters[k % 6],
                load_label(snap.load_n),
                if points == 1 { "" } else { "s" }
            );
            text(&title, &heading, (title.dim_in_pixel().0 as i32 / 2, 22), HEADING, (HPos::Center, VPos::Center))?;
            let values = snap.pressure.mapv(|p| if p > 0.0 { p } else { f64::NAN });
            let layer = Layer::on(snap, &values);
            let colour = |p: f64| pressure_colour(p / p_max);
            let window = View::window(snap);
            // Zoom into a contact that is small beside the window; when the contact is spread
            // but sparse, into its most loaded patch.
            let small = |v: &View| v.width().max(v.height()) < 0.15 * window.width().min(window.height());
            // Under 1 % of the window in contact (the paper's insets at 0.1, 1 and 10 mN).
            let sparse = (points as f64) < 0.01 * (snap.grid.0 * snap.grid.1) as f64;
            let zoom = Some(View::contact(snap))
                .filter(small)
                .or_else(|| Some(View::main_patch(snap)).filter(|v| sparse && small(v)));
            let plot = plot_size(body.dim_in_pixel());
            let place = zoom.map(|z| inset_place(window.fit(plot), plot, window, z, &layer));
            // Where every place on the map would hide contact, the map is narrowed and the
            // inset drawn beside it.
            let (map, beside) = match place {
                Some(None) => {
                    let (map, beside) = body.split_horizontally(body.dim_in_pixel().0 - INSET_COLUMN);
                    // Centred at the height of its narrower plotting area: a square window.
                    let (w, h) = plot_size(map.dim_in_pixel());
                    let pad = (h.saturating_sub(w) / 2) as i32;
                    let (top, bottom) = (pad + MAP_MARGIN as i32, pad + X_LABELS as i32);
                    (map.margin(pad, pad, 0, 0), beside.margin(top, bottom, 0, MAP_MARGIN as i32))
                }
                _ => (body.clone(), body.clone()),
            };
            let MapAxes { chart, view, plot } = map_chart(&map, window, true)?;
            draw_layer(&chart, view, plot, &layer, colour)?;
            let frame = [(window.x.0, window.y.0), (window.x.1, window.y.1)];
            chart.plotting_area().draw(&Rectangle::new(frame, style::GREY.mix(0.7).stroke_width(1)))?;
            if let (Some(zoom), Some(place)) = (zoom, place) {
                inset(&chart, place, &beside, zoom, &layer, colour)?;
            }
        }
        colour_bar(
            &bar.margin(10, 10, 300, 300),
            (0.0, p_max * p_scale),
            &format!("local normal stress σ [{p_unit}]"),
            pressure_colour,
        )
    }
}

/// Element classes at the critical state (Fig. 4f): critical, pre-sliding and subcritical
/// elements in their colours, zoomed to the contact region, with a legend of counts.
pub(super) struct ClassMap<'a> {
    pub snap: &'a MapSnapshot,
    pub onset: Onset,
    pub law_name: String,
}

impl Draw for ClassMap<'_> {
    fn size(&self) -> (u32, u32) {
        (1400, 1060)
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (snap, onset) = (self.snap, &self.onset);
        let (head, rest) = area.split_vertically(56);
        let law = &onset.law;
        text(
            &head,
            &format!(
                "Element classes at the critical state, N = {} ({}: μ^S = {}, μ^D = {})",
                load_label(snap.load_n),
                self.law_name,
                tick_label(&law.mu_s),
                tick_label(&law.mu_d)
            ),
            (head.dim_in_pixel().0 as i32 / 2, 30),
            style::TITLE_SIZE * 0.85,
            (HPos::Center, VPos::Center),
        )?;
        let (map, side) = rest.split_horizontally(rest.dim_in_pixel().1);
        let area_px = snap.pixel_area();
        // Priorities where a screen pixel shows several elements: the rare critical ones first.
        let priority = |class: ElementClass| match class {
            ElementClass::Critical => 3.0,
            ElementClass::Subcritical => 2.0,
            ElementClass::PreSliding => 1.0,
            ElementClass::NoContact => f64::NAN,
        };
        let values = snap.pressure.mapv(|p| if p > 0.0 { priority(onset.class_of(p * area_px)) } else { f64::NAN });
        let colour = |v: f64| match v as i32 {
            3 => style::CRITICAL,
            2 => style::SUBCRITICAL,
            _ => style::PRE_SLIDING,
        };
        let MapAxes { chart, view, plot } = map_chart(&map, View::contact(snap), true)?;
        let layer = Layer::on(snap, &values);
        draw_layer(&chart, view, plot, &layer, colour)?;
        // Where a screen pixel shows several elements, the most loaded patch at full resolution:
        // on the map where it hides no contact, else below the legend.
        let patch = View::main_patch(snap);
        if patch.width().max(patch.height()) < 0.3 * view.width().min(view.height()) {
            let place = inset_place(view, plot, view, patch, &layer);
            inset(&chart, place, &side.margin(400, 20, 10, 20), patch, &layer, colour)?;
        }
        // A few critical elements among thousands would be lost: ring each.
        if onset.critical.count <= 50 {
            let (dx, dy) = snap.pixel_size;
            let rings = snap
                .pressure
                .indexed_iter()
                .filter(|(_, p)| **p > 0.0 && onset.class_of(**p * area_px) == ElementClass::Critical);
            for ((r, c), _) in rings {
                let centre = ((snap.origin.1 + c) as f64 * dx + 0.5 * dx, (snap.origin.0 + r) as f64 * dy + 0.5 * dy);
                chart.plotting_area().draw(&Circle::new(centre, 11, style::CRITICAL.stroke_width(2)))?;
            }
        }
        let m = onset.elements as f64;
        let share = |c: usize| format!("{c} ({})", percent(c as f64 / m));
        let mut entries = vec![
            (style::CRITICAL, format!("critical (μ = μ^S): {}", share(onset.critical.count))),
            (style::PRE_SLIDING, format!("pre-sliding (μ = μ^D): {}", share(onset.pre_sliding.count))),
            (style::SUBCRITICAL, format!("subcritical (μ^0 < μ^S): {}", share(onset.subcritical.count))),
        ];
        entries.push((WHITE, "no contact".to_string()));
        let legend = side.margin(60, 0, 10, 10);
        swatches(&legend, &entries, LABEL * 0.95)?;
        let notes = [
            format!("{} elements, F_S/N = {:.4}", onset.elements, onset.static_coefficient()),
            format!("friction drop F_S/(μ^D N) = {:.4}", onset.friction_drop()),
            "μ^0: the stress ratio of a stuck element".to_string(),
            if onset.critical.count <= 50 { "critical elements ringed".to_string() } else { String::new() },
        ];
        for (k, note) in notes.iter().enumerate() {
            text(&legend, note, (10, 190 + 32 * k as i32), TICK, (HPos::Left, VPos::Center))?;
        }
        Ok(())
    }
}
