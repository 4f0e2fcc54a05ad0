//! MATLAB level 5 MAT-files (`.mat`, versions 5 to 7: `save`'s default, compressed or not):
//! each 2-D real numeric variable (double, single, integers) is a channel named after it,
//! rows along y as for a `.npy` (MATLAB's `A(row, column)` is the map's `[row, column]`;
//! SurfaceTopography's grid is its transpose). The file states neither size nor unit: both come
//! from the user. Version 7.3 files are HDF5 and refused here.
//!
//! After a 128-byte header (text, then `IM` or `MI` telling the byte order), the file is a
//! sequence of data elements: an 8-byte tag (type, length; or a 4-byte tag for at most 4
//! bytes of data), padded to 8 bytes. A variable is an `miMATRIX` element (array flags,
//! dimensions, name, real part), or one inside an `miCOMPRESSED` (zlib) element, inflated as a
//! stream within the input limits. Every length is checked against the bytes present.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

use super::gzip;
use super::reading::{Channel, Format};
use crate::limits::Limits;
use crate::quantity::quoted;

pub struct Mat;

const HEADER: usize = 128;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;

impl Format for Mat {
    fn name(&self) -> &'static str {
        "mat"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["mat"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(b"MATLAB 5.0 MAT-file")
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        if bytes.starts_with(b"MATLAB 7.3 MAT-file") {
            return Err("a MATLAB 7.3 (HDF5) MAT-file: only level 5 MAT-files (save -v7 and earlier) are read".into());
        }
        let big = match bytes.get(126..HEADER) {
            Some(b"IM") => false,
            Some(b"MI") => true,
            _ => return Err("not a level 5 MAT-file (no IM or MI byte-order mark at offset 126)".into()),
        };
        let mut channels = Vec::new();
        let mut at = HEADER;
        while at < bytes.len() {
            let (kind, data, next) = element(bytes, at, big)?;
            at = next;
            match kind {
                MI_MATRIX => channels.extend(matrix(data, big, limits)?),
                MI_COMPRESSED => {
                    let hint = data.len() as u64 * 4;
                    let inner = gzip::read_within(flate2::read::ZlibDecoder::new(data), limits, hint)
                        .map_err(|e| format!("a compressed MAT variable: {e}"))?;
                    let (kind, data, _) = element(&inner, 0, big)?;
                    if kind == MI_MATRIX {
                        channels.extend(matrix(data, big, limits)?);
                    }
                }
                _ => {}
            }
        }
        if channels.is_empty() {
            return Err("a MAT-file without a 2-D numeric variable".into());
        }
        Ok(channels)
    }

    fn is_bare(&self) -> bool {
        true
    }
}

fn u32_at(b: &[u8], big: bool) -> u32 {
    let a: [u8; 4] = b[..4].try_into().expect("4 bytes");
    if big {
        u32::from_be_bytes(a)
    } else {
        u32::from_le_bytes(a)
    }
}

/// The data element at `at`: its type, its data and where the next one starts.
fn element(bytes: &[u8], at: usize, big: bool) -> Result<(u32, &[u8], usize), String> {
    let truncated = || format!("truncated MAT-file: a data element at offset {at} runs past the end");
    let tag = bytes.get(at..at + 8).or_else(|| bytes.get(at..at + 4)).ok_or_else(truncated)?;
    let first = u32_at(tag, big);
    if first >> 16 != 0 {
        // The small format: length and type in 4 bytes, up to 4 bytes of data after them.
        let (kind, len) = (first & 0xFFFF, (first >> 16) as usize);
        let data = bytes.get(at + 4..at + 4 + len.min(4)).ok_or_else(truncated)?;
        return Ok((kind, data, at + 8));
    }
    let len = u32_at(bytes.get(at + 4..at + 8).ok_or_else(truncated)?, big) as usize;
    let end = at.checked_add(8 + len).filter(|&e| e <= bytes.len()).ok_or_else(truncated)?;
    // Compressed elements are not padded; the others to 8 bytes.
    let next = if first == MI_COMPRESSED { end } else { end.next_multiple_of(8).min(bytes.len()) };
    Ok((first, &bytes[at + 8..end], next))
}

/// A variable as a channel, when it is a 2-D real numeric array.
fn matrix(data: &[u8], big: bool, limits: &Limits) -> Result<Option<Channel>, String> {
    let (_, flags, at) = element(data, 0, big)?;
    let (_, dims, at) = element(data, at, big)?;
    let (_, name, at) = element(data, at, big)?;
    let name = String::from_utf8_lossy(name).into_owned();
    let flags = flags.get(..4).map(|f| u32_at(f, big)).ok_or("a MAT variable without its array flags")?;
    let (class, complex) = (flags & 0xFF, flags & 0x800 != 0);
    // Classes 6 to 15: double, single, int8 … uint64.
    if !(6..=15).contains(&class) || complex || dims.len() != 8 {
        return Ok(None);
    }
    let (rows, cols) = (u32_at(&dims[..4], big) as usize, u32_at(&dims[4..], big) as usize);
    if rows == 0 || cols == 0 {
        return Ok(None);
    }
    limits.check_grid(cols, rows).map_err(|e| format!("MAT variable {}: {e}", quoted(&name)))?;
    let (kind, real, _) = element(data, at, big)?;
    let size = match kind {
        1 | 2 => 1,
        3 | 4 => 2,
        5..=7 => 4,
        9 | 12 | 13 => 8,
        k => return Err(format!("MAT variable {}: data of type {k} is not numeric", quoted(&name))),
    };
    if real.len() != rows * cols * size {
        return Err(format!(
            "MAT variable {}: {} bytes of data for {rows} × {cols} values of {size} bytes",
            quoted(&name),
            real.len()
        ));
    }
    let value = |b: &[u8]| -> f64 {
        let mut raw = [0u8; 8];
        if big {
            raw[..size].copy_from_slice(b);
            raw[..size].reverse();
        } else {
            raw[..size].copy_from_slice(b);
        }
        let w = u64::from_le_bytes(raw);
        match kind {
            1 => w as u8 as i8 as f64,
            2 => w as u8 as f64,
            3 => w as u16 as i16 as f64,
            4 => w as u16 as f64,
            5 => w as u32 as i32 as f64,
            6 => w as u32 as f64,
            7 => f64::from(f32::from_bits(w as u32)),
            9 => f64::from_bits(w),
            12 => w as i64 as f64,
            _ => w as f64,
        }
    };
    // Column-major: element (r, c) at r + c · rows.
    let data = Array2::from_shape_fn((rows, cols), |(r, c)| {
        let k = (r + c * rows) * size;
        value(&real[k..k + size])
    });
    Ok(Some(Channel { name, data, physical_size: None, unit: None, is_height: true }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn truncated_and_hostile_elements_are_refused() {
        let mut b = b"MATLAB 5.0 MAT-file".to_vec();
        b.resize(126, b' ');
        b.extend(b"IM");
        // An element declaring 4 GiB in a file of 136 bytes.
        b.extend(MI_MATRIX.to_le_bytes());
        b.extend(u32::MAX.to_le_bytes());
        assert!(Mat.read(&b).unwrap_err().contains("truncated"), "{:?}", Mat.read(&b));
        assert!(Mat.read(b"MATLAB 7.3 MAT-file").unwrap_err().contains("7.3"));
    }
}
