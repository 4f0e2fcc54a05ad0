//! The look shared by every figure: one embedded font, sizes in pixels for the default
//! canvas, and the colours that carry meaning across figures.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use std::sync::Once;

use plotters::style::{FontStyle, RGBColor};

/// The font family every text element asks for; it resolves to the embedded DejaVu Sans.
pub const FONT: &str = "sans-serif";

/// Default canvas \[px] of a single-panel figure (PNG; the SVG has the same size).
pub const SIZE: (u32, u32) = (1200, 800);

/// Text size \[px] of a panel's title.
pub const TITLE_SIZE: f64 = 30.0;
/// Text size \[px] of an axis' name.
pub const AXIS_LABEL_SIZE: f64 = 26.0;
/// Text size \[px] of tick labels.
pub const TICK_LABEL_SIZE: f64 = 21.0;
/// Text size \[px] of legend entries.
pub const LEGEND_SIZE: f64 = 21.0;

/// Line width \[px] of data lines, and of axes and frames.
pub const LINE_WIDTH: u32 = 2;
/// Marker radius \[px] of scatter points.
pub const MARKER_SIZE: u32 = 6;
/// Margin \[px] around a panel.
pub const MARGIN: u32 = 16;

/// Element classes of the stick-slip transition model, in the colours of the paper's movies.
/// Critical elements (stuck at the local static ratio mu_s): brown.
pub const CRITICAL: RGBColor = RGBColor(140, 75, 30);
/// Pre-sliding elements (already slipped, at mu_d): amber.
pub const PRE_SLIDING: RGBColor = RGBColor(240, 175, 0);
/// Subcritical elements (stuck below mu_s): green.
pub const SUBCRITICAL: RGBColor = RGBColor(50, 150, 70);
/// Weakening elements of elastic sharing (slipped, between mu_s and mu_d): red-orange, between
/// the critical brown and the pre-sliding amber.
pub const WEAKENING: RGBColor = RGBColor(225, 90, 40);

/// Colours for successive data series (black and red first, as the paper's 100 s and 10 s
/// hold times).
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(20, 20, 20),
    RGBColor(205, 35, 35),
    RGBColor(30, 100, 200),
    RGBColor(120, 60, 170),
    RGBColor(0, 150, 150),
    RGBColor(230, 120, 0),
];
/// Neutral grey for context (shaded intervals, reference lines).
pub const GREY: RGBColor = RGBColor(120, 120, 120);

static FONTS: Once = Once::new();

/// Make the embedded font known to plotters; called before anything is drawn, so text renders
/// the same on every machine, with or without system fonts.
pub fn register_fonts() {
    FONTS.call_once(|| {
        static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        let registered = plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS);
        assert!(registered.is_ok(), "the embedded DejaVu Sans is a valid TrueType font");
    });
}
