//! Bruker / Veeco / Digital Instruments NanoScope (`.spm`, `.di`, `.000`, `.001`, …).
//!
//! A Latin-1 text header of `\Key: value` lines in sections (`\*File list`, `\*Scanner list`,
//! `\*Ciao scan list`, one `\*Ciao image list` per channel, `\*File list end`), followed by
//! the channels as little-endian signed integers at their `Data offset`.
//!
//! Heights follow the Z scale chain: `\@2:Z scale: V [Sens. Zsens] (0.0050354 V/LSB) 2.910461 V`
//! names a soft scale (`\@Sens. Zsens: V 20.82646 nm/V`, elsewhere in the header) and a hard
//! value spread over the full integer range, so one LSB is `hard / 2^(8·bytes) · soft`, here
//! in nm. Lines are stored bottom first; they are returned top first.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;
use crate::quantity::metres_per;
use crate::quantity::quoted;

pub struct Nanoscope;

/// From this version on, data is stored as 32-bit integers whatever `Bytes/pixel` says;
/// `Bytes/pixel` then only sets the scaling.
const VERSION_32BIT: u32 = 0x0920_0000;

/// Section names holding an image (older software and other modes use other names).
const IMAGE_SECTIONS: &[&str] = &["ciao image list", "afm image list", "stm image list", "ncafm image list"];

impl Format for Nanoscope {
    fn name(&self) -> &'static str {
        "nanoscope"
    }

    fn size_field(&self) -> &'static str {
        "Scan Size"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["spm", "di", "000", "001", "002", "003", "004", "005", "006", "007", "008", "009"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"\\*File list") || head.starts_with(b"\\*EC File list")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// Every channel of the file; errors may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let header = Header::parse(bytes)?;
    let version = header
        .global("version")
        .and_then(|v| u32::from_str_radix(v.trim().trim_start_matches("0x").trim_start_matches("0X"), 16).ok())
        .unwrap_or(0);
    if header.images.is_empty() {
        return Err("no image in this NanoScope file (force curves and spectra are not topographies)".into());
    }
    let images: Vec<Image> = header.images.iter().map(|s| Image::parse(s, version)).collect::<Result<_, _>>()?;
    disjoint(&images)?;
    images.iter().map(|image| read_image(bytes, &header, image)).collect()
}
/// One `\*Section` with its `(lower-case key, value)` entries in file order.
struct Section {
    name: String,
    entries: Vec<(String, String)>,
}

impl Section {
    fn get(&self, key: &str) -> Option<&str> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The value of the first `@N:<suffix>` key (N a digit), with its N.
    fn get_numbered(&self, suffix: &str) -> Option<(char, &str)> {
        self.entries.iter().find_map(|(k, v)| {
            let mut c = k.chars();
            match (c.next(), c.next(), c.next()) {
                (Some('@'), Some(n), Some(':')) if n.is_ascii_digit() && c.as_str() == suffix => Some((n, v.as_str())),
                _ => None,
            }
        })
    }
}

/// The header: the image sections, and the keys of the other sections (file, scanner and scan
/// lists), where soft scales and scan parameters live, indexed once so that each lookup is
/// constant time whatever the number of images and keys.
struct Header {
    images: Vec<Section>,
    /// Each key of the sections that are not images with its first value.
    global: HashMap<String, String>,
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, String> {
        if bytes.starts_with(b"?*File list") {
            return Err("NanoScope files with data stored as text are not supported".into());
        }
        let mut sections: Vec<Section> = Vec::new();
        let mut ended = false;
        for raw in bytes.split(|&b| b == b'\n') {
            let line = binary::latin1(raw.strip_suffix(b"\r").unwrap_or(raw));
            let line = line.trim();
            if line.eq_ignore_ascii_case("\\*File list end") {
                ended = true;
                break;
            }
            if let Some(name) = line.strip_prefix("\\*") {
                sections.push(Section { name: name.trim().to_ascii_lowercase(), entries: Vec::new() });
            } else if let Some(entry) = line.strip_prefix('\\') {
                let section = sections.last_mut().ok_or("not a NanoScope file: a key comes before any section")?;
                let (key, value) = match entry.find(": ") {
                    Some(i) => (&entry[..i], &entry[i + 2..]),
                    None => (entry.trim_end_matches(':'), ""),
                };
                section.entries.push((key.trim().to_ascii_lowercase(), value.trim().to_string()));
            } else if !line.is_empty() {
                return Err("not a NanoScope file: a header line does not start with '\\'".into());
            }
        }
        if !ended {
            return Err("truncated NanoScope header: no '\\*File list end' line".into());
        }
        if !matches!(sections.first(), Some(s) if s.name == "file list" || s.name == "ec file list") {
            return Err("not a NanoScope file: the header does not start with '\\*File list'".into());
        }
        let (images, others): (Vec<Section>, Vec<Section>) =
            sections.into_iter().partition(|s| IMAGE_SECTIONS.contains(&s.name.as_str()));
        let mut global = HashMap::new();
        for (key, value) in others.into_iter().flat_map(|s| s.entries) {
            global.entry(key).or_insert(value);
        }
        Ok(Header { images, global })
    }

    /// A key from the sections that are not images.
    fn global(&self, key: &str) -> Option<&str> {
        self.global.get(key).map(String::as_str)
    }
}

/// A header value such as `V [Sens. Zsens] (0.0050354 V/LSB) 2.910461 V`, split into its soft
/// scale name and its trailing hard value with unit.
struct Value<'a> {
    soft_scale: Option<&'a str>,
    hard: &'a str,
}

impl<'a> Value<'a> {
    fn parse(v: &'a str) -> Value<'a> {
        // The leading type letter (V, C or S) goes; the rest may carry [soft] and (per LSB).
        let mut rest = v.trim().get(1..).unwrap_or("").trim_start();
        let mut soft_scale = None;
        if let Some(r) = rest.strip_prefix('[') {
            if let Some(end) = r.find(']') {
                soft_scale = Some(r[..end].trim()).filter(|s| !s.is_empty());
                rest = r[end + 1..].trim_start();
            }
        }
        if rest.starts_with('(') {
            // Units may hold parentheses themselves (log(Arb)): skip to the matching one.
            let mut depth = 0usize;
            for (i, c) in rest.char_indices() {
                match c {
                    '(' => depth += 1,
                    ')' => {
                        depth -= 1;
                        if depth == 0 {
                            rest = rest[i + 1..].trim_start();
                            break;
                        }
                    }
                    _ => {}
                }
            }
        }
        Value { soft_scale, hard: rest.trim() }
    }
}

/// `"2.910461 V"` → (2.910461, "V").
fn number_and_unit(s: &str) -> Option<(f64, &str)> {
    let s = s.trim();
    let (num, unit) = s.split_once(char::is_whitespace).unwrap_or((s, ""));
    let x: f64 = num.parse().ok()?;
    x.is_finite().then_some((x, unit.trim()))
}

/// Where an image section's data are and how they are stored.
struct Image<'a> {
    section: &'a Section,
    name: String,
    nx: usize,
    ny: usize,
    offset: usize,
    /// Bytes per stored pixel (2 or 4).
    stored: usize,
    /// Bytes per pixel of the scaling (`Bytes/pixel`).
    bytes_per_pixel: usize,
}

impl<'a> Image<'a> {
    fn parse(s: &'a Section, version: u32) -> Result<Image<'a>, String> {
        let name = channel_name(s);
        let what = || format!("channel '{}'", binary::printable(&name));
        let int = |key: &str| -> Result<usize, String> {
            let v = s.get(key).ok_or_else(|| format!("{}: no '{key}' in its image header", what()))?;
            v.trim().parse::<usize>().map_err(|_| format!("{}: '{key}' is not a count: '{v}'", what()))
        };
        let (nx, ny) = (int("samps/line")?, int("number of lines")?);
        let offset = int("data offset")?;
        let length = int("data length")?;
        let bytes_per_pixel = match s.get("bytes/pixel").map(str::trim) {
            None => 2,
            Some("2") => 2,
            Some("4") => 4,
            Some(v) => return Err(format!("{}: unsupported Bytes/pixel '{v}'", what())),
        };
        let n = binary::grid_points(nx, ny).map_err(|e| format!("{}: {e}", what()))?;
        let needed =
            |size: usize| n.checked_mul(size).ok_or_else(|| format!("{}: the declared data size overflows", what()));
        let stored = if version >= VERSION_32BIT && length >= needed(4)? { 4 } else { bytes_per_pixel };
        if needed(stored)? > length {
            return Err(format!(
                "{}: a {nx} x {ny} image of {stored}-byte pixels does not fit the declared Data length {length}",
                what()
            ));
        }
        Ok(Image { section: s, name, nx, ny, offset, stored, bytes_per_pixel })
    }

    /// The bytes its pixels take.
    fn len(&self) -> usize {
        self.nx * self.ny * self.stored
    }
}

/// Refuse images whose data overlap: each channel decodes its own bytes, so all of them
/// together never take more memory than a small multiple of the file (2 000 sections naming
/// one offset would otherwise decode it 2 000 times).
fn disjoint(images: &[Image]) -> Result<(), String> {
    let mut order: Vec<&Image> = images.iter().collect();
    order.sort_by_key(|i| i.offset);
    match order.windows(2).find(|w| w[0].offset.saturating_add(w[0].len()) > w[1].offset) {
        Some(w) => Err(format!(
            "channels '{}' and '{}' declare overlapping data (at offsets {} and {}): each image has its own",
            binary::printable(&w[0].name),
            binary::printable(&w[1].name),
            w[0].offset,
            w[1].offset
        )),
        None => Ok(()),
    }
}

fn read_image(bytes: &[u8], header: &Header, image: &Image) -> Result<Channel, String> {
    let &Image { section: s, nx, ny, offset, stored, bytes_per_pixel, .. } = image;
    let what = format!("channel '{}'", binary::printable(&image.name));
    let (per_lsb, unit) = z_scale(header, s, bytes_per_pixel).map_err(|e| format!("{what}: {e}"))?;
    let to_metres = metres_per(&unit);
    let factor = per_lsb * to_metres.unwrap_or(1.0);
    let sample = if stored == 4 { Sample::I32 } else { Sample::I16 };
    let data = binary::grid(
        bytes,
        offset,
        (nx, ny),
        Stored { sample, endian: Endian::Little, bottom_first: true },
        &what,
        |v| v * factor,
    )?;
    Ok(Channel {
        name: image.name.clone(),
        data,
        physical_size: scan_size(header, s, nx, ny),
        unit: Some(unit).filter(|u| !u.is_empty()),
        is_height: to_metres.is_some(),
    })
}

/// `\@2:Image Data: S [ZSensor] "Height Sensor"` → `ZSensor` (the short name in brackets,
/// else the quoted one).
fn channel_name(s: &Section) -> String {
    if let Some((_, v)) = s.get_numbered("image data") {
        let v = Value::parse(v);
        return v.soft_scale.map(str::to_string).unwrap_or_else(|| v.hard.trim_matches('"').to_string());
    }
    s.get("image data").map(|v| v.trim_matches('"').to_string()).unwrap_or_else(|| "unnamed".into())
}

/// The value of one LSB and its unit, from the `@N:Z scale` entry of the image section and
/// the soft scale it refers to.
fn z_scale(header: &Header, s: &Section, bytes_per_pixel: usize) -> Result<(f64, String), String> {
    let image_n = s.get_numbered("image data").map(|(n, _)| n);
    let z = image_n
        .and_then(|n| s.get(&format!("@{n}:z scale")))
        .or_else(|| s.get_numbered("z scale").map(|(_, v)| v))
        .ok_or("no '@2:Z scale' entry (NanoScope files before version 4.3 are not supported)")?;
    let z = Value::parse(z);
    let (hard, hard_unit) = number_and_unit(z.hard).ok_or_else(|| format!("unreadable Z scale value '{}'", z.hard))?;
    // The hard value spans the whole integer range of the declared pixel size.
    let hard_per_lsb = hard / 256f64.powi(bytes_per_pixel as i32);
    let soft = z.soft_scale.and_then(|name| header.global(&format!("@{}", name.to_ascii_lowercase())));
    let scaled = soft.and_then(|v| number_and_unit(Value::parse(v).hard)).and_then(|(soft, soft_unit)| {
        match soft_unit.split_once('/') {
            // The soft scale is per volt, the hard value may be in mV: convert between them.
            Some((num, den)) => {
                let ratio = if den.trim() == hard_unit {
                    Some(1.0)
                } else {
                    volts(hard_unit).zip(volts(den)).map(|(h, d)| h / d)
                };
                ratio.map(|ratio| (hard_per_lsb * ratio * soft, binary::normalise_unit(num)))
            }
            None => Some((hard_per_lsb * soft, binary::normalise_unit(hard_unit))),
        }
    });
    // No usable soft scale: the values stay in the hard unit (volts, degrees…).
    let (per_lsb, unit) = scaled.unwrap_or_else(|| (hard_per_lsb, binary::normalise_unit(hard_unit)));
    let full_scale = metres_per(&unit).map(|m| per_lsb * m * 256f64.powi(bytes_per_pixel as i32));
    plausible::height_factor(per_lsb, full_scale).map_err(|e| format!("Z scale {}: {e}", quoted(z.hard.trim())))?;
    Ok((per_lsb, unit))
}

/// Volts per `unit`, for the voltage units of Z scales.
fn volts(unit: &str) -> Option<f64> {
    match unit.trim() {
        "V" => Some(1.0),
        "mV" => Some(1e-3),
        "uV" | "µV" | "~V" => Some(1e-6),
        _ => None,
    }
}

/// Physical size (lx, ly) [m] from `Scan Size: 500 500 nm` (or a single number for a scan
/// whose y size follows from the aspect ratio); `None` when the unit is not a length.
fn scan_size(header: &Header, s: &Section, nx: usize, ny: usize) -> Option<(f64, f64)> {
    let text = s.get("scan size").or_else(|| header.global("scan size"))?;
    let tokens: Vec<&str> = text.split_whitespace().collect();
    let numbers: Vec<f64> = tokens.iter().map_while(|t| t.parse::<f64>().ok()).collect();
    let unit = binary::normalise_unit(&tokens[numbers.len()..].join(" "));
    let m = metres_per(&unit)?;
    let (sx, sy) = match numbers[..] {
        [sx, sy, ..] => (sx, sy),
        [sx] => {
            let aspect = s.get("aspect ratio").or_else(|| header.global("aspect ratio")).and_then(|a| {
                let (a, b) = a.split_once(':')?;
                Some(b.trim().parse::<f64>().ok()? / a.trim().parse::<f64>().ok()?)
            });
            (sx, sx * aspect.unwrap_or(ny as f64 / nx as f64))
        }
        _ => return None,
    };
    let (lx, ly) = (sx * m, sy * m);
    (lx > 0.0 && ly > 0.0 && lx.is_finite() && ly.is_finite()).then_some((lx, ly))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A NanoScope file of one 2 × 2 image with the given version, pixel scaling, storage
    /// (`wide`: 32-bit integers) and scan size.
    fn file(version: &str, bytes_per_pixel: usize, wide: bool, stored: &[i32], scan_size: &str) -> Vec<u8> {
        let offset = 1024;
        let header = format!(
            "\\*File list\r\n\\Version: {version}\r\n\\*Scanner list\r\n\\@Sens. Zsens: V 10.0 nm/V\r\n\
             \\*Ciao scan list\r\n\\Aspect Ratio: 2:1\r\n\\*Ciao image list\r\n\\Data offset: {offset}\r\n\
             \\Data length: {}\r\n\\Bytes/pixel: {bytes_per_pixel}\r\n\\Samps/line: 2\r\n\\Number of lines: 2\r\n\
             \\Scan Size: {scan_size}\r\n\\@2:Image Data: S [] \"Height\"\r\n\
             \\@2:Z scale: V [Sens. Zsens] (0.001 V/LSB) 65536.0 mV\r\n\\*File list end\r\n\x1a",
            stored.len() * if wide { 4 } else { 2 }
        );
        let mut out = header.into_bytes();
        out.resize(offset, 0);
        for v in stored {
            if wide {
                out.extend_from_slice(&v.to_le_bytes());
            } else {
                out.extend_from_slice(&(*v as i16).to_le_bytes());
            }
        }
        out
    }

    #[test]
    fn scale_chain_with_millivolt_hard_value_and_single_scan_size() {
        // One LSB: 65536 mV / 2^16 = 1 mV = 1e-3 V, times 10 nm/V = 0.01 nm.
        let ch = Nanoscope.read(&file("0x05300000", 2, false, &[100, 200, 300, 400], "1 ~m")).unwrap();
        assert_eq!(ch[0].name, "Height");
        assert_eq!(ch[0].unit.as_deref(), Some("nm"));
        let want = ndarray::array![[3e-9, 4e-9], [1e-9, 2e-9]]; // bottom line first
        assert!(ch[0].data.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-21), "{}", ch[0].data);
        // A single size with aspect ratio 2:1: the y size is half the x size.
        assert_eq!(ch[0].physical_size, Some((1e-6, 0.5e-6)));
    }

    #[test]
    fn from_version_9_2_pixels_are_32_bit_scaled_by_bytes_per_pixel() {
        // Bytes/pixel 4: one LSB is 65536 mV / 2^32.
        let ch = Nanoscope.read(&file("0x09200000", 4, true, &[1 << 16, 0, 0, 0], "2 2 um")).unwrap();
        assert!((ch[0].data[[1, 0]] - 1e-11).abs() < 1e-24, "{}", ch[0].data);
        assert_eq!(ch[0].physical_size, Some((2e-6, 2e-6)));
    }

    #[test]
    fn truncated_data_and_header_are_refused() {
        let mut f = file("0x05300000", 2, false, &[1, 2, 3, 4], "1 um");
        f.truncate(f.len() - 1);
        assert!(Nanoscope.read(&f).unwrap_err().contains("truncated"));
        let f = file("0x05300000", 2, false, &[1, 2, 3, 4], "1 um");
        let end = f.windows(15).position(|w| w == b"\\*File list end").unwrap();
        assert!(Nanoscope.read(&f[..end]).unwrap_err().contains("File list end"));
    }

    #[test]
    fn values_with_nested_parentheses() {
        let v = Value::parse("V [Sens. FVLogModulusSens] (0.1 log(Pa)/LSB) 2.5 log(Pa)");
        assert_eq!(v.soft_scale, Some("Sens. FVLogModulusSens"));
        assert_eq!(number_and_unit(v.hard), Some((2.5, "log(Pa)")));
    }
}
