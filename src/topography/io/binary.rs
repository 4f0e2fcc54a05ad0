//! Bounds-checked access to the bytes of binary instrument files.
//!
//! Instrument headers declare sizes, counts and offsets; a corrupt or truncated file declares
//! wrong ones. Every reader goes through these helpers, which check each declared extent
//! against the bytes actually present, with checked arithmetic, before anything is sliced or
//! allocated: a bad header gives an error, never a panic or a huge allocation.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::Array2;

/// Byte order of multi-byte numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    Little,
    Big,
}

/// The numeric type of the stored samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sample {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Sample {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            Sample::I8 | Sample::U8 => 1,
            Sample::I16 | Sample::U16 => 2,
            Sample::I32 | Sample::U32 | Sample::F32 => 4,
            Sample::F64 => 8,
        }
    }

    /// How many values an integer sample can hold (a height scale's full range), `None` for
    /// floating point.
    pub fn levels(self) -> Option<f64> {
        match self {
            Sample::F32 | Sample::F64 => None,
            s => Some(2f64.powi(8 * s.size() as i32)),
        }
    }
}

/// The number of points of an `nx` × `ny` grid, refusing empty grids and overflow.
pub fn grid_points(nx: usize, ny: usize) -> Result<usize, String> {
    if nx == 0 || ny == 0 {
        return Err(format!("the header declares an empty {nx} x {ny} grid"));
    }
    nx.checked_mul(ny).ok_or_else(|| format!("the header declares an impossible {nx} x {ny} grid"))
}

/// The `len` bytes at `offset`, or an error naming `what` when the file does not hold them.
pub fn extent<'a>(bytes: &'a [u8], offset: usize, len: usize, what: &str) -> Result<&'a [u8], String> {
    match offset.checked_add(len) {
        Some(end) if end <= bytes.len() => Ok(&bytes[offset..end]),
        _ => Err(format!(
            "truncated: {what} needs {len} bytes at offset {offset} but the file holds {} bytes",
            bytes.len()
        )),
    }
}

/// How a grid of numbers is stored.
#[derive(Debug, Clone, Copy)]
pub struct Stored {
    pub sample: Sample,
    pub endian: Endian,
    /// The file stores the bottom line first (most instruments); it is returned as row
    /// `ny - 1`, so that row 0 is the top of the image, as Gwyddion shows it.
    pub bottom_first: bool,
}

/// An `ny` × `nx` grid stored row by row at `offset`, as `f64`, each value mapped by `scale`.
/// The extent is checked before the array is allocated.
pub fn grid(
    bytes: &[u8],
    offset: usize,
    (nx, ny): (usize, usize),
    stored: Stored,
    what: &str,
    scale: impl Fn(f64) -> f64,
) -> Result<Array2<f64>, String> {
    let n = grid_points(nx, ny)?;
    let len = n.checked_mul(stored.sample.size()).ok_or_else(|| format!("{what}: the declared data size overflows"))?;
    let raw = extent(bytes, offset, len, what)?;
    // Only now, with the bytes known to be there, is room made for the values.
    let mut values = Vec::new();
    crate::limits::reserve(&mut values, n, what)?;
    macro_rules! decode {
        ($t:ty, $n:literal) => {
            match stored.endian {
                Endian::Little => {
                    rows::<$n>(raw, nx, stored.bottom_first, &mut values, |a| scale(<$t>::from_le_bytes(a) as f64))
                }
                Endian::Big => {
                    rows::<$n>(raw, nx, stored.bottom_first, &mut values, |a| scale(<$t>::from_be_bytes(a) as f64))
                }
            }
        };
    }
    match stored.sample {
        Sample::I8 => decode!(i8, 1),
        Sample::U8 => decode!(u8, 1),
        Sample::I16 => decode!(i16, 2),
        Sample::U16 => decode!(u16, 2),
        Sample::I32 => decode!(i32, 4),
        Sample::U32 => decode!(u32, 4),
        Sample::F32 => decode!(f32, 4),
        Sample::F64 => decode!(f64, 8),
    }
    Array2::from_shape_vec((ny, nx), values).map_err(|e| format!("{what}: {e}"))
}

/// Append the rows of `raw` (each `nx` values of `N` bytes) to `out`, in file order or reversed,
/// each value decoded by `f`. One monomorphised loop per type and byte order keeps it fast.
fn rows<const N: usize>(raw: &[u8], nx: usize, reversed: bool, out: &mut Vec<f64>, f: impl Fn([u8; N]) -> f64) {
    let mut push = |row: &[u8]| {
        out.extend(row.chunks_exact(N).map(|c| {
            let mut a = [0u8; N];
            a.copy_from_slice(c);
            f(a)
        }))
    };
    let lines = raw.chunks_exact(nx * N);
    if reversed {
        lines.rev().for_each(&mut push);
    } else {
        lines.for_each(&mut push);
    }
}

/// Sequential little- or big-endian reading of a binary header.
pub struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    endian: Endian,
}

impl<'a> Cursor<'a> {
    pub fn new(bytes: &'a [u8], endian: Endian) -> Self {
        Cursor { bytes, pos: 0, endian }
    }

    /// Current position from the start of the bytes.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// The bytes left after the current position.
    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let b = extent(self.bytes, self.pos, n, what)?;
        self.pos += n;
        Ok(b)
    }

    /// Skip `n` bytes (checked like [`Cursor::take`]).
    pub fn skip(&mut self, n: usize, what: &str) -> Result<(), String> {
        self.take(n, what).map(|_| ())
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }

    pub fn u16(&mut self, what: &str) -> Result<u16, String> {
        let a = self.array::<2>(what)?;
        Ok(if self.endian == Endian::Little { u16::from_le_bytes(a) } else { u16::from_be_bytes(a) })
    }

    pub fn i16(&mut self, what: &str) -> Result<i16, String> {
        let a = self.array::<2>(what)?;
        Ok(if self.endian == Endian::Little { i16::from_le_bytes(a) } else { i16::from_be_bytes(a) })
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, String> {
        let a = self.array::<4>(what)?;
        Ok(if self.endian == Endian::Little { i32::from_le_bytes(a) } else { i32::from_be_bytes(a) })
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, String> {
        let a = self.array::<4>(what)?;
        Ok(if self.endian == Endian::Little { u32::from_le_bytes(a) } else { u32::from_be_bytes(a) })
    }

    pub fn i64(&mut self, what: &str) -> Result<i64, String> {
        let a = self.array::<8>(what)?;
        Ok(if self.endian == Endian::Little { i64::from_le_bytes(a) } else { i64::from_be_bytes(a) })
    }

    pub fn f32(&mut self, what: &str) -> Result<f32, String> {
        let a = self.array::<4>(what)?;
        Ok(if self.endian == Endian::Little { f32::from_le_bytes(a) } else { f32::from_be_bytes(a) })
    }

    pub fn f64(&mut self, what: &str) -> Result<f64, String> {
        let a = self.array::<8>(what)?;
        Ok(if self.endian == Endian::Little { f64::from_le_bytes(a) } else { f64::from_be_bytes(a) })
    }

    /// A NUL-terminated string (the NUL is consumed, not returned), decoded as UTF-8 with
    /// invalid bytes replaced.
    pub fn cstr(&mut self, what: &str) -> Result<String, String> {
        let rest = &self.bytes[self.pos.min(self.bytes.len())..];
        let len = rest.iter().position(|&b| b == 0).ok_or_else(|| format!("truncated: unterminated {what}"))?;
        let s = String::from_utf8_lossy(&rest[..len]).into_owned();
        self.pos += len + 1;
        Ok(s)
    }
}

/// A reason as one readable line: text quoted from a corrupt file may hold newlines, control
/// characters or kilobytes of binary; those become `?` and the line is cut at 300 characters.
pub fn one_line(reason: String) -> String {
    const MAX: usize = 300;
    let mut out: String = reason.chars().take(MAX).map(|c| if c.is_control() { '?' } else { c }).collect();
    if reason.chars().nth(MAX).is_some() {
        out.push('…');
    }
    out
}

/// Text from a file as it may be quoted in a message (one rule for every message).
pub use crate::quantity::printable;

/// A header count or size read as a signed integer, refused when negative.
pub fn non_negative(v: i64, what: &str) -> Result<usize, String> {
    usize::try_from(v).map_err(|_| format!("the header declares a negative {what} ({v})"))
}

/// Text of a fixed-size, NUL-padded field.
pub fn padded_str(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    latin1(&b[..end]).trim().to_string()
}

/// Latin-1 text (the encoding of older instrument headers) as a `String`.
pub fn latin1(b: &[u8]) -> String {
    b.iter().map(|&c| char::from(c)).collect()
}

/// A length unit in its usual spelling: the ASCII and Latin-1 stand-ins instruments write for
/// "µ" (`um`, `~m`, a lone micro sign) become `µm`; everything else is returned trimmed.
pub fn normalise_unit(unit: &str) -> String {
    match unit.trim() {
        "um" | "~m" | "\u{3bc}m" | "micron" | "microns" => "µm".to_string(),
        u => u.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extent_refuses_past_the_end_and_overflow() {
        let b = [0u8; 10];
        assert_eq!(extent(&b, 2, 8, "x").unwrap().len(), 8);
        assert!(extent(&b, 3, 8, "x").unwrap_err().contains("needs 8 bytes at offset 3"));
        assert!(extent(&b, usize::MAX, 2, "x").is_err());
    }

    #[test]
    fn grid_decodes_and_checks_before_allocating() {
        let b: Vec<u8> = [1i16, -2, 3, -4, 5, -6].iter().flat_map(|v| v.to_be_bytes()).collect();
        let stored = Stored { sample: Sample::I16, endian: Endian::Big, bottom_first: false };
        let a = grid(&b, 0, (3, 2), stored, "data", |v| v * 0.5).unwrap();
        assert_eq!(a, ndarray::array![[0.5, -1.0, 1.5], [-2.0, 2.5, -3.0]]);
        let flipped = grid(&b, 0, (3, 2), Stored { bottom_first: true, ..stored }, "data", |v| v).unwrap();
        assert_eq!(flipped, ndarray::array![[-4.0, 5.0, -6.0], [1.0, -2.0, 3.0]]);
        let le: Vec<u8> = [1.5f32, -2.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let f32s = Stored { sample: Sample::F32, endian: Endian::Little, bottom_first: false };
        assert_eq!(grid(&le, 0, (1, 2), f32s, "data", |v| v).unwrap(), ndarray::array![[1.5], [-2.0]]);
        // A declared grid of 2^62 points must be refused without trying to allocate it.
        let f64s = Stored { sample: Sample::F64, endian: Endian::Little, bottom_first: false };
        assert!(grid(&b, 0, (1 << 31, 1 << 31), f64s, "data", |v| v).is_err());
        assert!(grid(&b, 0, (0, 3), f64s, "data", |v| v).is_err());
        assert!(grid(&b, 2, (3, 2), stored, "data", |v| v).unwrap_err().contains("truncated"));
    }

    #[test]
    fn reasons_stay_on_one_short_line() {
        assert_eq!(one_line("a\nb\r".into()), "a?b?");
        assert_eq!(one_line("x".repeat(500)).chars().count(), 301);
        assert_eq!(printable("ab\u{1}"), "ab\\u{1}");
        let long = printable(&format!("a{}z", "y".repeat(50)));
        assert!(
            long.starts_with('a') && long.ends_with('z') && long.contains('…') && long.chars().count() <= 41,
            "{long}"
        );
    }

    #[test]
    fn cursor_reads_in_both_byte_orders() {
        let b = [0x01, 0x02, 0x03, 0x04, b'a', b'b', 0];
        assert_eq!(Cursor::new(&b, Endian::Little).i32("n").unwrap(), 0x04030201);
        let mut c = Cursor::new(&b, Endian::Big);
        assert_eq!(c.i32("n").unwrap(), 0x01020304);
        assert_eq!(c.cstr("name").unwrap(), "ab");
        assert!(c.u8("next").is_err());
    }
}
