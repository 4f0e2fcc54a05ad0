//! Sensofar `.plu` (and `.apx`), confocal, interferometric and focus-variation profilometers.
//!
//! A packed little-endian header of 500 bytes: a date (128 bytes), a time (`u32`), a comment
//! (256 bytes); the calibration (rows, columns, …, the pixel sizes along x and y in µm, `f32`
//! at bytes 404 and 408); the measurement type (`u32` at 428; 3 is a topography, the only one
//! read); the scan settings; then `num_layers` (byte 489) and `num_images` (byte 492). Each
//! layer is `ny`, `nx` (`u32`), `ny` rows of `nx` `f32` heights in µm, their minimum and
//! maximum (`f32`), then `num_images` RGB images of `nx` × `ny` pixels. The value 1000001 marks
//! a point not measured. The format has no magic number: it is known by its extension.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};

pub struct Plu;

const HEADER: usize = 500;
const TOPOGRAPHY: u32 = 3;
const NOT_MEASURED: f64 = 1_000_001.0;

impl Format for Plu {
    fn name(&self) -> &'static str {
        "plu"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["plu", "apx"]
    }

    fn sniff(&self, _head: &[u8]) -> bool {
        false
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    binary::extent(bytes, 0, HEADER, "the 500-byte Sensofar header")?;
    let mut c = Cursor::new(bytes, Endian::Little);
    c.skip(404, "the date, comment and grid")?;
    let dx = f64::from(c.f32("the x pixel size")?);
    let dy = f64::from(c.f32("the y pixel size")?);
    c.skip(428 - 412, "the offsets")?;
    let kind = c.u32("the measurement type")?;
    if kind != TOPOGRAPHY {
        return Err(format!("a measurement of type {kind}: only topographies (type 3) are read"));
    }
    let layers = usize::from(bytes[489]);
    let images = usize::from(bytes[492]);
    let physical = |n: usize, d: f64| (d.is_finite() && d > 0.0).then_some(n as f64 * d * 1e-6);
    let stored = Stored { sample: Sample::F32, endian: Endian::Little, bottom_first: false };

    let mut offset = HEADER;
    let mut channels = Vec::new();
    for k in 0..layers {
        let what = format!("layer {k}");
        let mut l = Cursor::new(binary::extent(bytes, offset, 8, &what)?, Endian::Little);
        let ny = l.u32("the number of rows")? as usize;
        let nx = l.u32("the number of columns")? as usize;
        let n = binary::grid_points(nx, ny)?;
        let data = binary::grid(bytes, offset + 8, (nx, ny), stored, &what, |v| {
            if v == NOT_MEASURED {
                f64::NAN
            } else {
                v * 1e-6
            }
        })?;
        // Heights, their minimum and maximum, then the RGB images of the layer.
        let len = n.checked_mul(4 + 3 * images).and_then(|b| b.checked_add(8 + 8));
        offset = len.and_then(|b| offset.checked_add(b)).ok_or("the declared layer sizes overflow")?;
        channels.push(Channel {
            name: format!("layer{k}"),
            data,
            physical_size: physical(nx, dx).zip(physical(ny, dy)),
            unit: Some("µm".into()),
            is_height: true,
        });
    }
    Ok(channels)
}
