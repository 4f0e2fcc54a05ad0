//! A panel's legend: the glyph of each series (a line sample, a marker, a swatch) and how much
//! of the series a legend box placed over the axes would hide.
//!
//! Must not import report, study, friction, contact or shs: a legend knows only its series.

use plotters::chart::SeriesAnno;
use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::DrawingErrorKind;

use super::series::{Dash, Marker, Series, Shape};
use super::style;

/// How much of series `s` a legend box `rect` (left, top, right, bottom) would hide, in
/// pixels of its area over 10 (a marker counts as its disc): `to_px` maps the axes' units to
/// pixels, `shown` tells the points the axes can draw.
pub(super) fn hidden(
    s: &Series,
    rect: (f64, f64, f64, f64),
    to_px: impl Fn((f64, f64)) -> (f64, f64),
    shown: impl Fn(&(f64, f64)) -> bool,
) -> f64 {
    const STEP: f64 = 2.0;
    let inside = |(x, y): (f64, f64)| x >= rect.0 && x <= rect.2 && y >= rect.1 && y <= rect.3;
    let pixels = |points: &[(f64, f64)]| -> Vec<(f64, f64)> {
        points.iter().copied().filter(|p| shown(p)).map(&to_px).collect()
    };
    let covered = match &s.shape {
        Shape::Line { points, width, .. } => {
            let px = pixels(points);
            // Samples every STEP px along each segment, each standing for STEP px of the line.
            let mut n = 0usize;
            for seg in px.windows(2) {
                let (a, b) = (seg[0], seg[1]);
                let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) / STEP).ceil().max(1.0) as usize;
                n += (0..steps)
                    .filter(|&i| {
                        let t = i as f64 / steps as f64;
                        inside((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t))
                    })
                    .count();
            }
            // The samples start each segment: the line's final endpoint is its own sample.
            n += px.last().is_some_and(|p| inside(*p)) as usize;
            n as f64 * STEP * *width as f64
        }
        Shape::Scatter { points, .. } => {
            let r = style::MARKER_SIZE as f64;
            pixels(points).iter().filter(|p| inside(**p)).count() as f64 * std::f64::consts::PI * r * r
        }
        Shape::Band { x, lower, upper } => {
            let edge =
                |y: &[f64]| -> Vec<(f64, f64)> { x.iter().copied().zip(y.iter().copied()).map(&to_px).collect() };
            let (lo, hi) = (edge(lower), edge(upper));
            let mut area = 0.0;
            for i in 1..lo.len() {
                let (x0, x1) = (lo[i - 1].0, lo[i].0);
                if !(x0.is_finite() && x1.is_finite()) || x1 <= x0 {
                    continue;
                }
                let mut xs = x0.max(rect.0);
                while xs < x1.min(rect.2) {
                    let t = (xs - x0) / (x1 - x0);
                    let (a, b) = (hi[i - 1].1 + (hi[i].1 - hi[i - 1].1) * t, lo[i - 1].1 + (lo[i].1 - lo[i - 1].1) * t);
                    area += (b.max(a).min(rect.3) - a.min(b).max(rect.1)).max(0.0) * STEP;
                    xs += STEP;
                }
            }
            // Translucent: a legend over a band hides less than over a line.
            area * s.opacity
        }
        Shape::Span { .. } => 0.0,
    };
    covered / 10.0
}

pub(super) fn add_legend<'a, DB: DrawingBackend + 'a>(anno: &mut SeriesAnno<'a, DB>, s: &Series, colour: RGBAColor) {
    if let Some(label) = &s.label {
        let shape = s.shape.clone();
        anno.label(label.as_str()).legend(move |(lx, ly)| legend_glyph(&shape, colour, lx, ly));
    }
}

pub(super) fn legend_glyph<DB: DrawingBackend>(
    shape: &Shape,
    colour: RGBAColor,
    x: i32,
    y: i32,
) -> DynElement<'static, DB, (i32, i32)> {
    let r = style::MARKER_SIZE as i32;
    match shape {
        Shape::Line { width, dash, .. } => {
            // Pieces of a 24 px sample, so that dashed and dotted lines read as such.
            let (on, off) = match dash {
                Dash::Solid => (24, 0),
                Dash::Dashed => (9, 6),
                Dash::Dotted => (*width as i32, 2 * *width as i32 + 2),
            };
            let ends = (0..24).step_by((on + off) as usize).flat_map(|a| [(x + a, y), (x + (a + on).min(24), y)]);
            Segments { ends: ends.collect(), style: colour.stroke_width(*width) }.into_dyn()
        }
        Shape::Scatter { marker, filled, .. } => {
            let style = if *filled { colour.filled() } else { colour.stroke_width(style::LINE_WIDTH) };
            let c = (x + 12, y);
            match marker {
                Marker::Circle => Circle::new(c, r, style).into_dyn(),
                Marker::Square => Rectangle::new([(c.0 - r, y - r), (c.0 + r, y + r)], style).into_dyn(),
                Marker::Triangle if *filled => Polygon::new(triangle(c, r + 2, false), style).into_dyn(),
                Marker::Triangle => PathElement::new(triangle(c, r + 2, true), style).into_dyn(),
                Marker::Cross => Cross::new(c, r, style).into_dyn(),
            }
        }
        Shape::Band { .. } | Shape::Span { .. } => {
            Rectangle::new([(x, y - 8), (x + 24, y + 8)], colour.filled()).into_dyn()
        }
    }
}

/// Straight segments between consecutive pairs of `ends` [px]: a dashed line in a legend.
struct Segments {
    ends: Vec<(i32, i32)>,
    style: ShapeStyle,
}

impl<'a> PointCollection<'a, (i32, i32)> for &'a Segments {
    type Point = &'a (i32, i32);
    type IntoIter = &'a [(i32, i32)];
    fn point_iter(self) -> Self::IntoIter {
        &self.ends
    }
}

impl<DB: DrawingBackend> Drawable<DB> for Segments {
    fn draw<I: Iterator<Item = (i32, i32)>>(
        &self,
        points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let ends: Vec<_> = points.collect();
        for pair in ends.chunks_exact(2) {
            backend.draw_line(pair[0], pair[1], &self.style)?;
        }
        Ok(())
    }
}

/// The outline of an upward triangle of circumradius `r` [px] around `c`, closed (first corner
/// repeated) when `closed`. Plotters' own triangle marker is always filled.
pub(super) fn triangle(c: (i32, i32), r: i32, closed: bool) -> Vec<(i32, i32)> {
    let (dx, dy) = ((f64::from(r) * 0.866).round() as i32, r / 2);
    let mut corners = vec![(c.0, c.1 - r), (c.0 + dx, c.1 + dy), (c.0 - dx, c.1 + dy)];
    if closed {
        corners.push(corners[0]);
    }
    corners
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_legend_box_hides_what_lies_under_it() {
        let id = |p: (f64, f64)| p;
        let all = |_: &(f64, f64)| true;
        let rect = (0.0, 0.0, 100.0, 50.0);
        // A 2 px line across the box: 100 px of it hidden, 200 px² over 10.
        let across = Series::line(vec![(-50.0, 25.0), (150.0, 25.0)], BLACK).width(2);
        let h = hidden(&across, rect, id, all);
        assert!((h - 20.0).abs() <= 1.0, "{h}");
        assert_eq!(hidden(&Series::line(vec![(0.0, 80.0), (100.0, 90.0)], BLACK), rect, id, all), 0.0);
        // A band from y = 40 to 60 under the whole box: 100 × 10 px at a quarter's opacity.
        let band = Series::band(vec![-10.0, 200.0], vec![40.0, 40.0], vec![60.0, 60.0], BLACK);
        let h = hidden(&band, rect, id, all);
        assert!((h - 25.0).abs() <= 1.0, "{h}");
        // Markers count inside the box only.
        let dots = Series::scatter(vec![(10.0, 10.0), (20.0, 20.0), (300.0, 20.0)], Marker::Circle, BLACK);
        let disc = std::f64::consts::PI * (style::MARKER_SIZE as f64).powi(2) / 10.0;
        assert!((hidden(&dots, rect, id, all) - 2.0 * disc).abs() < 1e-9);
    }
}
