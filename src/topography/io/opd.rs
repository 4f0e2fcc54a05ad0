//! Bruker (Veeco) Wyko `.opd` (Vision software of Wyko white-light interferometers).
//!
//! After a 2-byte prelude comes a directory of 24-byte entries (a 16-byte name, an `i16` type,
//! an `i32` length, a `u16` attribute), itself the first entry (`Directory`, its length that of
//! the whole directory); the blocks follow in directory order, each of its stated length, all
//! little-endian. Arrays (type 3) named `RAW DATA`, `RAW_DATA`, `OPD`, `Raw` or `SAMPLE_DATA`
//! hold heights (the others, `Image`, `Intensity`, `SecArr_0`, intensities): `nx`, `ny` and the
//! item size (`u16` each), then `nx` columns of `ny` values (unsigned bytes, `i16` or `f32`),
//! the last row first. A value times `Wavelength / Mult` is a height in nm; `Pixel_size` is in
//! mm, along y times `Aspect`. Values of 32766 and up (`i16`), of 1e38 and up or not finite
//! (`f32`) mark points not measured.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Cursor, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;

pub struct Opd;

const ENTRY: usize = 24;
const HEIGHT_ARRAYS: &[&str] = &["RAW DATA", "RAW_DATA", "OPD", "Raw", "SAMPLE_DATA"];
const ARRAY: i16 = 3;

impl Format for Opd {
    fn name(&self) -> &'static str {
        "opd"
    }

    fn size_field(&self) -> &'static str {
        "Pixel_size"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["opd"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.get(2..18).is_some_and(|name| binary::padded_str(name) == "Directory")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        if !self.sniff(bytes) {
            return Err("not a Wyko OPD file (no Directory block at byte 2)".into());
        }
        decode(bytes).map_err(binary::one_line)
    }
}

/// A directory entry: the block's name, type, and where its bytes lie.
struct Block {
    name: String,
    kind: i16,
    offset: usize,
    len: usize,
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let mut c = Cursor::new(bytes, Endian::Little);
    c.skip(18, "the directory name")?;
    c.skip(2, "the directory type")?;
    let dir_len = binary::non_negative(i64::from(c.i32("the directory length")?), "directory length")?;
    if dir_len % ENTRY != 0 || dir_len == 0 {
        return Err(format!("the directory length {dir_len} is not a positive multiple of {ENTRY} bytes"));
    }
    let directory = binary::extent(bytes, 2, dir_len, "the directory")?;
    let mut offset = 2 + dir_len;
    let mut blocks = Vec::new();
    for entry in directory.chunks_exact(ENTRY).skip(1) {
        let mut e = Cursor::new(entry, Endian::Little);
        let name = binary::padded_str(e.take(16, "a block name")?);
        let kind = e.i16("a block type")?;
        let len = e.i32("a block length")?;
        // Blocks of no length have no bytes.
        let len = usize::try_from(len).unwrap_or(0);
        blocks.push(Block { name, kind, offset, len });
        offset = offset.checked_add(len).ok_or("the declared block sizes overflow")?;
    }

    let mut meta = HashMap::new();
    for b in blocks.iter().filter(|b| ["Wavelength", "Mult", "Aspect", "Pixel_size"].contains(&b.name.as_str())) {
        let v = binary::extent(bytes, b.offset, b.len, &format!("the {} block", b.name))?;
        if let Some(x) = number(b.kind, v) {
            meta.insert(b.name.as_str(), x);
        }
    }
    let wavelength = *meta.get("Wavelength").ok_or("the file has no Wavelength block: its height scale is unknown")?;
    let mult = meta.get("Mult").copied().unwrap_or(1.0);
    let aspect = meta.get("Aspect").copied().unwrap_or(1.0);
    let scale = wavelength / mult * 1e-9;
    // Items of up to 2 bytes: the smallest range a height channel stores.
    plausible::height_factor(scale, Some(65536.0 * scale))
        .map_err(|e| format!("the height scale Wavelength / Mult = {wavelength} / {mult} nm: {e}"))?;
    let pixel = meta.get("Pixel_size").copied().filter(|p| p.is_finite() && *p > 0.0).map(|p| p * 1e-3);

    let mut channels = Vec::new();
    for b in blocks.iter().filter(|b| b.kind == ARRAY && HEIGHT_ARRAYS.contains(&b.name.as_str())) {
        let what = format!("the {} block", b.name);
        let block = binary::extent(bytes, b.offset, b.len, &what)?;
        let mut h = Cursor::new(block, Endian::Little);
        let nx = usize::from(h.u16("the number of columns")?);
        let ny = usize::from(h.u16("the number of rows")?);
        let (sample, limit) = match h.u16("the item size")? {
            1 => (Sample::U8, f64::INFINITY),
            2 => (Sample::I16, 32766.0),
            4 => (Sample::F32, 1e38),
            n => return Err(format!("{what}: items of {n} bytes are not supported (1, 2 or 4)")),
        };
        let stored = Stored { sample, endian: Endian::Little, bottom_first: false };
        // Stored column by column: decoded as nx rows of ny values, then transposed.
        let columns = binary::grid(block, 6, (ny, nx), stored, &what, |v| {
            if v.is_finite() && v < limit {
                v * scale
            } else {
                f64::NAN
            }
        })?;
        let data = columns.t().slice(ndarray::s![..;-1, ..]).to_owned();
        channels.push(Channel {
            name: b.name.clone(),
            data,
            physical_size: pixel.map(|p| (nx as f64 * p, ny as f64 * p * aspect)),
            unit: Some("nm".into()),
            is_height: true,
        });
    }
    if channels.is_empty() {
        return Err("the file holds no height array (RAW DATA, OPD, Raw, SAMPLE_DATA)".into());
    }
    Ok(channels)
}

/// The number a scalar block holds, by its type and length (files state some types wrongly).
fn number(kind: i16, v: &[u8]) -> Option<f64> {
    let i16_ = || Some(f64::from(i16::from_le_bytes([v[0], v[1]])));
    let i32_ = || Some(f64::from(i32::from_le_bytes([v[0], v[1], v[2], v[3]])));
    match (kind, v.len()) {
        (6, 2) | (7, 2) => i16_(),
        (6, 4) => i32_(),
        (7, n) if n >= 4 => Some(f64::from(f32::from_le_bytes([v[0], v[1], v[2], v[3]]))),
        (8, n) if n >= 8 => Some(f64::from_le_bytes(v[..8].try_into().ok()?)),
        (12, n) if n >= 4 => i32_(),
        _ => None,
    }
}
