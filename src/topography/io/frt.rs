//! FRT MicroProf `.frt` (optical profilometers of Fries Research & Technology).
//!
//! The magic `FRTM_GLIDERV` and a four-character version (`1.00`: 32-bit block sizes, `1.01`:
//! 64-bit), a little-endian block count, then tagged blocks (tag `u16`, size). Block 0x0066
//! gives the grid (`u32` nx, ny and bits per point, 16 or 32), 0x0067 the physical size in
//! metres (`f64` x, y), 0x006c the metres per stored unit (`f64` after a `u32`), and 0x000b
//! the heights: unsigned 16-bit or signed 32-bit integers, row by row, bottom line first. The
//! stored value 1 marks a point without data. Files whose heights are only in the multi-image
//! block 0x007d (no block 0x000b) are refused: no such sample has been seen.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;

pub struct Frt;

const MAGIC: &[u8] = b"FRTM_GLIDERV";
/// The stored value of a point without data.
const UNDEFINED: f64 = 1.0;

impl Format for Frt {
    fn name(&self) -> &'static str {
        "frt"
    }

    fn size_field(&self) -> &'static str {
        "the physical size block (0x0067)"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["frt"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// The blocks that shape the heights, as the file holds them.
#[derive(Default)]
struct Blocks<'a> {
    grid: Option<(usize, usize, u32)>,
    size: Option<(f64, f64)>,
    scale: Option<f64>,
    heights: Option<(usize, &'a [u8])>,
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let mut c = Cursor::new(bytes, Endian::Little);
    if c.take(MAGIC.len(), "the magic")? != MAGIC {
        return Err("not an FRT file (no FRTM_GLIDERV magic)".into());
    }
    let wide = match c.take(4, "the version")? {
        b"1.00" => false,
        b"1.01" => true,
        v => return Err(format!("FRT version '{}' is not supported (1.00 or 1.01)", binary::latin1(v))),
    };
    let count = c.i16("the block count")? as u16;
    let mut blocks = Blocks::default();
    for _ in 0..count {
        // As SurfaceTopography and Gwyddion, a count past the last block ends the list.
        if bytes.len() - c.pos() < if wide { 10 } else { 6 } {
            break;
        }
        let tag = c.i16("a block tag")? as u16;
        let len = if wide {
            binary::non_negative(c.i64("a block size")?, "block size")?
        } else {
            c.u32("a block size")? as usize
        };
        let at = c.pos();
        let body = c.take(len, &format!("block 0x{tag:04x}"))?;
        let mut b = Cursor::new(body, Endian::Little);
        let what = format!("block 0x{tag:04x}");
        match tag {
            0x0066 => {
                let (nx, ny) = (b.u32(&what)? as usize, b.u32(&what)? as usize);
                blocks.grid = Some((nx, ny, b.u32(&what)?));
            }
            0x0067 => blocks.size = Some((b.f64(&what)?, b.f64(&what)?)),
            0x006c => {
                b.skip(4, &what)?;
                blocks.scale = Some(b.f64(&what)?);
            }
            0x000b => blocks.heights = Some((at, body)),
            _ => {}
        }
    }
    let (nx, ny, bits) = blocks.grid.ok_or("the FRT file has no grid block (0x0066)")?;
    let (offset, body) = blocks.heights.ok_or("the FRT file has no topography block (0x000b)")?;
    let sample = match bits {
        16 => Sample::U16,
        32 => Sample::I32,
        _ => return Err(format!("{bits} bits per point are not supported (16 or 32)")),
    };
    let points = binary::grid_points(nx, ny)?;
    if points.checked_mul(sample.size()) != Some(body.len()) {
        return Err(format!(
            "the grid block declares {nx} x {ny} points of {bits} bits but the topography block holds {} bytes",
            body.len()
        ));
    }
    let (lx, ly) = blocks.size.ok_or("the FRT file has no physical size block (0x0067)")?;
    if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) {
        return Err(format!("the physical size {lx} x {ly} m is not positive"));
    }
    let scale = blocks.scale.ok_or("the FRT file has no height scale block (0x006c)")?;
    plausible::height_factor(scale, sample.levels().map(|l| scale * l))
        .map_err(|e| format!("the height scale block (0x006c), {scale} m per unit: {e}"))?;
    let stored = Stored { sample, endian: Endian::Little, bottom_first: true };
    let data = binary::grid(bytes, offset, (nx, ny), stored, "the topography block", |v| {
        if v == UNDEFINED {
            f64::NAN
        } else {
            v * scale
        }
    })?;
    Ok(vec![Channel {
        name: "default".into(),
        data,
        physical_size: Some((lx, ly)),
        unit: Some("m".into()),
        is_height: true,
    }])
}
