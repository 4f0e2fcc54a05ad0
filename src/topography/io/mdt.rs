//! NT-MDT `.mdt` (Nova, Solver, Ntegra): a 33-byte header (magic `01 B0 93 FF`, the index of
//! the last frame at byte 12), then frames, each with a 22-byte header (its size, its type,
//! version and date). The 2-D images of MDA frames (type 106) are read, one channel per frame,
//! named by the frame's title: after the frame's name, metadata and sizes, an array header
//! (cell size, dimensions, measurands) and one calibration per axis (its unit, `bias` and
//! `scale`, the index range, the data type), then the values, x fastest, rows as stored.
//! A value is `bias + scale · stored` in the measurand's unit; the pixel is the x and y
//! calibrations' `scale` in theirs. Other frames (text, spectra, point clouds, older scanned
//! frames) are skipped. A frame in a unit that is not a length (a current in nA) is a channel
//! of its own unit, never heights.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::quantity::metres_per;
use crate::quantity::quoted;

pub struct Mdt;

const MAGIC: &[u8] = b"\x01\xb0\x93\xff";
const HEADER: usize = 33;
const FRAME_HEADER: usize = 22;
const MDA: u16 = 106;

impl Format for Mdt {
    fn name(&self) -> &'static str {
        "mdt"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["mdt"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn size_field(&self) -> &'static str {
        "the x and y calibrations"
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// One axis's calibration: unit, offset, step per index, index count and storage type.
struct Calibration {
    unit: String,
    bias: f64,
    scale: f64,
    points: u64,
    data_type: i32,
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    binary::extent(bytes, 0, HEADER, "the 33-byte header")?;
    let frames = usize::from(u16::from_le_bytes([bytes[12], bytes[13]])) + 1;
    let mut at = HEADER;
    let mut channels = Vec::new();
    let mut skipped = Vec::new();
    for i in 0..frames {
        let mut c =
            Cursor::new(binary::extent(bytes, at, FRAME_HEADER, &format!("frame {i}'s header"))?, Endian::Little);
        let size = c.u32("the frame size")? as usize;
        let kind = c.u16("the frame type")?;
        if size < FRAME_HEADER {
            return Err(format!("frame {i} declares {size} bytes, less than its header"));
        }
        let frame = binary::extent(bytes, at, size, &format!("frame {i}"))?;
        if kind == MDA {
            match mda(frame).map_err(|e| format!("frame {i}: {e}"))? {
                Some(ch) => channels.push(ch),
                None => skipped.push(kind),
            }
        } else {
            skipped.push(kind);
        }
        at += size;
    }
    if channels.is_empty() {
        return Err(format!(
            "no 2-D image among the {frames} frames (frame types {skipped:?}; images are MDA frames, type 106)"
        ));
    }
    Ok(channels)
}

/// The image of an MDA frame, `None` when it is not one 2-D measurand (a spectrum, a cloud).
fn mda(frame: &[u8]) -> Result<Option<Channel>, String> {
    let mut c = Cursor::new(frame, Endian::Little);
    c.skip(FRAME_HEADER + 8 + 32 + 4, "the MDA header")?;
    let mut size = || c.u32("the MDA sizes").map(|v| v as usize);
    let (name_len, xml, info, spec, source) = (size()?, size()?, size()?, size()?, size()?);
    c.skip(12, "the MDA sizes")?;
    let name = String::from_utf8_lossy(c.take(name_len, "the frame's name")?).trim().to_string();
    for (len, what) in
        [(xml, "the XML metadata"), (info, "the info block"), (spec, "the spec block"), (source, "the source info")]
    {
        c.skip(len, what)?;
    }
    c.skip(4, "the MDA array header")?;
    let struct_len = c.u32("the MDA array header")? as usize;
    let start = c.pos();
    let array_size = c.i64("the array size")?;
    let cell = c.u32("the cell size")? as usize;
    let dims = c.u32("the number of dimensions")?;
    let measurands = c.u32("the number of measurands")?;
    c.skip(struct_len.checked_sub(c.pos() - start).ok_or("a short MDA array header")?, "the MDA array header")?;
    if dims != 2 || measurands != 1 {
        return Ok(None);
    }
    let x = calibration(&mut c)?;
    let y = calibration(&mut c)?;
    let z = calibration(&mut c)?;
    let (nx, ny) = (usize::try_from(x.points).unwrap_or(usize::MAX), usize::try_from(y.points).unwrap_or(usize::MAX));
    let n = binary::grid_points(nx, ny)?;
    let sample = match z.data_type {
        -1 => Sample::I8,
        1 => Sample::U8,
        -2 => Sample::I16,
        2 => Sample::U16,
        -4 => Sample::I32,
        4 => Sample::U32,
        -5892 => Sample::F32,
        -13320 => Sample::F64,
        t => return Err(format!("{}: values of data type {t} are not supported", quoted(&name))),
    };
    if sample.size() != cell || i64::try_from(n) != Ok(array_size) {
        return Err(format!(
            "{}: an array of {array_size} cells of {cell} bytes for a {nx} × {ny} grid of {}-byte values",
            quoted(&name),
            sample.size()
        ));
    }
    let metres = metres_per(&z.unit);
    let to_unit = metres.unwrap_or(1.0);
    let (bias, scale) = (z.bias, z.scale);
    if !(bias.is_finite() && scale.is_finite()) {
        return Err(format!("{}: the calibration {bias} + {scale} · v is not finite", quoted(&name)));
    }
    let stored = Stored { sample, endian: Endian::Little, bottom_first: false };
    let data = binary::grid(frame, c.pos(), (nx, ny), stored, "the image", |v| (bias + scale * v) * to_unit)?;
    let side = |a: &Calibration| metres_per(&a.unit).map(|m| a.points as f64 * a.scale.abs() * m);
    Ok(Some(Channel {
        name,
        data,
        physical_size: side(&x).zip(side(&y)),
        is_height: metres.is_some(),
        unit: Some(z.unit).filter(|u| !u.is_empty()),
    }))
}

/// One calibration record, the cursor left after it.
fn calibration(c: &mut Cursor) -> Result<Calibration, String> {
    let start = c.pos();
    let total = c.u32("a calibration")? as usize;
    let fixed = c.u32("a calibration")? as usize;
    let after_fixed = c.pos() + fixed;
    let (name, comment, unit) = (c.u32("a calibration")?, c.u32("a calibration")?, c.u32("a calibration")?);
    c.skip(8 + 8 + 8, "a calibration")?;
    let bias = c.f64("a calibration's bias")?;
    let scale = c.f64("a calibration's scale")?;
    let min = c.i64("a calibration's index range")?;
    let max = c.i64("a calibration's index range")?;
    let data_type = c.i32("a calibration's data type")?;
    c.skip(after_fixed.checked_sub(c.pos()).ok_or("a short calibration")?, "a calibration")?;
    c.skip(name as usize + comment as usize, "a calibration's name")?;
    let unit = binary::normalise_unit(&binary::latin1(c.take(unit as usize, "a calibration's unit")?));
    c.skip((start + total).checked_sub(c.pos()).ok_or("a calibration longer than it states")?, "a calibration")?;
    let points = u64::try_from(max.wrapping_sub(min).wrapping_add(1)).unwrap_or(0);
    Ok(Calibration { unit, bias, scale, points, data_type })
}
