//! Park Systems `.tiff` (XEI): a TIFF whose first directory carries the measurement in private
//! tags: 50432 the magic 0x0E031301, 50433 the version (0x1000001 or 0x1000002), 50434 the
//! data (bytes: `ny` rows of `nx` values, bottom line first) and 50435 a little-endian header
//! (image type, the source's name in UTF-16, the grid, the scan size in µm, the data's gain,
//! scale, offset and unit, and from version 2 the data type: 0 i16, 1 i32, 2 f32). A value is
//! `(stored · scale + offset) · gain` in the data unit (µm when it states none). The TIFF's
//! own image is a preview and is not read. Line profiles (image type 1) are refused.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use super::tiff::{Entry, Tiff};
use crate::quantity::metres_per;

pub struct Ps;

const MAGIC: u32 = 0x0E03_1301;

impl Format for Ps {
    fn name(&self) -> &'static str {
        "ps"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["tiff", "tif"]
    }

    /// A TIFF whose first directory, within the head, holds Park Systems' magic tag: other
    /// TIFF-based formats are told apart by their own tags.
    fn sniff(&self, head: &[u8]) -> bool {
        Tiff::parse(head, true).is_ok_and(|t| t.directories[0].find(50432).is_some())
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let t = Tiff::parse(bytes, false)?;
    if t.directories.len() > 1 {
        return Err("a TIFF of several images, not a Park Systems file".into());
    }
    let find = |tag: u16| t.directories[0].find(tag);
    let word = |e: &Entry| t.number(e).map(|v| v as u32);
    match find(50432).map(word).transpose()? {
        Some(MAGIC) => {}
        _ => return Err("a TIFF image without Park Systems' measurement tags (50432), not a topography".into()),
    }
    let version = find(50433).map(word).transpose()?.ok_or("the Park Systems TIFF has no version tag (50433)")?;
    if version != 0x0100_0001 && version != 0x0100_0002 {
        return Err(format!("Park Systems TIFF version {version:#x} is not supported (1 or 2)"));
    }
    let header = t.raw(find(50435).ok_or("the Park Systems TIFF has no header tag (50435)")?)?;
    let mut h = Cursor::new(header, Endian::Little);
    let image_type = h.u32("the header")?;
    if image_type == 1 {
        return Err("a Park Systems line profile, not a map (only 2-D images are read)".into());
    }
    let name = utf16(h.take(64, "the header")?);
    h.skip(16 + 8 + 4 + 4, "the header")?;
    let (nx, ny) = (h.u32("the header")? as usize, h.u32("the header")? as usize);
    h.skip(8 + 4 + 8 + 4 + 4 + 4, "the header")?;
    let (lx, ly) = (h.f64("the header")? * 1e-6, h.f64("the header")? * 1e-6);
    if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) {
        return Err(format!("the scan size {lx} x {ly} m is not positive"));
    }
    h.skip(8 * 4 + 16 + 8 + 8, "the header")?;
    let (gain, scale, offset) = (h.f64("the header")?, h.f64("the header")?, h.f64("the header")?);
    let scale = if scale == 0.0 { 1.0 } else { scale };
    let unit = match utf16(h.take(16, "the header")?) {
        u if u.is_empty() => "µm".to_string(),
        u => binary::normalise_unit(&u),
    };
    let to_metres =
        metres_per(&unit).ok_or_else(|| format!("the data unit '{}' is not a length", binary::printable(&unit)))?;
    h.skip(6 * 4, "the header")?;
    let sample = if version == 0x0100_0001 {
        Sample::I16
    } else {
        h.skip(8 + 8 + 3 * 16, "the header")?;
        match h.u32("the header")? {
            0 => Sample::I16,
            1 => Sample::I32,
            2 => Sample::F32,
            t => return Err(format!("data type {t} is not supported (0, 1 or 2)")),
        }
    };
    if ![scale, gain, offset].iter().all(|v| v.is_finite()) || gain == 0.0 {
        return Err(format!("the data gain {gain}, scale {scale} and offset {offset} are not finite and non-zero"));
    }
    let data = find(50434).ok_or("the Park Systems TIFF has no data tag (50434)")?;
    let raw = t.raw(data)?;
    if binary::grid_points(nx, ny)?.checked_mul(sample.size()) != Some(raw.len()) {
        return Err(format!("the header declares {nx} x {ny} points but the data tag holds {} bytes", raw.len()));
    }
    let stored = Stored { sample, endian: Endian::Little, bottom_first: true };
    let data = binary::grid(raw, 0, (nx, ny), stored, "the data", |v| (v * scale + offset) * gain * to_metres)?;
    Ok(vec![Channel { name, data, physical_size: Some((lx, ly)), unit: Some(unit), is_height: true }])
}

/// A NUL-padded little-endian UTF-16 field.
fn utf16(b: &[u8]) -> String {
    let units = b.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).take_while(|&u| u != 0);
    char::decode_utf16(units).map(|c| c.unwrap_or('\u{fffd}')).collect::<String>().trim().to_string()
}
