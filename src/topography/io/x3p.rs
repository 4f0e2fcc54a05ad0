//! ISO 25178-71 / ISO 5436-2 `.x3p`: a zip container holding `main.xml` and the point data.
//!
//! `main.xml` describes the axes (`Record1/Axes/CX|CY|CZ`: `AxisType`, `DataType`,
//! `Increment`, `Offset`), the grid (`Record3/MatrixDimension/SizeX|SizeY|SizeZ`) and where
//! the data are (`Record3/DataLink/PointDataLink`, optionally `ValidPointsLink`). The point
//! data are little-endian `I` (i16), `L` (i32), `F` (f32) or `D` (f64) values, x fastest;
//! z = Offset + Increment · value, in metres. The optional validity file holds one bit per
//! point, least significant bit first: 0 marks a missing point, as does NaN in float data.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::{Cursor, Read};

use ndarray::Array2;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::limits::Limits;

pub struct X3p;

/// `main.xml` is a few kilobytes; anything inflating past this is not one.
const MAX_MAIN_XML: u64 = 16 << 20;

impl Format for X3p {
    fn name(&self) -> &'static str {
        "x3p"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["x3p"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        // A zip whose first entry is main.xml or the point data; other zips go by extension.
        head.starts_with(b"PK\x03\x04")
            && (head.get(30..38) == Some(b"main.xml") || head.get(30..38) == Some(b"bindata/"))
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        decode(bytes, limits).map_err(binary::one_line)
    }
}

/// Every channel of the file, its grid within `limits` before its data are inflated; errors
/// may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
    let mut zip =
        zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| format!("not a readable x3p (zip) file: {e}"))?;
    let xml = entry(&mut zip, "main.xml", MAX_MAIN_XML, bytes.len())?;
    let xml = String::from_utf8(xml).map_err(|_| "main.xml is not UTF-8 text".to_string())?;
    let doc = roxmltree::Document::parse(&xml).map_err(|e| format!("main.xml: {e}"))?;
    let m = Main::parse(&doc)?;

    let n = binary::grid_points(m.nx, m.ny)?;
    limits.check_grid(m.nx, m.ny)?;
    let len = n.checked_mul(m.sample.size()).ok_or("the declared data size overflows")?;
    let raw = entry(&mut zip, &m.data_link, len as u64, bytes.len())?;
    if raw.len() != len {
        return Err(format!(
            "{}: {} bytes where a {} x {} grid of {}-byte values needs {len}",
            m.data_link,
            raw.len(),
            m.nx,
            m.ny,
            m.sample.size()
        ));
    }
    let (inc, off) = (m.z_increment, m.z_offset);
    let stored = Stored { sample: m.sample, endian: Endian::Little, bottom_first: false };
    let mut data = binary::grid(&raw, 0, (m.nx, m.ny), stored, &m.data_link, |v| off + inc * v)?;
    if let Some(link) = &m.valid_link {
        let bits = entry(&mut zip, link, n.div_ceil(8) as u64, bytes.len())?;
        apply_validity(&mut data, &bits).map_err(|e| format!("{link}: {e}"))?;
    }
    Ok(vec![Channel {
        name: "Default".into(),
        data,
        physical_size: Some((m.nx as f64 * m.dx, m.ny as f64 * m.dy)),
        unit: Some("m".into()),
        is_height: true,
    }])
}

/// The content of the zip entry `name`, inflated as a stream and stopped at `limit` bytes
/// (plus one, so that an entry longer than expected shows). Room is made beforehand only for what the compressed bytes
/// present in the file (`file_len` in all) can plausibly inflate to; past that the buffer grows
/// with the bytes actually inflated, never to a size the archive merely declares.
fn entry<R: Read + std::io::Seek>(
    zip: &mut zip::ZipArchive<R>,
    name: &str,
    limit: u64,
    file_len: usize,
) -> Result<Vec<u8>, String> {
    let f = zip.by_name(name).map_err(|e| format!("{name}: {e}"))?;
    // Deflate rarely shrinks measured heights below a quarter of their size.
    let plausible = f.compressed_size().min(file_len as u64).saturating_mul(4).min(limit);
    let mut out = Vec::with_capacity(usize::try_from(plausible).unwrap_or(0));
    f.take(limit.saturating_add(1)).read_to_end(&mut out).map_err(|e| format!("{name}: {e}"))?;
    if out.len() as u64 > limit {
        return Err(format!("{name}: larger than the {limit} bytes the header declares"));
    }
    Ok(out)
}

/// Mark as missing (NaN) the points whose validity bit is 0.
fn apply_validity(data: &mut Array2<f64>, bits: &[u8]) -> Result<(), String> {
    let n = data.len();
    if bits.len() < n.div_ceil(8) {
        return Err(format!("{} bytes of validity bits for {n} points", bits.len()));
    }
    for (i, h) in data.iter_mut().enumerate() {
        if bits[i / 8] >> (i % 8) & 1 == 0 {
            *h = f64::NAN;
        }
    }
    Ok(())
}

/// What `main.xml` says about the surface.
struct Main {
    nx: usize,
    ny: usize,
    dx: f64,
    dy: f64,
    sample: Sample,
    z_increment: f64,
    z_offset: f64,
    data_link: String,
    valid_link: Option<String>,
}

impl Main {
    fn parse(doc: &roxmltree::Document) -> Result<Main, String> {
        let root = doc.root_element();
        let record1 = child(root, "Record1")?;
        let record3 = child(root, "Record3")?;
        let feature = text(child(record1, "FeatureType")?);
        if feature != "SUR" {
            return Err(format!("x3p feature type '{feature}' is not a surface (SUR)"));
        }
        let axes = child(record1, "Axes")?;
        let (cx, cy, cz) = (child(axes, "CX")?, child(axes, "CY")?, child(axes, "CZ")?);
        for (axis, name) in [(cx, "CX"), (cy, "CY")] {
            let t = text(child(axis, "AxisType")?);
            if t != "I" {
                return Err(format!("x3p axis {name} of type '{t}': only incremental (I) x and y axes are supported"));
            }
        }
        let increment = |axis, name: &str| -> Result<f64, String> {
            match number(axis, "Increment")? {
                Some(d) if d > 0.0 => Ok(d),
                _ => Err(format!("x3p axis {name} has no positive Increment")),
            }
        };
        let sample = match text(child(cz, "DataType")?) {
            "I" => Sample::I16,
            "L" => Sample::I32,
            "F" => Sample::F32,
            "D" => Sample::F64,
            t => return Err(format!("unknown x3p data type '{t}' (I, L, F or D)")),
        };
        let dims = child(record3, "MatrixDimension")?;
        let size = |name: &str| -> Result<usize, String> {
            let t = text(child(dims, name)?);
            t.parse().map_err(|_| format!("x3p {name} is not a count: '{t}'"))
        };
        if size("SizeZ")? != 1 {
            return Err("x3p files with several layers (SizeZ > 1) are not supported".into());
        }
        let Ok(link) = child(record3, "DataLink") else {
            return Err("x3p point data stored in main.xml (DataList) are not supported, only binary data".into());
        };
        Ok(Main {
            nx: size("SizeX")?,
            ny: size("SizeY")?,
            dx: increment(cx, "CX")?,
            dy: increment(cy, "CY")?,
            sample,
            z_increment: number(cz, "Increment")?.unwrap_or(1.0),
            z_offset: number(cz, "Offset")?.unwrap_or(0.0),
            data_link: text(child(link, "PointDataLink")?).to_string(),
            valid_link: child(link, "ValidPointsLink").ok().map(|n| text(n).to_string()).filter(|l| !l.is_empty()),
        })
    }
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Result<roxmltree::Node<'a, 'i>, String> {
    node.children()
        .find(|c| c.has_tag_name(name))
        .ok_or_else(|| format!("main.xml: no <{name}> in <{}>", node.tag_name().name()))
}

fn text<'a>(node: roxmltree::Node<'a, '_>) -> &'a str {
    node.text().unwrap_or("").trim()
}

/// An optional numeric child element; present but not a finite number is an error.
fn number(node: roxmltree::Node, name: &str) -> Result<Option<f64>, String> {
    let Ok(c) = child(node, name) else { return Ok(None) };
    match text(c).parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(Some(x)),
        _ => Err(format!("main.xml: <{name}> is not a number: '{}'", text(c))),
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::*;

    /// The main.xml of an x3p of `nx` × `ny` points of type `ty`.
    fn main_xml(ty: &str, (nx, ny): (usize, usize), valid: bool, feature: &str) -> String {
        let valid_link = if valid { "<ValidPointsLink>bindata/valid.bin</ValidPointsLink>" } else { "" };
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">
  <Record1><Revision>ISO5436 - 2000</Revision><FeatureType>{feature}</FeatureType>
    <Axes>
      <CX><AxisType>I</AxisType><DataType>D</DataType><Increment>2.5e-7</Increment><Offset>0</Offset></CX>
      <CY><AxisType>I</AxisType><DataType>D</DataType><Increment>5e-7</Increment><Offset>0</Offset></CY>
      <CZ><AxisType>A</AxisType><DataType>{ty}</DataType><Increment>1e-9</Increment><Offset>1e-6</Offset></CZ>
    </Axes>
  </Record1>
  <Record3><MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>
    <DataLink><PointDataLink>bindata/data.bin</PointDataLink>{valid_link}</DataLink>
  </Record3>
</p:ISO5436_2>"#
        )
    }

    /// An x3p of `nx` × `ny` points of type `ty` with the given raw data and validity bits.
    fn x3p(ty: &str, grid: (usize, usize), data: &[u8], valid: Option<&[u8]>, feature: &str) -> Vec<u8> {
        let xml = main_xml(ty, grid, valid.is_some(), feature);
        let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let opts = zip::write::SimpleFileOptions::default();
        let mut files = vec![("main.xml", xml.as_bytes()), ("bindata/data.bin", data)];
        files.extend(valid.map(|v| ("bindata/valid.bin", v)));
        for (name, content) in files {
            w.start_file(name, opts).unwrap();
            w.write_all(content).unwrap();
        }
        w.finish().unwrap().into_inner()
    }

    #[test]
    fn integer_data_are_scaled_and_masked() {
        // 3 × 2 points of type L: z = 1e-6 + 1e-9 · raw; points 1 and 5 invalid.
        let raw: Vec<u8> = [0i32, 1, 2, 3, -4, 5].iter().flat_map(|v| v.to_le_bytes()).collect();
        let bytes = x3p("L", (3, 2), &raw, Some(&[0b0001_1101]), "SUR");
        let ch = X3p.read(&bytes).unwrap();
        let d = &ch[0].data;
        assert_eq!(d.dim(), (2, 3));
        assert!(d[[0, 1]].is_nan() && d[[1, 2]].is_nan());
        for (got, want) in [(d[[0, 0]], 1e-6), (d[[0, 2]], 1.002e-6), (d[[1, 0]], 1.003e-6), (d[[1, 1]], 0.996e-6)] {
            assert!((got - want).abs() < 1e-18, "{got} vs {want}");
        }
        let (lx, ly) = ch[0].physical_size.unwrap();
        assert!((lx - 7.5e-7).abs() < 1e-20 && (ly - 1e-6).abs() < 1e-20);
    }

    #[test]
    fn zip_bombs_are_refused_before_they_inflate() {
        // A stream of zeros through the deflate encoder: 64 MB in about 64 kB.
        let zeros = vec![0u8; 64 << 20];
        let bomb = |grid| {
            let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
            let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
            let main = main_xml("D", grid, false, "SUR");
            w.start_file("main.xml", opts).unwrap();
            w.write_all(main.as_bytes()).unwrap();
            w.start_file("bindata/data.bin", opts).unwrap();
            w.write_all(&zeros).unwrap();
            w.finish().unwrap().into_inner()
        };
        // Self-consistent but over the point limit: refused before a byte is inflated.
        let big = bomb((20000, 20000));
        assert!(big.len() < 1 << 20, "{} bytes", big.len());
        let e = X3p.read(&big).unwrap_err();
        assert!(e.contains("20000 × 20000") && e.contains("--max-points"), "{e}");
        let e = X3p.read_within(&big, &Limits::new(1000, "--max-points").unwrap()).unwrap_err();
        assert!(e.contains("limit of 1000 points"), "{e}");
        // A small grid whose entry inflates past its size: inflating stops one byte after it.
        let e = X3p.read(&bomb((16, 16))).unwrap_err();
        assert!(e.contains("larger than the 2048 bytes"), "{e}");
    }

    #[test]
    fn sixteen_bit_data_and_refusals() {
        let raw: Vec<u8> = [-1i16, 7].iter().flat_map(|v| v.to_le_bytes()).collect();
        let ch = X3p.read(&x3p("I", (2, 1), &raw, None, "SUR")).unwrap();
        assert!((ch[0].data[[0, 1]] - 1.007e-6).abs() < 1e-18);
        assert!(X3p.read(&x3p("I", (2, 1), &raw, None, "PRF")).unwrap_err().contains("not a surface"));
        // The header promises 3 points, the data hold 2.
        let err = X3p.read(&x3p("I", (3, 1), &raw, None, "SUR")).unwrap_err();
        assert!(err.contains("bindata/data.bin") && err.contains("needs 6"), "{err}");
        assert!(X3p.read(&x3p("Q", (2, 1), &raw, None, "SUR")).unwrap_err().contains("data type"));
    }
}
