//! NetCDF classic (`.nc`, CDF-1, CDF-2 and CDF-5), as SurfaceTopography and contact.engineering
//! write topographies: a variable `heights(x, y)` (its first index along x), variables `x` and
//! `y` whose attributes give the physical size (`length`) and the unit (`unit`, the heights'
//! too), and an optional variable `mask` whose non-zero points are missing. `_FillValue` and
//! `missing_value` mark missing points, `scale_factor` and `add_offset` scale the values.
//!
//! The header (big-endian: dimensions, attributes, variables with their types, shapes and
//! offsets) is parsed here; every count is checked against the bytes left before anything is
//! allocated from it, and every variable's data against the file's length. NetCDF-4 files are
//! HDF5 and not read here; neither are record (unlimited) variables nor line scans.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

use super::reading::{Channel, Format};
use crate::quantity::{metres_per, quoted};

pub struct NetCdf;

impl Format for NetCdf {
    fn name(&self) -> &'static str {
        "netcdf"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["nc"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"CDF") && matches!(head.get(3), Some(1 | 2 | 5))
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let file = Header::parse(bytes)?;
        let heights = file.variable("heights").ok_or("a NetCDF file without a 'heights' variable")?;
        let shape = file.shape(heights)?;
        let [nx, ny] = shape[..] else {
            return Err(format!(
                "NetCDF 'heights' of {} dimensions: only maps (x, y) are read, not line scans",
                shape.len()
            ));
        };
        let stored = file.values(heights, bytes)?;
        let mask = match file.variable("mask") {
            Some(m) if file.shape(m)? == shape => Some(file.values(m, bytes)?),
            Some(_) => return Err("NetCDF 'mask' is not shaped as 'heights'".into()),
            None => None,
        };
        let unit = file.variable("x").and_then(|x| x.text("unit"));
        if let Some(h) = heights.text("unit") {
            if Some(&h) != unit.as_ref() {
                return Err(format!(
                    "NetCDF heights in {} but positions in {}",
                    quoted(&h),
                    quoted(&unit.unwrap_or_default())
                ));
            }
        }
        let scale = match unit.as_deref() {
            Some(u) => metres_per(u).ok_or_else(|| format!("NetCDF unit {} is not a length", quoted(u)))?,
            None => 1.0,
        };
        // Lengths in the file's unit: metres only when it states one.
        let length = |name: &str| file.variable(name).and_then(|v| v.number("length"));
        let physical_size = match (length("x"), length("y"), &unit) {
            (Some(lx), Some(ly), Some(_)) => Some((lx * scale, ly * scale)),
            _ => None,
        };
        // Stored x slowest (heights(x, y)); the map is (ny, nx).
        let data = Array2::from_shape_fn((ny, nx), |(j, i)| {
            let k = i * ny + j;
            match &mask {
                Some(m) if m[k] != 0.0 => f64::NAN,
                _ => stored[k] * scale,
            }
        });
        Ok(vec![Channel { name: "heights".into(), data, physical_size, unit, is_height: true }])
    }
}

/// A type of NetCDF values, by its code.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Type {
    Byte,
    Char,
    Short,
    Int,
    Float,
    Double,
    UByte,
    UShort,
    UInt,
    Int64,
    UInt64,
}

impl Type {
    fn from_code(code: u64) -> Result<Type, String> {
        Ok(match code {
            1 => Type::Byte,
            2 => Type::Char,
            3 => Type::Short,
            4 => Type::Int,
            5 => Type::Float,
            6 => Type::Double,
            7 => Type::UByte,
            8 => Type::UShort,
            9 => Type::UInt,
            10 => Type::Int64,
            11 => Type::UInt64,
            c => return Err(format!("unknown NetCDF type {c}")),
        })
    }

    fn size(self) -> usize {
        match self {
            Type::Byte | Type::Char | Type::UByte => 1,
            Type::Short | Type::UShort => 2,
            Type::Int | Type::UInt | Type::Float => 4,
            Type::Double | Type::Int64 | Type::UInt64 => 8,
        }
    }

    /// The value of one big-endian element.
    fn decode(self, b: &[u8]) -> f64 {
        let mut raw = [0u8; 8];
        raw[8 - b.len()..].copy_from_slice(b);
        let word = u64::from_be_bytes(raw);
        match self {
            Type::Byte => word as u8 as i8 as f64,
            Type::Short => word as u16 as i16 as f64,
            Type::Int => word as u32 as i32 as f64,
            Type::Int64 => word as i64 as f64,
            Type::Float => f64::from(f32::from_bits(word as u32)),
            Type::Double => f64::from_bits(word),
            Type::Char | Type::UByte | Type::UShort | Type::UInt | Type::UInt64 => word as f64,
        }
    }
}

/// An attribute's values: text, or numbers.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Text(String),
    Numbers(Vec<f64>),
}

#[derive(Debug)]
struct Variable {
    name: String,
    dims: Vec<usize>,
    attributes: Vec<(String, Value)>,
    kind: Type,
    begin: u64,
}

impl Variable {
    fn attribute(&self, name: &str) -> Option<&Value> {
        self.attributes.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    fn text(&self, name: &str) -> Option<String> {
        match self.attribute(name)? {
            Value::Text(t) => Some(t.trim_end_matches('\0').to_string()),
            Value::Numbers(_) => None,
        }
    }

    fn number(&self, name: &str) -> Option<f64> {
        match self.attribute(name)? {
            Value::Numbers(n) => n.first().copied(),
            Value::Text(_) => None,
        }
    }
}

/// What the header says: the variables, each with its dimensions' lengths (0 for the
/// unlimited one).
struct Header {
    variables: Vec<Variable>,
}

/// A reader of the header's big-endian fields, refusing to read past the file.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    /// CDF-5 writes counts and lengths in 8 bytes.
    wide: bool,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or("truncated NetCDF header")?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u32(&mut self) -> Result<u64, String> {
        Ok(u32::from_be_bytes(self.take(4)?.try_into().expect("4 bytes")) as u64)
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_be_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }

    /// A count or length (4 bytes, 8 in CDF-5).
    fn count(&mut self) -> Result<u64, String> {
        if self.wide {
            self.u64()
        } else {
            self.u32()
        }
    }

    /// A count of items of at least `min` bytes each, checked against the bytes left.
    fn items(&mut self, min: usize) -> Result<usize, String> {
        let n = self.count()?;
        let left = (self.bytes.len() - self.at) as u64;
        if n.saturating_mul(min as u64) > left {
            return Err(format!("NetCDF header declares {n} items but the file holds {left} bytes after it"));
        }
        Ok(n as usize)
    }

    /// `n` bytes, then the padding to a multiple of 4.
    fn padded(&mut self, n: usize) -> Result<&'a [u8], String> {
        let s = self.take(n)?;
        self.take((4 - n % 4) % 4)?;
        Ok(s)
    }

    fn name(&mut self) -> Result<String, String> {
        let n = self.items(1)?;
        Ok(String::from_utf8_lossy(self.padded(n)?).into_owned())
    }

    /// A list's tag (`expected`, or ABSENT: zero) and its length.
    fn list(&mut self, expected: u32, min: usize) -> Result<usize, String> {
        match self.u32()? {
            0 => {
                self.count()?;
                Ok(0)
            }
            t if t == expected as u64 => self.items(min),
            t => Err(format!("malformed NetCDF header: tag {t:#x} where {expected:#x} was expected")),
        }
    }

    fn attributes(&mut self) -> Result<Vec<(String, Value)>, String> {
        let n = self.list(0x0C, 12)?;
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let name = self.name()?;
            let kind = Type::from_code(self.u32()?)?;
            let count = self.items(kind.size())?;
            let raw = self.padded(count * kind.size())?;
            let value = match kind {
                Type::Char => Value::Text(String::from_utf8_lossy(raw).into_owned()),
                _ => Value::Numbers(raw.chunks_exact(kind.size()).map(|b| kind.decode(b)).collect()),
            };
            out.push((name, value));
        }
        Ok(out)
    }
}

impl Header {
    fn parse(bytes: &[u8]) -> Result<Header, String> {
        let version = match bytes.get(..4) {
            Some([b'C', b'D', b'F', v @ (1 | 2 | 5)]) => *v,
            _ => return Err("not a NetCDF classic file (no CDF magic)".into()),
        };
        let mut c = Cursor { bytes, at: 4, wide: version == 5 };
        c.count()?; // records
        let ndims = c.list(0x0A, 8)?;
        let mut dims = Vec::with_capacity(ndims);
        for _ in 0..ndims {
            c.name()?;
            dims.push(usize::try_from(c.count()?).map_err(|_| "a NetCDF dimension too long to count")?);
        }
        c.attributes()?;
        let nvars = c.list(0x0B, 16)?;
        let mut variables = Vec::with_capacity(nvars);
        for _ in 0..nvars {
            let name = c.name()?;
            let rank = c.items(4)?;
            let mut shape = Vec::with_capacity(rank);
            for _ in 0..rank {
                let id = c.count()? as usize;
                shape.push(
                    *dims.get(id).ok_or_else(|| format!("NetCDF variable {} uses no dimension {id}", quoted(&name)))?,
                );
            }
            let attributes = c.attributes()?;
            let kind = Type::from_code(c.u32()?)?;
            c.count()?; // vsize: recomputed from the shape
            let begin = if version == 1 { c.u32()? } else { c.u64()? };
            variables.push(Variable { name, dims: shape, attributes, kind, begin });
        }
        Ok(Header { variables })
    }

    fn variable(&self, name: &str) -> Option<&Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// A variable's shape; a record variable (of the unlimited dimension) is refused.
    fn shape(&self, v: &Variable) -> Result<Vec<usize>, String> {
        if v.dims.contains(&0) {
            return Err(format!("NetCDF variable {} is a record (unlimited) variable: not supported", quoted(&v.name)));
        }
        Ok(v.dims.clone())
    }

    /// A variable's values, scaled by its `scale_factor` and `add_offset`, `_FillValue` and
    /// `missing_value` as NaN; its extent checked against the file before anything is allocated.
    fn values(&self, v: &Variable, bytes: &[u8]) -> Result<Vec<f64>, String> {
        let n = self.shape(v)?.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or("a NetCDF shape too large")?;
        let len = n.checked_mul(v.kind.size()).ok_or("a NetCDF shape too large")?;
        let start = usize::try_from(v.begin).map_err(|_| "a NetCDF offset past the file")?;
        let raw = start.checked_add(len).and_then(|end| bytes.get(start..end)).ok_or_else(|| {
            format!(
                "NetCDF variable {} needs {len} bytes from offset {start} but the file holds {}",
                quoted(&v.name),
                bytes.len()
            )
        })?;
        let missing: Vec<f64> = ["_FillValue", "missing_value"].iter().filter_map(|a| v.number(a)).collect();
        let (factor, offset) = (v.number("scale_factor").unwrap_or(1.0), v.number("add_offset").unwrap_or(0.0));
        let values = raw.chunks_exact(v.kind.size()).map(|b| v.kind.decode(b)).map(|x| {
            if missing.contains(&x) {
                f64::NAN
            } else {
                x * factor + offset
            }
        });
        crate::limits::collected(values, &format!("NetCDF variable {}", quoted(&v.name)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_counts_and_offsets_are_refused() {
        // A header declaring 2^32 - 1 dimensions in a 20-byte file.
        let mut b = b"CDF\x01\0\0\0\0\0\0\0\x0a\xff\xff\xff\xff".to_vec();
        b.extend([0u8; 4]);
        assert!(NetCdf.read(&b).unwrap_err().contains("declares 4294967295 items"));
        assert!(NetCdf.read(b"CDF\x01\0\0").unwrap_err().contains("truncated"));
        assert!(NetCdf.read(b"\x89HDF\r\n\x1a\n").unwrap_err().contains("not a NetCDF classic"));
    }
}
