//! A figure's series as plain data: the shape drawn (line, markers, band, stripe) with its
//! colour, opacity, stroke and legend entry, in the units of the panel's axes.
//!
//! Must not import the other files of plot but `style`, nor report, study, friction, contact
//! or shs: a series knows only its data.

use plotters::style::RGBColor;

use super::style;

/// Marker of a scatter series.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// A disc.
    Circle,
    /// A square.
    Square,
    /// An upward triangle.
    Triangle,
    /// A diagonal cross (×).
    Cross,
}

/// How a line is stroked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dash {
    /// An unbroken line.
    Solid,
    /// Dashes several line widths long.
    Dashed,
    /// Dots one line width long (a reference level, a limit).
    Dotted,
}

/// The geometry of a series, in the units of the panel's axes.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A polyline through `points`, `width` px wide.
    Line {
        /// The vertices (x, y), in order.
        points: Vec<(f64, f64)>,
        /// Stroke width \[px].
        width: u32,
        /// Solid, dashed or dotted.
        dash: Dash,
    },
    /// Markers at `points`, with optional symmetric vertical error bars (± `y_err`).
    Scatter {
        /// The marker positions (x, y).
        points: Vec<(f64, f64)>,
        /// Half-length of each point's error bar, in the y axis' unit; none without bars.
        y_err: Option<Vec<f64>>,
        /// The marker's shape.
        marker: Marker,
        /// Filled, or outlined only.
        filled: bool,
    },
    /// The area between `lower(x)` and `upper(x)`.
    Band {
        /// The abscissae, increasing.
        x: Vec<f64>,
        /// The lower edge at each `x`.
        lower: Vec<f64>,
        /// The upper edge at each `x`.
        upper: Vec<f64>,
    },
    /// A vertical stripe from `x0` to `x1` over the whole height of the panel.
    Span {
        /// The stripe's left edge.
        x0: f64,
        /// The stripe's right edge.
        x1: f64,
    },
}

/// A series: a shape with its colour, opacity and legend entry.
#[derive(Clone, Debug)]
pub struct Series {
    /// What is drawn: line, markers, band or stripe.
    pub shape: Shape,
    /// Its colour.
    pub colour: RGBColor,
    /// 1 opaque, 0 invisible.
    pub opacity: f64,
    /// Legend text; unlabelled series are left out of the legend.
    pub label: Option<String>,
}

impl Series {
    /// A solid line.
    pub fn line(points: Vec<(f64, f64)>, colour: RGBColor) -> Self {
        Series::new(Shape::Line { points, width: style::LINE_WIDTH, dash: Dash::Solid }, colour, 1.0)
    }

    /// Filled markers.
    pub fn scatter(points: Vec<(f64, f64)>, marker: Marker, colour: RGBColor) -> Self {
        Series::new(Shape::Scatter { points, y_err: None, marker, filled: true }, colour, 1.0)
    }

    /// A translucent band between two curves sampled at the same `x`.
    pub fn band(x: Vec<f64>, lower: Vec<f64>, upper: Vec<f64>, colour: RGBColor) -> Self {
        assert!(x.len() == lower.len() && x.len() == upper.len(), "a band needs x, lower and upper of one length");
        Series::new(Shape::Band { x, lower, upper }, colour, 0.25)
    }

    /// A translucent vertical stripe from `x0` to `x1`.
    pub fn span(x0: f64, x1: f64, colour: RGBColor) -> Self {
        Series::new(Shape::Span { x0, x1 }, colour, 0.15)
    }

    fn new(shape: Shape, colour: RGBColor, opacity: f64) -> Self {
        Series { shape, colour, opacity, label: None }
    }

    /// Name the series in the legend.
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Opacity: 1 opaque, 0 invisible.
    pub fn opacity(mut self, opacity: f64) -> Self {
        self.opacity = opacity;
        self
    }

    /// Line width \[px]; lines only.
    pub fn width(mut self, px: u32) -> Self {
        match &mut self.shape {
            Shape::Line { width, .. } => *width = px,
            _ => panic!("Series::width applies to lines"),
        }
        self
    }

    /// Dashed instead of solid; lines only.
    pub fn dashed(self) -> Self {
        self.dash(Dash::Dashed, "dashed")
    }

    /// Dotted instead of solid; lines only.
    pub fn dotted(self) -> Self {
        self.dash(Dash::Dotted, "dotted")
    }

    fn dash(mut self, style: Dash, name: &str) -> Self {
        match &mut self.shape {
            Shape::Line { dash, .. } => *dash = style,
            _ => panic!("Series::{name} applies to lines"),
        }
        self
    }

    /// Outlined instead of filled markers; scatter only.
    pub fn hollow(mut self) -> Self {
        match &mut self.shape {
            Shape::Scatter { filled, .. } => *filled = false,
            _ => panic!("Series::hollow applies to scatter series"),
        }
        self
    }

    /// Vertical error bars of half-length `y_err[i]` on point i; scatter only.
    pub fn errors(mut self, err: Vec<f64>) -> Self {
        match &mut self.shape {
            Shape::Scatter { points, y_err, .. } => {
                assert_eq!(points.len(), err.len(), "one error bar per point");
                *y_err = Some(err);
            }
            _ => panic!("Series::errors applies to scatter series"),
        }
        self
    }

    /// Drawing order: stripes and bands under lines under markers.
    pub(super) fn layer(&self) -> u8 {
        match self.shape {
            Shape::Span { .. } => 0,
            Shape::Band { .. } => 1,
            Shape::Line { .. } => 2,
            Shape::Scatter { .. } => 3,
        }
    }

    pub(super) fn xs(&self) -> Box<dyn Iterator<Item = f64> + '_> {
        match &self.shape {
            Shape::Line { points, .. } | Shape::Scatter { points, .. } => Box::new(points.iter().map(|p| p.0)),
            Shape::Band { x, .. } => Box::new(x.iter().copied()),
            Shape::Span { x0, x1 } => Box::new([*x0, *x1].into_iter()),
        }
    }

    pub(super) fn ys(&self) -> Box<dyn Iterator<Item = f64> + '_> {
        match &self.shape {
            Shape::Line { points, .. } | Shape::Scatter { points, y_err: None, .. } => {
                Box::new(points.iter().map(|p| p.1))
            }
            Shape::Scatter { points, y_err: Some(e), .. } => {
                Box::new(points.iter().zip(e).flat_map(|(p, e)| [p.1 - e.abs(), p.1 + e.abs()]))
            }
            Shape::Band { lower, upper, .. } => Box::new(lower.iter().chain(upper).copied()),
            Shape::Span { .. } => Box::new(std::iter::empty()),
        }
    }
}
