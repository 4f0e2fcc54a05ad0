//! TrueMap `.tmd` (TrueGage TrueMap surface metrology software).
//!
//! A 32-byte magic `Binary TrueMap Data File v2.0\r\n\0`, a NUL-terminated comment, then
//! little-endian `u32` nx, ny and `f32` x and y lengths and offsets, all lengths in
//! millimetres; then ny rows of nx `f32` heights in millimetres.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};

pub struct Tmd;

const MAGIC: &[u8] = b"Binary TrueMap Data File v2.0";
/// Bytes of the magic field, padding included.
const MAGIC_FIELD: usize = 32;

impl Format for Tmd {
    fn name(&self) -> &'static str {
        "tmd"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["tmd"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    if !bytes.starts_with(MAGIC) {
        return Err("not a TrueMap file (no 'Binary TrueMap Data File v2.0' magic)".into());
    }
    let mut c = Cursor::new(bytes, Endian::Little);
    c.skip(MAGIC_FIELD, "the magic")?;
    c.cstr("the comment")?;
    let (nx, ny) = (c.u32("the grid")? as usize, c.u32("the grid")? as usize);
    let f32 = |c: &mut Cursor, what: &str| c.u32(what).map(|b| f64::from(f32::from_bits(b)));
    let (lx, ly) = (f32(&mut c, "the lengths")?, f32(&mut c, "the lengths")?);
    if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) {
        return Err(format!("the lengths {lx} x {ly} mm are not positive"));
    }
    c.skip(8, "the offsets")?;
    let stored = Stored { sample: Sample::F32, endian: Endian::Little, bottom_first: false };
    let data = binary::grid(bytes, c.pos(), (nx, ny), stored, "the heights", |v| v * 1e-3)?;
    Ok(vec![Channel {
        name: "Default".into(),
        data,
        physical_size: Some((lx * 1e-3, ly * 1e-3)),
        unit: Some("mm".into()),
        is_height: true,
    }])
}
