//! ISO 25178-71 Surface Data File (SDF), ASCII (`aISO-1.0`) and binary (`bISO-1.0`).
//!
//! The ASCII file is a `Key = value` header ending at a line `*`, then `NumProfiles` rows
//! (y) of `NumPoints` values (x) ending at the next `*`, then an optional trailer. The binary
//! file has a fixed 81-byte little-endian header followed by the values. A value times
//! `Zscale` is a height in metres; the point spacings `Xscale`, `Yscale` are in metres, so the
//! physical size is `NumPoints · Xscale` by `NumProfiles · Yscale`. `BAD` marks a missing point
//! in the ASCII variant.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

use super::reading::{Channel, Format};
use super::text;

pub struct Sdf;

const ASCII_MAGIC: &[u8] = b"aISO-1.0";
const BINARY_MAGIC: &[u8] = b"bISO-1.0";
/// Magic, ManufacID (10), CreateDate and ModDate (12 each), NumPoints and NumProfiles (u16),
/// Xscale, Yscale, Zscale, Zresolution (f64), Compression, DataType, CheckType (u8).
const BINARY_HEADER: usize = 8 + 10 + 12 + 12 + 2 + 2 + 4 * 8 + 3;

impl Format for Sdf {
    fn name(&self) -> &'static str {
        "sdf"
    }

    fn size_field(&self) -> &'static str {
        "Xscale and Yscale"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["sdf"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(ASCII_MAGIC) || head.starts_with(BINARY_MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let (header, data) = if bytes.starts_with(BINARY_MAGIC) {
            read_binary(bytes)?
        } else if bytes.starts_with(ASCII_MAGIC) {
            read_ascii(bytes)?
        } else {
            return Err("not an SDF file (no aISO-1.0 or bISO-1.0 magic)".into());
        };
        let data = data.mapv(|v| v * header.zscale);
        Ok(vec![Channel {
            name: "Default".into(),
            data,
            physical_size: Some((header.nx as f64 * header.xscale, header.ny as f64 * header.yscale)),
            unit: Some(unit_of(header.zscale).into()),
            is_height: true,
        }])
    }
}

/// The fields of an SDF header that shape the data.
struct Header {
    nx: usize,
    ny: usize,
    /// Point spacings [m] and the height of one stored unit [m].
    xscale: f64,
    yscale: f64,
    zscale: f64,
    data_type: u8,
}

impl Header {
    fn check(self) -> Result<Self, String> {
        if self.nx == 0 || self.ny == 0 {
            return Err(format!("NumPoints = {} and NumProfiles = {} must be positive", self.nx, self.ny));
        }
        for (key, v) in [("Xscale", self.xscale), ("Yscale", self.yscale), ("Zscale", self.zscale)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{key} = {v} is not a positive spacing in metres"));
            }
        }
        crate::plausible::height_factor(self.zscale, None).map_err(|e| format!("Zscale = {}: {e}", self.zscale))?;
        if self.data_type > 7 {
            return Err(format!("unknown DataType {}", self.data_type));
        }
        Ok(self)
    }
}

/// The stored unit a `Zscale` names when it is a whole unit, else metres (the values are then
/// in steps of `Zscale` metres).
fn unit_of(zscale: f64) -> &'static str {
    [("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9), ("pm", 1e-12)]
        .iter()
        .find(|(_, s)| (zscale / s - 1.0).abs() < 1e-9)
        .map_or("m", |(u, _)| u)
}

fn read_ascii(bytes: &[u8]) -> Result<(Header, Array2<f64>), String> {
    let text = text::decode(bytes)?;
    let mut lines = text.lines().enumerate().skip(1).map(|(i, l)| (i + 1, l.trim()));
    let mut fields = std::collections::HashMap::new();
    for (line_no, line) in lines.by_ref() {
        if line == "*" {
            break;
        }
        if line.is_empty() || line.starts_with(';') {
            continue;
        }
        let (key, value) = line
            .split_once('=')
            .ok_or_else(|| format!("line {line_no}: '{}' is not a 'Key = value' header line", text::excerpt(line)))?;
        fields.insert(key.trim().to_ascii_lowercase(), value.trim().to_string());
    }
    let get = |key: &str| fields.get(&key.to_ascii_lowercase()).ok_or_else(|| format!("the header has no {key}"));
    let int = |key: &str| -> Result<usize, String> {
        let v = get(key)?;
        v.parse().map_err(|_| format!("{key} = '{}' is not a count", text::excerpt(v)))
    };
    let float = |key: &str| -> Result<f64, String> {
        let v = get(key)?;
        text::number(v).ok_or_else(|| format!("{key} = '{}' is not a number", text::excerpt(v)))
    };
    if get("Compression").is_ok_and(|c| c != "0") {
        return Err("compressed SDF data is not supported".into());
    }
    let data_type = int("DataType")?;
    let header = Header {
        nx: int("NumPoints")?,
        ny: int("NumProfiles")?,
        xscale: float("Xscale")?,
        yscale: float("Yscale")?,
        zscale: float("Zscale")?,
        data_type: u8::try_from(data_type).unwrap_or(u8::MAX),
    }
    .check()?;

    // Values are collected as they come, so a header's counts never size an allocation.
    let mut values = Vec::new();
    let mut ended = false;
    for (line_no, line) in lines {
        if line == "*" {
            ended = true;
            break;
        }
        for token in line.split_whitespace() {
            let v = match token {
                "BAD" => f64::NAN,
                _ => text::number(token)
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("line {line_no}: '{}' is not a height", text::excerpt(token)))?,
            };
            values.push(v);
        }
    }
    if !ended {
        return Err("the data section has no closing '*' line: the file is truncated".into());
    }
    shape(header, values)
}

fn read_binary(bytes: &[u8]) -> Result<(Header, Array2<f64>), String> {
    if bytes.len() < BINARY_HEADER {
        return Err(format!("{} bytes are too few for the {BINARY_HEADER}-byte binary SDF header", bytes.len()));
    }
    let u16_at = |at: usize| usize::from(u16::from_le_bytes([bytes[at], bytes[at + 1]]));
    let f64_at = |at: usize| f64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    let header = Header {
        nx: u16_at(42),
        ny: u16_at(44),
        xscale: f64_at(46),
        yscale: f64_at(54),
        zscale: f64_at(62),
        data_type: bytes[79],
    }
    .check()?;
    if bytes[78] != 0 {
        return Err("compressed SDF data is not supported".into());
    }
    let width = [1, 2, 4, 4, 1, 2, 4, 8][usize::from(header.data_type)];
    let body = &bytes[BINARY_HEADER..];
    let n = header.nx.checked_mul(header.ny).filter(|n| n.checked_mul(width).is_some_and(|b| b <= body.len()));
    let Some(n) = n else {
        return Err(format!(
            "the header promises {} × {} values of {width} bytes but the file holds {} bytes of data: truncated",
            header.nx,
            header.ny,
            body.len()
        ));
    };
    let values = body[..n * width]
        .chunks_exact(width)
        .map(|b| match header.data_type {
            0 => f64::from(b[0]),
            1 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            2 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            3 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            4 => f64::from(b[0] as i8),
            5 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            6 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => f64::from_le_bytes(b.try_into().expect("8 bytes")),
        })
        .collect();
    shape(header, values)
}

fn shape(header: Header, values: Vec<f64>) -> Result<(Header, Array2<f64>), String> {
    if header.nx.checked_mul(header.ny) != Some(values.len()) {
        return Err(format!(
            "the header promises {} × {} values but the data section holds {}",
            header.nx,
            header.ny,
            values.len()
        ));
    }
    if let Some(i) = values.iter().position(|v| v.is_infinite()) {
        return Err(format!("value {i} is infinite"));
    }
    let data = Array2::from_shape_vec((header.ny, header.nx), values).map_err(|e| e.to_string())?;
    Ok((header, data))
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;

    #[test]
    fn ascii_sample() {
        let ch = Sdf.read(&testing::sample("sdf-1.sdf")).unwrap();
        assert_eq!(ch[0].data.dim(), (4, 7));
        assert!((ch[0].data[(3, 5)] - 0.94907e-6).abs() < 1e-18);
        assert_eq!(ch[0].physical_size, Some((7.0 * 1e-6, 4.0 * 1e-6)));
        assert_eq!(ch[0].unit.as_deref(), Some("µm"));
    }

    /// A binary SDF of int16 values, 3 points × 2 profiles, written field by field.
    fn binary(nx: u16, ny: u16, values: &[i16]) -> Vec<u8> {
        let mut b = BINARY_MAGIC.to_vec();
        b.extend_from_slice(b"ManufactID");
        b.extend_from_slice(b"010120250000010120250000");
        b.extend_from_slice(&nx.to_le_bytes());
        b.extend_from_slice(&ny.to_le_bytes());
        for s in [2e-9, 3e-9, 1e-9, 1e-12] {
            b.extend_from_slice(&f64::to_le_bytes(s));
        }
        b.extend_from_slice(&[0, 5, 0]);
        assert_eq!(b.len(), BINARY_HEADER);
        for v in values {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    #[test]
    fn binary_int16() {
        let ch = Sdf.read(&binary(3, 2, &[1, -2, 3, 4, 5, -32768])).unwrap();
        assert_eq!(ch[0].data.dim(), (2, 3));
        assert_eq!(ch[0].data[(0, 1)], -2e-9);
        assert_eq!(ch[0].data[(1, 2)], -32768.0 * 1e-9);
        let (lx, ly) = ch[0].physical_size.unwrap();
        assert!((lx - 6e-9).abs() < 1e-24 && (ly - 6e-9).abs() < 1e-24);
        assert_eq!(ch[0].unit.as_deref(), Some("nm"));
    }

    #[test]
    fn declared_sizes_are_checked_before_use() {
        let e = Sdf.read(&binary(65535, 65535, &[1, 2, 3])).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let huge = String::from_utf8(testing::sample("sdf-1.sdf"))
            .unwrap()
            .replace("NumPoints = 7", "NumPoints = 1000000")
            .replace("NumProfiles = 4", "NumProfiles = 1000000");
        let e = Sdf.read(huge.as_bytes()).unwrap_err();
        assert!(e.contains("promises 1000000 × 1000000 values but the data section holds 28"), "{e}");
        let cut = &testing::sample("sdf-1.sdf")[..300];
        assert!(Sdf.read(cut).unwrap_err().contains("truncated"));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn mutated_ascii_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(testing::sample("sdf-1.sdf"), &edits);
            prop_assert!(testing::one_line(&Sdf.read(&bytes)));
        }

        #[test]
        fn mutated_binary_never_panics(edits in testing::edits()) {
            let bytes = testing::apply(binary(3, 2, &[1, -2, 3, 4, 5, 6]), &edits);
            prop_assert!(testing::one_line(&Sdf.read(&bytes)));
        }

        #[test]
        fn arbitrary_after_magic_never_panics(tail in testing::texts(), binary in any::<bool>()) {
            let mut bytes = if binary { BINARY_MAGIC } else { ASCII_MAGIC }.to_vec();
            bytes.extend(tail);
            prop_assert!(testing::one_line(&Sdf.read(&bytes)));
        }
    }
}
