//! A figure as plain data — panels of axes and their series (`series.rs`) — drawn on any
//! plotters backend.
//!
//! Must not import report, study, friction, contact or shs: a figure knows only its series.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::HPos;

pub use plotters::chart::SeriesLabelPosition as LegendPosition;

use super::draw::{Draw, DrawResult};
use super::legend::{add_legend, hidden, legend_glyph, triangle};
use super::series::{Dash, Marker, Series, Shape};
use super::style;
use super::ticks::{linear_ticks, log_ticks, mixed_notation, power_label, tick_label};
use super::typeset::{typeset, typeset_width};

/// One axis of a panel: its label (quantity and unit), linear or logarithmic, and its range
/// (fitted to the data unless fixed).
#[derive(Clone, Debug)]
pub struct Axis {
    label: String,
    log: bool,
    range: Option<(f64, f64)>,
}

impl Axis {
    /// An axis for `quantity` in `unit`, labelled "quantity [unit]".
    pub fn new(quantity: &str, unit: &str) -> Self {
        Axis { label: format!("{quantity} [{unit}]"), log: false, range: None }
    }

    /// An axis for a dimensionless quantity (a ratio, a coefficient), labelled by its name.
    pub fn dimensionless(quantity: &str) -> Self {
        Axis { label: quantity.to_string(), log: false, range: None }
    }

    /// Logarithmic scale: only positive values are shown.
    pub fn log(mut self) -> Self {
        self.log = true;
        self
    }

    /// Fix the range to `lo..hi` (in the axis' unit) instead of fitting it to the data.
    pub fn range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }

    fn shows(&self, v: f64) -> bool {
        v.is_finite() && (!self.log || v > 0.0)
    }

    /// The range to draw: the fixed one, or the data's padded by a few percent.
    fn resolve(&self, values: impl Iterator<Item = f64>) -> (f64, f64) {
        if let Some(r) = self.range {
            return r;
        }
        let (lo, hi) = values
            .filter(|&v| self.shows(v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        const PAD: f64 = 0.04;
        if self.log {
            let (lo, hi) = if lo > hi {
                (1.0, 10.0)
            } else if lo == hi {
                (lo / 2.0, hi * 2.0)
            } else {
                (lo, hi)
            };
            let f = (hi / lo).powf(PAD);
            (lo / f, hi * f)
        } else {
            let (lo, hi) = if lo > hi {
                (0.0, 1.0)
            } else if lo == hi {
                let d = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
                (lo - d, hi + d)
            } else {
                (lo, hi)
            };
            let d = (hi - lo) * PAD;
            (lo - d, hi + d)
        }
    }
}

/// One set of axes with its series and an optional legend.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Text above the axes, if any.
    pub title: Option<String>,
    /// The horizontal axis.
    pub x: Axis,
    /// The vertical axis.
    pub y: Axis,
    /// The series, drawn stripes and bands first, then lines, then markers.
    pub series: Vec<Series>,
    /// Where the legend of the labelled series goes; none without a legend.
    pub legend: Option<SeriesLabelPosition>,
    /// Width \[px] kept right of the axes for the legend, when it is drawn beside them.
    pub legend_beside: u32,
    /// A second x axis along the top: its label, and the factor from the bottom axis' values
    /// to its own (the same quantity in another unit).
    pub top: Option<(Axis, f64)>,
}

/// Height [px] kept above the axes for a top axis: its ticks, their labels and its name.
const TOP_AXIS_PX: u32 = 90;

impl Panel {
    /// Empty axes `x` and `y`: no title, no series, no legend.
    pub fn new(x: Axis, y: Axis) -> Self {
        Panel { title: None, x, y, series: Vec::new(), legend: None, legend_beside: 0, top: None }
    }

    /// A second x axis along the top, `axis` (only its label is used), whose values are the
    /// bottom axis' times `scale`: the same positions in another unit.
    pub fn top_axis(mut self, axis: Axis, scale: f64) -> Self {
        self.top = Some((axis, scale));
        self
    }

    /// Put `title` above the axes.
    pub fn title(mut self, title: impl Into<String>) -> Self {
        self.title = Some(title.into());
        self
    }

    /// Show the labelled series in a legend at `position`.
    pub fn legend(mut self, position: SeriesLabelPosition) -> Self {
        self.legend = Some(position);
        self
    }

    /// Show the legend right of the axes, in a column `width` px wide, where it hides no data
    /// (entries in the order the series were pushed).
    pub fn legend_beside(mut self, width: u32) -> Self {
        self.legend = Some(SeriesLabelPosition::UpperRight);
        self.legend_beside = width;
        self
    }

    /// Add a series; the legend lists labelled series in the order pushed.
    pub fn push(&mut self, series: Series) {
        self.series.push(series);
    }

    /// The width [px] kept right of the axes for a legend beside them: the width asked for, or
    /// more where the widest entry needs it, so that no entry is cut at the figure's edge.
    fn beside_width<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB, u32> {
        if self.legend_beside == 0 {
            return Ok(0);
        }
        let mut widest = 0;
        for label in self.series.iter().filter_map(|s| s.label.as_ref()) {
            widest = widest.max(typeset_width(area, label, style::LEGEND_SIZE)?);
        }
        // The entry's text starts 62 px right of the axes (see `draw_on`).
        Ok(self.legend_beside.max((62 + widest + style::MARGIN as i32) as u32))
    }

    fn draw_on<DB, X, Y>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (x, y): (X, Y),
        y_range: (f64, f64),
        powers: (bool, bool),
    ) -> DrawResult<DB>
    where
        DB: DrawingBackend,
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        // The title is set above the area the chart is built on, centred on the whole width
        // (the chart's own caption would be centred left of a legend beside the axes, and sit
        // below its margin, under a top axis).
        let titled;
        let area = match &self.title {
            Some(title) => {
                let size = title_size(area, title)?;
                titled = area.margin(style::MARGIN, 0, 0, 0).titled(title, (style::FONT, size))?;
                &titled
            }
            None => area,
        };
        let mut builder = ChartBuilder::on(area);
        builder.margin(style::MARGIN).margin_right(style::MARGIN + self.beside_width(area)?);
        if self.top.is_some() {
            builder.margin_top(TOP_AXIS_PX);
        } else if self.title.is_some() {
            builder.margin_top(0);
        }
        builder.x_label_area_size(70).y_label_area_size(105);
        let mut chart = builder.build_cartesian_2d(x, y)?;
        chart
            .configure_mesh()
            .label_style((style::FONT, style::TICK_LABEL_SIZE))
            .x_label_formatter(&|v| if powers.0 { power_label(v) } else { tick_label(v) })
            .y_label_formatter(&|v| if powers.1 { power_label(v) } else { tick_label(v) })
            .bold_line_style(RGBColor(220, 220, 220))
            .light_line_style(RGBColor(242, 242, 242))
            .axis_style(BLACK.stroke_width(style::LINE_WIDTH))
            .draw()?;
        // Axis names typeset (sub- and superscripts), below and left of the plotting area.
        let base = area.get_base_pixel();
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        let (_, height) = area.dim_in_pixel();
        let size = style::AXIS_LABEL_SIZE;
        let centre_x = (xr.start + xr.end) / 2 - base.0;
        typeset(area, &self.x.label, (centre_x, height as i32 - 24), size, HPos::Center, false)?;
        typeset(area, &self.y.label, (22, (yr.start + yr.end) / 2 - base.1), size, HPos::Center, true)?;
        if let Some((axis, scale)) = &self.top {
            // The top axis: a line along the plotting area, ticks at round values of its own
            // unit placed through the bottom axis, their labels, its name above them.
            let (top, left, right) = (yr.start - base.1, xr.start - base.0, xr.end - base.0);
            let axis_style = BLACK.stroke_width(style::LINE_WIDTH);
            area.draw(&PathElement::new(vec![(left, top), (right, top)], axis_style))?;
            let range = chart.x_range();
            let (lo, hi) = (range.start * scale, range.end * scale);
            let ticks = if self.x.log { log_ticks(lo, hi) } else { linear_ticks(lo, hi) };
            for t in ticks {
                let x = chart.backend_coord(&(t / scale, y_range.1)).0 - base.0;
                area.draw(&PathElement::new(vec![(x, top), (x, top - 8)], axis_style))?;
                let label = tick_label(&t);
                typeset(
                    area,
                    &label,
                    (x, top - 8 - style::TICK_LABEL_SIZE as i32 / 2 - 4),
                    style::TICK_LABEL_SIZE,
                    HPos::Center,
                    false,
                )?;
            }
            typeset(area, &axis.label, (centre_x, top - TOP_AXIS_PX as i32 + 22), size, HPos::Center, false)?;
        }

        let (xa, ya) = (&self.x, &self.y);
        let shown = |&(px, py): &(f64, f64)| xa.shows(px) && ya.shows(py);
        let mut order: Vec<&Series> = self.series.iter().collect();
        order.sort_by_key(|s| s.layer());
        for s in order {
            let colour = s.colour.mix(s.opacity);
            match &s.shape {
                Shape::Line { points, width, dash } => {
                    let line = colour.stroke_width(*width);
                    let pts = points.iter().copied().filter(shown);
                    let w = *width as i32;
                    let anno = match dash {
                        Dash::Solid => chart.draw_series(LineSeries::new(pts, line))?,
                        Dash::Dashed => chart.draw_series(DashedLineSeries::new(pts, 4 * w + 4, 4 * w, line))?,
                        Dash::Dotted => chart.draw_series(DashedLineSeries::new(pts, w, 2 * w + 2, line))?,
                    };
                    add_legend(anno, s, colour);
                }
                Shape::Scatter { points, y_err, marker, filled } => {
                    if let Some(err) = y_err {
                        let bar = colour.stroke_width(style::LINE_WIDTH);
                        let cap = style::MARKER_SIZE as i32;
                        for (&(px, py), e) in points.iter().zip(err) {
                            let (lo, hi) = (py - e.abs(), py + e.abs());
                            if !(shown(&(px, py)) && ya.shows(lo)) {
                                continue;
                            }
                            chart.draw_series([PathElement::new(vec![(px, lo), (px, hi)], bar)])?;
                            chart.draw_series([lo, hi].map(|y| {
                                EmptyElement::at((px, y)) + PathElement::new(vec![(-cap, 0), (cap, 0)], bar)
                            }))?;
                        }
                    }
                    let pts: Vec<_> = points.iter().copied().filter(shown).collect();
                    let style = if *filled { colour.filled() } else { colour.stroke_width(style::LINE_WIDTH) };
                    let r = style::MARKER_SIZE as i32;
                    let anno =
                        match marker {
                            Marker::Circle => chart.draw_series(pts.into_iter().map(|p| Circle::new(p, r, style)))?,
                            Marker::Square => chart.draw_series(
                                pts.into_iter()
                                    .map(|p| EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], style)),
                            )?,
                            Marker::Triangle if *filled => chart
                                .draw_series(pts.into_iter().map(|p| {
                                    EmptyElement::at(p) + Polygon::new(triangle((0, 0), r + 2, false), style)
                                }))?,
                            Marker::Triangle => chart.draw_series(pts.into_iter().map(|p| {
                                EmptyElement::at(p) + PathElement::new(triangle((0, 0), r + 2, true), style)
                            }))?,
                            Marker::Cross => chart.draw_series(pts.into_iter().map(|p| Cross::new(p, r, style)))?,
                        };
                    add_legend(anno, s, colour);
                }
                Shape::Band { x, lower, upper } => {
                    let mut outline: Vec<(f64, f64)> = x.iter().copied().zip(upper.iter().copied()).collect();
                    outline.extend(x.iter().copied().zip(lower.iter().copied()).rev());
                    outline.retain(shown);
                    let anno = chart.draw_series(std::iter::once(Polygon::new(outline, colour.filled())))?;
                    add_legend(anno, s, colour);
                }
                Shape::Span { x0, x1 } => {
                    let anno = chart.draw_series(std::iter::once(Rectangle::new(
                        [(*x0, y_range.0), (*x1, y_range.1)],
                        colour.filled(),
                    )))?;
                    add_legend(anno, s, colour);
                }
            }
        }
        let labelled: Vec<(&Series, &String)> =
            self.series.iter().filter_map(|s| s.label.as_ref().map(|l| (s, l))).collect();
        if let (Some(position), false) = (&self.legend, labelled.is_empty()) {
            // Entries in the order the series were pushed, labels typeset; beside the axes
            // (outside the plotting area, which clips what is drawn on it) or in a corner.
            let line = (style::LEGEND_SIZE * 1.55) as i32;
            let widths = labelled
                .iter()
                .map(|(_, l)| typeset_width(area, l, style::LEGEND_SIZE))
                .collect::<Result<Vec<i32>, _>>()?;
            let (w, h) = (widths.iter().max().copied().unwrap_or(0) + 34 + 20, labelled.len() as i32 * line + 12);
            let (left, top) = (xr.start - base.0, yr.start - base.1);
            let (right, bottom) = (xr.end - base.0, yr.end - base.1);
            let corner = |position: &SeriesLabelPosition| match position {
                SeriesLabelPosition::UpperLeft => (left + 12, top + 12),
                SeriesLabelPosition::LowerLeft => (left + 12, bottom - h - 12),
                SeriesLabelPosition::LowerRight => (right - w - 12, bottom - h - 12),
                _ => (right - w - 12, top + 12),
            };
            let (x, y) = if self.legend_beside > 0 {
                (right + 20, top)
            } else {
                // The corner asked for, unless another hides less of the data.
                let to_px = |p: (f64, f64)| {
                    let (px, py) = chart.backend_coord(&p);
                    ((px - base.0) as f64, (py - base.1) as f64)
                };
                let cover = |(x, y): (i32, i32)| {
                    let rect = (x as f64, y as f64, (x + w) as f64, (y + h) as f64);
                    self.series.iter().map(|s| hidden(s, rect, to_px, shown)).sum::<f64>()
                };
                let mut best = (corner(position), cover(corner(position)));
                for other in [
                    SeriesLabelPosition::UpperRight,
                    SeriesLabelPosition::UpperLeft,
                    SeriesLabelPosition::LowerRight,
                    SeriesLabelPosition::LowerLeft,
                ] {
                    let c = cover(corner(&other));
                    if c < best.1 {
                        best = (corner(&other), c);
                    }
                }
                best.0
            };
            if self.legend_beside == 0 {
                area.draw(&Rectangle::new([(x, y), (x + w, y + h)], WHITE.mix(0.88).filled()))?;
                area.draw(&Rectangle::new([(x, y), (x + w, y + h)], BLACK.mix(0.6).stroke_width(1)))?;
            }
            for (k, (s, label)) in labelled.iter().enumerate() {
                let ly = y + 6 + line / 2 + k as i32 * line;
                area.draw(&legend_glyph(&s.shape, s.colour.mix(s.opacity), x + 8, ly))?;
                typeset(area, label, (x + 42, ly), style::LEGEND_SIZE, HPos::Left, false)?;
            }
        }
        Ok(())
    }
}

/// The font size [px] of a panel's `title` on `area`: style::TITLE_SIZE, or smaller where the
/// title would be wider than the area less a margin each side (a long law name), so that no
/// title runs off the figure (it is centred, and plotters would cut both of its ends).
fn title_size<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, title: &str) -> DrawResult<DB, f64> {
    let room = area.dim_in_pixel().0 as f64 - 2.0 * style::MARGIN as f64;
    let font = (style::FONT, style::TITLE_SIZE).into_font();
    let width = area.estimate_text_size(title, &font.into_text_style(area))?.0 as f64;
    // The width grows with the size, but in whole pixels per glyph: 2 % to spare.
    Ok(if width > room { style::TITLE_SIZE * 0.98 * room / width } else { style::TITLE_SIZE })
}

impl Draw for Panel {
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (x0, x1) = self.x.resolve(self.series.iter().flat_map(|s| s.xs()));
        let (y0, y1) = self.y.resolve(self.series.iter().flat_map(|s| s.ys()));
        let (xr, yr) = (x0..x1, y0..y1);
        let log_x = || xr.clone().log_scale().with_key_points(log_ticks(x0, x1));
        let log_y = || yr.clone().log_scale().with_key_points(log_ticks(y0, y1));
        // A log axis whose plain labels would mix notations is written in powers of ten.
        let powers =
            (self.x.log && mixed_notation(&log_ticks(x0, x1)), self.y.log && mixed_notation(&log_ticks(y0, y1)));
        let r = (y0, y1);
        match (self.x.log, self.y.log) {
            (false, false) => self.draw_on(area, (xr.clone(), yr.clone()), r, powers),
            (true, false) => self.draw_on(area, (log_x(), yr.clone()), r, powers),
            (false, true) => self.draw_on(area, (xr.clone(), log_y()), r, powers),
            (true, true) => self.draw_on(area, (log_x(), log_y()), r, powers),
        }
    }
}

/// Panels stacked top to bottom, each given a share of the height proportional to its weight.
#[derive(Clone, Debug)]
pub struct Figure {
    size: (u32, u32),
    rows: Vec<(Panel, u32)>,
}

impl Figure {
    /// A figure of one panel on the default canvas.
    pub fn new(panel: Panel) -> Self {
        Figure { size: style::SIZE, rows: vec![(panel, 1)] }
    }

    /// Panels stacked vertically with relative heights.
    pub fn stack(rows: Vec<(Panel, u32)>) -> Self {
        assert!(!rows.is_empty() && rows.iter().all(|r| r.1 > 0), "a figure needs panels of positive weight");
        Figure { size: style::SIZE, rows }
    }

    /// Canvas size \[px].
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }
}

impl Draw for Figure {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let total: u32 = self.rows.iter().map(|r| r.1).sum();
        let height = area.dim_in_pixel().1 as f64;
        let mut acc = 0;
        let breaks: Vec<i32> = self.rows[..self.rows.len() - 1]
            .iter()
            .map(|r| {
                acc += r.1;
                (height * f64::from(acc) / f64::from(total)).round() as i32
            })
            .collect();
        let areas = area.split_by_breakpoints::<i32, i32, _, _>([], breaks);
        for ((panel, _), sub) in self.rows.iter().zip(&areas) {
            panel.draw(sub)?;
        }
        Ok(())
    }
}

/// Panels side by side in rows of `columns`, each in an equal cell.
#[derive(Clone, Debug)]
pub struct Grid {
    size: (u32, u32),
    columns: usize,
    panels: Vec<Panel>,
}

impl Grid {
    /// `panels` in rows of `columns` on a `size` px canvas.
    pub fn new(panels: Vec<Panel>, columns: usize, size: (u32, u32)) -> Self {
        assert!(columns > 0 && !panels.is_empty(), "a grid needs panels and columns");
        Grid { size, columns, panels }
    }
}

impl Draw for Grid {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let rows = self.panels.len().div_ceil(self.columns);
        let cells = area.split_evenly((rows, self.columns));
        for (panel, cell) in self.panels.iter().zip(&cells) {
            panel.draw(cell)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::draw::write_figure;

    /// A legend beside the axes widens its column to its longest entry: a study's long law
    /// names were cut at the figure's right edge.
    #[test]
    fn a_legend_beside_the_axes_is_not_cut() {
        let long = "a law with a long name measured after a hold of 100 s: model, 3 topographies";
        let mut panel = Panel::new(Axis::new("load", "mN").log(), Axis::dimensionless("drop")).legend_beside(200);
        panel.push(Series::line(vec![(1e-3, 1.0), (1e2, 1.5)], BLACK).label(long));
        let figure = Figure::new(panel).with_size(1200, 600);
        let mut svg = String::new();
        let width = {
            let root = SVGBackend::with_string(&mut svg, (1200, 600)).into_drawing_area();
            style::register_fonts();
            figure.draw(&root).unwrap();
            let width = typeset_width(&root, long, style::LEGEND_SIZE).unwrap();
            root.present().unwrap();
            width
        };
        let at = svg.find(long).expect("the entry is drawn");
        let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
        let x: i32 = tag.split("x=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
        assert!(x + width <= 1200, "the entry ends at {} px on a 1200 px figure", x + width);
    }

    /// A title wider than the figure is set smaller: Fig. 4g's title, with a long law name,
    /// was cut at both edges of its figure.
    #[test]
    fn a_long_title_stays_on_the_figure() {
        let long = "Force carried per element class at the critical state (a law with a long name, hold \
                    100 s; mean over 3 topographies)";
        for (top, beside) in [(false, false), (true, false), (false, true)] {
            let mut panel = Panel::new(Axis::new("load", "mN").log(), Axis::dimensionless("fraction")).title(long);
            if top {
                panel = panel.top_axis(Axis::new("load", "N"), 1e-3);
            }
            if beside {
                panel = panel.legend_beside(330);
            }
            panel.push(Series::line(vec![(1e-3, 0.2), (1e2, 0.5)], BLACK));
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, (1000, 600)).into_drawing_area();
                style::register_fonts();
                Figure::new(panel).with_size(1000, 600).draw(&root).unwrap();
                root.present().unwrap();
            }
            let at = svg.find(long).expect("the title is drawn");
            let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
            let attr = |name: &str| -> f64 {
                tag.split(&format!(" {name}=\"")).nth(1).unwrap().split('"').next().unwrap().parse().unwrap()
            };
            let (x, size) = (attr("x"), attr("font-size"));
            let mut scratch = String::new();
            let root = SVGBackend::with_string(&mut scratch, (1000, 600)).into_drawing_area();
            let width =
                |size: f64| root.estimate_text_size(long, &(style::FONT, size).into_text_style(&root)).unwrap().0;
            let (full, w) = (width(style::TITLE_SIZE) as f64, width(size) as f64);
            let drawn = (x - w / 2.0, x + w / 2.0);
            assert!(full > 1000.0, "the title at full size, {full} px, is wider than the figure");
            let case = format!("top axis {top}, legend beside {beside}");
            assert!(drawn.0 >= 0.0 && drawn.1 <= 1000.0, "{case}: the title spans {drawn:?} px");
        }
    }

    /// Every series kind on a log-log and a linear panel: both files appear, the PNG decodes
    /// to the canvas size and has drawn content, the SVG carries the labels.
    #[test]
    fn writes_png_and_svg() {
        let x: Vec<f64> = (0..50).map(|i| 1e-4 * 10f64.powf(i as f64 / 12.0)).collect();
        let mut top = Panel::new(Axis::new("normal load", "N").log(), Axis::dimensionless("friction drop").log())
            .title("all series kinds")
            .legend(LegendPosition::UpperRight);
        top.push(Series::band(
            x.clone(),
            x.iter().map(|v| 1.5 - v.log10() / 20.0).collect(),
            vec![2.2; 50],
            style::GREY,
        ));
        top.push(
            Series::line(x.iter().map(|&v| (v, 2.0 - v.log10() / 10.0)).collect(), style::PALETTE[0]).label("model"),
        );
        top.push(Series::line(vec![(1e-4, 1.2), (1e-1, 1.2)], style::PALETTE[1]).dashed().width(1));
        top.push(
            Series::scatter(vec![(1e-3, 1.8), (1e-2, 1.6)], Marker::Square, style::PALETTE[1])
                .errors(vec![0.1, 0.05])
                .label("measured"),
        );
        top.push(Series::scatter(vec![(3e-3, 1.7)], Marker::Triangle, style::PALETTE[2]).hollow());
        top.push(Series::scatter(vec![(3e-2, 1.5)], Marker::Cross, style::PALETTE[3]));
        top.push(Series::scatter(vec![(5e-2, 1.4)], Marker::Circle, style::PALETTE[4]));
        let mut bottom =
            Panel::new(Axis::new("time", "s"), Axis::new("force", "mN").range(-1.0, 5.0)).legend_beside(220);
        bottom.push(Series::line(vec![(0.0, 1.0), (6.0, 1.0)], style::GREY).dotted().label("limit"));
        bottom.push(Series::span(2.0, 3.0, style::CRITICAL).label("critical"));
        bottom.push(Series::span(4.0, 5.0, style::PRE_SLIDING).opacity(0.4));
        bottom.push(Series::line(vec![(0.0, 0.0), (6.0, 4.0)], style::SUBCRITICAL));
        let figure = Figure::stack(vec![(top, 2), (bottom, 1)]).with_size(900, 900);

        let dir = tempfile::tempdir().unwrap();
        let png_path = dir.path().join("all.png");
        let svg_path = write_figure(&png_path, &figure).unwrap();
        assert_eq!(svg_path, dir.path().join("all.svg"));

        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png_path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (900, 900));
        let pixels = &buf[..info.buffer_size()];
        let dark = pixels.chunks(3).filter(|p| p.iter().all(|&c| c < 100)).count();
        let amber = pixels.chunks(3).filter(|p| p[0] > 200 && p[1] > 150 && p[2] < 200 && p[1] < 230).count();
        assert!(dark > 5_000, "axes, text and lines are drawn ({dark} dark pixels)");
        assert!(amber > 1_000, "the pre-sliding span is drawn ({amber} amber pixels)");

        let svg = std::fs::read_to_string(&svg_path).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("friction drop") && svg.contains("normal load [N]"));
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 2, "no temporary files left: {names:?}");
        let e = write_figure(&dir.path().join("all.svg"), &figure).unwrap_err().to_string();
        assert!(e.contains("all.svg") && e.contains(".png"), "{e}");
    }
}
