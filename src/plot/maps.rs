//! Maps of the contact window drawn pixel by pixel: what every map is drawn with (views,
//! layers, colour scales, axes) and the local stress ratio as the displacement grows; the
//! contact maps and the element classes, which add an inset, are in `contact_maps.rs`.
//!
//! A map is drawn as rectangles in window coordinates [m] (tick labels in µm or nm): one per
//! run of equally coloured pixels along a row when a pixel covers at least a screen pixel,
//! else one per run of screen pixels, each showing the largest value of the map's pixels whose
//! centres fall in it, so that a lone contact pixel on a large window still shows. Colour
//! scales have a fixed number of levels, which keeps the runs long and the SVG small.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use ndarray::Array2;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::draw::{Draw, DrawResult};
use super::style;
use super::ticks::{prefixed, tick_label};
use crate::friction::{FrictionLaw, Onset};
use crate::study::MapSnapshot;

/// Levels of a colour scale.
pub(super) const LEVELS: usize = 64;

/// Text sizes [px] of the map figures, whose panels are smaller than a default figure's.
pub(super) const TICK: f64 = 17.0;
pub(super) const LABEL: f64 = 20.0;
pub(super) const HEADING: f64 = 23.0;

/// Space [px] around a map's plotting area: margin, then the label areas (left, bottom).
pub(super) const MAP_MARGIN: u32 = 10;
const Y_LABELS: u32 = 78;
pub(super) const X_LABELS: u32 = 52;

/// Least size [px] of a map pixel on the detailed views of snapshots and movies.
pub(super) const DETAIL_PX: f64 = 2.5;

/// Extent of a detailed view about the most loaded patch, in units of the patch's own.
const SURROUNDINGS: f64 = 4.0;
/// Least extent of a detailed view about the most loaded patch [map pixels].
const SURROUNDINGS_PX: f64 = 24.0;

/// Least size [px] of a drawn pixel on a sparse map.
const SPARSE_MIN_PX: f64 = 3.0;

/// Value of a stress-ratio layer at an element that has slipped (the ratio is then mu_d, shown
/// in the pre-sliding colour); stuck elements hold their ratio, ≥ 0.
pub(super) const SLIPPED: f64 = -1.0;

/// A rectangle of the window [m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct View {
    pub x: (f64, f64),
    pub y: (f64, f64),
}

impl View {
    /// The whole window of a snapshot.
    pub fn window(snap: &MapSnapshot) -> View {
        let (dx, dy) = snap.pixel_size;
        View { x: (0.0, snap.grid.1 as f64 * dx), y: (0.0, snap.grid.0 as f64 * dy) }
    }

    /// The contact points of a snapshot with a margin of a tenth of their extent, and at
    /// least six pixels on a side (a single element is then a visible square).
    pub fn contact(snap: &MapSnapshot) -> View {
        let boxes = patches(snap);
        match boxes.iter().map(|p| p.0).reduce(View::union) {
            Some(all) => all.with_margin(snap.pixel_size),
            None => View::window(snap),
        }
    }

    /// The region of the contact patch (4-connected pixels) that carries the largest force.
    pub fn main_patch(snap: &MapSnapshot) -> View {
        match patches(snap).into_iter().reduce(|a, b| if b.1 >= a.1 { b } else { a }) {
            Some((main, _)) => main.with_margin(snap.pixel_size),
            None => View::window(snap),
        }
    }

    /// The view of a map drawn on a plotting area of `plot` px: the whole contact when its
    /// pixels then show at least [`DETAIL_PX`] px wide, else the most loaded patch with its
    /// surroundings — [`SURROUNDINGS`] times its extent, at least [`SURROUNDINGS_PX`] pixels and
    /// at most what shows pixels [`DETAIL_PX`] wide — grown until it cuts no patch (see
    /// [`View::uncut`]). The view keeps inside the window where it fits. Returns the view
    /// (fitted to `plot`) and whether it leaves some of the contact out.
    pub fn detail(snap: &MapSnapshot, plot: (u32, u32)) -> (View, bool) {
        let window = View::window(snap);
        let region = View::contact(snap);
        let (dx, dy) = snap.pixel_size;
        let least = f64::from(plot.0) / DETAIL_PX;
        if region.width().max(region.height()) <= least * dx.max(dy) {
            return (region.fit(plot).inside(window), false);
        }
        let patch = View::main_patch(snap);
        let grow = |(a, b): (f64, f64), d: f64| {
            let span = (SURROUNDINGS * (b - a)).max(SURROUNDINGS_PX * d).min(least * d);
            let half = (0.5 * (b - a)).max(0.5 * span);
            (0.5 * (a + b) - half, 0.5 * (a + b) + half)
        };
        let boxes = patches(snap);
        let view = View { x: grow(patch.x, dx), y: grow(patch.y, dy) }.uncut(&boxes, plot);
        let inside = view.inside(window);
        let view = if boxes.iter().any(|(b, _)| inside.cuts(b)) { view } else { inside };
        let zoomed = boxes.iter().any(|(b, _)| !view.holds(b));
        (view, zoomed)
    }

    /// This view moved to lie inside `window` where it fits (a zoom near the edge showed
    /// positions off the scan); centred on it where it does not.
    fn inside(self, window: View) -> View {
        let shift = |(a, b): (f64, f64), (lo, hi): (f64, f64)| {
            let d = if b - a >= hi - lo {
                0.5 * (lo + hi) - 0.5 * (a + b)
            } else if a < lo {
                lo - a
            } else if b > hi {
                hi - b
            } else {
                0.0
            };
            (a + d, b + d)
        };
        View { x: shift(self.x, window.x), y: shift(self.y, window.y) }
    }

    /// This view fitted to `plot` px and grown, as often as needed, over every patch of
    /// `boxes` it cuts, so that each patch lies wholly inside it or wholly outside (a patch cut
    /// at the panel's edge reads as a smaller patch than the contact has, as at 1 mN).
    fn uncut(self, boxes: &[(View, f64)], plot: (u32, u32)) -> View {
        let mut view = self.fit(plot);
        loop {
            let grown = boxes.iter().filter(|(b, _)| view.cuts(b)).fold(view, |v, (b, _)| v.union(*b));
            if grown == view {
                return view;
            }
            view = grown.fit(plot);
        }
    }

    /// Whether `b` lies inside this view (to a millionth of its size: the fit that a chart
    /// applies again may move an edge by a rounding error).
    fn holds(&self, b: &View) -> bool {
        let (ex, ey) = (1e-6 * self.width(), 1e-6 * self.height());
        b.x.0 >= self.x.0 - ex && b.x.1 <= self.x.1 + ex && b.y.0 >= self.y.0 - ey && b.y.1 <= self.y.1 + ey
    }

    /// Whether this view shows part of `b` but not all of it.
    pub fn cuts(&self, b: &View) -> bool {
        let overlaps = b.x.0 < self.x.1 && b.x.1 > self.x.0 && b.y.0 < self.y.1 && b.y.1 > self.y.0;
        overlaps && !self.holds(b)
    }

    /// The smallest view holding both.
    fn union(self, b: View) -> View {
        View { x: (self.x.0.min(b.x.0), self.x.1.max(b.x.1)), y: (self.y.0.min(b.y.0), self.y.1.max(b.y.1)) }
    }

    /// Grown about its centre by a tenth of its extent on each side, to at least six pixels
    /// (`pixel` = (dx, dy) [m]) on a side.
    fn with_margin(self, (dx, dy): (f64, f64)) -> View {
        let side = |(a, b): (f64, f64), d: f64| {
            let half = ((b - a) * 0.6).max(3.0 * d);
            let mid = 0.5 * (a + b);
            (mid - half, mid + half)
        };
        View { x: side(self.x, dx), y: side(self.y, dy) }
    }

    pub fn width(&self) -> f64 {
        self.x.1 - self.x.0
    }

    pub fn height(&self) -> f64 {
        self.y.1 - self.y.0
    }

    /// The view grown about its centre to the aspect ratio of a `w` × `h` px area, so that
    /// x and y have equal scales.
    pub fn fit(self, (w, h): (u32, u32)) -> View {
        let scale = (self.width() / f64::from(w.max(1))).max(self.height() / f64::from(h.max(1)));
        let grow = |(a, b): (f64, f64), px: u32| {
            let (mid, half) = (0.5 * (a + b), 0.5 * scale * f64::from(px));
            (mid - half, mid + half)
        };
        View { x: grow(self.x, w), y: grow(self.y, h) }
    }

    /// The factor to display positions in and its unit (µm, nm) for this view: that of its
    /// largest coordinate, so that a zoom far from the origin reads "17.8 µm", not "17800 nm".
    pub fn unit(&self) -> (f64, String) {
        let largest = [self.x.0, self.x.1, self.y.0, self.y.1].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prefixed(largest, "m")
    }
}

/// The contact patches (4-connected pixels of positive pressure, not wrapped across the
/// edges) of a snapshot, in the order of their first pixel: each one's bounding box in the
/// window [m] and the sum of its pressures [Pa] (its force over the pixel area).
pub(super) fn patches(snap: &MapSnapshot) -> Vec<(View, f64)> {
    let mask: Vec<bool> = snap.pressure.iter().map(|p| *p > 0.0).collect();
    let (labels, sizes) = crate::contact::patches::label(&mask, snap.pressure.dim(), false);
    // Per patch: first and last row + 1, first and last column + 1, and its pressure sum.
    let mut extent = vec![(usize::MAX, 0, usize::MAX, 0, 0.0); sizes.len()];
    let nx = snap.pressure.ncols();
    for ((r, c), p) in snap.pressure.indexed_iter() {
        let l = labels[r * nx + c] as usize;
        if l > 0 {
            let e = &mut extent[l - 1];
            *e = (e.0.min(r), e.1.max(r + 1), e.2.min(c), e.3.max(c + 1), e.4 + p);
        }
    }
    let (dx, dy) = snap.pixel_size;
    let (or, oc) = (snap.origin.0 as f64, snap.origin.1 as f64);
    extent
        .into_iter()
        .map(|(r0, r1, c0, c1, force)| {
            let x = ((oc + c0 as f64) * dx, (oc + c1 as f64) * dx);
            let y = ((or + r0 as f64) * dy, (or + r1 as f64) * dy);
            (View { x, y }, force)
        })
        .collect()
}

/// Values on pixels of the window: NaN where nothing is drawn.
pub(super) struct Layer<'a> {
    pub values: &'a Array2<f64>,
    /// (row, column) of `values`' first pixel in the window.
    pub origin: (usize, usize),
    /// Pixel size (dx, dy) [m].
    pub pixel: (f64, f64),
}

impl<'a> Layer<'a> {
    pub fn on(snap: &MapSnapshot, values: &'a Array2<f64>) -> Layer<'a> {
        Layer { values, origin: snap.origin, pixel: snap.pixel_size }
    }
}

/// A chart on window coordinates [m].
pub(super) type MapChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A map's axes as drawn.
pub(super) struct MapAxes<'a, DB: DrawingBackend> {
    pub chart: MapChart<'a, DB>,
    /// The view fitted to the plotting area.
    pub view: View,
    /// The plotting area's size [px].
    pub plot: (u32, u32),
}

/// The plotting area [px] of a map drawn on an area of `(w, h)` px: what [`map_chart`] fits
/// its view to.
pub(super) fn plot_size((w, h): (u32, u32)) -> (u32, u32) {
    (w.saturating_sub(2 * MAP_MARGIN + Y_LABELS), h.saturating_sub(2 * MAP_MARGIN + X_LABELS))
}

/// Axes for a map on `area`: the view fitted to the plotting area, lengths labelled in the
/// view's unit, the axis names only when `named`.
pub(super) fn map_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    view: View,
    named: bool,
) -> DrawResult<DB, MapAxes<'a, DB>> {
    let plot = plot_size(area.dim_in_pixel());
    let view = view.fit(plot);
    let (scale, unit) = view.unit();
    let mut chart = ChartBuilder::on(area)
        .margin(MAP_MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(view.x.0..view.x.1, view.y.0..view.y.1)?;
    // Ticks a rounding error away from zero ("-4.2e-16") read 0.
    let tiny = 1e-9 * view.width().max(view.height()) * scale;
    let label = move |v: &f64| tick_label(&if (v * scale).abs() < tiny { 0.0 } else { v * scale });
    let (x_desc, y_desc) = if named { (format!("x [{unit}]"), format!("y [{unit}]")) } else { Default::default() };
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(5)
        .y_labels(5)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&label)
        .y_label_formatter(&label)
        .label_style((style::FONT, TICK))
        .axis_desc_style((style::FONT, LABEL))
        .axis_style(BLACK.stroke_width(1))
        .draw()?;
    Ok(MapAxes { chart, view, plot })
}

/// Draw `layer` on `chart` (whose view is `view`, its plotting area `plot` px), each value
/// coloured by `colour`; NaN is left blank. Where pixels are smaller than the screen's, a
/// screen pixel shows the largest value among the map pixels centred in it. On a sparse map
/// each pixel is drawn at least [`SPARSE_MIN_PX`] wide.
pub(super) fn draw_layer<DB: DrawingBackend>(
    chart: &MapChart<'_, DB>,
    view: View,
    plot: (u32, u32),
    layer: &Layer,
    colour: impl Fn(f64) -> RGBColor,
) -> DrawResult<DB> {
    let (dx, dy) = layer.pixel;
    let (or, oc) = (layer.origin.0 as f64, layer.origin.1 as f64);
    let mut runs: Vec<([(f64, f64); 2], RGBColor)> = Vec::new();
    // Consecutive cells of one colour along a row, as one rectangle.
    let mut push_row = |cells: &mut dyn Iterator<Item = ((f64, f64), Option<RGBColor>)>, y: (f64, f64)| {
        let mut open: Option<(f64, f64, RGBColor)> = None;
        for ((x0, x1), c) in cells {
            match (&mut open, c) {
                (Some((_, end, oc)), Some(c)) if *oc == c => *end = x1,
                _ => {
                    if let Some((a, b, oc)) = open.take() {
                        runs.push(([(a, y.0), (b, y.1)], oc));
                    }
                    open = c.map(|c| (x0, x1, c));
                }
            }
        }
        if let Some((a, b, oc)) = open {
            runs.push(([(a, y.0), (b, y.1)], oc));
        }
    };
    let (ny, nx) = layer.values.dim();
    if view.width() / dx <= f64::from(plot.0) * 1.01 {
        // Each map pixel covers at least a screen pixel: draw it as it is.
        for (r, row) in layer.values.outer_iter().enumerate() {
            let y = ((or + r as f64) * dy, (or + r as f64 + 1.0) * dy);
            if y.1 < view.y.0 || y.0 > view.y.1 {
                continue;
            }
            let mut cells = row.iter().enumerate().map(|(c, v)| {
                let x = ((oc + c as f64) * dx, (oc + c as f64 + 1.0) * dx);
                (x, (!v.is_nan()).then(|| colour(*v)))
            });
            push_row(&mut cells, y);
        }
    } else {
        let (w, h) = (plot.0.max(1) as usize, plot.1.max(1) as usize);
        let mut cells = Array2::from_elem((h, w), f64::NAN);
        for r in 0..ny {
            let y = (or + r as f64 + 0.5) * dy;
            let i = ((y - view.y.0) / view.height() * h as f64).floor();
            if !(0.0..h as f64).contains(&i) {
                continue;
            }
            for c in 0..nx {
                let v = layer.values[[r, c]];
                let x = (oc + c as f64 + 0.5) * dx;
                let j = ((x - view.x.0) / view.width() * w as f64).floor();
                if v.is_nan() || !(0.0..w as f64).contains(&j) {
                    continue;
                }
                let cell = &mut cells[[i as usize, j as usize]];
                if cell.is_nan() || v > *cell {
                    *cell = v;
                }
            }
        }
        let (cw, ch) = (view.width() / w as f64, view.height() / h as f64);
        for (i, row) in cells.outer_iter().enumerate() {
            if row.iter().all(|v| v.is_nan()) {
                continue;
            }
            let y = (view.y.0 + i as f64 * ch, view.y.0 + (i + 1) as f64 * ch);
            let mut cells = row.iter().enumerate().map(|(j, v)| {
                let x = (view.x.0 + j as f64 * cw, view.x.0 + (j + 1) as f64 * cw);
                (x, (!v.is_nan()).then(|| colour(*v)))
            });
            push_row(&mut cells, y);
        }
    }
    // On a sparse map (drawn pixels covering under 2 % of the plot) each is drawn at least
    // SPARSE_MIN_PX wide, so that lone elements show.
    let (sx, sy) = (view.width() / f64::from(plot.0.max(1)), view.height() / f64::from(plot.1.max(1)));
    let drawn = layer.values.iter().filter(|v| !v.is_nan()).count() as f64;
    let coverage = drawn * (dx / sx).max(1.0) * (dy / sy).max(1.0) / (f64::from(plot.0) * f64::from(plot.1)).max(1.0);
    let least = if coverage < 0.02 { SPARSE_MIN_PX } else { 0.0 };
    let widen = |(a, b): (f64, f64), s: f64| {
        let half = (0.5 * (b - a)).max(0.5 * least * s);
        (0.5 * (a + b) - half, 0.5 * (a + b) + half)
    };
    let clip = |[(x0, y0), (x1, y1)]: [(f64, f64); 2]| {
        let ((x0, x1), (y0, y1)) = (widen((x0, x1), sx), widen((y0, y1), sy));
        [(x0.max(view.x.0), y0.max(view.y.0)), (x1.min(view.x.1), y1.min(view.y.1))]
    };
    let plotting = chart.plotting_area();
    for (corners, c) in runs {
        let [(x0, y0), (x1, y1)] = clip(corners);
        // A run outside the view clips to nothing; drawn, plotters would pin it to the panel's
        // edge as a sliver, which reads as a cut patch.
        if x0 < x1 && y0 < y1 {
            plotting.draw(&Rectangle::new([(x0, y0), (x1, y1)], c.filled()))?;
        }
    }
    Ok(())
}

/// Linear interpolation between colour stops (position in [0, 1], colour), on `LEVELS` levels.
fn scale(stops: &[(f64, (u8, u8, u8))], t: f64) -> RGBColor {
    let t = ((t.clamp(0.0, 1.0) * (LEVELS - 1) as f64).round()) / (LEVELS - 1) as f64;
    let k = stops.windows(2).position(|w| t <= w[1].0).unwrap_or(stops.len() - 2);
    let ((a, ca), (b, cb)) = (stops[k], stops[k + 1]);
    let f = if b > a { (t - a) / (b - a) } else { 0.0 };
    let mix = |x: u8, y: u8| (f64::from(x) + f * (f64::from(y) - f64::from(x))).round() as u8;
    RGBColor(mix(ca.0, cb.0), mix(ca.1, cb.1), mix(ca.2, cb.2))
}

/// The pressure scale, t = p / p_max: dark violet (low) through red to yellow (high), all
/// clearly off the white background.
pub(super) fn pressure_colour(t: f64) -> RGBColor {
    scale(&[(0.0, (45, 20, 120)), (0.35, (150, 35, 145)), (0.7, (232, 95, 60)), (1.0, (245, 205, 45))], t)
}

/// The stress-ratio scale of stuck elements, t = ratio / mu_s: pale green (unloaded) to the
/// subcritical green, turning to the critical brown as the ratio reaches mu_s.
pub(super) fn ratio_colour(t: f64) -> RGBColor {
    let (g, b) = (style::SUBCRITICAL, style::CRITICAL);
    scale(&[(0.0, (200, 230, 190)), (0.6, (105, 185, 110)), (0.85, (g.0, g.1, g.2)), (1.0, (b.0, b.1, b.2))], t)
}

/// The colour of a stress-ratio layer value (see [`SLIPPED`]) for the law's mu_s.
pub(super) fn ratio_value_colour(v: f64, mu_s: f64) -> RGBColor {
    if v < 0.0 {
        style::PRE_SLIDING
    } else {
        ratio_colour(v / mu_s)
    }
}

/// The stress-ratio layer of a snapshot at δ = `fraction` · δ_peak under equal load sharing:
/// stuck elements at their ratio, slipped ones [`SLIPPED`], NaN off contact. At 0 every
/// element is stuck and unloaded; past the peak (fraction > 1) the avalanche at the peak has
/// set every element sliding.
pub(super) fn ratio_layer(snap: &MapSnapshot, onset: &Onset, fraction: f64) -> Array2<f64> {
    let area = snap.pixel_area();
    snap.pressure.mapv(|p| {
        let n = p * area;
        if p <= 0.0 {
            f64::NAN
        } else if fraction <= 0.0 {
            0.0
        } else if fraction > 1.0 || onset.has_slipped(n, fraction) {
            SLIPPED
        } else {
            onset.stress_ratio_of(n, fraction)
        }
    })
}

/// Text at `pos` [px] on `area`, anchored by `anchor`.
pub(super) fn text<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &str,
    pos: (i32, i32),
    size: f64,
    anchor: (HPos, VPos),
) -> DrawResult<DB> {
    if matches!(anchor.1, VPos::Center) {
        // Typeset: sub- and superscripts ("μ^S", "δ/δ_{peak}").
        return super::typeset::typeset(area, s, pos, size, anchor.0, false);
    }
    let style = (style::FONT, size).into_font().into_text_style(area).pos(Pos::new(anchor.0, anchor.1));
    area.draw_text(s, &style, pos)
}

/// A horizontal colour bar on `area`: `colour(t)` for t from 0 to 1 across the values `lo` to
/// `hi` (in the unit of `label`, which names the quantity and unit).
pub(super) fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    label: &str,
    colour: impl Fn(f64) -> RGBColor,
) -> DrawResult<DB> {
    let mut chart = ChartBuilder::on(area).margin(8).x_label_area_size(58).build_cartesian_2d(lo..hi, 0.0..1.0)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(6)
        .x_label_formatter(&|v| tick_label(v))
        .label_style((style::FONT, style::TICK_LABEL_SIZE))
        .draw()?;
    // The name typeset below the ticks: "μ^S" as a superscript, not as written.
    let (w, h) = area.dim_in_pixel();
    text(area, label, (w as i32 / 2, h as i32 - 18), LABEL, (HPos::Center, VPos::Center))?;
    let step = (hi - lo) / LEVELS as f64;
    chart.draw_series((0..LEVELS).map(|k| {
        let t = (k as f64 + 0.5) / LEVELS as f64;
        Rectangle::new([(lo + k as f64 * step, 0.0), (lo + (k + 1) as f64 * step, 1.0)], colour(t).filled())
    }))?;
    chart.draw_series(std::iter::once(Rectangle::new([(lo, 0.0), (hi, 1.0)], BLACK.stroke_width(1))))?;
    Ok(())
}

/// Legend entries as colour swatches with text, one a line, from the top left of `area`.
pub(super) fn swatches<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(RGBColor, String)],
    size: f64,
) -> DrawResult<DB> {
    let line = (size * 1.6) as i32;
    let box_px = (size * 0.9) as i32;
    for (k, (c, label)) in entries.iter().enumerate() {
        let y = 8 + k as i32 * line;
        area.draw(&Rectangle::new([(8, y), (8 + box_px, y + box_px)], c.filled()))?;
        area.draw(&Rectangle::new([(8, y), (8 + box_px, y + box_px)], BLACK.mix(0.5).stroke_width(1)))?;
        text(area, label, (16 + box_px, y + box_px / 2), size, (HPos::Left, VPos::Center))?;
    }
    Ok(())
}

/// A fraction as a percentage, with two significant digits below 10 %: "84.2 %", "0.025 %".
pub(super) fn percent(f: f64) -> String {
    let p = 100.0 * f;
    let digits = if p > 0.0 && p < 10.0 { (1.0 - p.log10().floor()) as usize } else { 1 };
    format!("{p:.digits$} %")
}

/// A load [N] as the figures name it, in mN as the paper: "0.1 mN", "12.3 mN".
pub(super) fn load_label(load: f64) -> String {
    format!("{} mN", tick_label(&(load * 1e3)))
}

/// Stress-ratio snapshots (Fig. S6): rows δ/δ_peak, columns loads, each map zoomed to its
/// contact region; stuck elements coloured by their stress ratio from 0 to mu_s, slipped ones
/// in the pre-sliding colour.
pub(super) struct RatioSnapshots<'a> {
    /// (target load [N], the snapshot and its onset, if any).
    pub columns: Vec<(&'a MapSnapshot, Onset)>,
    /// δ/δ_peak of the rows, each in (0, 1].
    pub fractions: Vec<f64>,
    pub law: FrictionLaw,
    pub law_name: String,
}

const ROW_HEADER: u32 = 150;
const CELL: u32 = 400;
const COLUMN_HEADER: u32 = 60;

impl Draw for RatioSnapshots<'_> {
    fn size(&self) -> (u32, u32) {
        let (cols, rows) = (self.columns.len() as u32, self.fractions.len() as u32);
        (ROW_HEADER + cols * CELL + 20, 60 + COLUMN_HEADER + rows * CELL + 150)
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (w, _) = area.dim_in_pixel();
        let (head, rest) = area.split_vertically(60);
        text(
            &head,
            &format!(
                "Local stress ratio as the displacement grows ({}: μ^S = {}, μ^D = {})",
                self.law_name,
                tick_label(&self.law.mu_s),
                tick_label(&self.law.mu_d)
            ),
            (w as i32 / 2, 32),
            style::TITLE_SIZE * 0.8,
            (HPos::Center, VPos::Center),
        )?;
        let (col_heads, rest) = rest.split_vertically(COLUMN_HEADER);
        let (rows_area, bottom) = rest.split_vertically(self.fractions.len() as u32 * CELL);
        for (j, (snap, onset)) in self.columns.iter().enumerate() {
            let x = (ROW_HEADER + j as u32 * CELL + CELL / 2) as i32;
            let heading = format!("N = {}, {} elements", load_label(snap.load_n), onset.elements);
            let (view, zoomed) = View::detail(snap, plot_size((CELL, CELL)));
            let what = if zoomed { "zoom on the main patch" } else { "whole contact" };
            let zoom = format!("{what}; x, y [{}]", view.fit(plot_size((CELL, CELL))).unit().1);
            text(&col_heads, &heading, (x, 16), LABEL, (HPos::Center, VPos::Center))?;
            text(&col_heads, &zoom, (x, 42), TICK, (HPos::Center, VPos::Center))?;
        }
        let layers: Vec<(&MapSnapshot, &Onset, View)> =
            self.columns.iter().map(|(s, o)| (*s, o, View::detail(s, plot_size((CELL, CELL))).0)).collect();
        for (i, f) in self.fractions.iter().enumerate() {
            let row = rows_area.clone().shrink((0, i as u32 * CELL), (w, CELL));
            let (label, cells) = row.split_horizontally(ROW_HEADER);
            let y = CELL as i32 / 2;
            text(
                &label,
                &format!("δ/δ_{{peak}} = {}", tick_label(f)),
                (ROW_HEADER as i32 / 2, y),
                LABEL,
                (HPos::Center, VPos::Center),
            )?;
            for (j, (snap, onset, view)) in layers.iter().enumerate() {
                let cell = cells.clone().shrink((j as u32 * CELL, 0), (CELL, CELL));
                let values = ratio_layer(snap, onset, *f);
                let MapAxes { chart, view: fitted, plot } = map_chart(&cell, *view, false)?;
                let mu_s = self.law.mu_s;
                draw_layer(&chart, fitted, plot, &Layer::on(snap, &values), |v| ratio_value_colour(v, mu_s))?;
            }
        }
        ratio_key(&bottom.margin(10, 10, ROW_HEADER as i32, 20), &self.law)
    }
}

/// The key of a stress-ratio map: the bar of stuck ratios (0 … mu_s) beside the swatch of
/// slipped elements.
pub(super) fn ratio_key<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, law: &FrictionLaw) -> DrawResult<DB> {
    let (w, _) = area.dim_in_pixel();
    let (bar, side) = area.split_horizontally((w as f64 * 0.62) as u32);
    let mu_s = law.mu_s;
    colour_bar(&bar, (0.0, mu_s), "stress ratio of stuck elements (μ^S: critical)", ratio_colour)?;
    swatches(
        &side.margin(6, 0, 20, 0),
        &[(style::PRE_SLIDING, format!("slipped: μ^D = {} (pre-sliding)", tick_label(&law.mu_d)))],
        TICK,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentages_keep_two_digits() {
        assert_eq!(percent(0.842), "84.2 %");
        assert_eq!(percent(0.053), "5.3 %");
        assert_eq!(percent(0.00025), "0.025 %");
        assert_eq!(percent(0.0), "0.0 %");
    }

    /// A zoom cuts no contact patch (a 1 mN zoom, as in Fig. S6 and the movies, is where a
    /// patch would reach past the panel's edge): as drawn, every patch lies inside the view or
    /// outside it.
    #[test]
    fn zooms_cut_no_patch() {
        let mut pressure = Array2::zeros((400, 400));
        // The most loaded patch, a neighbour across where a zoom of the least size ends, and a
        // far patch that makes the whole contact too wide to show at DETAIL_PX.
        for (rows, cols, p) in [(195..205, 95..105, 5e9), (190..193, 115..140, 1e9), (200..204, 380..384, 1e9)] {
            pressure.slice_mut(ndarray::s![rows, cols]).fill(p);
        }
        let pixel = 1e-8;
        let snap = MapSnapshot {
            topography: "ball".into(),
            load_n: 1e-3,
            pressure,
            origin: (0, 0),
            grid: (400, 400),
            pixel_size: (pixel, pixel),
            stuck_stiffness: None,
        };
        let plot = plot_size((CELL, CELL));
        let mut boxes: Vec<View> = patches(&snap).into_iter().map(|p| p.0).collect();
        boxes.sort_by(|a, b| a.x.0.total_cmp(&b.x.0));
        let [main, neighbour, far] = boxes[..] else { panic!("three patches: {boxes:?}") };
        // The zoom about the main patch (12 pixels with its margin) at four times its extent:
        // it cuts the neighbour.
        let least = View { x: (76.0 * pixel, 124.0 * pixel), y: (176.0 * pixel, 224.0 * pixel) }.fit(plot);
        assert!(least.cuts(&neighbour), "the case: {least:?} against {neighbour:?}");

        let (view, zoomed) = View::detail(&snap, plot);
        let drawn = view.fit(plot);
        for b in [main, neighbour, far] {
            assert!(!drawn.cuts(&b), "{drawn:?} cuts the patch {b:?}");
        }
        assert!(zoomed && drawn.holds(&main) && drawn.holds(&neighbour) && !drawn.holds(&far), "{drawn:?}");
        assert!(drawn.width() < 100.0 * pixel, "still a zoom: {drawn:?}");
    }

    /// Pixels outside the view are not drawn (their clipped rectangles were pinned to the
    /// panel's edge: the slivers of patches beside a zoom in Fig. S6 at 1 mN).
    #[test]
    fn pixels_outside_the_view_leave_no_sliver() {
        let mut values = Array2::from_elem((20, 40), f64::NAN);
        values.slice_mut(ndarray::s![5..10, 30..35]).fill(1.0);
        values.slice_mut(ndarray::s![12..14, 2..4]).fill(1.0);
        let layer = Layer { values: &values, origin: (0, 0), pixel: (1.0, 1.0) };
        let view = View { x: (0.0, 20.0), y: (0.0, 20.0) };
        let mut rgb = vec![255u8; 200 * 200 * 3];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (200, 200)).into_drawing_area();
            let chart = ChartBuilder::on(&root).build_cartesian_2d(0.0..20.0, 0.0..20.0).unwrap();
            draw_layer(&chart, view, (200, 200), &layer, |_| RGBColor(255, 0, 0)).unwrap();
            root.present().unwrap();
        }
        let red: Vec<usize> =
            (0..200 * 200).filter(|k| rgb[3 * k..3 * k + 3] == [255, 0, 0]).map(|k| k % 200).collect();
        // The patch inside (x from 2 to 4: columns 20 to 40) is drawn; the one beyond x = 20 is not.
        assert!(red.len() >= 400, "the patch inside is drawn: {} px", red.len());
        assert!(red.iter().all(|&column| (19..42).contains(&column)), "no sliver at the right edge");
    }

    #[test]
    fn views_fit_the_screen_about_their_centre() {
        let v = View { x: (0.0, 2.0), y: (0.0, 1.0) }.fit((100, 100));
        assert_eq!(v, View { x: (0.0, 2.0), y: (-0.5, 1.5) });
        // A zoom at the scan's edge keeps inside it; one wider than the scan is centred on it.
        let window = View { x: (0.0, 10.0), y: (0.0, 10.0) };
        assert_eq!(View { x: (-2.0, 3.0), y: (8.0, 11.0) }.inside(window), View { x: (0.0, 5.0), y: (7.0, 10.0) });
        assert_eq!(View { x: (-4.0, 12.0), y: (2.0, 3.0) }.inside(window), View { x: (-3.0, 13.0), y: (2.0, 3.0) });
    }
}
