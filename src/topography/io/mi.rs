//! Agilent / Molecular Imaging PicoView `.mi` images (binary variant).
//!
//! A text header of fixed-width lines, the key in the first 14 columns and the value after it
//! (`xPixels       256`). Each `bufferLabel` line opens one channel (`bufferUnit`,
//! `bufferRange` follow it). The line `data          BINARY` (16-bit) or `BINARY_32` ends the
//! header; the channels follow as little-endian signed integers, one after the other, the
//! full integer range spanning ±`bufferRange`. Lines are stored bottom first; they are
//! returned top first.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::plausible;
use crate::quantity::metres_per;

pub struct Mi;

/// Width of the key column.
const KEY_WIDTH: usize = 14;

impl Format for Mi {
    fn name(&self) -> &'static str {
        "mi"
    }

    fn size_field(&self) -> &'static str {
        "xLength and yLength"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["mi"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"fileType      Image")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// Every channel of the file; errors may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    if !bytes.starts_with(b"fileType") {
        return Err("not a PicoView .mi file: it does not start with 'fileType'".into());
    }
    let mut header: Vec<(String, String)> = Vec::new();
    let mut buffers: Vec<Buffer> = Vec::new();
    let mut data = None;
    let mut pos = 0;
    while pos < bytes.len() {
        let end = bytes[pos..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |i| pos + i);
        let line = binary::latin1(&bytes[pos..end]);
        let line = line.trim_end_matches('\r');
        pos = (end + 1).min(bytes.len());
        let split = line.char_indices().nth(KEY_WIDTH).map_or(line.len(), |(i, _)| i);
        let (key, value) = (line[..split].trim(), line[split..].trim());
        match key {
            "data" => {
                data = Some((value.to_string(), pos));
                break;
            }
            "bufferLabel" => buffers.push(Buffer { label: value.to_string(), unit: None, range: None }),
            "bufferUnit" | "bufferRange" if !buffers.is_empty() => {
                if let Some(b) = buffers.last_mut() {
                    if key == "bufferUnit" {
                        b.unit = Some(value.to_string());
                    } else {
                        b.range = value.parse::<f64>().ok().filter(|r| r.is_finite());
                    }
                }
            }
            _ => header.push((key.to_string(), value.to_string())),
        }
    }
    let get = |k: &str| header.iter().find(|(key, _)| key == k).map(|(_, v)| v.as_str());
    match get("fileType") {
        Some("Image") => {}
        Some(t) => return Err(format!("PicoView '{t}' files are not topographies (only 'Image')")),
        None => return Err("not a PicoView .mi file: no fileType".into()),
    }
    let (encoding, data_start) = data.ok_or("truncated PicoView header: no 'data' line")?;
    let sample = match encoding.as_str() {
        "BINARY" => Sample::I16,
        "BINARY_32" => Sample::I32,
        e => return Err(format!("PicoView data encoding '{e}' is not supported (only BINARY, BINARY_32)")),
    };
    let count = |k: &str| get(k).and_then(|v| v.parse::<usize>().ok()).ok_or_else(|| format!("no valid {k} count"));
    let (nx, ny) = (count("xPixels")?, count("yPixels")?);
    let length = |k: &str| get(k).and_then(|v| v.parse::<f64>().ok()).filter(|l| *l > 0.0 && l.is_finite());
    let physical_size = length("xLength").zip(length("yLength"));
    if buffers.is_empty() {
        return Err("the PicoView header declares no buffer (bufferLabel)".into());
    }

    let block = binary::grid_points(nx, ny)?.checked_mul(sample.size()).ok_or("the declared data size overflows")?;
    let stored = Stored { sample, endian: Endian::Little, bottom_first: true };
    let full_scale = if sample == Sample::I16 { 32768.0 } else { 2147483648.0 };
    let mut channels = Vec::with_capacity(buffers.len());
    for (k, b) in buffers.into_iter().enumerate() {
        let what = format!("buffer '{}'", binary::printable(&b.label));
        let range = b.range.ok_or_else(|| format!("{what}: no valid bufferRange"))?;
        let unit = binary::normalise_unit(b.unit.as_deref().unwrap_or(""));
        let to_metres = metres_per(&unit);
        let step = range / full_scale * to_metres.unwrap_or(1.0);
        plausible::height_factor(step, to_metres.map(|_| 2.0 * full_scale * step))
            .map_err(|e| format!("{what}: bufferRange {range}: {e}"))?;
        let offset =
            block.checked_mul(k).and_then(|o| o.checked_add(data_start)).ok_or("the declared data size overflows")?;
        let data = binary::grid(bytes, offset, (nx, ny), stored, &what, |v| v * step)?;
        channels.push(Channel {
            name: b.label,
            data,
            physical_size,
            unit: Some(unit).filter(|u| !u.is_empty()),
            is_height: to_metres.is_some(),
        });
    }
    Ok(channels)
}

/// One channel declared in the header.
struct Buffer {
    label: String,
    unit: Option<String>,
    range: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 16-bit variant, made from the real 32-bit sample by keeping the upper half of
    /// each integer: the same image to within one 16-bit step.
    #[test]
    fn sixteen_bit_data_match_the_32_bit_original() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mi-1.mi");
        let original = std::fs::read(path).unwrap();
        let marker = b"data          BINARY_32\n";
        let start = original.windows(marker.len()).position(|w| w == marker).unwrap();
        let mut short = original[..start].to_vec();
        short.extend_from_slice(b"data          BINARY\n");
        for v in original[start + marker.len()..].chunks_exact(4) {
            let v = i32::from_le_bytes([v[0], v[1], v[2], v[3]]);
            short.extend_from_slice(&((v >> 16) as i16).to_le_bytes());
        }
        let (a, b) = (Mi.read(&original).unwrap(), Mi.read(&short).unwrap());
        assert_eq!(b.len(), 4);
        // Topography: bufferRange 2.9025 µm over 2^15 steps.
        let step = 2.9025e-6 / 32768.0;
        let worst = a[0].data.iter().zip(&b[0].data).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        assert!(worst <= step, "largest difference {worst:e} vs step {step:e}");
        assert_eq!(b[0].unit.as_deref(), Some("µm"));
    }

    #[test]
    fn spectroscopy_and_text_data_are_refused() {
        let head = "fileType      Spectroscopy\nxPixels       2\n";
        assert!(Mi.read(head.as_bytes()).unwrap_err().contains("Spectroscopy"));
        let text = "fileType      Image\nxPixels       2\nyPixels       1\nbufferLabel   Topography\ndata          ASCII\n1 2\n";
        assert!(Mi.read(text.as_bytes()).unwrap_err().contains("ASCII"));
    }
}
