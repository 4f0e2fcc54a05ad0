//! NumPy `.npy`: a bare 2-D array of heights; size and unit come from the user.
//!
//! The header is a Python dict literal, `{'descr': '<f8', 'fortran_order': False, 'shape':
//! (ny, nx), }`, padded with spaces. It is parsed here in one pass over its bytes (no
//! recursion, no backtracking), and the size it declares is checked against the bytes the file
//! holds before anything is allocated from it.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use ndarray::{Array2, ShapeBuilder};

use super::reading::{Channel, Format};
use crate::quantity::quoted;

/// The reader of `.npy` files (`--format npy`): one height channel, without size or unit.
pub struct Npy;

impl Format for Npy {
    fn name(&self) -> &'static str {
        "npy"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["npy"]
    }

    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        let data = read_f64(bytes)?;
        Ok(vec![Channel { name: "default".into(), data, physical_size: None, unit: None, is_height: true }])
    }

    fn is_bare(&self) -> bool {
        true
    }
}

const MAGIC: &[u8] = b"\x93NUMPY";

/// A 2-D `.npy` array of any integer or floating-point type, as float64.
pub fn read_f64(bytes: &[u8]) -> Result<Array2<f64>, String> {
    let (header, data) = split(bytes)?;
    let h = Header::parse(header)?;
    let (ny, nx) = match h.shape[..] {
        [ny, nx] => (ny, nx),
        _ => return Err(format!("a 2-D array is needed, the header declares shape {}", h.shape_text())),
    };
    if ny == 0 || nx == 0 {
        return Err(format!("the array is empty: shape {}", h.shape_text()));
    }
    let size = h.dtype.size();
    let needed = ny.checked_mul(nx).and_then(|n| n.checked_mul(size));
    if needed != Some(data.len()) {
        return Err(format!(
            "the header declares shape {} of {size}-byte values ({} bytes) but the file holds {} bytes of data",
            h.shape_text(),
            needed.map_or("more than can be counted".to_string(), |n| n.to_string()),
            data.len()
        ));
    }
    let values = crate::limits::collected(data.chunks_exact(size).map(|b| h.dtype.decode(b)), "the values")?;
    let array = if h.fortran_order {
        Array2::from_shape_vec((ny, nx).f(), values).map(|a| a.as_standard_layout().into_owned())
    } else {
        Array2::from_shape_vec((ny, nx), values)
    };
    Ok(array.expect("the length was checked against the shape"))
}

/// The number of dimensions a `.npy` file's header declares (an `.npz` keeps only its 2-D
/// arrays); the reason when the header cannot be read.
pub(super) fn dimensions(bytes: &[u8]) -> Result<usize, String> {
    Ok(Header::parse(split(bytes)?.0)?.shape.len())
}

/// The header text and the data of a `.npy` file.
fn split(bytes: &[u8]) -> Result<(&[u8], &[u8]), String> {
    if !bytes.starts_with(MAGIC) {
        return Err("not a .npy file (no \\x93NUMPY magic)".into());
    }
    let (len_at, len_bytes) = match bytes.get(6) {
        Some(1) => (8, 2),
        Some(2) | Some(3) => (8, 4),
        Some(v) => return Err(format!(".npy format version {v} is not one NumPy writes (1, 2 or 3)")),
        None => return Err("truncated .npy header".into()),
    };
    let field = bytes.get(len_at..len_at + len_bytes).ok_or("truncated .npy header")?;
    let header_len = field.iter().rev().fold(0usize, |acc, &b| acc << 8 | b as usize);
    let start = len_at + len_bytes;
    match bytes.get(start..start + header_len) {
        Some(header) => Ok((header, &bytes[start + header_len..])),
        None => Err(format!(
            "the header declares {header_len} bytes but the file holds {} after its start",
            bytes.len() - start
        )),
    }
}

/// The element type of the array.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dtype {
    kind: u8,
    size: usize,
    big_endian: bool,
}

impl Dtype {
    /// `'<f8'`, `'>i4'`, `'|u1'`… (floats of 4 or 8 bytes, integers of 1 to 8).
    fn parse(descr: &str) -> Result<Dtype, String> {
        let b = descr.as_bytes();
        let unsupported = || format!("dtype {} is not a plain integer or float type ('<f8', '<i4', …)", quoted(descr));
        if b.len() != 3 {
            return Err(unsupported());
        }
        let big_endian = match b[0] {
            b'<' | b'|' | b'=' => false,
            b'>' => true,
            _ => return Err(unsupported()),
        };
        let size = (b[2] as char).to_digit(10).ok_or_else(unsupported)? as usize;
        match (b[1], size) {
            (b'f', 4 | 8) | (b'i' | b'u', 1 | 2 | 4 | 8) => Ok(Dtype { kind: b[1], size, big_endian }),
            _ => Err(unsupported()),
        }
    }

    fn size(self) -> usize {
        self.size
    }

    /// The value of one element's bytes.
    fn decode(self, bytes: &[u8]) -> f64 {
        let mut raw = [0u8; 8];
        if self.big_endian {
            raw[..self.size].copy_from_slice(bytes);
            raw[..self.size].reverse();
        } else {
            raw[..self.size].copy_from_slice(bytes);
        }
        let word = u64::from_le_bytes(raw);
        let bits = 8 * self.size as u32;
        match self.kind {
            b'f' if self.size == 4 => f64::from(f32::from_bits(word as u32)),
            b'f' => f64::from_bits(word),
            // Sign-extend from the element's width.
            b'i' => ((word << (64 - bits)) as i64 >> (64 - bits)) as f64,
            _ => word as f64,
        }
    }
}

/// What the header says.
#[derive(Debug, Clone, PartialEq)]
struct Header {
    dtype: Dtype,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// A value of the header's dict.
enum Value<'a> {
    Str(&'a str),
    Bool(bool),
    Tuple(Vec<usize>),
}

impl Header {
    /// Parse the dict literal in one pass; errors are one short line.
    fn parse(text: &[u8]) -> Result<Header, String> {
        let mut p = Parser { text, at: 0 };
        let (mut descr, mut fortran_order, mut shape) = (None, None, None);
        p.expect(b'{')?;
        loop {
            if p.peek() == Some(b'}') {
                p.at += 1;
                break;
            }
            let key = p.string()?;
            p.expect(b':')?;
            let value = p.value()?;
            match (key, value) {
                ("descr", Value::Str(s)) if descr.is_none() => descr = Some(Dtype::parse(s)?),
                ("fortran_order", Value::Bool(b)) if fortran_order.is_none() => fortran_order = Some(b),
                ("shape", Value::Tuple(t)) if shape.is_none() => shape = Some(t),
                ("descr" | "fortran_order" | "shape", _) => {
                    return Err(format!("malformed .npy header: bad or repeated value for '{key}'"))
                }
                _ => return Err(format!("malformed .npy header: unknown key {}", quoted(key))),
            }
            match p.peek() {
                Some(b',') => p.at += 1,
                Some(b'}') => {}
                _ => return Err(p.error("',' or '}'")),
            }
        }
        if p.peek().is_some() {
            return Err(p.error("the end of the header"));
        }
        match (descr, fortran_order, shape) {
            (Some(dtype), Some(fortran_order), Some(shape)) => Ok(Header { dtype, fortran_order, shape }),
            _ => Err("malformed .npy header: it needs 'descr', 'fortran_order' and 'shape'".into()),
        }
    }

    fn shape_text(&self) -> String {
        let dims: Vec<String> = self.shape.iter().map(|d| d.to_string()).collect();
        format!("({})", dims.join(", "))
    }
}

/// A cursor over the header's bytes.
struct Parser<'a> {
    text: &'a [u8],
    at: usize,
}

impl<'a> Parser<'a> {
    /// The next byte that is not white space, without taking it.
    fn peek(&mut self) -> Option<u8> {
        while self.text.get(self.at).is_some_and(|b| b.is_ascii_whitespace()) {
            self.at += 1;
        }
        self.text.get(self.at).copied()
    }

    fn error(&self, wanted: &str) -> String {
        let found = match self.text.get(self.at) {
            Some(&b) if b.is_ascii_graphic() => format!("'{}'", b as char),
            Some(&b) => format!("byte 0x{b:02x}"),
            None => "the end".to_string(),
        };
        format!("malformed .npy header: expected {wanted} at byte {}, found {found}", self.at)
    }

    fn expect(&mut self, b: u8) -> Result<(), String> {
        if self.peek() == Some(b) {
            self.at += 1;
            Ok(())
        } else {
            Err(self.error(&format!("'{}'", b as char)))
        }
    }

    /// A quoted string without escapes (what NumPy writes for keys and plain dtypes).
    fn string(&mut self) -> Result<&'a str, String> {
        let quote = match self.peek() {
            Some(q @ (b'\'' | b'"')) => q,
            _ => return Err(self.error("a quoted key")),
        };
        let start = self.at + 1;
        let len = self.text[start..].iter().position(|&b| b == quote || b == b'\\');
        match len.map(|l| (l, self.text[start + l])) {
            Some((l, b)) if b == quote => {
                self.at = start + l + 1;
                std::str::from_utf8(&self.text[start..start + l]).map_err(|_| self.error("text"))
            }
            _ => Err(self.error("a plain quoted string")),
        }
    }

    fn value(&mut self) -> Result<Value<'a>, String> {
        match self.peek() {
            Some(b'\'' | b'"') => self.string().map(Value::Str),
            Some(b'(') => {
                self.at += 1;
                let mut dims = Vec::new();
                loop {
                    match self.peek() {
                        Some(b')') => break,
                        Some(b'0'..=b'9') => dims.push(self.integer()?),
                        _ => return Err(self.error("a dimension or ')'")),
                    }
                    match self.peek() {
                        Some(b',') => self.at += 1,
                        Some(b')') => {}
                        _ => return Err(self.error("',' or ')'")),
                    }
                }
                self.at += 1;
                Ok(Value::Tuple(dims))
            }
            _ => {
                for (word, b) in [(&b"True"[..], true), (&b"False"[..], false)] {
                    if self.text[self.at..].starts_with(word) {
                        self.at += word.len();
                        return Ok(Value::Bool(b));
                    }
                }
                Err(self.error("a string, True, False or a shape"))
            }
        }
    }

    fn integer(&mut self) -> Result<usize, String> {
        let mut n: usize = 0;
        while let Some(&b) = self.text.get(self.at).filter(|b| b.is_ascii_digit()) {
            n = n
                .checked_mul(10)
                .and_then(|n| n.checked_add((b - b'0') as usize))
                .ok_or("malformed .npy header: a dimension overflows")?;
            self.at += 1;
        }
        // Python 2 wrote long dimensions as `3L`.
        if self.text.get(self.at) == Some(&b'L') {
            self.at += 1;
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// A version 1 `.npy` file with `header` (padded as NumPy pads it) and `data`.
    fn npy(header: &str, data: &[u8]) -> Vec<u8> {
        let mut h = header.as_bytes().to_vec();
        while !(10 + h.len() + 1).is_multiple_of(64) {
            h.push(b' ');
        }
        h.push(b'\n');
        let mut out = MAGIC.to_vec();
        out.extend([1, 0]);
        out.extend((h.len() as u16).to_le_bytes());
        out.extend(h);
        out.extend(data);
        out
    }

    fn le(values: &[f64]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn what_numpy_writes_reads() {
        let data = le(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let c = read_f64(&npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", &data)).unwrap();
        assert_eq!(c, ndarray::array![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        let f = read_f64(&npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }", &data)).unwrap();
        assert_eq!(f, ndarray::array![[1.0, 3.0, 5.0], [2.0, 4.0, 6.0]]);
        assert!(f.is_standard_layout());
        let i: Vec<u8> = [-2i16, 7].iter().flat_map(|v| v.to_be_bytes()).collect();
        let a = read_f64(&npy("{\"shape\":(1,2),\"fortran_order\":False,\"descr\":\">i2\"}", &i)).unwrap();
        assert_eq!(a, ndarray::array![[-2.0, 7.0]]);
        let u = read_f64(&npy("{'descr': '|u1', 'fortran_order': False, 'shape': (1L, 2L), }", &[255, 1])).unwrap();
        assert_eq!(u, ndarray::array![[255.0, 1.0]]);
        let f4: Vec<u8> = [0.5f32, -1.25].iter().flat_map(|v| v.to_le_bytes()).collect();
        let a = read_f64(&npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 1), }", &f4)).unwrap();
        assert_eq!(a, ndarray::array![[0.5], [-1.25]]);
    }

    #[test]
    fn the_declared_size_is_checked_before_allocating() {
        let e = read_f64(&npy("{'descr': '<f8', 'fortran_order': False, 'shape': (100000, 100000), }", &[0; 16]))
            .unwrap_err();
        assert!(e.contains("(100000, 100000)") && e.contains("80000000000 bytes") && e.contains("holds 16"), "{e}");
        let huge = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}", usize::MAX, 3);
        assert!(read_f64(&npy(&huge, &[])).unwrap_err().contains("more than can be counted"));
        let e = read_f64(&npy("{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }", &le(&[1.0; 3])));
        assert!(e.unwrap_err().contains("2-D"));
        let e = read_f64(&npy("{'descr': '<f8', 'fortran_order': False, 'shape': (0, 3), }", &[]));
        assert!(e.unwrap_err().contains("empty"));
        assert!(read_f64(b"\x93NUMPY\x01\x00\xff\xff{}").unwrap_err().contains("declares 65535 bytes"));
    }

    #[test]
    fn hostile_headers_are_one_short_line_at_once() {
        let nested = format!("{{'descr': '<f8', 'x': {}", "[".repeat(22));
        let parens = format!("{{'descr': '<f8', 'shape': {}", "(".repeat(50_000));
        // Exponential parsers take minutes on these; a linear one a few microseconds.
        for header in [nested.as_str(), &parens, "{'descr': [('a', '<f8')], }", "{'descr': '<c16'}", "{", "", "}"] {
            let e = read_f64(&npy(header, &[])).unwrap_err();
            assert!(e.len() < 200 && !e.contains('\n'), "{e}");
            assert!(e.contains(".npy header") || e.contains("dtype"), "{e}");
        }
        let e = read_f64(&npy("{'descr': '<f8', 'fortran_order': False}", &[])).unwrap_err();
        assert!(e.contains("needs 'descr', 'fortran_order' and 'shape'"), "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Any header bytes give a value or a one-line reason, never a panic.
        #[test]
        fn any_header_is_read_or_refused_in_one_line(header in proptest::collection::vec(any::<u8>(), 0..200)) {
            let mut bytes = MAGIC.to_vec();
            bytes.extend([1, 0]);
            bytes.extend((header.len() as u16).to_le_bytes());
            bytes.extend(&header);
            if let Err(e) = read_f64(&bytes) {
                prop_assert!(e.len() < 300 && !e.contains('\n'));
            }
        }

        /// Headers in every spelling NumPy's writers use read back the array; cutting the
        /// header anywhere is an error.
        #[test]
        fn valid_headers_in_any_order(
            ny in 1usize..5, nx in 1usize..5, fortran in any::<bool>(), order in 0usize..6,
            double in any::<bool>(), trailing in any::<bool>(), cut in 0usize..80,
        ) {
            let values: Vec<f64> = (0..nx * ny).map(|i| i as f64 - 3.0).collect();
            let fields = [
                format!("'descr': '{}'", if double { "<f8" } else { "<i8" }),
                format!("'fortran_order': {}", if fortran { "True" } else { "False" }),
                format!("'shape': ({ny}, {nx})"),
            ];
            let perm = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]][order];
            let body = perm.iter().map(|&i| fields[i].as_str()).collect::<Vec<_>>().join(", ");
            let header = format!("{{{body}{}}}", if trailing { ", " } else { "" });
            let data: Vec<u8> = if double {
                values.iter().flat_map(|v| v.to_le_bytes()).collect()
            } else {
                values.iter().flat_map(|&v| (v as i64).to_le_bytes()).collect()
            };
            let a = read_f64(&npy(&header, &data)).unwrap();
            prop_assert_eq!(a.dim(), (ny, nx));
            let stored = |r: usize, c: usize| if fortran { values[c * ny + r] } else { values[r * nx + c] };
            for ((r, c), v) in a.indexed_iter() {
                prop_assert_eq!(*v, stored(r, c));
            }
            let cut = cut.min(header.len() - 1);
            let mut bytes = MAGIC.to_vec();
            bytes.extend([1, 0]);
            bytes.extend((cut as u16).to_le_bytes());
            bytes.extend(&header.as_bytes()[..cut]);
            bytes.extend(&data);
            prop_assert!(read_f64(&bytes).is_err());
        }
    }
}
