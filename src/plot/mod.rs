//! Figures. A figure is plain data ([`Figure`], [`Panel`], [`Axis`], [`Series`]) drawn by
//! plotters on any backend; [`write_figure`] renders it once as PNG and once as SVG and writes
//! both atomically. Text uses an embedded DejaVu Sans ([`style::register_fonts`]), so a figure
//! looks the same on a machine without system fonts. Figures with their own layout (maps,
//! movie frames) implement [`Draw`] and reuse [`style`] and [`write_figure`].
//!
//! [`study::render`] draws a numerical study's figures, movies and report; [`trace_figure`] a
//! slide-hold-slide trace with what [`crate::shs`] found in it.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

mod coefficients;
mod contact_maps;
mod convergence;
mod draw;
mod figure;
mod histograms;
mod inset;
mod legend;
mod maps;
mod movie;
mod report;
mod series;
mod shared;
pub mod study;
pub mod style;
mod ticks;
mod trace;
mod typeset;

pub use convergence::{sharing_convergence, ConvergencePoint};
pub use draw::{write_figure, Draw, DrawResult};
pub use figure::{Axis, Figure, Grid, LegendPosition, Panel};
pub use plotters::style::RGBColor;
pub use series::{Dash, Marker, Series, Shape};
pub use shared::FigureInput;
pub use ticks::{prefixed, tick_label};
pub use trace::trace_figure;
