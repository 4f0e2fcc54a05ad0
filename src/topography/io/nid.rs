//! Nanosurf `.nid` (and the older `.ezd`).
//!
//! An INI-style text header: `[DataSet]` lists the groups (`Gr0-Name=Scan forward`) and their
//! channels (`Gr0-Ch1=DataSet-0:1`); each `[DataSet-G:C]` section gives the grid (`Points`,
//! `Lines`), the axes (`Dim0Range`, `Dim0Unit`, … `Dim2Name`, `Dim2Unit`, `Dim2Range`,
//! `Dim2Min`) and the storage (`SaveBits`, `SaveSign`, `SaveOrder`). After a `#!` marker the
//! channels follow one after the other in the order of that list. The stored integers span
//! `[Dim2Min, Dim2Min + Dim2Range]`. Lines are stored bottom first; they are returned top first.
//!
//! Only the topography channels (those whose `Dim2Unit` is a length) are listed, named
//! `Frame (Dim2Name)`, e.g. "Scan forward (Z-Axis)"; force and voltage channels are skipped.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Endian, Sample, Stored};
use super::reading::{Channel, Format};
use crate::quantity::metres_per;

pub struct Nid;

impl Format for Nid {
    fn name(&self) -> &'static str {
        "nid"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["nid", "ezd"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.strip_prefix(b"\xef\xbb\xbf").unwrap_or(head).starts_with(b"[DataSet]")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// Every channel of the file; errors may quote the file's own (possibly corrupt) text.
fn decode(bytes: &[u8]) -> Result<Vec<Channel>, String> {
    let data_start = bytes
        .windows(3)
        .position(|w| w == b"\n#!")
        .map(|i| i + 3)
        .ok_or("not a Nanosurf file: no '#!' marker before the data")?;
    let header = Ini::parse(&String::from_utf8_lossy(&bytes[..data_start - 3]));
    let dataset = header.section("DataSet").ok_or("not a Nanosurf file: no [DataSet] section")?;

    // `GrG-ChC=DataSet-G:C` entries in (G, C) order: the order of the data blocks.
    let mut list: Vec<((usize, usize), &str)> = dataset
        .iter()
        .filter_map(|(k, v)| {
            let (g, c) = k.strip_prefix("Gr")?.split_once("-Ch")?;
            Some(((g.parse().ok()?, c.parse().ok()?), v.as_str()))
        })
        .collect();
    list.sort_by_key(|&(gc, _)| gc);
    if list.is_empty() {
        return Err("the Nanosurf header lists no channel".into());
    }

    let mut offset = data_start;
    let mut channels = Vec::new();
    for ((g, _), section) in list {
        let quoted = binary::printable(section);
        let s =
            header.section(section).ok_or_else(|| format!("the header lists [{quoted}] but has no such section"))?;
        let block = Block::parse(s).map_err(|e| format!("[{quoted}]: {e}"))?;
        let len = block.bytes().map_err(|e| format!("[{quoted}]: {e}"))?;
        let here = offset;
        offset = offset.checked_add(len).ok_or("the declared data size overflows")?;
        // Every block must be present, also those not returned: a short file is truncated.
        binary::extent(bytes, here, len, &format!("[{quoted}]"))?;
        let Some(to_metres) = metres_per(&block.z_unit) else { continue };
        let frame = block
            .frame
            .clone()
            .or_else(|| dataset.get(&format!("Gr{g}-Name")).cloned())
            .unwrap_or_else(|| format!("Group {g}"));
        let name = format!("{frame} ({})", block.z_name);
        let step = block.z_range / 2f64.powi(block.bits as i32);
        // Signed integers are centred on the middle of the range.
        let base = block.z_min + if block.signed { block.z_range * 0.5 } else { 0.0 };
        let data =
            binary::grid(bytes, here, (block.nx, block.ny), block.stored(), &name, |v| (base + v * step) * to_metres)?;
        channels.push(Channel {
            name,
            data,
            physical_size: block.physical_size,
            unit: Some(block.z_unit),
            is_height: true,
        });
    }
    if channels.is_empty() {
        return Err("the Nanosurf file holds no topography channel (no channel in a length unit)".into());
    }
    Ok(channels)
}

/// A section's `(key, value)` entries in file order, with the index of each key's first entry.
type Entries = (Vec<(String, String)>, HashMap<String, usize>);

/// INI sections in file order, each with its `(key, value)` entries, indexed once so that each
/// lookup is constant time whatever the number of sections and keys (the first of repeated
/// names counts).
struct Ini {
    sections: Vec<Entries>,
    index: HashMap<String, usize>,
}

impl Ini {
    fn parse(text: &str) -> Ini {
        let mut ini = Ini { sections: Vec::new(), index: HashMap::new() };
        for line in text.lines() {
            let line = line.trim();
            if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
                ini.index.entry(name.to_string()).or_insert(ini.sections.len());
                ini.sections.push((Vec::new(), HashMap::new()));
            } else if let (Some((k, v)), Some((entries, keys))) = (line.split_once('='), ini.sections.last_mut()) {
                keys.entry(k.trim().to_string()).or_insert(entries.len());
                entries.push((k.trim().to_string(), v.trim().to_string()));
            }
        }
        ini
    }

    fn section(&self, name: &str) -> Option<Section<'_>> {
        self.index.get(name).map(|&i| Section(&self.sections[i].0, &self.sections[i].1))
    }
}

#[derive(Clone, Copy)]
struct Section<'a>(&'a [(String, String)], &'a HashMap<String, usize>);

impl<'a> Section<'a> {
    fn get(&self, key: &str) -> Option<&'a String> {
        self.1.get(key).map(|&i| &self.0[i].1)
    }

    fn iter(&self) -> impl Iterator<Item = &'a (String, String)> {
        self.0.iter()
    }
}

/// One `[DataSet-G:C]` section: how its block is stored and scaled.
struct Block {
    nx: usize,
    ny: usize,
    bits: u32,
    sample: Sample,
    signed: bool,
    endian: Endian,
    frame: Option<String>,
    z_name: String,
    z_unit: String,
    z_range: f64,
    z_min: f64,
    physical_size: Option<(f64, f64)>,
}

impl Block {
    fn parse(s: Section) -> Result<Block, String> {
        let text = |k: &str| s.get(k).map(String::as_str).ok_or_else(|| format!("no {k}"));
        let count = |k: &str| text(k)?.parse::<usize>().map_err(|_| format!("{k} is not a count"));
        let number = |k: &str| match text(k)?.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("{k} is not a number")),
        };
        if let Some(mode) = s.get("SaveMode").filter(|m| !m.eq_ignore_ascii_case("Binary")) {
            return Err(format!("SaveMode '{mode}' is not supported (only Binary)"));
        }
        let signed = !s.get("SaveSign").is_some_and(|v| v.eq_ignore_ascii_case("Unsigned"));
        let bits = count("SaveBits")?;
        let sample = match (bits, signed) {
            (16, true) => Sample::I16,
            (16, false) => Sample::U16,
            (32, true) => Sample::I32,
            (32, false) => Sample::U32,
            _ => return Err(format!("SaveBits {bits} is not supported (16 or 32)")),
        };
        let endian = match s.get("SaveOrder").map(String::as_str) {
            None | Some("Intel") => Endian::Little,
            Some("Motorola") => Endian::Big,
            Some(o) => return Err(format!("unknown SaveOrder '{o}'")),
        };
        let size = |d: u8| -> Option<f64> {
            let m = metres_per(&binary::normalise_unit(s.get(&format!("Dim{d}Unit"))?))?;
            let l = number(&format!("Dim{d}Range")).ok()? * m;
            (l > 0.0).then_some(l)
        };
        Ok(Block {
            nx: count("Points")?,
            ny: count("Lines")?,
            bits: bits as u32,
            sample,
            signed,
            endian,
            frame: s.get("Frame").cloned(),
            z_name: text("Dim2Name")?.to_string(),
            z_unit: binary::normalise_unit(text("Dim2Unit")?),
            z_range: number("Dim2Range")?,
            z_min: number("Dim2Min")?,
            physical_size: size(0).zip(size(1)),
        })
    }

    /// Storage of the block: lines bottom first.
    fn stored(&self) -> Stored {
        Stored { sample: self.sample, endian: self.endian, bottom_first: true }
    }

    /// Size of the block in bytes, checked.
    fn bytes(&self) -> Result<usize, String> {
        binary::grid_points(self.nx, self.ny)?
            .checked_mul(self.sample.size())
            .ok_or_else(|| "the declared data size overflows".to_string())
    }
}
