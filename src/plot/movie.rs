//! The paper's supplemental movies as animated GIFs: the local stress-ratio map as the imposed
//! displacement grows from 0 past δ_peak, with the friction–displacement curve below it.
//!
//! Frames are drawn by plotters into RGB buffers (in parallel), mapped to one fixed palette
//! (the map's colour scale, the class colours and greys for the text) and written with the
//! `gif` crate; each frame after the first stores only the rectangle that changed, with
//! unchanged pixels inside it transparent, which keeps a movie small.
//!
//! Must not import report: plot draws what study, friction, contact and shs hand it.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use rayon::prelude::*;

use super::draw::{Draw, DrawResult};
use super::figure::{Axis, Panel};
use super::maps::{
    draw_layer, map_chart, plot_size, ratio_key, ratio_layer, ratio_value_colour, text, Layer, MapAxes, View, LEVELS,
};
use super::series::{Marker, Series};
use super::style;
use super::ticks::tick_label;
use crate::error::{Error, Result};
use crate::friction::{Curve, ElementLoads, Loading, Onset};
use crate::study::MapSnapshot;

/// Frames per δ_peak: frame k shows δ/δ_peak = k / STEPS, so one frame is exactly the peak.
const STEPS: usize = 40;
/// The movie runs to δ/δ_peak = END_STEPS / STEPS, past the peak into total sliding.
const END_STEPS: usize = 48;
/// Frame delays [1/100 s]: while loading, at the peak, on the last frame (before it loops).
const DELAY: u16 = 8;
const DELAY_PEAK: u16 = 120;
const DELAY_END: u16 = 200;
/// Canvas [px].
const SIZE: (u32, u32) = (760, 1080);
/// Height [px] of the map's area, below the heading.
const MAP_HEIGHT: u32 = 580;

/// Number of frames of a movie.
pub const FRAMES: usize = END_STEPS + 1;

/// One frame: the stress-ratio map at δ = fraction · δ_peak, and the curve with where it is.
struct Frame<'a> {
    snap: &'a MapSnapshot,
    onset: &'a Onset,
    law_name: &'a str,
    view: View,
    /// Whether the view shows the most loaded patch rather than the whole contact.
    zoomed: bool,
    /// The equal-load-sharing curve as (δ/δ_peak, F/N), up to the movie's end.
    curve: &'a [(f64, f64)],
    fraction: f64,
    index: usize,
}

impl Draw for Frame<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let (w, _) = area.dim_in_pixel();
        let law = &self.onset.law;
        let (head, rest) = area.split_vertically(110);
        let title = format!(
            "N = {}, {} (μ^S = {}, μ^D = {})",
            super::maps::load_label(self.snap.load_n),
            self.law_name,
            tick_label(&law.mu_s),
            tick_label(&law.mu_d),
        );
        text(&head, &title, (w as i32 / 2, 22), 22.0, (HPos::Center, VPos::Center))?;
        let shown = if self.zoomed { "the most loaded contact patch and its neighbours" } else { "the whole contact" };
        let subtitle = format!("{} elements; the map shows {shown}", self.onset.elements);
        text(&head, &subtitle, (w as i32 / 2, 54), 19.0, (HPos::Center, VPos::Center))?;
        let values = ratio_layer(self.snap, self.onset, self.fraction);
        let slipped = values.iter().filter(|v| **v < 0.0).count();
        let force = force_at(self.curve, self.fraction);
        let state = format!(
            "δ/δ_{{peak}} = {:.3}   F/N = {:.4}   slipped {slipped} of {}   [frame {}/{}]",
            self.fraction,
            force,
            self.onset.elements,
            self.index + 1,
            FRAMES
        );
        text(&head, &state, (w as i32 / 2, 88), 19.0, (HPos::Center, VPos::Center))?;

        let (map, rest) = rest.split_vertically(MAP_HEIGHT);
        let MapAxes { chart, view, plot } = map_chart(&map, self.view, true)?;
        let mu_s = law.mu_s;
        draw_layer(&chart, view, plot, &Layer::on(self.snap, &values), |v| ratio_value_colour(v, mu_s))?;
        let (key, curve) = rest.split_vertically(110);
        ratio_key(&key.margin(4, 0, 10, 10), law)?;

        let top = self.curve.iter().fold(law.mu_s, |m, p| m.max(p.1)) * 1.08;
        let mut panel = Panel::new(
            Axis::dimensionless("δ/δ_{peak}").range(0.0, END_STEPS as f64 / STEPS as f64),
            Axis::dimensionless("F/N").range(0.0, top),
        );
        panel.push(Series::line(self.curve.to_vec(), style::PALETTE[0]));
        panel.push(Series::line(vec![(self.fraction, 0.0), (self.fraction, top)], style::GREY).width(1));
        panel.push(Series::scatter(vec![(self.fraction, force)], Marker::Circle, style::PALETTE[1]));
        panel.draw(&curve)
    }
}

/// F/N on `curve` (vertices (δ/δ_peak, F/N) in loading order) at δ/δ_peak = `x`: on the first
/// sloped or flat segment that spans x, so that at the peak the peak is read and past it the
/// sliding level.
fn force_at(curve: &[(f64, f64)], x: f64) -> f64 {
    curve.windows(2).find(|w| w[0].0 <= x && x <= w[1].0 && w[1].0 > w[0].0).map_or_else(
        || curve.last().map_or(0.0, |p| p.1),
        |w| w[0].1 + (w[1].1 - w[0].1) * (x - w[0].0) / (w[1].0 - w[0].0),
    )
}

/// The friction curve of `loads` under `loading` as (δ/δ_peak, F/N), cut at δ/δ_peak = `end`
/// and held at its last level up to there.
pub(super) fn scaled_curve(loads: &ElementLoads, onset: &Onset, loading: Loading, end: f64) -> Vec<(f64, f64)> {
    let curve = Curve::new(loads, &onset.law, loading, 4000);
    let s_peak = curve.peak_point().element_shear;
    let n = curve.normal_force;
    let mut points: Vec<(f64, f64)> = Vec::with_capacity(curve.points.len());
    for p in &curve.points {
        let (x, y) = (p.element_shear / s_peak, p.force / n);
        if x > end {
            // Cut the segment where it leaves the range.
            if let Some(&(x0, y0)) = points.last() {
                if x0 < end {
                    points.push((end, y0 + (y - y0) * (end - x0) / (x - x0)));
                }
            }
            break;
        }
        points.push((x, y));
    }
    // After the last vertex (total sliding) the force stays at its level.
    if let Some(&(x, y)) = points.last() {
        if x < end {
            points.push((end, y));
        }
    }
    points
}

/// The fixed palette: white, greys for text, the stress-ratio scale, the class colours and the
/// curve's colours. The last entry is transparent (pixels unchanged since the last frame).
fn palette() -> Vec<[u8; 3]> {
    let mut colours: Vec<[u8; 3]> = Vec::with_capacity(256);
    let mut add = |c: RGBColor| {
        if !colours.contains(&[c.0, c.1, c.2]) {
            colours.push([c.0, c.1, c.2]);
        }
    };
    for c in [WHITE, BLACK, style::PRE_SLIDING, style::CRITICAL, style::SUBCRITICAL, style::GREY] {
        add(c);
    }
    for c in &style::PALETTE[..2] {
        add(*c);
    }
    for g in (0..=255u32).step_by(12) {
        add(RGBColor(g as u8, g as u8, g as u8));
    }
    add(RGBColor(220, 220, 220));
    add(RGBColor(242, 242, 242));
    for k in 0..LEVELS {
        add(super::maps::ratio_colour(k as f64 / (LEVELS - 1) as f64));
    }
    assert!(colours.len() < 256, "the movie palette leaves room for the transparent entry");
    colours.push([255, 0, 255]);
    colours
}

/// Write the movie of `snap` (its onset `onset`) as a GIF at `path`, atomically.
pub(super) fn write_movie(path: &Path, snap: &MapSnapshot, onset: &Onset, law_name: &str) -> Result<()> {
    super::style::register_fonts();
    let loads = ElementLoads::from_pressure(&snap.pressure, snap.pixel_area())?;
    let end = END_STEPS as f64 / STEPS as f64;
    let curve = scaled_curve(&loads, onset, Loading::EqualLoadSharing, end);
    let (view, zoomed) = View::detail(snap, plot_size((SIZE.0, MAP_HEIGHT)));
    let colours = palette();
    let transparent = (colours.len() - 1) as u8;
    let quantizer = Quantizer::new(&colours[..colours.len() - 1]);
    let (w, h) = SIZE;
    let failed = |e: &dyn std::fmt::Display| Error::file(path, format!("cannot draw the movie: {e}"));

    let frames: Vec<Vec<u8>> = (0..FRAMES)
        .into_par_iter()
        .map(|index| {
            let fraction = index as f64 / STEPS as f64;
            let frame = Frame { snap, onset, law_name, view, zoomed, curve: &curve, fraction, index };
            let mut rgb = vec![0u8; w as usize * h as usize * 3];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
                root.fill(&WHITE).map_err(|e| failed(&e))?;
                frame.draw(&root).map_err(|e| failed(&e))?;
                root.present().map_err(|e| failed(&e))?;
            }
            Ok(quantizer.indices(&rgb))
        })
        .collect::<Result<_>>()?;

    let flat: Vec<u8> = colours.iter().flatten().copied().collect();
    crate::output::write_atomic(path, |out| {
        let gif_error = std::io::Error::other;
        let mut encoder = gif::Encoder::new(out, w as u16, h as u16, &flat).map_err(gif_error)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_error)?;
        for (k, pixels) in frames.iter().enumerate() {
            let delay = match k {
                _ if k + 1 == FRAMES => DELAY_END,
                STEPS => DELAY_PEAK,
                _ => DELAY,
            };
            let mut frame = match k.checked_sub(1).map(|p| &frames[p]) {
                None => gif::Frame { width: w as u16, height: h as u16, buffer: pixels.into(), ..Default::default() },
                Some(previous) => changed(previous, pixels, (w as usize, h as usize), transparent),
            };
            frame.delay = delay;
            frame.dispose = gif::DisposalMethod::Keep;
            encoder.write_frame(&frame).map_err(gif_error)?;
        }
        Ok(())
    })
}

/// Maps RGB pixels to palette indices: exactly where a pixel has a palette colour (the map,
/// lines, fills), else to the entry nearest the pixel's colour at 5 bits a channel (the blended
/// edges of text).
struct Quantizer {
    /// Palette colours packed as 0xRRGGBB, sorted, with their index.
    exact: Vec<(u32, u8)>,
    /// Nearest index for each 5-bit (r, g, b).
    nearest: Vec<u8>,
}

impl Quantizer {
    fn new(colours: &[[u8; 3]]) -> Self {
        let pack = |c: [u8; 3]| u32::from(c[0]) << 16 | u32::from(c[1]) << 8 | u32::from(c[2]);
        let mut exact: Vec<(u32, u8)> = colours.iter().enumerate().map(|(i, c)| (pack(*c), i as u8)).collect();
        exact.sort_unstable();
        let nearest = (0..1usize << 15)
            .map(|k| {
                let c = [(k >> 10) as i32 * 8 + 4, ((k >> 5) & 31) as i32 * 8 + 4, (k & 31) as i32 * 8 + 4];
                let distance = |q: &[u8; 3]| (0..3).map(|i| (c[i] - i32::from(q[i])).pow(2)).sum::<i32>();
                (0..colours.len()).min_by_key(|&i| distance(&colours[i])).expect("a non-empty palette") as u8
            })
            .collect();
        Quantizer { exact, nearest }
    }

    fn indices(&self, rgb: &[u8]) -> Vec<u8> {
        let mut last = (u32::MAX, 0u8);
        rgb.chunks_exact(3)
            .map(|p| {
                let packed = u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]);
                if packed != last.0 {
                    let index = match self.exact.binary_search_by_key(&packed, |e| e.0) {
                        Ok(k) => self.exact[k].1,
                        Err(_) => {
                            self.nearest
                                [usize::from(p[0] >> 3) << 10 | usize::from(p[1] >> 3) << 5 | usize::from(p[2] >> 3)]
                        }
                    };
                    last = (packed, index);
                }
                last.1
            })
            .collect()
    }
}

/// The frame that turns `previous` into `current` (both `size` (w, h) px): the bounding
/// rectangle of the changed pixels, unchanged ones inside it `transparent`.
fn changed(previous: &[u8], current: &[u8], (w, h): (usize, usize), transparent: u8) -> gif::Frame<'static> {
    let (mut x0, mut x1, mut y0, mut y1) = (w, 0, h, 0);
    for (i, (a, b)) in previous.iter().zip(current).enumerate() {
        if a != b {
            let (x, y) = (i % w, i / w);
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x + 1), y0.min(y), y1.max(y + 1));
        }
    }
    if x0 >= x1 {
        // Nothing changed: one transparent pixel keeps the frame's delay.
        (x0, x1, y0, y1) = (0, 1, 0, 1);
    }
    let mut buffer = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        for x in x0..x1 {
            let i = y * w + x;
            buffer.push(if previous[i] == current[i] { transparent } else { current[i] });
        }
    }
    gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0) as u16,
        height: (y1 - y0) as u16,
        buffer: buffer.into(),
        transparent: Some(transparent),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_is_read_at_the_peak_and_after_the_drop() {
        let curve = [(0.0, 0.0), (1.0, 0.6), (1.0, 0.4), (1.2, 0.4)];
        assert_eq!(force_at(&curve, 0.5), 0.3);
        assert_eq!(force_at(&curve, 1.0), 0.6);
        assert_eq!(force_at(&curve, 1.1), 0.4);
    }

    #[test]
    fn frames_store_what_changed() {
        let (a, b) = (vec![0u8; 12], {
            let mut b = vec![0u8; 12];
            b[5] = 3;
            b[10] = 4;
            b
        });
        // 4 × 3 px: (1, 1) and (2, 2) changed.
        let f = changed(&a, &b, (4, 3), 9);
        assert_eq!((f.left, f.top, f.width, f.height), (1, 1, 2, 2));
        assert_eq!(&f.buffer[..], &[3, 9, 9, 4]);
        let same = changed(&a, &a, (4, 3), 9);
        assert_eq!((same.width, same.height, same.buffer[0]), (1, 1, 9));
    }
}
