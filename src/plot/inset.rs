//! Insets of a map: where an inset that zooms into the contact goes (inside the map where it
//! hides no contact pixel, else beside it), and the inset itself with its scale bar.
//!
//! Must not import report, friction, contact or shs: an inset draws a map's layer.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::draw::DrawResult;
use super::maps::{draw_layer, text, Layer, MapChart, View, TICK};
use super::ticks::{prefixed, tick_label};

/// Where an inset goes: `(left, top)` and side [px] inside the map's plotting area, where it
/// hides no drawn pixel, or none when every place inside would hide some.
pub(super) type InsetPlace = Option<((i32, i32), i32)>;

/// The place of an inset on the map `view` (fitted to a plotting area of `plot` px) that shows
/// `zoom` of `layer`: inside the window `frame` where it hides none of the layer's drawn
/// pixels (see [`place_inset`]), else none: it then goes beside the map.
pub(super) fn inset_place(view: View, plot: (u32, u32), frame: View, zoom: View, layer: &Layer) -> InsetPlace {
    let at = |x: f64, y: f64| {
        let px = (x - view.x.0) / view.width() * f64::from(plot.0);
        let py = (view.y.1 - y) / view.height() * f64::from(plot.1);
        (px.round() as i32, py.round() as i32)
    };
    let (dx, dy) = layer.pixel;
    let drawn: Vec<(i32, i32)> = layer
        .values
        .indexed_iter()
        .filter(|(_, v)| !v.is_nan())
        .map(|((r, c), _)| at((layer.origin.1 + c) as f64 * dx + 0.5 * dx, (layer.origin.0 + r) as f64 * dy + 0.5 * dy))
        .collect();
    let ((fx0, fy0), (fx1, fy1)) = (at(frame.x.0, frame.y.1), at(frame.x.1, frame.y.0));
    let centre = at(0.5 * (zoom.x.0 + zoom.x.1), 0.5 * (zoom.y.0 + zoom.y.1));
    place_inset((fx0.max(0), fy0.max(0), fx1.min(plot.0 as i32), fy1.min(plot.1 as i32)), &drawn, centre)
}

/// An inset showing `zoom` of `layer` at full resolution with a scale bar, the zoomed region
/// marked on the map: at `place` inside the map's plotting area (joined to the mark by a
/// line), or, without one, as large a square as fits at the top of `beside`.
pub(super) fn inset<DB: DrawingBackend>(
    chart: &MapChart<'_, DB>,
    place: InsetPlace,
    beside: &DrawingArea<DB, Shift>,
    zoom: View,
    layer: &Layer,
    colour: impl Fn(f64) -> RGBColor,
) -> DrawResult<DB> {
    let plotting = chart.plotting_area();
    let base = plotting.get_base_pixel();
    let screen = plotting.strip_coord_spec();

    // The zoomed region on the main map, at least 14 px wide so that it is seen.
    let (a, b) = (chart.backend_coord(&(zoom.x.0, zoom.y.1)), chart.backend_coord(&(zoom.x.1, zoom.y.0)));
    let grow = |lo: i32, hi: i32| {
        let (mid, half) = ((lo + hi) / 2, ((hi - lo) / 2).max(7));
        (mid - half, mid + half)
    };
    let ((x0, x1), (y0, y1)) = (grow(a.0 - base.0, b.0 - base.0), grow(a.1 - base.1, b.1 - base.1));
    screen.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(2)))?;
    let (area, side) = match place {
        Some(((left, top), side)) => {
            // A line to the inset's nearer corners.
            let corner_x = if left > x1 { left } else { left + side };
            let corner_y = if top > y1 { top } else { top + side };
            let (mark_x, mark_y) = (if corner_x > x1 { x1 } else { x0 }, if corner_y > y1 { y1 } else { y0 });
            let line = vec![(mark_x, mark_y), (corner_x, corner_y)];
            screen.draw(&PathElement::new(line, BLACK.mix(0.5).stroke_width(1)))?;
            (screen.shrink((left, top), (side as u32, side as u32)), side)
        }
        None => {
            let (w, h) = beside.dim_in_pixel();
            let side = w.min(h);
            (beside.clone().shrink(((w - side) / 2, 0), (side, side)), side as i32)
        }
    };
    area.fill(&WHITE)?;
    let (dx, dy) = layer.pixel;
    // A strip below the zoomed region keeps the scale bar off the contact it measures.
    let (bh, strip) = (44, 52.0);
    let fitted = zoom.fit((side as u32, side as u32));
    let per_px = fitted.height() / f64::from(side as u32);
    let zoom = View { x: zoom.x, y: (zoom.y.0 - strip * per_px, zoom.y.1) }.fit((side as u32, side as u32));
    let zchart = ChartBuilder::on(&area).build_cartesian_2d(zoom.x.0..zoom.x.1, zoom.y.0..zoom.y.1)?;
    draw_layer(&zchart, zoom, (side as u32, side as u32), layer, colour)?;
    area.draw(&Rectangle::new([(0, 0), (side - 1, side - 1)], BLACK.stroke_width(2)))?;
    let length = scale_bar_length(zoom.width());
    let (ls, lu) = prefixed(length, "m");
    let bar_px = (length / zoom.width() * side as f64).round() as i32;
    // The scale bar in the inset's corner that hides the fewest zoomed pixels.
    let zbase = area.get_base_pixel();
    let zoomed: Vec<(i32, i32)> = layer
        .values
        .indexed_iter()
        .filter(|(_, v)| !v.is_nan())
        .map(|((r, c), _)| {
            let p = zchart.backend_coord(&(
                (layer.origin.1 + c) as f64 * dx + 0.5 * dx,
                (layer.origin.0 + r) as f64 * dy + 0.5 * dy,
            ));
            (p.0 - zbase.0, p.1 - zbase.1)
        })
        .collect();
    let bw = bar_px.max(60) + 14;
    let (bx, by) = scale_bar_corner((side, side), (bw, bh), &zoomed, dx / zoom.width() * side as f64);
    area.draw(&Rectangle::new([(bx, by), (bx + bw, by + bh)], WHITE.mix(0.85).filled()))?;
    area.draw(&Rectangle::new([(bx + 6, by + bh - 14), (bx + 6 + bar_px, by + bh - 8)], BLACK.filled()))?;
    let label = format!("{} {lu}", tick_label(&(length * ls)));
    text(&area, &label, (bx + 6, by + bh - 20), TICK, (HPos::Left, VPos::Bottom))
}

/// How many of the pixels centred at `drawn` [px], each `pixel` px wide, a box (left, top,
/// width, height) [px] would touch.
fn covered(drawn: &[(i32, i32)], (l, t, w, h): (i32, i32, i32, i32), pixel: i32) -> usize {
    let half = pixel / 2 + 1;
    drawn.iter().filter(|(x, y)| *x + half > l && *x - half < l + w && *y + half > t && *y - half < t + h).count()
}

/// The corner (left, top) [px] of a `size` inset for the scale bar box `(w, h)` that touches the
/// fewest of the inset's `drawn` pixels (`pixel` px wide): bottom left first.
fn scale_bar_corner((iw, ih): (i32, i32), (w, h): (i32, i32), drawn: &[(i32, i32)], pixel: f64) -> (i32, i32) {
    let corners = [(4, ih - h - 4), (iw - w - 4, ih - h - 4), (4, 4), (iw - w - 4, 4)];
    let pixel = pixel.ceil() as i32;
    corners.into_iter().min_by_key(|&(l, t)| covered(drawn, (l, t, w, h), pixel)).expect("four corners")
}

/// Where an inset goes inside the frame (x0, y0, x1, y1) [px] of a map whose drawn pixels are
/// at `drawn` [px]: ((left, top), side) of the largest square, from 42 % of the frame's
/// smaller side down to 24 %, with a place that hides none of them (12 px kept clear) — a
/// corner first, then along the edges and inside, the farthest from `centre` (the zoomed
/// region) among equals; none where every place hides some.
fn place_inset((x0, y0, x1, y1): (i32, i32, i32, i32), drawn: &[(i32, i32)], centre: (i32, i32)) -> InsetPlace {
    const PAD: i32 = 8;
    const CLEAR: i32 = 12;
    const STEPS: i32 = 12;
    for share in [0.42, 0.36, 0.30, 0.24] {
        let side = ((x1 - x0).min(y1 - y0) as f64 * share) as i32;
        let (free_x, free_y) = ((x1 - x0 - side - 2 * PAD).max(0), (y1 - y0 - side - 2 * PAD).max(0));
        let mut places: Vec<(i32, i32)> = Vec::new();
        for i in 0..=STEPS {
            for j in 0..=STEPS {
                places.push((x0 + PAD + free_x * i / STEPS, y0 + PAD + free_y * j / STEPS));
            }
        }
        let corner = |&(l, t): &(i32, i32)| {
            let edge = |v: i32, lo: i32, free: i32| v == lo + PAD || v == lo + PAD + free;
            edge(l, x0, free_x) && edge(t, y0, free_y)
        };
        let far = |(l, t): (i32, i32)| -(((l + side / 2 - centre.0) as f64).hypot((t + side / 2 - centre.1) as f64));
        let hides = |(l, t): (i32, i32)| covered(drawn, (l - CLEAR, t - CLEAR, side + 2 * CLEAR, side + 2 * CLEAR), 0);
        let free = places
            .into_iter()
            .filter(|p| hides(*p) == 0)
            .min_by(|a, b| corner(b).cmp(&corner(a)).then(far(*a).total_cmp(&far(*b))));
        if let Some(place) = free {
            return Some((place, side));
        }
    }
    None
}

/// A round length [m] of about a quarter of `width` [m] (1, 2 or 5 × 10^k), for a scale bar.
fn scale_bar_length(width: f64) -> f64 {
    let target = width / 4.0;
    let decade = 10f64.powf(target.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * decade).find(|l| *l <= target).unwrap_or(decade)
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::*;
    use crate::study::MapSnapshot;

    /// An inset hides no contact where some place can: contact in all four corners of the
    /// frame (the 4f inset covered a patch in a user's study) leaves it to an edge or a smaller
    /// size.
    #[test]
    fn insets_are_placed_off_the_contact() {
        let frame = (0, 0, 600, 600);
        let mut drawn = Vec::new();
        for (x, y) in [(40, 40), (560, 40), (40, 560), (560, 560), (300, 300)] {
            for d in 0..20 {
                drawn.extend([(x + d - 10, y), (x, y + d - 10)]);
            }
        }
        let ((l, t), side) = place_inset(frame, &drawn, (300, 300)).expect("a free place");
        assert!(side >= 100 && l >= 0 && t >= 0 && l + side <= 600 && t + side <= 600, "{l} {t} {side}");
        assert_eq!(covered(&drawn, (l - 12, t - 12, side + 24, side + 24), 0), 0, "{l} {t} {side}");
        // A free corner is taken first, at the largest size.
        // (the top left corner's contact only).
        let few = &drawn[..40];
        let ((l, t), side) = place_inset(frame, few, (300, 300)).expect("a free corner");
        assert_eq!(side, 252);
        assert_eq!(covered(few, (l - 12, t - 12, side + 24, side + 24), 0), 0, "{l} {t}");
        assert!(l == 340 || t == 340, "a corner away from the contact: {l} {t}");
        // Contact every 100 px leaves no place for the smallest inset (144 px): none is taken.
        let everywhere: Vec<(i32, i32)> = (0..7).flat_map(|i| (0..7).map(move |j| (100 * i, 100 * j))).collect();
        assert_eq!(place_inset(frame, &everywhere, (300, 300)), None);
        // The scale bar goes to a corner of the inset its box leaves clear.
        let inset_pixels = [(20, 230), (230, 230)];
        let (bx, by) = scale_bar_corner((252, 252), (80, 44), &inset_pixels, 10.0);
        assert_eq!(covered(&inset_pixels, (bx, by, 80, 44), 10), 0, "{bx} {by}");
    }

    /// On a map's own pixels: the inset covers no contact pixel of a sparse map (a 7-pixel
    /// patch lay under the inset at 10 mN), and on a map with contact everywhere it has no place
    /// on the map (it is drawn beside it).
    #[test]
    fn an_inset_covers_no_contact_pixel_or_goes_beside_the_map() {
        let map = |cells: &[(usize, usize)]| {
            let mut pressure = Array2::zeros((200, 200));
            for &(r, c) in cells {
                pressure[[r, c]] = 1e9;
            }
            let pixel = (1e-8, 1e-8);
            MapSnapshot {
                topography: "scan".into(),
                load_n: 1e-2,
                pressure,
                origin: (0, 0),
                grid: (200, 200),
                pixel_size: pixel,
                stuck_stiffness: None,
            }
        };
        let plot = (600, 600);
        // A 7-pixel patch in each corner region, the zoomed patch in the middle.
        let mut cells: Vec<(usize, usize)> = vec![(100, 100), (100, 101), (101, 100)];
        for (r, c) in [(30, 30), (30, 160), (160, 30), (160, 160)] {
            cells.extend((0..7).map(|k| (r + k % 3, c + k / 3)));
        }
        let sparse = map(&cells);
        let window = View::window(&sparse);
        let values = sparse.pressure.mapv(|p| if p > 0.0 { p } else { f64::NAN });
        let layer = Layer::on(&sparse, &values);
        let zoom = View::main_patch(&sparse);
        let ((l, t), side) = inset_place(window.fit(plot), plot, window, zoom, &layer).expect("room on a sparse map");
        // Each map pixel is 3 px; row 0 at the bottom.
        for &(r, c) in &cells {
            let (x0, y1) = (3 * c as i32, 600 - 3 * r as i32);
            let apart = x0 + 3 <= l || x0 >= l + side || y1 <= t || y1 - 3 >= t + side;
            assert!(apart, "contact pixel ({r}, {c}) under the inset at ({l}, {t}), side {side}");
        }
        // A pixel every 15 map pixels (45 px): no place for the smallest inset (144 px).
        let grid: Vec<(usize, usize)> = (0..14).flat_map(|i| (0..14).map(move |j| (15 * i, 15 * j))).collect();
        let dense = map(&grid);
        let values = dense.pressure.mapv(|p| if p > 0.0 { p } else { f64::NAN });
        let layer = Layer::on(&dense, &values);
        assert_eq!(inset_place(window.fit(plot), plot, window, View::main_patch(&dense), &layer), None);
    }

    #[test]
    fn scale_bars_are_round_lengths() {
        assert_eq!(scale_bar_length(1e-6), 2e-7);
        assert_eq!(scale_bar_length(3e-7), 5e-8);
    }
}
