//! Alicona Imaging `.al3d` (focus-variation microscopes, e.g. InfiniteFocus).
//!
//! After the magic `AliconaImaging\0\r\n` come 52-byte tags (a 20-byte key, a 30-byte value,
//! CR LF): `Version`, `TagCount`, then that many tags, among them `Cols`, `Rows`,
//! `PixelSizeXMeter`, `PixelSizeYMeter`, `DepthImageOffset` and `InvalidPixelValue`. The depth
//! image is `Rows` rows of little-endian 32-bit floats in metres, each row padded to a multiple
//! of 8 bytes, at `DepthImageOffset`. A NaN or the `InvalidPixelValue` marks a point not
//! measured.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};

pub struct Al3d;

const MAGIC: &[u8] = b"AliconaImaging\x00\r\n";
const TAG: usize = 52;

impl Format for Al3d {
    fn name(&self) -> &'static str {
        "al3d"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["al3d"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        if !bytes.starts_with(MAGIC) {
            return Err("not an Alicona file (no AliconaImaging magic)".into());
        }
        decode(bytes).map_err(binary::one_line)
    }
}

/// The tag at `offset`: key and value, checked to end in CR LF.
fn tag(bytes: &[u8], offset: usize) -> Result<(String, String), String> {
    let t = binary::extent(bytes, offset, TAG, "a header tag")?;
    if &t[50..] != b"\r\n" {
        return Err(format!("the header tag at byte {offset} does not end in CR LF"));
    }
    Ok((binary::padded_str(&t[..20]), binary::padded_str(&t[20..50])))
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let (key, _) = tag(bytes, MAGIC.len())?;
    let (count_key, count) = tag(bytes, MAGIC.len() + TAG)?;
    if key != "Version" || count_key != "TagCount" {
        return Err("the header does not begin with the Version and TagCount tags".into());
    }
    let count: usize = count.parse().map_err(|_| format!("TagCount '{}' is not a count", binary::printable(&count)))?;
    // Each tag is read from the file, so the count cannot reserve more than the file holds.
    let mut tags = HashMap::new();
    for k in 0..count {
        let (key, value) = tag(bytes, MAGIC.len() + TAG * (2 + k))?;
        tags.entry(key).or_insert(value);
    }
    let get = |key: &str| tags.get(key).ok_or_else(|| format!("the header has no {key} tag"));
    let count = |key: &str| -> Result<usize, String> {
        let v = get(key)?;
        v.parse().map_err(|_| format!("{key} '{}' is not a count", binary::printable(v)))
    };
    let number = |key: &str| -> Result<f64, String> {
        let v = get(key)?;
        v.parse().map_err(|_| format!("{key} '{}' is not a number", binary::printable(v)))
    };
    let (nx, ny) = (count("Cols")?, count("Rows")?);
    binary::grid_points(nx, ny)?;
    let offset = count("DepthImageOffset")?;
    // Rows are padded to whole multiples of 8 bytes (two floats).
    let row = nx.checked_add(nx % 2).ok_or("the declared row length overflows")?;
    let invalid = number("InvalidPixelValue").unwrap_or(f64::NAN);
    let stored = Stored { sample: Sample::F32, endian: Endian::Little, bottom_first: false };
    let padded = binary::grid(bytes, offset, (row, ny), stored, "the depth image", |v| {
        // The marker is written as text: compare to the precision of a float.
        if v.is_nan() || (v - invalid).abs() < 1.5e-7 * invalid.abs() {
            f64::NAN
        } else {
            v
        }
    })?;
    let data = padded.slice(ndarray::s![.., ..nx]).to_owned();
    let pixel = |key: &str| number(key).ok().filter(|p| p.is_finite() && *p > 0.0);
    let physical_size =
        pixel("PixelSizeXMeter").zip(pixel("PixelSizeYMeter")).map(|(dx, dy)| (nx as f64 * dx, ny as f64 * dy));
    Ok(vec![Channel { name: "Default".into(), data, physical_size, unit: Some("m".into()), is_height: true }])
}
