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
mod convergence;
mod figure;
mod histograms;
mod inset;
mod legend;
mod maps;
mod movie;
mod report;
mod shared;
pub mod study;
pub mod style;
mod ticks;
mod trace;
mod typeset;

use std::path::{Path, PathBuf};

use plotters::prelude::*;

pub use convergence::{sharing_convergence, ConvergencePoint};
pub use figure::{Axis, Dash, Draw, DrawResult, Figure, Grid, Marker, Panel, Series, Shape};
pub use plotters::chart::SeriesLabelPosition as LegendPosition;
pub use plotters::style::RGBColor;
pub use shared::FigureInput;
pub use ticks::tick_label;
pub use trace::trace_figure;

use crate::error::{Error, Result};

/// The most pixels of a figure: 2^26, a 200 MB image.
const MAX_FIGURE_PIXELS: u64 = 1 << 26;

/// Draw `figure` and write it as a PNG at `png` and as an SVG beside it (same name, extension
/// `.svg`), each atomically. Returns the SVG's path.
pub fn write_figure(png: &Path, figure: &impl Draw) -> Result<PathBuf> {
    if !png.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return Err(Error::file(png, "a figure is written as .png, with its .svg beside it: name the .png"));
    }
    style::register_fonts();
    let (width, height) = figure.size();
    let failed = |e: &dyn std::fmt::Display| Error::file(png, format!("cannot draw the figure: {e}"));
    // plotters indexes its buffer with u32 arithmetic: a larger figure would wrap and panic.
    if width == 0 || height == 0 || u64::from(width) * u64::from(height) > MAX_FIGURE_PIXELS {
        return Err(failed(&format!("{width} × {height} pixels is over the {MAX_FIGURE_PIXELS} a figure may have")));
    }

    let mut rgb = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| failed(&e))?;
        figure.draw(&root).map_err(|e| failed(&e))?;
        root.present().map_err(|e| failed(&e))?;
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| failed(&e))?;
        figure.draw(&root).map_err(|e| failed(&e))?;
        root.present().map_err(|e| failed(&e))?;
    }

    crate::output::write_atomic(png, |w| {
        let mut encoder = png::Encoder::new(w, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer.write_image_data(&rgb).map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    })?;
    let svg_path = png.with_extension("svg");
    crate::output::write_atomic(&svg_path, |w| w.write_all(svg.as_bytes()))?;
    Ok(svg_path)
}

/// The SI prefix that shows values up to `magnitude` (in `unit`) with one to three digits
/// before the decimal point: returns the factor to multiply values by and the prefixed unit,
/// e.g. `(1e3, "mN")` for 0.024 N.
pub fn prefixed(magnitude: f64, unit: &str) -> (f64, String) {
    const PREFIXES: [(f64, &str); 8] =
        [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p")];
    let m = magnitude.abs();
    if !m.is_normal() {
        return (1.0, unit.to_string());
    }
    let &(p, name) = PREFIXES.iter().find(|(p, _)| m >= *p * (1.0 - 1e-12)).unwrap_or(&PREFIXES[PREFIXES.len() - 1]);
    (1.0 / p, format!("{name}{unit}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_are_short() {
        let cases = [
            (0.0, "0"),
            (0.30000000000000004, "0.3"),
            (250.0, "250"),
            (1.5, "1.5"),
            (-2.0, "-2"),
            (12345.0, "12345"),
            (1e-4, "1e-4"),
            (2.5e6, "2.5e6"),
            (0.0125, "0.0125"),
        ];
        for (v, s) in cases {
            assert_eq!(tick_label(&v), s, "{v}");
        }
    }

    #[test]
    fn figures_too_large_to_index_are_refused() {
        // 10 000 snapshot rows made a 1370 × 4 000 270 figure: plotters' u32 index wrapped and
        // panicked (after a 16 GB buffer).
        struct Huge((u32, u32));
        impl Draw for Huge {
            fn size(&self) -> (u32, u32) {
                self.0
            }
            fn draw<DB: DrawingBackend>(&self, _: &DrawingArea<DB, plotters::coord::Shift>) -> DrawResult<DB> {
                Ok(())
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("huge.png");
        for size in [(1370, 4_000_270), (8192, 8193), (0, 10), (u32::MAX, u32::MAX)] {
            let e = write_figure(&png, &Huge(size)).unwrap_err().to_string();
            assert!(e.contains("huge.png: cannot draw the figure") && e.contains("pixels is over"), "{e}");
        }
        assert!(!png.exists());
        write_figure(&png, &Huge((64, 64))).unwrap();
    }

    #[test]
    fn prefixes() {
        assert_eq!(prefixed(0.024, "N"), (1e3, "mN".to_string()));
        assert_eq!(prefixed(2.4e-5, "N"), (1e6, "µN".to_string()));
        assert_eq!(prefixed(1.0, "m"), (1.0, "m".to_string()));
        assert_eq!(prefixed(3.2e9, "Pa"), (1e-9, "GPa".to_string()));
        assert_eq!(prefixed(0.0, "N"), (1.0, "N".to_string()));
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
