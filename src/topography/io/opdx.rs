//! Bruker Dektak OPDx (`.opdx`, Vision64 software of the Dektak XT stylus profilometers).
//!
//! A magic `VCA DATA\x01\x00\x00\x55`, then a tree of items, each a name (`u32` length and
//! UTF-8), a type byte and a value whose layout the type gives; containers hold items up to a
//! terminator. A line profile (`/MetaData/DataKind` `Surface Profile`) names its channels in
//! `/MetaData/1D_Channels/Height`; channel `C` holds under `/1D_Data/C` its `NumPoints`, its
//! `Extent` (the distance from the first point to the last, a quantity with a unit), its
//! `DataScale` (the height per stored value, with a unit) and its `Array` of `f64` values
//! after a 5-byte prefix. Maps (`Surface Height`) are refused: no sample of one was at hand to
//! check a reader against.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::collections::HashMap;

use super::binary::{self, Cursor, Endian};
use super::columns;
use super::reading::{ProfileData, ProfileFormat};

pub struct Opdx;

const MAGIC: &[u8] = b"VCA DATA\x01\x00\x00\x55";
/// Bytes before the values of a double array.
const ARRAY_PREFIX: usize = 5;
/// Containers nest no deeper in files Vision64 writes; a deeper tree is damage.
const MAX_DEPTH: usize = 32;

impl ProfileFormat for Opdx {
    fn name(&self) -> &'static str {
        "opdx"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["opdx"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<ProfileData, String> {
        decode(bytes).map_err(binary::one_line)
    }
}

/// The value of an item, as far as the reader needs it.
enum Value {
    Number(f64),
    Text(String),
    List(Vec<String>),
    /// A quantity: its value and unit symbol.
    Quantity(f64, String),
    /// Where an array's bytes lie in the file: offset and length.
    Array(usize, usize),
    /// What the reader does not use (time stamps, type ids, matrices, position functions).
    Other,
}

fn decode(bytes: &[u8]) -> Result<ProfileData, String> {
    if !bytes.starts_with(MAGIC) {
        return Err("not a Dektak OPDx file (no 'VCA DATA' magic)".into());
    }
    let mut c = Cursor::new(bytes, Endian::Little);
    c.skip(MAGIC.len(), "the magic")?;
    let mut items = HashMap::new();
    while c.pos() < bytes.len() && item(&mut c, "", 0, &mut items)? {}

    let text = |key: &str| match items.get(key) {
        Some(Value::Text(s)) => Some(s.as_str()),
        _ => None,
    };
    let kind = text("/MetaData/DataKind").unwrap_or("");
    let has = |prefix: &str| items.keys().any(|k| k.starts_with(prefix));
    if kind == "Surface Height" || (kind != "Surface Profile" && has("/2D_Data/")) {
        return Err(
            "a Dektak OPDx map: asperity reads OPDx line profiles only (no map was at hand to check a reader on)"
                .into(),
        );
    }
    let channel = match items.get("/MetaData/1D_Channels/Height") {
        Some(Value::List(names)) if !names.is_empty() => names[0].clone(),
        _ => return Err("no line profile: '/MetaData/1D_Channels/Height' names no channel".into()),
    };
    let prefix = format!("/1D_Data/{channel}");
    let missing = |what: &str| format!("channel '{}' has no {what}", binary::printable(&channel));
    let n = match items.get(&format!("{prefix}/NumPoints")) {
        Some(&Value::Number(n)) if n >= 2.0 && n.fract() == 0.0 => n as usize,
        Some(&Value::Number(n)) => return Err(format!("{}: {n} points, not a profile", missing("profile"))),
        _ => return Err(missing("NumPoints")),
    };
    let quantity = |name: &str| match items.get(&format!("{prefix}/{name}")) {
        Some(Value::Quantity(v, unit)) => {
            let unit = binary::normalise_unit(unit);
            match columns::metres_per(&unit) {
                Some(_) if v.is_finite() => Ok((*v, unit)),
                _ => Err(format!("its {name} {v} '{}' is not a length", binary::printable(&unit))),
            }
        }
        _ => Err(missing(name)),
    };
    let (extent, position_unit) = quantity("Extent")?;
    let (scale, height_unit) = quantity("DataScale")?;
    if extent <= 0.0 {
        return Err(format!("its Extent {extent} {position_unit} is not positive"));
    }
    let raw = match items.get(&format!("{prefix}/Array")) {
        Some(&Value::Array(offset, len)) => {
            let want = n.checked_mul(8).and_then(|b| b.checked_add(ARRAY_PREFIX));
            if want != Some(len) {
                return Err(format!("its Array holds {len} bytes, not the {n} values of NumPoints"));
            }
            binary::extent(bytes, offset + ARRAY_PREFIX, len - ARRAY_PREFIX, "the heights")?
        }
        _ => return Err(missing("Array of heights")),
    };
    // Extent is the distance from the first point to the last: n points, n − 1 steps.
    let step = extent / (n - 1) as f64;
    let positions = (0..n).map(|i| i as f64 * step).collect();
    let heights = raw.chunks_exact(8).map(|b| f64::from_le_bytes(b.try_into().expect("chunks of 8")) * scale);
    let heights = crate::limits::collected(heights, "the heights")?;
    Ok(ProfileData {
        name: text(&format!("{prefix}/DataKind")).unwrap_or(&channel).to_string(),
        positions,
        heights,
        position_unit: Some(position_unit),
        height_unit: Some(height_unit),
        decided: true,
        stated_step: None,
    })
}

/// A name: `u32` length and UTF-8.
fn name(c: &mut Cursor) -> Result<String, String> {
    let len = c.u32("a name's length")? as usize;
    Ok(String::from_utf8_lossy(c.take(len, "a name")?).into_owned())
}

/// A length of 1, 2 or 4 bytes, preceded by its size.
fn varlen(c: &mut Cursor) -> Result<usize, String> {
    Ok(match c.u8("a length's size")? {
        1 => c.u8("a length")? as usize,
        2 => c.u16("a length")? as usize,
        4 => c.u32("a length")? as usize,
        k => return Err(format!("a length of {k} bytes at offset {}", c.pos())),
    })
}

/// Read the next item below `prefix` into `items`; false at a terminator.
fn item(c: &mut Cursor, prefix: &str, depth: usize, items: &mut HashMap<String, Value>) -> Result<bool, String> {
    let path = format!("{prefix}/{}", name(c)?);
    let at = c.pos();
    let value = match c.u8("an item's type")? {
        // A container, raw data of a profile or of a map: items up to a terminator, then
        // two bytes, filling the length the container declares.
        0x7D | 0x46 | 0x47 => {
            if depth >= MAX_DEPTH {
                return Err(format!("containers nested deeper than {MAX_DEPTH} at offset {at}"));
            }
            let len = varlen(c)?;
            if len > c.remaining() {
                return Err(format!(
                    "truncated: the container '{}' needs {len} bytes at offset {}",
                    binary::printable(&path),
                    c.pos()
                ));
            }
            let end = c.pos() + len;
            while item(c, &path, depth + 1, items)? {}
            c.skip(2, "a container's end")?;
            if c.pos() != end {
                return Err(format!(
                    "the container '{}' ends at offset {} but declares {end}",
                    binary::printable(&path),
                    c.pos()
                ));
            }
            return Ok(true);
        }
        0x7F => return Ok(false),
        0x01 => Value::Number(f64::from(c.u8("a boolean")?)),
        0x04 => Value::Number(f64::from(c.i16("an integer")?)),
        0x05 => Value::Number(f64::from(c.u16("an integer")?)),
        0x06 => Value::Number(f64::from(c.i32("an integer")?)),
        0x07 => Value::Number(f64::from(c.u32("an integer")?)),
        0x0A => Value::Number(c.i64("an integer")? as f64),
        0x0B => Value::Number(u64::from_le_bytes(c.take(8, "an integer")?.try_into().expect("8 bytes")) as f64),
        0x0C => Value::Number(f64::from(c.f32("a number")?)),
        0x0D => Value::Number(c.f64("a number")?),
        0x12 => {
            let len = varlen(c)?;
            Value::Text(String::from_utf8_lossy(c.take(len, "a string")?).into_owned())
        }
        0x13 => {
            // A quantity: value, unit name and symbol, within its declared length.
            let len = varlen(c)?;
            let mut q = Cursor::new(c.take(len, "a quantity")?, Endian::Little);
            let v = q.f64("a quantity's value")?;
            name(&mut q)?;
            Value::Quantity(v, name(&mut q)?)
        }
        0x15 => {
            c.skip(9, "a time stamp")?;
            Value::Other
        }
        0x18 => {
            let len = varlen(c)?;
            c.skip(len, "a unit")?;
            Value::Other
        }
        // A type id, a double array, a matrix, an anonymous matrix, position data: a type
        // name, then (for a matrix, after a number and a name) a length and the bytes.
        t @ (0x0E | 0x40 | 0x00 | 0x45 | 0x7C) => {
            name(c)?;
            if t == 0x00 {
                c.u32("a matrix")?;
                name(c)?;
            }
            let len = varlen(c)?;
            let offset = c.pos();
            c.skip(len, "an array")?;
            if t == 0x40 {
                Value::Array(offset, len)
            } else {
                Value::Other
            }
        }
        0x42 => {
            name(c)?;
            let len = varlen(c)?;
            let mut l = Cursor::new(c.take(len, "a list of strings")?, Endian::Little);
            let mut list = Vec::new();
            while l.pos() < len {
                list.push(name(&mut l)?);
            }
            Value::List(list)
        }
        t => return Err(format!("an item of unknown type {t:#04x} at offset {at}")),
    };
    items.insert(path, value);
    Ok(true)
}
