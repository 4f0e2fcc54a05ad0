//! Digital Surf Mountains documents (`.mnt`).
//!
//! A Microsoft compound file (OLE, [MS-CFB]) whose stream `ScopedContents` holds the document:
//! a `u64` size, then a tree of entries, each a `u16` tag, a `u64` size and its bytes (a value
//! or more entries). The document is a list of objects (each entry after a `u64` of its own);
//! an object has a class number (entry 1.1), a body (2) and an id (3). Only the measured
//! surface (class 9012) stores heights; layers derived from it are recomputed by Mountains and
//! are not in the file. A surface's measurement (class 9062) holds its x and y axes (step, unit,
//! number of points), the height axis (height per count, unit, origin in the display unit), the
//! heights as `i32` (or `i16`) counts row by row in zlib blocks (each after its first element,
//! its element count and its compressed size), and optionally a mask of (nx + 2) × (ny + 2)
//! bytes, a border of one point, where 9 marks a measured point. A height is
//! `count × step + origin`.
//!
//! Must not import contact, friction, study, report, plot, shs, cli (the layers above topography).

use std::io::Read;

use ndarray::Array2;

use super::binary::{self, Cursor, Endian};
use super::gzip;
use super::reading::{Channel, Format};
use crate::limits::{reserve, Limits};
use crate::quantity::metres_per;

pub struct Mnt;

/// The signature of a compound file.
const MAGIC: &[u8] = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1";
const CLASS_SURFACE: u32 = 9012;
const CLASS_MEASUREMENT: u32 = 9062;
const CLASS_HEIGHTS: u32 = 9049;
const CLASS_MASK: u32 = 9056;
const CLASS_MASK_ARRAY: u32 = 9048;
const MEASURED: u8 = 9;

impl Format for Mnt {
    fn name(&self) -> &'static str {
        "mnt"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["mnt"]
    }

    /// The only compound files the registry knows; another one (a Word document) is refused
    /// for its missing `ScopedContents` stream.
    fn sniff(&self, head: &[u8]) -> bool {
        head.starts_with(MAGIC)
    }

    fn read(&self, bytes: &[u8]) -> Result<Vec<Channel>, String> {
        self.read_within(bytes, &Limits::default())
    }

    fn read_within(&self, bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
        decode(bytes, limits).map_err(binary::one_line)
    }
}

fn decode(bytes: &[u8], limits: &Limits) -> Result<Vec<Channel>, String> {
    if !bytes.starts_with(MAGIC) {
        return Err("not a Mountains document (no compound-file signature)".into());
    }
    let contents = Compound::new(bytes)?.stream("ScopedContents")?;
    let tree = contents.get(8..).ok_or("truncated: the stream ScopedContents is shorter than 8 bytes")?;
    let main = need(tree, &[1], "the document")?;
    let objects = need(main, &[0x2BD, 2, 1], "the list of objects")?;
    let mut channels = Vec::new();
    for object in list(objects)? {
        if class(object)? == Some(CLASS_SURFACE) {
            if let Some(channel) = surface(need(object, &[2], "a surface's body")?, limits)? {
                channels.push(channel);
            }
        }
    }
    if channels.is_empty() {
        return Err("the document holds no measured surface of heights".into());
    }
    Ok(channels)
}

/// One measured surface as a channel in metres; `None` when its heights are not lengths.
fn surface(body: &[u8], limits: &Limits) -> Result<Option<Channel>, String> {
    let Some(measurement) = find(body, &[1])? else { return Ok(None) };
    if class(measurement)? != Some(CLASS_MEASUREMENT) {
        return Ok(None);
    }
    let m = need(measurement, &[2, 0xFFFF], "a measurement")?;
    let grid = need(m, &[0xFFFF], "the grid")?;
    let x = axis(need(grid, &[1, 0xFFFF], "the x axis")?, "x")?;
    let y = axis(need(grid, &[2, 0xFFFF], "the y axis")?, "y")?;
    let z_axis = need(m, &[2], "the height axis")?;
    let z = scale(need(z_axis, &[0xFFFF], "the height axis")?, "z")?;
    // Heights in another unit (an intensity) are no topography: SurfaceTopography skips them too.
    let display = z.display_unit.as_deref().unwrap_or(&z.unit);
    let (Some(per_count), Some(per_display)) = (metres_per(&z.unit), metres_per(display)) else {
        return Ok(None);
    };
    let name = match find(grid, &[0xFFFF, 0xFFFF, 1])?.and_then(text) {
        Some(n) if !n.is_empty() => n,
        _ => find(body, &[0xFFFF, 4])?.and_then(text).filter(|t| !t.is_empty()).unwrap_or_else(|| "Default".into()),
    };
    let (nx, ny) = (x.points, y.points);
    let n = binary::grid_points(nx, ny)?;
    limits.check_grid(nx, ny)?;

    let heights = need(m, &[1], "the heights")?;
    if class(heights)? != Some(CLASS_HEIGHTS) {
        return Err("the heights are not an array of counts".into());
    }
    let (counts, size) = array(heights, n, "the heights")?;
    if size == 1 {
        return Err("heights of 1 byte a point (Mountains stores 2 or 4)".into());
    }
    let mask = match find(grid, &[3])? {
        Some(mask) if class(mask)? == Some(CLASS_MASK) => {
            let (w, h) = (u32_of(need(mask, &[2, 1], "the mask's width")?)?, u32_of(need(mask, &[2, 2], "the mask")?)?);
            if (w as usize, h as usize) != (nx, ny) {
                return Err(format!("the mask is {w} x {h} points, the grid {nx} x {ny}"));
            }
            let array_object = need(mask, &[2, 5], "the mask's array")?;
            if class(array_object)? != Some(CLASS_MASK_ARRAY) {
                return Err("the mask holds no array".into());
            }
            let border = binary::grid_points(nx + 2, ny + 2)?;
            let (mask, size) = array(array_object, border, "the mask")?;
            if size != 1 {
                return Err(format!("the mask has {size} bytes a point, not 1"));
            }
            Some(mask)
        }
        _ => None,
    };

    let (step, origin) = (z.step * per_count, z.origin * per_display);
    let mut values = Vec::new();
    reserve(&mut values, n, "the heights")?;
    for (i, c) in counts.chunks_exact(size).enumerate() {
        let count = if size == 2 {
            f64::from(i16::from_le_bytes([c[0], c[1]]))
        } else {
            f64::from(i32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        };
        let measured = mask.as_ref().is_none_or(|m| m[(i / nx + 1) * (nx + 2) + i % nx + 1] == MEASURED);
        values.push(if measured { count * step + origin } else { f64::NAN });
    }
    let data = Array2::from_shape_vec((ny, nx), values).map_err(|e| e.to_string())?;
    Ok(Some(Channel {
        name,
        data,
        physical_size: Some((nx as f64 * x.step, ny as f64 * y.step)),
        unit: Some(display.to_string()),
        is_height: true,
    }))
}

/// A lateral axis: its step [m] and number of points.
struct Axis {
    step: f64,
    points: usize,
}

fn axis(entries: &[u8], what: &str) -> Result<Axis, String> {
    let s = scale(need(entries, &[0xFFFF], &format!("the {what} axis's scale"))?, what)?;
    let metres = metres_per(&s.unit)
        .ok_or_else(|| format!("the {what} axis's unit '{}' is not a length", binary::printable(&s.unit)))?;
    let step = s.step * metres;
    if !(step > 0.0 && step.is_finite()) {
        return Err(format!("the {what} axis's step {} {} is not positive", s.step, s.unit));
    }
    Ok(Axis { step, points: u32_of(need(entries, &[1], &format!("the {what} axis's points"))?)? as usize })
}

/// An axis's scale: the step (grid spacing or height per count) in `unit`, the origin in
/// `display_unit` (else `unit`).
struct Scale {
    step: f64,
    unit: String,
    display_unit: Option<String>,
    origin: f64,
}

fn scale(entries: &[u8], what: &str) -> Result<Scale, String> {
    let incomplete = || format!("the {what} axis has no step or unit");
    let step = find(entries, &[1])?.and_then(f64_of).filter(|s| s.is_finite()).ok_or_else(incomplete)?;
    let unit = find(entries, &[2])?.and_then(text).filter(|u| !u.is_empty()).ok_or_else(incomplete)?;
    let display_unit =
        find(entries, &[3])?.and_then(text).filter(|u| !u.is_empty()).map(|u| binary::normalise_unit(&u));
    let origin = match find(entries, &[5])? {
        Some(o) => {
            f64_of(o).filter(|o| o.is_finite()).ok_or_else(|| format!("the {what} axis's origin is no number"))?
        }
        None => 0.0,
    };
    Ok(Scale { step, unit: binary::normalise_unit(&unit), display_unit, origin })
}

/// The values of an array object of `count` elements, inflated from its zlib blocks, with
/// the bytes an element takes. Each block is checked against what the array declares, and
/// what the blocks inflate to must cover the array once.
fn array(object: &[u8], count: usize, what: &str) -> Result<(Vec<u8>, usize), String> {
    let declared = u32_of(need(object, &[2, 1], what)?)? as usize;
    if declared != count {
        return Err(format!("{what}: {declared} values for a grid of {count} points"));
    }
    let data = need(object, &[2, 2], what)?;
    let mut c = Cursor::new(data, Endian::Little);
    let total = c.i64(what)? as u64;
    let size = usize::try_from(total / count as u64).unwrap_or(0);
    if !total.is_multiple_of(count as u64) || !matches!(size, 1 | 2 | 4) {
        return Err(format!("{what}: {total} bytes for {count} values"));
    }
    let mut blocks = Vec::new();
    while c.remaining() > 0 {
        let first = usize::try_from(c.i64("a block's first element")? as u64).unwrap_or(usize::MAX);
        let elements = c.u32("a block's element count")? as usize;
        let compressed_len = c.u32("a block's size")? as usize;
        let compressed = c.take(compressed_len, "a compressed block")?;
        let len = elements * size;
        if first.checked_add(elements).is_none_or(|end| end > count)
            || len > gzip::MAX_INFLATION * compressed.len() + 64
        {
            return Err(format!("{what}: a block of {elements} values from {first} does not fit {count} values"));
        }
        let mut block = Vec::new();
        flate2::read::ZlibDecoder::new(compressed)
            .take(len as u64 + 1)
            .read_to_end(&mut block)
            .map_err(|e| format!("{what}: a damaged zlib block ({e})"))?;
        if block.len() != len {
            return Err(format!("{what}: a block inflates to {} bytes, not {len}", block.len()));
        }
        blocks.push((first, block));
    }
    blocks.sort_by_key(|b| b.0);
    let mut out = Vec::new();
    reserve(&mut out, count * size, what)?;
    for (first, block) in blocks {
        if first * size != out.len() {
            return Err(format!("{what}: the blocks leave a gap or overlap at value {first}"));
        }
        out.extend_from_slice(&block);
    }
    if out.len() != count * size {
        return Err(format!("{what}: the blocks hold {} of {count} values", out.len() / size));
    }
    Ok((out, size))
}

/// The entries of `b`: tag, bytes.
fn entries(b: &[u8]) -> Result<Vec<(u16, &[u8])>, String> {
    let mut c = Cursor::new(b, Endian::Little);
    let mut out = Vec::new();
    while c.remaining() > 0 {
        let tag = c.u16("an entry's tag")?;
        let len = usize::try_from(c.i64("an entry's size")? as u64).unwrap_or(usize::MAX);
        out.push((tag, c.take(len, "an entry")?));
    }
    Ok(out)
}

/// The bytes of the first entry at the path of tags `path`, if there is one.
fn find<'a>(mut b: &'a [u8], path: &[u16]) -> Result<Option<&'a [u8]>, String> {
    for &tag in path {
        match entries(b)?.into_iter().find(|e| e.0 == tag) {
            Some((_, inner)) => b = inner,
            None => return Ok(None),
        }
    }
    Ok(Some(b))
}

fn need<'a>(b: &'a [u8], path: &[u16], what: &str) -> Result<&'a [u8], String> {
    find(b, path)?.ok_or_else(|| format!("the document has no {what}"))
}

/// The objects of the document's list, each after a `u64` of its own.
fn list(b: &[u8]) -> Result<Vec<&[u8]>, String> {
    let mut c = Cursor::new(b, Endian::Little);
    let mut out = Vec::new();
    while c.remaining() > 0 {
        c.skip(8, "an object's prefix")?;
        let tag = c.u16("an object's tag")?;
        let len = usize::try_from(c.i64("an object's size")? as u64).unwrap_or(usize::MAX);
        let object = c.take(len, "an object")?;
        if tag == 1 {
            out.push(object);
        }
    }
    Ok(out)
}

/// An object's class number.
fn class(object: &[u8]) -> Result<Option<u32>, String> {
    Ok(find(object, &[1, 1])?.and_then(|b| b.try_into().ok()).map(u32::from_le_bytes))
}

fn u32_of(b: &[u8]) -> Result<u32, String> {
    b.try_into().map(u32::from_le_bytes).map_err(|_| format!("a count of {} bytes, not 4", b.len()))
}

fn f64_of(b: &[u8]) -> Option<f64> {
    b.try_into().ok().map(f64::from_le_bytes)
}

/// Text: a marker byte 4, then UTF-16 (little-endian), NUL-padded.
fn text(b: &[u8]) -> Option<String> {
    let (&4, rest) = b.split_first()? else { return None };
    if rest.len() % 2 != 0 {
        return None;
    }
    let units: Vec<u16> = rest.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
    String::from_utf16(&units).ok().map(|s| s.trim_end_matches('\0').to_string())
}

/// A compound file: its sectors, allocation tables and directory.
struct Compound<'a> {
    bytes: &'a [u8],
    /// Bytes a sector.
    sector: usize,
    fat: Vec<u32>,
    mini_fat: Vec<u32>,
    /// The mini stream (the root entry's stream), of 64-byte sectors.
    mini: Vec<u8>,
    /// Streams smaller than this live in the mini stream.
    cutoff: u64,
    /// The directory: entries of 128 bytes.
    directory: Vec<u8>,
}

const END_OF_CHAIN: u32 = 0xFFFF_FFFE;
/// Ids from this one up are markers (free, end of chain, table sectors), not sectors.
const MARKERS: u32 = 0xFFFF_FFFA;
const MINI_SECTOR: usize = 64;

impl<'a> Compound<'a> {
    fn new(bytes: &'a [u8]) -> Result<Compound<'a>, String> {
        let mut h = Cursor::new(binary::extent(bytes, 0, 512, "the compound file's header")?, Endian::Little);
        h.skip(0x1E, "the header")?;
        let shift = h.u16("the header")?;
        if !matches!(shift, 9 | 12) {
            return Err(format!("a compound file with sectors of 2^{shift} bytes"));
        }
        let sector = 1usize << shift;
        h.skip(0x2C - 0x20, "the header")?;
        let fat_sectors = h.u32("the header")? as usize;
        let directory_start = h.u32("the header")?;
        h.skip(4, "the header")?;
        let cutoff = u64::from(h.u32("the header")?);
        let mini_fat_start = h.u32("the header")?;
        h.skip(4, "the header")?;
        let mut difat_next = h.u32("the header")?;
        h.skip(4, "the header")?;
        let mut fat_ids: Vec<u32> = (0..109).map(|_| h.u32("the header")).collect::<Result<_, _>>()?;
        let mut c = Compound {
            bytes,
            sector,
            fat: Vec::new(),
            mini_fat: Vec::new(),
            mini: Vec::new(),
            cutoff,
            directory: Vec::new(),
        };
        // More ids of allocation sectors, in a chain of sectors whose last word is the next.
        let mut hops = 0;
        while difat_next < MARKERS {
            hops += 1;
            if hops > bytes.len() / sector {
                return Err("the compound file's sector tables loop".into());
            }
            let ids = words(c.sector_bytes(difat_next)?);
            difat_next = ids[ids.len() - 1];
            fat_ids.extend_from_slice(&ids[..ids.len() - 1]);
        }
        if fat_sectors > bytes.len() / sector {
            return Err(format!(
                "truncated: the compound file declares {fat_sectors} allocation sectors of {sector} bytes but holds {} \
                 bytes",
                bytes.len()
            ));
        }
        if fat_sectors > fat_ids.len() {
            return Err(format!(
                "the compound file declares {fat_sectors} allocation sectors but lists {}",
                fat_ids.len()
            ));
        }
        for &id in &fat_ids[..fat_sectors] {
            let w = words(c.sector_bytes(id)?);
            c.fat.extend(w);
        }
        c.directory = c.chain(false, directory_start, None)?;
        let root = binary::extent(&c.directory, 0, 128, "the compound file's directory")?;
        let (start, size) = c.start_and_size(root);
        c.mini = if start < MARKERS { c.chain(false, start, Some(size))? } else { Vec::new() };
        if mini_fat_start < MARKERS {
            c.mini_fat = words(&c.chain(false, mini_fat_start, None)?);
        }
        Ok(c)
    }

    /// The bytes of a directory entry's stream named `name`.
    fn stream(&self, name: &str) -> Result<Vec<u8>, String> {
        for e in self.directory.chunks_exact(128) {
            let len = usize::from(u16::from_le_bytes([e[64], e[65]])).min(64);
            let units: Vec<u16> = e[..len].chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
            if e[66] == 2 && String::from_utf16_lossy(&units).trim_end_matches('\0') == name {
                let (start, size) = self.start_and_size(e);
                return self.chain(size < self.cutoff, start, Some(size));
            }
        }
        Err(format!("not a Mountains document (a compound file without the stream {name})"))
    }

    /// A directory entry's first sector and its stream's size (32 bits in files of 512-byte
    /// sectors, whose high word may hold anything).
    fn start_and_size(&self, entry: &[u8]) -> (u32, u64) {
        let start = u32::from_le_bytes(entry[116..120].try_into().expect("4 bytes"));
        let size = u64::from_le_bytes(entry[120..128].try_into().expect("8 bytes"));
        (start, if self.sector == 512 { size & 0xFFFF_FFFF } else { size })
    }

    fn sector_bytes(&self, id: u32) -> Result<&'a [u8], String> {
        let offset = (id as usize).checked_add(1).and_then(|i| i.checked_mul(self.sector)).unwrap_or(usize::MAX);
        binary::extent(self.bytes, offset, self.sector, "a sector of the compound file")
    }

    /// The bytes of the chain of sectors from `start` (of the mini stream when `mini`), `size`
    /// of them when given, else the whole chain.
    fn chain(&self, mini: bool, start: u32, size: Option<u64>) -> Result<Vec<u8>, String> {
        let table = if mini { &self.mini_fat } else { &self.fat };
        let mut out = Vec::new();
        if let Some(size) = size {
            // A stream lies in the file: it is never longer.
            if size > self.bytes.len() as u64 {
                return Err(format!("a stream of {size} bytes in a file of {}", self.bytes.len()));
            }
            reserve(&mut out, size as usize, "a stream of the compound file")?;
        }
        let want = size.map_or(usize::MAX, |s| s as usize);
        // A chain visits each sector once: more hops than sectors is a loop.
        let sectors = if mini { self.mini.len() / MINI_SECTOR } else { self.bytes.len() / self.sector };
        let mut id = start;
        let mut hops = 0;
        while out.len() < want && id != END_OF_CHAIN {
            hops += 1;
            if hops > sectors || id >= MARKERS {
                return Err("a chain of sectors of the compound file loops or is broken".into());
            }
            let sector = if mini {
                let offset = (id as usize).saturating_mul(MINI_SECTOR);
                binary::extent(&self.mini, offset, MINI_SECTOR, "a sector of the mini stream")?
            } else {
                self.sector_bytes(id)?
            };
            out.extend_from_slice(sector);
            id = *table.get(id as usize).ok_or("a chain of sectors of the compound file leaves its table")?;
        }
        if let Some(size) = size {
            if (out.len() as u64) < size {
                return Err(format!("truncated: a stream of {size} bytes ends after {}", out.len()));
            }
            out.truncate(size as usize);
        }
        Ok(out)
    }
}

/// Little-endian `u32` words.
fn words(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect()
}
