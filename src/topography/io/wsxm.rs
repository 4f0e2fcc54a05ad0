//! WSxM `.stp`, `.top` (and `.tom`, `.cur`) image files.
//!
//! Three text lines (`WSxM file copyright …`, `SxM Image file`, `Image header size: N`), then
//! an INI-like header of `[Section]` lines and `Key: value` entries up to `[Header end]`, N
//! bytes in all (Latin-1); the image follows: `Number of rows` × `Number of columns` values of
//! `Image Data Type` (`short`/`integer`: i16, `float`: f32, `double`: f64), little endian,
//! stored rotated by 180° (returned as Gwyddion shows it). `[Control]` gives the scan size
//! (`X Amplitude: 600 nm`, `Y Amplitude`, the latter defaulting to the former) and
//! `[General Info]` the height range `Z Amplitude: 18.9 nm`. Floating-point values are in the
//! unit of `Z Amplitude`; integers span `Z Amplitude` over the `[Miscellaneous]` `Minimum` to
//! `Maximum` they take, as SurfaceTopography and WSxM scale them.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::quantity::metres_per;

pub struct Wsxm;

const MAGIC: &[u8] = b"WSxM file copyright";

impl Format for Wsxm {
    fn name(&self) -> &'static str {
        "wsxm"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["stp", "top", "tom", "cur"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// `[Section]` → key → value, the first of repeated names counting.
type Header = HashMap<String, HashMap<String, String>>;

fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let mut lines = bytes.split(|&b| b == b'\n').map(|l| binary::latin1(l).trim().to_string());
    if !lines.next().is_some_and(|l| l.as_bytes().starts_with(MAGIC)) {
        return Err("not a WSxM file (no 'WSxM file copyright' line)".into());
    }
    if lines.next().as_deref() != Some("SxM Image file") {
        return Err("not a WSxM image file (its second line is not 'SxM Image file')".into());
    }
    let size_line = lines.next().unwrap_or_default();
    let header_len: usize = size_line
        .strip_prefix("Image header size:")
        .and_then(|n| n.trim().parse().ok())
        .ok_or_else(|| format!("the third line '{}' gives no 'Image header size: N'", binary::printable(&size_line)))?;
    let header = binary::extent(bytes, 0, header_len, "the header")?;
    let header = parse(header)?;
    let get = |section: &str, key: &str| {
        header
            .get(section)
            .and_then(|s| s.get(key))
            .map(String::as_str)
            .ok_or_else(|| format!("the header has no '{key}' in [{section}]"))
    };
    let count = |key: &str| -> Result<usize, String> {
        let v = get("General Info", key)?;
        v.parse().map_err(|_| format!("{key} '{}' is not a count", binary::printable(v)))
    };
    let (nx, ny) = (count("Number of columns")?, count("Number of rows")?);
    let data_type = get("General Info", "Image Data Type")?;
    let sample = match data_type {
        "short" | "integer" => Sample::I16,
        "float" => Sample::F32,
        "double" => Sample::F64,
        t => return Err(format!("Image Data Type '{}' is not supported", binary::printable(t))),
    };

    let (z_amplitude, z_unit) = quantity(get("General Info", "Z Amplitude")?, "Z Amplitude")?;
    let to_metres = metres_per(&z_unit);
    let lateral = |key: &str| -> Result<f64, String> {
        let (v, unit) = quantity(get("Control", key)?, key)?;
        let m = metres_per(&unit).ok_or_else(|| format!("{key} is in '{}', not a length", binary::printable(&unit)))?;
        match v * m {
            l if l > 0.0 && l.is_finite() => Ok(l),
            l => Err(format!("{key} {l} m is not a positive length")),
        }
    };
    let lx = lateral("X Amplitude")?;
    let ly = if get("Control", "Y Amplitude").is_ok() { lateral("Y Amplitude")? } else { lx };

    // Integers are scaled to span the Z amplitude over their stated range.
    let step = if sample == Sample::I16 {
        let number = |key: &str| -> Result<f64, String> {
            let v = get("Miscellaneous", key)?;
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{key} '{}' is not a number", binary::printable(v)))
        };
        let range = number("Maximum")? - number("Minimum")?;
        if range > 0.0 {
            z_amplitude / range
        } else {
            1.0
        }
    } else {
        1.0
    };
    let scale = step * to_metres.unwrap_or(1.0);
    let stored = Stored { sample, endian: Endian::Little, bottom_first: true };
    let mut data = binary::grid(bytes, header_len, (nx, ny), stored, "the image", |v| v * scale)?;
    // Rows were read bottom first; reversing each one completes the half turn.
    for mut row in data.rows_mut() {
        let n = row.len();
        for i in 0..n / 2 {
            row.swap(i, n - 1 - i);
        }
    }
    let name = get("General Info", "Acquisition channel").unwrap_or("Default");
    Ok(vec![Channel {
        name: name.to_string(),
        data,
        physical_size: Some((lx, ly)),
        is_height: to_metres.is_some(),
        unit: Some(z_unit),
    }])
}

/// The sections of the header text, which must end with a `[Header end]` line.
fn parse(header: &[u8]) -> Result<Header, String> {
    let mut sections = Header::new();
    let mut current: Option<String> = None;
    for line in header.split(|&b| b == b'\n').skip(3).map(|l| binary::latin1(l).trim().to_string()) {
        if line == "[Header end]" {
            return Ok(sections);
        }
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            sections.entry(name.to_string()).or_default();
            current = Some(name.to_string());
        } else if let (Some((k, v)), Some(section)) = (line.split_once(':'), current.as_ref()) {
            let entries = sections.entry(section.clone()).or_default();
            entries.entry(k.trim().to_string()).or_insert_with(|| v.trim().to_string());
        }
    }
    Err("the header has no '[Header end]' line within its stated size".into())
}

/// A `value unit` field (`600 nm`), the unit in its usual spelling.
fn quantity(field: &str, key: &str) -> Result<(f64, String), String> {
    let (v, unit) = field.split_once(' ').unwrap_or((field, ""));
    let v = v.parse::<f64>().ok().filter(|v| v.is_finite());
    match v {
        Some(v) if !unit.trim().is_empty() => Ok((v, binary::normalise_unit(unit))),
        _ => Err(format!("{key} '{}' is not a number and a unit", binary::printable(field))),
    }
}
