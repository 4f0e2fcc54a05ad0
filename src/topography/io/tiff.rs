//! The directories of a TIFF file (classic TIFF, either byte order): the tags of each image, as
//! the TIFF-based formats (Park Systems, JPK) read their private tags. Only the bytes present
//! are read: a directory, a value or a strip past the end of the file is an error.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use super::binary::{self, Cursor, Endian};

/// The most directories followed: a chain that loops or runs on is refused.
const MAX_DIRECTORIES: usize = 4096;

/// One tag of a directory: its TIFF type, its count, and where its value lies.
pub struct Entry {
    pub tag: u16,
    kind: u16,
    count: usize,
    /// The value's offset in the file (in the entry itself when it fits in 4 bytes).
    at: usize,
}

/// One image file directory: its tags.
pub struct Directory {
    pub entries: Vec<Entry>,
}

/// A TIFF file's bytes, byte order and directories.
pub struct Tiff<'a> {
    bytes: &'a [u8],
    pub endian: Endian,
    /// The image file directories, in file order: at least one.
    pub directories: Vec<Directory>,
}

/// The byte order a TIFF header states, `None` when `head` is no TIFF.
pub fn endian(head: &[u8]) -> Option<Endian> {
    match head.get(..4) {
        Some(b"II*\0") => Some(Endian::Little),
        Some(b"MM\0*") => Some(Endian::Big),
        _ => None,
    }
}

/// Bytes per value of a TIFF type (BYTE, ASCII, SHORT, LONG, RATIONAL, SBYTE, UNDEFINED,
/// SSHORT, SLONG, SRATIONAL, FLOAT, DOUBLE); `None` for a type TIFF does not define.
fn type_size(kind: u16) -> Option<usize> {
    Some(match kind {
        1 | 2 | 6 | 7 => 1,
        3 | 8 => 2,
        4 | 9 | 11 => 4,
        5 | 10 | 12 => 8,
        _ => return None,
    })
}

impl<'a> Tiff<'a> {
    /// The directories of `bytes`; with `first_only`, the first one (enough to sniff a head).
    pub fn parse(bytes: &'a [u8], first_only: bool) -> Result<Tiff<'a>, String> {
        let endian = endian(bytes).ok_or("not a TIFF file")?;
        let mut c = Cursor::new(bytes, endian);
        c.skip(4, "the TIFF header")?;
        let mut next = c.u32("the TIFF header")? as usize;
        let mut directories = Vec::new();
        while next != 0 {
            if directories.len() == MAX_DIRECTORIES {
                return Err(format!("more than {MAX_DIRECTORIES} TIFF directories (a loop?)"));
            }
            let n = usize::from(Cursor::new(binary::extent(bytes, next, 2, "a TIFF directory")?, endian).u16("n")?);
            let raw = binary::extent(bytes, next + 2, n * 12 + 4, "a TIFF directory")?;
            let mut d = Cursor::new(raw, endian);
            let mut entries = Vec::with_capacity(n);
            for i in 0..n {
                let (tag, kind) = (d.u16("a TIFF tag")?, d.u16("a TIFF tag")?);
                let count = d.u32("a TIFF tag")? as usize;
                let field = next + 2 + 12 * i + 8;
                let inline = type_size(kind).and_then(|s| s.checked_mul(count)).is_some_and(|len| len <= 4);
                let at = if inline { field } else { d.u32("a TIFF tag")? as usize };
                if inline {
                    d.skip(4, "a TIFF tag")?;
                }
                entries.push(Entry { tag, kind, count, at });
            }
            directories.push(Directory { entries });
            next = d.u32("a TIFF directory")? as usize;
            if first_only {
                break;
            }
        }
        if directories.is_empty() {
            return Err("a TIFF without an image (its first directory's offset is 0)".into());
        }
        Ok(Tiff { bytes, endian, directories })
    }

    /// The raw bytes of `entry`'s value, checked against the file.
    pub fn raw(&self, entry: &Entry) -> Result<&'a [u8], String> {
        let size =
            type_size(entry.kind).ok_or_else(|| format!("TIFF tag {} has unknown type {}", entry.tag, entry.kind))?;
        let len = size.checked_mul(entry.count).ok_or_else(|| format!("TIFF tag {} is too long", entry.tag))?;
        binary::extent(self.bytes, entry.at, len, &format!("TIFF tag {}", entry.tag))
    }

    /// The value of `entry` as text (ASCII, NUL-terminated or not).
    pub fn text(&self, entry: &Entry) -> Result<String, String> {
        Ok(binary::padded_str(self.raw(entry)?))
    }

    /// The numbers of `entry` (any integer or floating-point type) as `f64`.
    pub fn numbers(&self, entry: &Entry) -> Result<Vec<f64>, String> {
        let raw = self.raw(entry)?;
        let size = type_size(entry.kind).unwrap_or(1);
        let mut c = Cursor::new(raw, self.endian);
        let what = format!("TIFF tag {}", entry.tag);
        (0..entry.count)
            .map(|_| {
                Ok(match entry.kind {
                    1 | 7 => f64::from(c.u8(&what)?),
                    6 => f64::from(c.u8(&what)? as i8),
                    3 => f64::from(c.u16(&what)?),
                    8 => f64::from(c.i16(&what)?),
                    4 => f64::from(c.u32(&what)?),
                    9 => f64::from(c.i32(&what)?),
                    11 => f64::from(c.f32(&what)?),
                    12 => c.f64(&what)?,
                    5 => f64::from(c.u32(&what)?) / f64::from(c.u32(&what)?),
                    10 => f64::from(c.i32(&what)?) / f64::from(c.i32(&what)?),
                    _ => return Err(format!("{what} of type {} (size {size}) is not a number", entry.kind)),
                })
            })
            .collect()
    }

    /// The single number of `entry`.
    pub fn number(&self, entry: &Entry) -> Result<f64, String> {
        match self.numbers(entry)?[..] {
            [v] => Ok(v),
            ref v => Err(format!("TIFF tag {} holds {} values, not one", entry.tag, v.len())),
        }
    }

    /// The image data of directory `d`, uncompressed strips joined in order.
    pub fn strips(&self, d: &Directory) -> Result<Vec<u8>, String> {
        if let Some(c) = d.find(259) {
            let compression = self.number(c)?;
            if compression != 1.0 {
                return Err(format!("compressed TIFF images (compression {compression}) are not supported"));
            }
        }
        let offsets = self.numbers(d.find(273).ok_or("a TIFF image without strip offsets (tag 273)")?)?;
        let counts = self.numbers(d.find(279).ok_or("a TIFF image without strip byte counts (tag 279)")?)?;
        if offsets.len() != counts.len() {
            return Err(format!("{} strip offsets for {} strip byte counts", offsets.len(), counts.len()));
        }
        let total = counts.iter().map(|&n| n as usize).fold(0usize, usize::saturating_add);
        binary::extent(self.bytes, 0, total, "the TIFF strips")?;
        let mut out = Vec::with_capacity(total);
        for (&at, &n) in offsets.iter().zip(&counts) {
            out.extend_from_slice(binary::extent(self.bytes, at as usize, n as usize, "a TIFF strip")?);
        }
        Ok(out)
    }
}

impl Directory {
    /// The entry of `tag`, if the directory has one.
    pub fn find(&self, tag: u16) -> Option<&Entry> {
        self.entries.iter().find(|e| e.tag == tag)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A little-endian TIFF of one directory: a SHORT 7, an ASCII "ab" and a DOUBLE 2.5.
    fn tiny() -> Vec<u8> {
        let mut b = b"II*\0".to_vec();
        b.extend(8u32.to_le_bytes());
        b.extend(3u16.to_le_bytes());
        let entry = |tag: u16, kind: u16, count: u32, value: [u8; 4]| {
            let mut e = tag.to_le_bytes().to_vec();
            e.extend(kind.to_le_bytes());
            e.extend(count.to_le_bytes());
            e.extend(value);
            e
        };
        b.extend(entry(256, 3, 1, [7, 0, 0, 0]));
        b.extend(entry(270, 2, 3, *b"ab\0\0"));
        b.extend(entry(32834, 12, 1, 50u32.to_le_bytes()));
        b.extend(0u32.to_le_bytes());
        b.extend(2.5f64.to_le_bytes());
        b
    }

    #[test]
    fn tags_are_read_by_type() {
        let bytes = tiny();
        let t = Tiff::parse(&bytes, false).unwrap();
        assert_eq!(t.directories.len(), 1);
        let d = &t.directories[0];
        assert_eq!(t.number(d.find(256).unwrap()).unwrap(), 7.0);
        assert_eq!(t.text(d.find(270).unwrap()).unwrap(), "ab");
        assert_eq!(t.number(d.find(32834).unwrap()).unwrap(), 2.5);
        assert!(d.find(273).is_none());
    }

    #[test]
    fn values_past_the_end_and_loops_are_refused() {
        let mut bytes = tiny();
        bytes.truncate(bytes.len() - 4);
        let t = Tiff::parse(&bytes, false).unwrap();
        assert!(t.number(t.directories[0].find(32834).unwrap()).unwrap_err().contains("truncated"));
        // A directory whose next offset points back at itself.
        let mut looped = tiny();
        let next = 8 + 2 + 3 * 12;
        looped[next..next + 4].copy_from_slice(&8u32.to_le_bytes());
        let e = Tiff::parse(&looped, false).map(|t| t.directories.len()).unwrap_err();
        assert!(e.contains("more than 4096 TIFF directories"), "{e}");
        // A header whose first directory is at 0: no image, refused (readers index the first).
        let mut empty = b"II*\0".to_vec();
        empty.extend([0u8; 12]);
        let e = Tiff::parse(&empty, true).map(|t| t.directories.len()).unwrap_err();
        assert!(e.contains("a TIFF without an image"), "{e}");
    }
}
