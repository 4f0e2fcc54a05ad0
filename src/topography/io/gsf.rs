//! Gwyddion Simple Field (`.gsf`): reader and writer.
//!
//! The file is the line `Gwyddion Simple Field 1.0`, a header of `Name = value` lines (UTF-8),
//! one to four NUL bytes that bring the header to a multiple of four bytes, then
//! `XRes · YRes` little-endian float32 values, row by row (rows = y). `XRes`, `YRes` are
//! required; `XReal`, `YReal` are the physical sizes in `XYUnits`, the values are in `ZUnits`,
//! `Title` names the channel. A size without a unit is no physical size, and is left to the user.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::Write;
use std::path::Path;

use ndarray::Array2;

use super::reading::{Channel, Format};
use super::text;
use crate::error::{Error, Result};
use crate::output;
use crate::quantity::metres_per;
use crate::topography::map::Topography;

pub struct Gsf;

const MAGIC: &[u8] = b"Gwyddion Simple Field 1.0\n";

impl Format for Gsf {
    fn name(&self) -> &'static str {
        "gsf"
    }

    fn size_field(&self) -> &'static str {
        "XReal and YReal"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["gsf"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> std::result::Result<Vec<Channel>, String> {
        if !bytes.starts_with(MAGIC) {
            return Err("not a Gwyddion Simple Field file (no 'Gwyddion Simple Field 1.0' line)".into());
        }
        let nul = bytes.iter().position(|&b| b == 0).ok_or("the header has no NUL padding: the file is truncated")?;
        let data_start = (nul / 4 + 1) * 4;
        if bytes.len() < data_start || bytes[nul..data_start].iter().any(|&b| b != 0) {
            return Err("the header's NUL padding is broken".into());
        }
        let header = text::decode(&bytes[MAGIC.len()..nul])?;
        let mut fields = std::collections::HashMap::new();
        for (i, line) in header.lines().enumerate() {
            if line.trim().is_empty() {
                continue;
            }
            let (key, value) = line
                .split_once('=')
                .ok_or_else(|| format!("header line {} ('{}') is not 'Name = value'", i + 2, text::excerpt(line)))?;
            fields.insert(key.trim(), value.trim());
        }
        let count = |key: &str| -> std::result::Result<usize, String> {
            let v = fields.get(key).ok_or_else(|| format!("the header has no {key}"))?;
            v.parse()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("{key} = '{}' is not a positive count", text::excerpt(v)))
        };
        let (nx, ny) = (count("XRes")?, count("YRes")?);
        let body = &bytes[data_start..];
        // The header's counts are checked against the bytes present before anything is allocated.
        if nx.checked_mul(ny).and_then(|n| n.checked_mul(4)) != Some(body.len()) {
            return Err(format!(
                "the header promises {nx} × {ny} float32 values ({} bytes) but {} bytes follow it",
                nx as u128 * ny as u128 * 4,
                body.len()
            ));
        }
        let values = body.chunks_exact(4).map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])));
        let values = crate::limits::collected(values, "the values")?;
        let mut data = Array2::from_shape_vec((ny, nx), values).map_err(|e| e.to_string())?;
        if let Some(i) = data.iter().position(|v| v.is_infinite()) {
            return Err(format!("value {i} (row {}, column {}) is infinite", i / nx, i % nx));
        }

        let real = |key: &str| -> std::result::Result<Option<f64>, String> {
            fields
                .get(key)
                .map(|v| {
                    text::number(v)
                        .filter(|r| r.is_finite() && *r > 0.0)
                        .ok_or_else(|| format!("{key} = '{}' is not a positive size", text::excerpt(v)))
                })
                .transpose()
        };
        let (xreal, yreal) = (real("XReal")?, real("YReal")?);
        let lateral = fields.get("XYUnits").and_then(|u| metres_per(u));
        let physical_size = match (xreal, yreal, lateral) {
            (Some(lx), Some(ly), Some(s)) => Some((lx * s, ly * s)),
            _ => None,
        };
        let unit = fields.get("ZUnits").filter(|u| !u.is_empty()).map(|u| u.to_string());
        let scale = unit.as_deref().and_then(metres_per);
        if let Some(s) = scale {
            data.mapv_inplace(|h| h * s);
        }
        Ok(vec![Channel {
            name: fields.get("Title").filter(|t| !t.is_empty()).map_or("default", |t| t).to_string(),
            data,
            physical_size,
            is_height: unit.is_none() || scale.is_some(),
            unit,
        }])
    }
}

/// Write `topo` as a Gwyddion Simple Field file, atomically: heights in metres as float32 (the
/// format's only type, so values are rounded to float32), `NaN` for missing points, the
/// physical size in metres when known.
pub fn write_gsf(path: &Path, topo: &Topography) -> Result<()> {
    if let Some(h) = topo.heights.iter().find(|h| h.is_finite() && !(h.abs() as f32).is_finite()) {
        return Err(Error::file(path, format!("height {h} m is beyond the float32 range of .gsf")));
    }
    let mut header = String::from_utf8(MAGIC.to_vec()).expect("ASCII magic");
    header += &format!("XRes = {}\nYRes = {}\n", topo.nx(), topo.ny());
    if let Some((lx, ly)) = topo.physical_size {
        header += &format!("XReal = {lx:e}\nYReal = {ly:e}\nXYUnits = m\n");
    }
    // A title is one header line: line breaks and NULs in a channel name would end it.
    let title: String = topo.channel.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    header += &format!("ZUnits = m\nTitle = {title}\n");
    let padding = 4 - header.len() % 4;
    output::write_atomic(path, |w: &mut dyn Write| {
        w.write_all(header.as_bytes())?;
        w.write_all(&[0; 4][..padding])?;
        for &h in &topo.heights {
            w.write_all(&(h as f32).to_le_bytes())?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::text::testing;
    use super::*;
    use crate::topography::map::Provenance;

    #[test]
    fn wafer_sample() {
        let ch = Gsf.read(&testing::sample("wafer-roughness.gsf")).unwrap();
        assert_eq!(ch[0].name, "Height");
        assert_eq!(ch[0].data.dim(), (96, 128));
        assert_eq!(ch[0].physical_size, Some((5e-06, 3.7500000000000005e-06)));
        assert_eq!(ch[0].unit.as_deref(), Some("m"));
        // The first value, bytes 72 ff 70 b1 after the 132-byte header.
        assert_eq!(ch[0].data[(0, 0)], f64::from(f32::from_le_bytes([0x72, 0xff, 0x70, 0xb1])));
    }

    fn gsf(header: &str, values: usize) -> Vec<u8> {
        let mut b = [MAGIC, header.as_bytes()].concat();
        b.resize((b.len() / 4 + 1) * 4 + 4 * values, 0);
        b
    }

    #[test]
    fn declared_sizes_are_checked_before_use() {
        let e = Gsf.read(&gsf("XRes = 1000000\nYRes = 1000000\n", 4)).unwrap_err();
        assert!(e.contains("promises 1000000 × 1000000 float32 values (4000000000000 bytes) but 16 bytes"), "{e}");
        let e = Gsf.read(&gsf("XRes = 18446744073709551615\nYRes = 2\n", 4)).unwrap_err();
        assert!(e.contains("but 16 bytes follow"), "{e}");
        assert!(Gsf.read(&gsf("XRes = 2\n", 4)).unwrap_err().contains("no YRes"));
        assert!(Gsf.read(&gsf("XRes = 0\nYRes = 2\n", 0)).unwrap_err().contains("not a positive count"));
        let cut = &testing::sample("wafer-roughness.gsf")[..1000];
        assert!(Gsf.read(cut).unwrap_err().contains("but 868 bytes follow"));
    }

    #[test]
    fn size_without_unit_or_nm_values() {
        let ch = Gsf.read(&gsf("XRes = 2\nYRes = 2\nXReal = 3\nYReal = 4\nZUnits = nm\n", 4)).unwrap();
        assert_eq!(ch[0].physical_size, None);
        assert_eq!(ch[0].name, "default");
        assert!(ch[0].is_height);
        let ch = Gsf.read(&gsf("XRes = 2\nYRes = 2\nXReal = 3\nYReal = 4\nXYUnits = um\nZUnits = V\n", 4)).unwrap();
        assert_eq!(ch[0].physical_size, Some((3e-6, 4e-6)));
        assert!(!ch[0].is_height);
    }

    #[test]
    fn header_padding_fills_to_four_bytes() {
        let dir = tempfile::tempdir().unwrap();
        for name_len in 0..4 {
            let topo = Topography {
                heights: Array2::from_elem((2, 3), 1e-9),
                physical_size: None,
                periodic: false,
                height_unit_known: true,
                channel: "h".repeat(name_len),
                provenance: Provenance::default(),
            };
            let path = dir.path().join("t.gsf");
            write_gsf(&path, &topo).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            assert_eq!(bytes.len() % 4, 0);
            let ch = Gsf.read(&bytes).unwrap();
            assert_eq!(ch[0].data.dim(), (2, 3));
        }
    }

    #[test]
    fn overflowing_heights_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let topo = Topography {
            heights: Array2::from_elem((2, 2), 1e39),
            physical_size: None,
            periodic: false,
            height_unit_known: true,
            channel: "h".into(),
            provenance: Provenance::default(),
        };
        let path = dir.path().join("t.gsf");
        assert!(write_gsf(&path, &topo).unwrap_err().to_string().contains("beyond the float32 range"));
        assert!(!path.exists());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        #[test]
        fn mutated_sample_never_panics(edits in testing::edits()) {
            let valid = gsf("XRes = 3\nYRes = 2\nXReal = 1e-6\nYReal = 1e-6\nXYUnits = m\nZUnits = m\nTitle = H\n", 6);
            let bytes = testing::apply(valid, &edits);
            prop_assert!(testing::one_line(&Gsf.read(&bytes)));
        }

        #[test]
        fn arbitrary_header_never_panics(header in testing::texts(), values in 0usize..64) {
            prop_assert!(testing::one_line(&Gsf.read(&gsf(&String::from_utf8_lossy(&header), values))));
        }
    }
}
