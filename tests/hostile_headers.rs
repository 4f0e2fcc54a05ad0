//! Instrument headers built to exhaust memory or time, from real files: the channels of a file
//! decode within a small multiple of its size (measured by a tracking allocator), and a header
//! is parsed in time linear in its length.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::time::{Duration, Instant};

use asperity::limits::Limits;
use asperity::topography::io::{self, container_members, read_channels, Member, ReadOptions};

struct Tracking;

thread_local! {
    /// Bytes this thread holds now, and the most it held since the last reset.
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

fn grow(by: usize) {
    let _ = LIVE.try_with(|l| {
        l.set(l.get() + by);
        let _ = PEAK.try_with(|p| p.set(p.get().max(l.get())));
    });
}

fn shrink(by: usize) {
    let _ = LIVE.try_with(|l| l.set(l.get().saturating_sub(by)));
}

// SAFETY: every call is forwarded unchanged to the system allocator; only sizes are counted.
unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        grow(new_size);
        shrink(layout.size());
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        shrink(layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Tracking = Tracking;

/// Read `bytes` as `format`: the outcome as text, the most memory held while reading beyond
/// what was held before [bytes], and the time it took.
fn read(format: &str, bytes: &[u8]) -> (Result<usize, String>, usize, Duration) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case");
    std::fs::write(&path, bytes).unwrap();
    let before = LIVE.with(|l| l.get());
    PEAK.with(|p| p.set(before));
    let start = Instant::now();
    let result = read_channels(&path, Some(format)).map(|(_, channels)| channels.len()).map_err(|e| e.to_string());
    let elapsed = start.elapsed();
    let peak = PEAK.with(|p| p.get()) - before;
    (result, peak, elapsed)
}

/// The file list, scanner and scan lists of the real `di-3.di` (everything before its first
/// image section), with `keys` more scanner keys.
fn nanoscope_preamble(keys: usize) -> Vec<u8> {
    let b = std::fs::read(common::sample("di-3.di")).unwrap();
    let first = b.windows(17).position(|w| w == b"\\*Ciao image list").unwrap();
    let scanner = b.windows(14).position(|w| w == b"\\*Scanner list").unwrap() + 16;
    assert_eq!(&b[scanner - 2..scanner], b"\r\n");
    let mut out = b[..scanner].to_vec();
    for k in 0..keys {
        out.extend(format!("\\Key{k}: {k}\r\n").bytes());
    }
    out.extend(&b[scanner..first]);
    out
}

/// A NanoScope image section of an `n` × `n` height image at `offset` (offsets padded to ten
/// digits, so that a section's length does not depend on them).
fn image_section(n: usize, offset: usize) -> String {
    format!(
        "\\*Ciao image list\r\n\\Data offset: {offset:010}\r\n\\Data length: {}\r\n\\Samps/line: {n}\r\n\
         \\Number of lines: {n}\r\n\\@2:Image Data: S [Height] \"Height\"\r\n\
         \\@2:Z scale: V [Sens. Zsens] (0.1 V/LSB) 1 V\r\n",
        2 * n * n
    )
}

/// A NanoScope file: `preamble`, then `images` sections of `n` × `n` 16-bit images whose data
/// follow the header, each at its own offset or all at the first.
fn nanoscope(preamble: Vec<u8>, images: usize, n: usize, shared: bool) -> Vec<u8> {
    let end = "\\*File list end\r\n";
    let data_start = preamble.len() + images * image_section(n, 0).len() + end.len();
    let block = 2 * n * n;
    let mut out = preamble;
    for k in 0..images {
        out.extend(image_section(n, data_start + if shared { 0 } else { k * block }).bytes());
    }
    out.extend(end.bytes());
    assert_eq!(out.len(), data_start);
    out.resize(data_start + block * if shared { 1 } else { images }, 1);
    out
}

#[test]
fn nanoscope_images_sharing_their_data_are_refused() {
    // 200 sections naming one 256 × 256 image: 105 MB decoded from 0.5 MB (2 000 of them
    // aborted past 4 GB).
    let file = nanoscope(nanoscope_preamble(0), 200, 256, true);
    let (result, peak, _) = read("nanoscope", &file);
    let e = result.unwrap_err();
    assert!(e.contains("channels 'Height' and 'Height' declare overlapping data"), "{e}");
    assert!(peak < 4 * file.len(), "{peak} bytes held reading {} bytes", file.len());
    // The same images, each with its own data, decode within a small multiple of the file: f64
    // values from 16-bit integers take 4× their bytes.
    let file = nanoscope(nanoscope_preamble(0), 20, 256, false);
    let (result, peak, _) = read("nanoscope", &file);
    assert_eq!(result, Ok(20));
    assert!(peak < 6 * file.len(), "{peak} bytes held reading {} bytes", file.len());
    // An image's data overlapping the next one's by a byte is refused as well.
    let mut file = nanoscope(nanoscope_preamble(0), 2, 16, false);
    let second = nanoscope_preamble(0).len() + 2 * image_section(16, 0).len() + 17 + 512;
    let at = file.windows(10).position(|w| w == format!("{second:010}").as_bytes()).unwrap();
    file[at..at + 10].copy_from_slice(format!("{:010}", second - 1).as_bytes());
    assert!(read("nanoscope", &file).0.unwrap_err().contains("overlapping"));
    file[at..at + 10].copy_from_slice(format!("{second:010}").as_bytes());
    assert_eq!(read("nanoscope", &file).0, Ok(2));
}

#[test]
fn nanoscope_headers_parse_in_linear_time() {
    // 30 000 images and 300 000 scanner keys (10 MB): each image looked its scales up through
    // every key, about a minute; linear, well under a second.
    let file = nanoscope(nanoscope_preamble(300_000), 30_000, 1, false);
    let (result, _, elapsed) = read("nanoscope", &file);
    assert_eq!(result, Ok(30_000));
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?} to read {} bytes", file.len());
}

#[test]
fn nid_headers_parse_in_linear_time() {
    // The real header of nid-1.nid listing 200 000 more channels, each a 1 × 1 block (3.5 MB):
    // each looked its group's name up through every entry, 49 s; linear, well under a second.
    let b = std::fs::read(common::sample("nid-1.nid")).unwrap();
    let marker = b.windows(3).position(|w| w == b"\n#!").unwrap();
    let header = String::from_utf8_lossy(&b[..marker]).to_string();
    let list = header.find("Gr0-Ch0=").unwrap();
    let channels = 200_000;
    let mut text = header[..list].to_string();
    for k in 8..8 + channels {
        text += &format!("Gr0-Ch{k}=DataSet-0:9\r\n");
    }
    text += &header[list..];
    text += "\r\n[DataSet-0:9]\r\nPoints=1\r\nLines=1\r\nDim2Name=Z\r\nDim2Unit=m\r\nDim2Range=1e-6\r\nDim2Min=0\r\n\
             SaveBits=16\r\n";
    let mut file = text.into_bytes();
    file.extend(&b[marker..]);
    file.resize(file.len() + 2 * channels, 0);
    let (result, peak, elapsed) = read("nid", &file);
    // The real file's 4 height channels, then the 200 000 listed ones.
    assert_eq!(result, Ok(4 + channels));
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?} to read {} bytes", file.len());
    assert!(peak < 64 * file.len(), "{peak} bytes held reading {} bytes", file.len());
}

/// A zip of `members` (name, content), deflated.
fn zip_of(members: &[(&str, &[u8])]) -> Vec<u8> {
    use std::io::Write;
    let mut w = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, content) in members {
        w.start_file(*name, opts).unwrap();
        w.write_all(content).unwrap();
    }
    w.finish().unwrap().into_inner()
}

/// The container members of `zip` written to a file (`Err` with the error's text), and the time
/// the listing took.
fn list(zip: &[u8]) -> (Result<Vec<Member>, String>, Duration) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scans.zip");
    std::fs::write(&path, zip).unwrap();
    let start = Instant::now();
    let members = container_members(&path, &Limits::default()).map(Option::unwrap).map_err(|e| e.to_string());
    (members, start.elapsed())
}

#[test]
fn a_zip_of_many_members_lists_in_linear_time() {
    // 20 000 empty members (2 MB): the archive was parsed again for each member, 18 s for
    // 8 000 and growing with the square; parsed once, well under a second.
    let names: Vec<String> = (0..20_000).map(|k| format!("m{k:05}.txt")).collect();
    let zip = zip_of(&names.iter().map(|n| (n.as_str(), &b""[..])).collect::<Vec<_>>());
    let (members, elapsed) = list(&zip);
    let members = members.unwrap();
    assert_eq!(members.len(), 20_000);
    assert_eq!(members[19_999].name, "m19999.txt");
    assert_eq!(members[0].content, Err("no topography in it: no row of numbers".to_string()));
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?} to list {} bytes", zip.len());
}

#[test]
fn overlapping_zip_entries_are_refused_before_inflating() {
    // One member of 16 MiB of zeros, then 199 more entries of the central directory naming its
    // bytes: each inflated in full to be listed (77 s for 200 of 256 MiB each).
    let zip = zip_of(&[("m000.txt", &vec![b'0'; 16 << 20])]);
    let cd = zip.windows(4).rposition(|w| w == b"PK\x01\x02").unwrap();
    let end = zip.windows(4).rposition(|w| w == b"PK\x05\x06").unwrap();
    let entry = zip[cd..end].to_vec();
    let mut bomb = zip[..end].to_vec();
    for k in 1..200 {
        let mut e = entry.clone();
        e[46..54].copy_from_slice(format!("m{k:03}.txt").as_bytes());
        bomb.extend(e);
    }
    let mut eocd = zip[end..].to_vec();
    eocd[8..10].copy_from_slice(&200u16.to_le_bytes());
    eocd[10..12].copy_from_slice(&200u16.to_le_bytes());
    eocd[12..16].copy_from_slice(&(200 * entry.len() as u32).to_le_bytes());
    bomb.extend(eocd);
    let (members, elapsed) = list(&bomb);
    let e = members.unwrap_err();
    assert!(
        e.ends_with(
            "scans.zip: members of the archive share their bytes (overlapping entries, as zip bombs are made): refused"
        ),
        "{e}"
    );
    assert!(elapsed < Duration::from_secs(5), "{elapsed:?}");
    // Reading one member is refused alike.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b.zip"), &bomb).unwrap();
    let e = read_channels(&dir.path().join("b.zip#m007.txt"), None).unwrap_err().to_string();
    assert!(e.contains("b.zip#m007.txt: members of the archive share their bytes"), "{e}");
}

#[test]
fn a_zip_naming_a_member_twice_is_refused() {
    // Two members, the second renamed as the first in its local and central headers.
    let zip = zip_of(&[("a.txt", b"1 2\n3 4\n"), ("b.txt", b"5 6\n7 8\n")]);
    let mut twice = zip.clone();
    for at in (0..zip.len() - 5).filter(|&i| &zip[i..i + 5] == b"b.txt") {
        twice[at] = b'a';
    }
    let e = list(&twice).0.unwrap_err();
    assert!(
        e.ends_with("scans.zip: member 'a.txt' appears twice in the archive: which one is meant is ambiguous"),
        "{e}"
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.zip"), &twice).unwrap();
    let e = read_channels(&dir.path().join("t.zip#a.txt"), None).unwrap_err().to_string();
    assert!(
        e.ends_with("t.zip#a.txt: member 'a.txt' appears twice in the archive: which one is meant is ambiguous"),
        "{e}"
    );
    // As written, both read.
    assert_eq!(list(&zip).0.unwrap().len(), 2);
}

/// `bytes` with every `from` replaced by `to`.
fn replaced(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let (from, to) = (from.as_bytes(), to.as_bytes());
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            out.extend(to);
            i += from.len();
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}

/// A NanoScope file of one 4 × 4 height image (Z scale `1 V` at 34.55678 nm/V), its header
/// edited by `edits` and its data offset moved to follow it.
fn nanoscope_edited(edits: &[(&str, &str)]) -> Vec<u8> {
    let file = nanoscope(nanoscope_preamble(0), 1, 4, false);
    let start = file.len() - 32;
    let mut header = file[..start].to_vec();
    for (from, to) in edits {
        header = replaced(&header, from, to);
    }
    let offset = |at: usize| format!("\\Data offset: {at:010}");
    header = replaced(&header, &offset(start), &offset(header.len()));
    [header, file[start..].to_vec()].concat()
}

/// The error reading `bytes` as a map (the file named `case`), or the map's size.
fn read_map(bytes: &[u8]) -> Result<Option<(f64, f64)>, String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case");
    std::fs::write(&path, bytes).unwrap();
    io::read(&path, &ReadOptions::default()).map(|t| t.physical_size).map_err(|e| e.to_string())
}

#[test]
fn a_height_scale_flattening_the_heights_is_refused_naming_it() {
    let z = |value: &str| nanoscope_edited(&[("(0.1 V/LSB) 1 V\r\n", &format!("(0.1 V/LSB) {value}\r\n"))]);
    let (result, ..) = read("nanoscope", &z("1 V"));
    assert_eq!(result, Ok(1));
    // Zero or subnormal: every height decoded as 0 and the map was solved as flat.
    for (value, factor) in [("0 V", "0"), ("1e-320 V", "0")] {
        let e = read("nanoscope", &z(value)).0.unwrap_err();
        let said = format!(
            "channel 'Height': Z scale '{value}': a factor of {factor} per stored unit is zero, subnormal or not \
             finite: every height would decode as flat"
        );
        assert!(e.ends_with(&said), "{e}");
    }
    // Normal, but the whole 16-bit range spans 1e-37 m.
    let e = read("nanoscope", &z("2.9e-30 V")).0.unwrap_err();
    assert!(e.contains("channel 'Height': Z scale '2.9e-30 V': the whole range of the stored values spans "), "{e}");
    assert!(e.ends_with(", below 0.1 pm, the smallest heights any instrument measures"), "{e}");
}

/// A Gwyddion Simple Field of `nx` × 2 zeros in metres, its header ending with `fields`.
fn gsf(nx: usize, fields: &str) -> Vec<u8> {
    let mut out =
        format!("Gwyddion Simple Field 1.0\nXRes = {nx}\nYRes = 2\nXYUnits = m\nZUnits = m\n{fields}").into_bytes();
    out.resize((out.len() / 4 + 1) * 4, 0);
    out.resize(out.len() + nx * 2 * 4, 0);
    out
}

#[test]
fn sizes_read_from_files_are_judged_as_the_size_option() {
    assert_eq!(read_map(&gsf(4, "XReal = 1e-5\nYReal = 5e-6\n")), Ok(Some((1e-5, 5e-6))));
    // Solved on a 1e10 m window with exit 0.
    let e = read_map(&gsf(4, "XReal = 1e10\nYReal = 1e10\n")).unwrap_err();
    assert!(
        e.ends_with(
            "case: the physical size 1e10 m × 1e10 m stated by XReal and YReal: 1e10 m is not the size of a \
             measured window (1 nm to 1 m)"
        ),
        "{e}"
    );
    // A number meant in micrometres: the unit is suggested, as for --size.
    let e = read_map(&gsf(4, "XReal = 31.13\nYReal = 31.13\n")).unwrap_err();
    assert!(e.ends_with("31.13 m is not the size of a measured window (1 nm to 1 m); did you mean 31.13um?"), "{e}");
    // Each pixel as --pixel-size.
    let e = read_map(&gsf(4096, "XReal = 2e-9\nYReal = 1e-9\n")).unwrap_err();
    assert!(
        e.contains("stated by XReal and YReal: a pixel of 2e-9 m / 4096 points: 0.488281 pm is not a pixel size"),
        "{e}"
    );
    // NanoScope's scan size alike.
    let huge = nanoscope_edited(&[("\\Data offset", "\\Scan Size: 500 1e30 nm\r\n\\Data offset")]);
    let e = read_map(&huge).unwrap_err();
    assert!(e.ends_with("case: the physical size 500 nm × 1e21 m stated by Scan Size: 1e21 m is not the size of a measured window (1 nm to 1 m)"), "{e}");
    // A line profile's positions alike.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.csv");
    std::fs::write(&path, "x in µm,y in µm\n0,1\n1e7,2\n2e7,3\n3e7,1\n4e7,2\n").unwrap();
    let e = io::read_any(&path, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.ends_with("p.csv: the length 50 m its positions state: 50 m is not the size of a measured window (1 nm to 1 m); did you mean 50um?"), "{e}");
    std::fs::write(&path, "x in µm,y in µm\n0,1\n1,2\n2,3\n3,1\n4,2\n").unwrap();
    assert!(io::read_any(&path, &ReadOptions::default()).is_ok());
}

/// The reason of a refused read, without the temporary file's path before it.
fn reason(format: &str, bytes: &[u8]) -> String {
    let message = read(format, bytes).0.unwrap_err();
    message.split_once(": ").map(|(_, reason)| reason.to_string()).unwrap_or(message)
}

#[test]
fn a_npy_header_key_holding_a_newline_is_quoted_on_one_line() {
    // The header of example-2d.npy with a newline and a NUL before 'shape' (found by fuzzing:
    // the key was quoted as it stood, on two lines).
    let header = "{'descr': '<f8', 'fortran_order': False, '\0\nshape': (2, 2), }";
    let mut file = b"\x93NUMPY\x01\x00".to_vec();
    let padded = format!("{header:<117}\n");
    file.extend((padded.len() as u16).to_le_bytes());
    file.extend(padded.bytes());
    file.extend([1.0f64, 2.0, 3.0, 4.0].iter().flat_map(|v| v.to_le_bytes()));
    assert_eq!(reason("npy", &file), "malformed .npy header: unknown key '\\0\\nshape'");
}

#[test]
fn a_netcdf_variable_name_holding_a_newline_is_quoted_on_one_line() {
    // A classic NetCDF header whose variable 'a\nb' names dimension 11 of its one (found by
    // fuzzing: the name was quoted as it stood, on two lines).
    let word = |v: u32| v.to_be_bytes();
    let mut file = b"CDF\x01".to_vec();
    file.extend(word(0)); // records
    file.extend([word(0x0A), word(1), word(1)].concat()); // one dimension, named 'x',
    file.extend(b"x\0\0\0");
    file.extend(word(2)); // of 2 points
    file.extend([word(0), word(0)].concat()); // no attribute
    file.extend([word(0x0B), word(1), word(3)].concat()); // one variable, named 'a\nb',
    file.extend(b"a\nb\0");
    file.extend([word(1), word(11)].concat()); // of rank 1, on dimension 11
    file.resize(file.len() + 32, 0);
    assert_eq!(reason("netcdf", &file), "NetCDF variable 'a\\nb' uses no dimension 11");
}

#[test]
fn an_hdf5_error_quoting_the_file_stays_on_one_line() {
    // A mutation of multiple_data_sets.h5, minimised by the hdf5 fuzzing target: 1160 bytes, zero
    // but for these runs (offset, hex). Its group names a child by bytes of the signature,
    // '\r\n\x1a\n', which the HDF5 decoder's error quoted as they stood, over two lines.
    let runs: [(usize, &str); 15] = [
        (
            0,
            concat!(
                "894844460d0a1a0a0000000000080800040010010000000000000f0000000000ffffffffffffffff",
                "00c81a0000000000ffffffffffffffff500000000000000060000000000000000100000000000000",
                "8800000000000000a802000000000000010001000100000018000000000000001100100000000000",
                "8800000000000000a8020000000000005452454500000100ffffffffffffffffffffffffffffffff"
            ),
        ),
        (168, "3004000000000000180000000050414548"),
        (347, "51414548"),
        (680, "484541500000000058000000000000002800000000000000c802"),
        (716, "894844460d0a1a0a0000000000080800c4"),
        (778, "666606dcdfbf5d8fc2f560e0"),
        (800, "01000500010000000001000000000000010028000000000000534e4f440100020008"),
        (850, "1805"),
        (886, "c2ed3ee0bfc3285c2f42e0bfec51b81ee942e0bf15ae68e0bf3e0ad718000000000003010008"),
        (932, "8e"),
        (946, "78"),
        (1012, "92"),
        (1072, "534e4f440100020008"),
        (1096, "1805"),
        (1132, "c2ed3ee0bfc3285c2f42e0bfec51b81ee942e0bf15ae68e0bf3e0ad7"),
    ];
    let mut file = vec![0u8; 1160];
    for (at, hex) in runs {
        let bytes = (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap());
        file.splice(at..at + hex.len() / 2, bytes);
    }
    assert_eq!(reason("hdf5", &file), "HDF5: child '????' at 0x0: unsupported object header version 137");
}
