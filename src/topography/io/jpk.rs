//! JPK Instruments (Bruker) `.jpk` scans and `.jpk-qi-image` QI images: a TIFF whose first
//! directory describes the grid in private tags (32834/32835 its lengths along u and v in
//! metres, 32838/32839 its points) and whose further directories are the channels, each a
//! 32-bit integer image with its name (32848; 32850 the name shown, 32849 whether a retrace)
//! and its scaling slots: 32896 their number, 32897 the default one's name, then slot `i` at
//! 32912 + 48·i (its name), +18 its unit, +19 the scaling type, +20 the multiplier and +21 the
//! offset, which map the stored integer to the slot's value directly. A channel is read in
//! its default slot (a height's "calibrated" or "nominal" one); the integers' extremes
//! (−2³¹ and 2³¹ − 1) mark pixels the instrument could not measure. Rows are as stored, as
//! SurfaceTopography reads them; unlike SurfaceTopography, the slot's offset is applied.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

use super::binary::{self, Sample, Stored};
use super::reading::{Channel, Format};
use super::tiff::{Directory, Tiff};
use crate::quantity::metres_per;
use crate::quantity::quoted;

pub struct Jpk;

/// The tag of the grid's length along u [m]; its presence in the first directory tells a JPK file.
const GRID_U_LENGTH: u16 = 32834;

impl Format for Jpk {
    fn name(&self) -> &'static str {
        "jpk"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["jpk", "jpk-qi-image"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        Tiff::parse(head, true).is_ok_and(|t| t.directories[0].find(GRID_U_LENGTH).is_some())
    }

    fn size_field(&self) -> &'static str {
        "the grid lengths (tags 32834, 32835)"
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let t = Tiff::parse(bytes, false)?;
    let grid = &t.directories[0];
    let number = |d: &Directory, tag: u16, what: &str| {
        d.find(tag).ok_or_else(|| format!("the JPK file has no {what} (tag {tag})")).and_then(|e| t.number(e))
    };
    let text = |d: &Directory, tag: u16| d.find(tag).map(|e| t.text(e)).transpose();
    let lx = number(grid, GRID_U_LENGTH, "grid length along u")?;
    let ly = number(grid, 32835, "grid length along v")?;
    let nx = number(grid, 32838, "number of points along u")?;
    let ny = number(grid, 32839, "number of points along v")?;
    let (nx, ny) = (count(nx, "points along u")?, count(ny, "points along v")?);
    binary::grid_points(nx, ny)?;

    let mut channels = Vec::new();
    for (page, d) in t.directories.iter().enumerate().skip(1) {
        let Some(name) = text(d, 32848)? else { continue };
        let shown = text(d, 32850)?.filter(|s| !s.is_empty()).unwrap_or(name);
        let retrace = number(d, 32849, "retrace flag").unwrap_or(0.0) != 0.0;
        let name = if retrace { format!("{shown} (retrace)") } else { shown };
        let slot = text(d, 32897)?.ok_or_else(|| format!("channel {} names no default slot", quoted(&name)))?;
        let slots = count(number(d, 32896, "number of slots")?, "slots")?;
        let index = (0..slots.min(64))
            .find(|&i| text(d, slot_tag(i, 0)).ok().flatten().as_deref() == Some(slot.as_str()))
            .ok_or_else(|| format!("channel {}: no slot {}", quoted(&name), quoted(&slot)))?;
        let unit = text(d, slot_tag(index, 18))?.unwrap_or_default();
        let scaling = text(d, slot_tag(index, 19))?.unwrap_or_default();
        if scaling != "LinearScaling" {
            return Err(format!(
                "channel {}, slot {}: scaling {} is not supported (LinearScaling)",
                quoted(&name),
                quoted(&slot),
                quoted(&scaling)
            ));
        }
        let multiplier = number(d, slot_tag(index, 20), "scaling multiplier")?;
        let offset = number(d, slot_tag(index, 21), "scaling offset")?;
        let metres = metres_per(&unit);
        let to_unit = metres.unwrap_or(1.0);
        if !(multiplier.is_finite() && offset.is_finite()) {
            return Err(format!("channel {}: scaling {multiplier} · v + {offset} is not finite", quoted(&name)));
        }
        let (w, h) = (number(d, 256, "image width")?, number(d, 257, "image length")?);
        if (count(w, "columns")?, count(h, "rows")?) != (nx, ny) {
            return Err(format!("page {page}: a {w} × {h} image on a {nx} × {ny} grid"));
        }
        let bits = number(d, 258, "bits per sample")?;
        let format = d.find(339).map(|e| t.number(e)).transpose()?.unwrap_or(1.0);
        if (bits, format) != (32.0, 2.0) {
            return Err(format!("page {page}: samples of {bits} bits, format {format} (signed 32-bit integers only)"));
        }
        let raw = t.strips(d)?;
        let stored = Stored { sample: Sample::I32, endian: t.endian, bottom_first: false };
        let data: Array2<f64> = binary::grid(&raw, 0, (nx, ny), stored, "the image", |v| {
            if v == f64::from(i32::MIN) || v == f64::from(i32::MAX) {
                f64::NAN
            } else {
                (v * multiplier + offset) * to_unit
            }
        })?;
        channels.push(Channel {
            name,
            data,
            physical_size: Some((lx, ly)),
            is_height: metres.is_some(),
            unit: Some(unit).filter(|u| !u.is_empty()),
        });
    }
    if channels.is_empty() {
        return Err("a JPK file without a channel page".into());
    }
    Ok(channels)
}

/// The tag of field `field` of scaling slot `i`.
fn slot_tag(i: usize, field: usize) -> u16 {
    (32912 + 48 * i + field) as u16
}

/// A count a tag states as a number: a positive integer.
fn count(v: f64, what: &str) -> Result<usize, String> {
    if v.fract() == 0.0 && (1.0..1e9).contains(&v) {
        Ok(v as usize)
    } else {
        Err(format!("the JPK file states {v} {what}"))
    }
}
