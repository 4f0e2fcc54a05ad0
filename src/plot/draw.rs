//! What draws a figure and how it is written: [`Draw`], implemented by every figure, and
//! [`write_figure`], which renders one once as PNG and once as SVG and writes both atomically.
//!
//! Must not import the other files of plot but `style`, nor report, study, friction, contact
//! or shs: it draws whatever implements [`Draw`].

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style;
use crate::error::{Error, Result};

/// What drawing on a plotters area returns, for the backend `DB`: `T`, or the backend's error.
pub type DrawResult<DB, T = ()> = Result<T, DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Anything that draws itself onto an area of any backend (bitmap, SVG, a movie frame).
pub trait Draw {
    /// Canvas \[px] this drawing is laid out for.
    fn size(&self) -> (u32, u32) {
        style::SIZE
    }

    /// Draw onto `area` (already filled with the background).
    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
