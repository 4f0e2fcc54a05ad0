//! BCR-STM `.bcr` and BCRF `.bcrf` interchange files (Image Metrology's SPIP and others).
//!
//! A text header of `key = value` lines (`%` and `#` start comments), Latin-1 (`bcrstm`,
//! `bcrf`) or UTF-16 (`bcrstm_unicode`, `bcrf_unicode`, the `fileformat` key of its first line
//! tells), `headersize` characters long (2048 when the key is missing); the grid follows:
//! `ypixels` rows of `xpixels` values, 16-bit integers (`bcrstm`) or 32-bit floats (`bcrf`), in
//! the byte order `intelmode` gives (1, the default: little endian). `xlength`, `ylength` are in
//! `xunit`, `yunit`; heights in `zunit` (all three default to nm), integers times `bit2nm`
//! (which, despite its name, converts to `zunit`). Missing points are the integer 32767 and
//! floats above 1.7e38 or NaN (as Gwyddion and SurfaceTopography mark them).
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;
use crate::quantity::metres_per;

pub struct Bcr;

const KEY: &str = "fileformat = bcr";
/// The header's length in characters when it does not state one.
const DEFAULT_HEADER: usize = 2048;

impl Format for Bcr {
    fn name(&self) -> &'static str {
        "bcr"
    }

    fn size_field(&self) -> &'static str {
        "xlength and ylength"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["bcr", "bcrf"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        encoding(head).is_some()
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// How the header's characters are stored.
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Latin1,
    Utf16(Endian),
}

fn encoding(head: &[u8]) -> Option<Encoding> {
    let utf16 = |endian| {
        let units = KEY.encode_utf16();
        let bytes: Vec<u8> =
            units.flat_map(|u| if endian == Endian::Little { u.to_le_bytes() } else { u.to_be_bytes() }).collect();
        head.strip_prefix(b"\xff\xfe".as_slice())
            .or(head.strip_prefix(b"\xfe\xff".as_slice()))
            .unwrap_or(head)
            .starts_with(&bytes)
    };
    if head.starts_with(KEY.as_bytes()) {
        Some(Encoding::Latin1)
    } else if utf16(Endian::Little) {
        Some(Encoding::Utf16(Endian::Little))
    } else if utf16(Endian::Big) {
        Some(Encoding::Utf16(Endian::Big))
    } else {
        None
    }
}

/// The text of `bytes` in `encoding`; invalid UTF-16 becomes U+FFFD.
fn text(bytes: &[u8], encoding: Encoding) -> String {
    match encoding {
        Encoding::Latin1 => binary::latin1(bytes),
        Encoding::Utf16(endian) => {
            let units = bytes.chunks_exact(2).map(|c| match endian {
                Endian::Little => u16::from_le_bytes([c[0], c[1]]),
                Endian::Big => u16::from_be_bytes([c[0], c[1]]),
            });
            char::decode_utf16(units).map(|c| c.unwrap_or('\u{fffd}')).collect()
        }
    }
}

/// The `key = value` entries of a header text, the first of repeated keys counting.
fn entries(text: &str) -> HashMap<String, String> {
    let mut map = HashMap::new();
    for line in text.lines().map(str::trim).filter(|l| !l.starts_with('%') && !l.starts_with('#')) {
        if let Some((k, v)) = line.split_once('=') {
            map.entry(k.trim().to_string()).or_insert_with(|| v.trim().to_string());
        }
    }
    map
}

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let enc = encoding(bytes).ok_or("not a BCR file (no 'fileformat = bcr…' first line)")?;
    let width = if enc == Encoding::Latin1 { 1 } else { 2 };
    let probe = entries(&text(&bytes[..bytes.len().min(DEFAULT_HEADER * width)], enc));
    let chars = match probe.get("headersize") {
        Some(v) => v.parse::<usize>().map_err(|_| format!("headersize '{}' is not a count", binary::printable(v)))?,
        None => DEFAULT_HEADER,
    };
    let header_len = chars.checked_mul(width).ok_or("the header size overflows")?;
    let h = entries(&text(binary::extent(bytes, 0, header_len, "the header")?, enc));
    let get = |key: &str| h.get(key).map(String::as_str).ok_or_else(|| format!("the header has no '{key}'"));
    let stm = match get("fileformat")? {
        "bcrstm" | "bcrstm_unicode" => true,
        "bcrf" | "bcrf_unicode" => false,
        f => return Err(format!("fileformat '{}' is not a BCR image", binary::printable(f))),
    };
    let count = |key: &str| -> Result<usize, String> {
        let v = get(key)?;
        v.parse().map_err(|_| format!("{key} '{}' is not a count", binary::printable(v)))
    };
    let number = |key: &str| -> Result<f64, String> {
        let v = get(key)?;
        v.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{key} '{}' is not a number", binary::printable(v)))
    };
    let unit = |key: &str| -> Result<(String, f64), String> {
        let u = binary::normalise_unit(h.get(key).map_or("nm", String::as_str));
        let m = metres_per(&u).ok_or_else(|| format!("{key} '{}' is not a length unit", binary::printable(&u)))?;
        Ok((u, m))
    };
    let (xunit, x_metres) = unit("xunit")?;
    if unit("yunit")?.0 != xunit {
        return Err("xunit and yunit differ".into());
    }
    let (zunit, z_metres) = unit("zunit")?;
    let (lx, ly) = (number("xlength")? * x_metres, number("ylength")? * x_metres);
    if !(lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()) {
        return Err(format!("the scan size {lx} x {ly} m is not positive"));
    }
    let endian = if h.get("intelmode").is_none_or(|m| m != "0") { Endian::Little } else { Endian::Big };
    let scale = if stm { h.get("bit2nm").map_or(Ok(1.0), |_| number("bit2nm"))? } else { 1.0 } * z_metres;
    let sample = if stm { Sample::I16 } else { Sample::F32 };
    plausible::height_factor(scale, sample.levels().map(|l| scale * l))
        .map_err(|e| format!("the height scale (bit2nm × zunit), {scale} m per unit: {e}"))?;
    let stored = Stored { sample, endian, bottom_first: false };
    let missing = |v: f64| if stm { v == 32767.0 } else { v.is_nan() || v > 1.7e38 };
    let data = binary::grid(bytes, header_len, (count("xpixels")?, count("ypixels")?), stored, "the image", |v| {
        if missing(v) {
            f64::NAN
        } else {
            v * scale
        }
    })?;
    Ok(vec![Channel {
        name: "Default".into(),
        data,
        physical_size: Some((lx, ly)),
        unit: Some(zunit),
        is_height: true,
    }])
}
