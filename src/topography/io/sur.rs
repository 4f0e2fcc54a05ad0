//! Digital Surf `.sur` (MountainsMap's native format, written by instruments of many vendors).
//!
//! A 512-byte little-endian header (magic `DIGITAL SURF`) is followed by a comment and a private
//! zone of the sizes it states, then `nx` × `ny` signed integers of 16 or 32 bits, rows in file
//! order. A value times the height scale is a height in the header's data unit (`delta_data_unit`);
//! the point spacings are in `delta_x_unit` and `delta_y_unit`. With `special_points` set,
//! the value `zmin − 2` marks a point not measured. `inversion` 1–3 negates the heights, 2
//! mirrors the columns and 3 the rows (as Gwyddion and SurfaceTopography read it). Old files
//! write the micro sign as `æ` (code page 437). Of a file of several objects the first is read.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;
use crate::quantity::metres_per;
use crate::quantity::quoted;

pub struct Sur;

const MAGIC: &[u8] = b"DIGITAL SURF";
const HEADER: usize = 512;

impl Format for Sur {
    fn name(&self) -> &'static str {
        "sur"
    }

    fn size_field(&self) -> &'static str {
        "the x and y spacings"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["sur"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        if !bytes.starts_with(MAGIC) {
            return Err("not a Digital Surf file (no DIGITAL SURF magic)".into());
        }
        decode(bytes).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    binary::extent(bytes, 0, HEADER, "the 512-byte header")?;
    let mut c = Cursor::new(bytes, Endian::Little);
    let text = |at: usize, len: usize| unit(&binary::padded_str(&bytes[at..at + len]));
    c.skip(86, "the object description")?;
    let special_points = c.u16("special_points")?;
    c.skip(98 - 88, "the acquisition flags")?;
    let sample = match c.u16("the item size")? {
        16 => Sample::I16,
        32 => Sample::I32,
        bits => return Err(format!("items of {bits} bits are not supported (16 or 32)")),
    };
    let zmin = c.i32("zmin")?;
    c.skip(4, "zmax")?;
    let nx = binary::non_negative(i64::from(c.i32("the number of points")?), "number of points")?;
    let ny = binary::non_negative(i64::from(c.i32("the number of lines")?), "number of lines")?;
    let total = c.u32("the total number of points")?;
    let points = binary::grid_points(nx, ny)?;
    if u64::from(total) != points as u64 {
        return Err(format!("the header declares {total} points for a {nx} × {ny} grid"));
    }
    let dx = f64::from(c.f32("the x spacing")?);
    let dy = f64::from(c.f32("the y spacing")?);
    let z_scale = f64::from(c.f32("the height scale")?);
    for (what, v) in [("x spacing", dx), ("y spacing", dy)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(format!("the {what} {v} is not positive"));
        }
    }
    let (x_unit, y_unit, z_unit) = (text(180, 16), text(196, 16), text(212, 16));
    let inversion = u16::from_le_bytes([bytes[290], bytes[291]]);
    let comment = usize::from(u16::from_le_bytes([bytes[334], bytes[335]]));
    let private = usize::from(u16::from_le_bytes([bytes[336], bytes[337]]));

    let sign = if (1..=3).contains(&inversion) { -1.0 } else { 1.0 };
    let z_metres = metres_per(&z_unit);
    let to_unit = sign * z_scale * z_metres.unwrap_or(1.0);
    plausible::height_factor(to_unit, z_metres.and(sample.levels()).map(|l| to_unit * l))
        .map_err(|e| format!("the height scale {z_scale} {}: {e}", quoted(&z_unit)))?;
    let missing = (special_points == 1).then_some(i64::from(zmin) - 2);
    let stored = Stored { sample, endian: Endian::Little, bottom_first: inversion == 3 };
    let mut data = binary::grid(bytes, HEADER + comment + private, (nx, ny), stored, "the height data", |v| {
        if missing == Some(v as i64) {
            f64::NAN
        } else {
            v * to_unit
        }
    })?;
    if inversion == 2 {
        data = data.slice(ndarray::s![.., ..;-1]).to_owned();
    }
    let size = |n: usize, d: f64, u: &str| metres_per(u).map(|m| n as f64 * d * m);
    Ok(vec![Channel {
        name: "Default".into(),
        data,
        physical_size: size(nx, dx, &x_unit).zip(size(ny, dy, &y_unit)),
        is_height: z_metres.is_some(),
        unit: Some(z_unit).filter(|u| !u.is_empty()),
    }])
}

/// A unit as the header writes it, the code-page-437 micro sign (`æ` in Latin-1) made `µ`.
fn unit(s: &str) -> String {
    match s {
        "\u{e6}m" => "µm".to_string(),
        u => binary::normalise_unit(u),
    }
}
