//! Robustness of the binary readers on mutated real files (proptest): random byte flips,
//! truncation at any length, and corruption of header fields (counts, sizes and offsets set
//! to 0, negative, huge or non-numeric values). Every case must end in channels or in a
//! one-line error: never a panic, and never an allocation sized by a header field. The
//! latter is measured: a tracking allocator records the largest single allocation made while
//! a file is read, which must stay within a small multiple of the file's own size.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::{Cursor, Read, Write};
use std::path::Path;
use std::sync::Arc;

use asperity::topography::io::{read_any, read_any_bytes, read_channels, ReadOptions};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRng, TestRunner};

struct Tracking;

thread_local! {
    /// The largest single allocation of this thread since the last reset [bytes].
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    let _ = LARGEST.try_with(|m| m.set(m.get().max(size)));
}

// SAFETY: every call is forwarded unchanged to the system allocator; only sizes are noted.
unsafe impl GlobalAlloc for Tracking {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Tracking = Tracking;

/// Cases per strategy and file: the whole suite stays within seconds in release.
const CASES: u32 = 40;

/// Values that break naive readers, written into header fields.
const NASTY_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "3",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "18446744073709551615",
    "99999999999999999999999",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "",
    "x",
];
const NASTY_WORDS: &[u32] = &[0, 1, 2, 0x7f, 0xff, 0xffff, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 0x0010_0000];

/// Read `bytes` as `format` from a file ending in `ext`; check the outcome.
fn check(dir: &Path, format: &str, ext: &str, bytes: &[u8]) -> Result<(), TestCaseError> {
    let path = dir.join(format!("case.{ext}"));
    std::fs::write(&path, bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
    LARGEST.with(|m| m.set(0));
    let result = read_channels(&path, Some(format));
    let largest = LARGEST.with(|m| m.get());
    // f64 values from 16-bit integers take 4× the bytes, from 8-bit ones 8×; zipped data
    // inflate a little; 1 MiB covers the fixed buffers of the zip and XML readers.
    let bound = 16 * bytes.len() + (1 << 20);
    prop_assert!(largest <= bound, "an allocation of {largest} bytes reading {} bytes", bytes.len());
    match result {
        Ok((_, channels)) => {
            prop_assert!(!channels.is_empty());
            for c in &channels {
                prop_assert!(c.data.nrows() > 0 && c.data.ncols() > 0);
            }
        }
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(!msg.contains('\n') && !msg.is_empty(), "error not on one line: {msg:?}");
        }
    }
    Ok(())
}

/// How a file's header is laid out, for the header-field strategy.
enum Header {
    /// Text header of this many bytes: the numbers on its lines naming one of the keys
    /// (sizes, counts, offsets, scales) are replaced by nasty ones.
    Text(usize, &'static [&'static str]),
    /// Binary header of this many bytes: 4-byte words in it are overwritten, half the time at
    /// one of the given field offsets; `fix` restores a checksum afterwards so that the
    /// corruption reaches the parser behind it.
    Binary(usize, Vec<usize>, fn(&mut [u8])),
    /// x3p: the digit runs of `main.xml` inside the zip are replaced.
    X3pXml,
}

fn run(name: &str, strategy: impl Strategy<Value = Vec<u8>>, dir: &Path, format: &str, ext: &str) {
    // A fixed seed: a failure reproduces on every run and machine.
    let config = Config { cases: CASES, failure_persistence: None, ..Config::default() };
    let rng = TestRng::deterministic_rng(config.rng_algorithm);
    TestRunner::new_with_rng(config, rng)
        .run(&strategy, |bytes| check(dir, format, ext, &bytes))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
}

fn fuzz(file: &str, format: &str, header: Header) {
    let original = Arc::new(std::fs::read(common::sample(file)).unwrap());
    let ext = Path::new(file).extension().unwrap().to_str().unwrap().to_string();
    let dir = tempfile::tempdir().unwrap();
    let len = original.len();
    // The unmutated file reads.
    assert!(read_channels(&common::sample(file), Some(format)).is_ok(), "{file} must read");

    let o = original.clone();
    let flips = prop::collection::vec((0..len, 1u8..=255), 1..16).prop_map(move |flips| {
        let mut b = (*o).clone();
        for (i, x) in flips {
            b[i] ^= x;
        }
        b
    });
    run(&format!("{file}: byte flips"), flips, dir.path(), format, &ext);

    let o = original.clone();
    let truncated = (0..len).prop_map(move |n| o[..n].to_vec());
    run(&format!("{file}: truncation"), truncated, dir.path(), format, &ext);

    let o = original.clone();
    match header {
        Header::Text(header_len, keys) => {
            let runs = Arc::new(digit_runs_on_lines(&o[..header_len], keys));
            assert!(runs.len() >= keys.len(), "{file}: the header fields are found");
            let corrupt = (0..runs.len(), prop::sample::select(NASTY_NUMBERS), 1..4usize).prop_map(move |(i, v, k)| {
                // Replace k consecutive fields from the i-th on.
                let mut b = (*o).clone();
                for &(s, e) in runs[i..].iter().take(k).rev() {
                    b.splice(s..e, v.bytes());
                }
                b
            });
            run(&format!("{file}: header fields"), corrupt, dir.path(), format, &ext);
        }
        Header::Binary(header_len, fields, fix) => {
            let at = prop_oneof![0..header_len - 4, prop::sample::select(fields)];
            let corrupt = prop::collection::vec((at, prop::sample::select(NASTY_WORDS), any::<bool>()), 1..4).prop_map(
                move |words| {
                    let mut b = (*o).clone();
                    for (at, w, big) in words {
                        let w = if big { w.to_be_bytes() } else { w.to_le_bytes() };
                        b[at..at + 4].copy_from_slice(&w);
                    }
                    fix(&mut b);
                    b
                },
            );
            run(&format!("{file}: header fields"), corrupt, dir.path(), format, &ext);
        }
        Header::X3pXml => {
            let xml = zip_entry(&o, "main.xml");
            let runs = Arc::new(digit_runs(xml.as_bytes()));
            let corrupt = (0..runs.len(), prop::sample::select(NASTY_NUMBERS)).prop_map(move |(i, v)| {
                let mut x = xml.clone().into_bytes();
                let (s, e) = runs[i];
                x.splice(s..e, v.bytes());
                replace_zip_entry(&o, "main.xml", &x)
            });
            run(&format!("{file}: main.xml fields"), corrupt, dir.path(), format, &ext);
        }
    }
}

/// The digit runs of the lines of `b` that contain one of `keys`.
fn digit_runs_on_lines(b: &[u8], keys: &[&str]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut start = 0;
    for line in b.split(|&c| c == b'\n') {
        let text = String::from_utf8_lossy(line);
        if keys.iter().any(|k| text.contains(k)) {
            runs.extend(digit_runs(line).into_iter().map(|(s, e)| (start + s, start + e)));
        }
        start += line.len() + 1;
    }
    runs
}

/// (start, end) of each run of ASCII digits (with sign, point and exponent) in `b`.
fn digit_runs(b: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let s = i;
            while i < b.len() && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'E' | b'-' | b'+')) {
                i += 1;
            }
            runs.push((s, i));
        } else {
            i += 1;
        }
    }
    runs
}

fn zip_entry(zip: &[u8], name: &str) -> String {
    let mut a = zip::ZipArchive::new(Cursor::new(zip)).unwrap();
    let mut s = String::new();
    a.by_name(name).unwrap().read_to_string(&mut s).unwrap();
    s
}

/// The zip `zip` with entry `name` replaced by `content` (stored), the others copied as are.
fn replace_zip_entry(zip: &[u8], name: &str, content: &[u8]) -> Vec<u8> {
    let mut a = zip::ZipArchive::new(Cursor::new(zip)).unwrap();
    let mut w = zip::ZipWriter::new(Cursor::new(Vec::new()));
    for i in 0..a.len() {
        let f = a.by_index(i).unwrap();
        if f.name().unwrap() == name {
            drop(f);
            let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
            w.start_file(name, opts).unwrap();
            w.write_all(content).unwrap();
        } else {
            w.raw_copy_file(f).unwrap();
        }
    }
    w.finish().unwrap().into_inner()
}

/// Restore the Igor version 5 checksum: the 16-bit words of the first 384 bytes sum to 0.
fn fix_ibw_checksum(b: &mut [u8]) {
    let little = b[0] != 0;
    let word = |w: &[u8]| if little { u16::from_le_bytes([w[0], w[1]]) } else { u16::from_be_bytes([w[0], w[1]]) };
    // The version word is kept, so the byte order stays detectable.
    b[..2].copy_from_slice(&if little { 5u16.to_le_bytes() } else { 5u16.to_be_bytes() });
    b[2..4].fill(0);
    let sum = b[..384].chunks_exact(2).fold(0u16, |s, w| s.wrapping_add(word(w)));
    let fix = 0u16.wrapping_sub(sum);
    b[2..4].copy_from_slice(&if little { fix.to_le_bytes() } else { fix.to_be_bytes() });
}

fn position(file: &str, marker: &[u8]) -> usize {
    let b = std::fs::read(common::sample(file)).unwrap();
    b.windows(marker.len()).position(|w| w == marker).unwrap() + marker.len()
}

/// The fuzzing targets (`fuzz/`) read bytes, not files: the bytes of a file read as the file
/// does, gzip data and a line profile included.
#[test]
fn a_files_bytes_read_as_the_file_does() {
    let opts = ReadOptions::default();
    for file in ["di-3.di", "matrix-4.txt.gz", "xy-1.txt"] {
        let path = common::sample(file);
        let bytes = std::fs::read(&path).unwrap();
        let from_bytes = read_any_bytes(path.to_str().unwrap(), bytes, &opts).unwrap();
        assert_eq!(from_bytes, read_any(&path, &opts).unwrap(), "{file}");
    }
}

#[test]
fn nanoscope_survives_mutation() {
    let keys = &[
        "Version",
        "Data offset",
        "Data length",
        "Bytes/pixel",
        "Samps/line",
        "Number of lines",
        "Scan Size",
        "Aspect",
        "Z scale",
        "Sens. Zsens",
    ];
    for file in ["di-3.di", "di-1.di"] {
        fuzz(file, "nanoscope", Header::Text(position(file, b"\\*File list end"), keys));
    }
}

#[test]
fn ibw_survives_mutation() {
    // wfmSize, the sizes of the blocks after the data, npnts, type, nDim, sfA.
    let fields = [4, 8, 12, 16, 20, 36, 44, 76, 80, 132, 136, 140, 144, 148, 156];
    fuzz("10x10-one_channel_without_name.ibw", "ibw", Header::Binary(384, fields.to_vec(), fix_ibw_checksum));
}

#[test]
fn nid_survives_mutation() {
    let keys = &["Points", "Lines", "SaveBits", "Range", "Min", "Count", "-Ch"];
    fuzz("nid-1.nid", "nid", Header::Text(position("nid-1.nid", b"#!"), keys));
}

#[test]
fn mi_survives_mutation() {
    let keys = &["xPixels", "yPixels", "xLength", "yLength", "bufferRange"];
    fuzz("mi-1.mi", "mi", Header::Text(position("mi-1.mi", b"BINARY_32\n"), keys));
}

#[test]
fn gwy_survives_mutation() {
    // Everything before the data array; in particular the object sizes, xres, yres and the
    // array length.
    let file = "si-ball-roughness.gwy";
    let fields = ["GwyContainer\0", "GwyDataField\0", "xres\0i", "yres\0i", "data\0D"]
        .iter()
        .map(|m| position(file, m.as_bytes()))
        .collect();
    fuzz(file, "gwy", Header::Binary(position(file, b"data\0D") + 4, fields, |_| {}));
}

#[test]
fn x3p_survives_mutation() {
    fuzz("x3p-2.x3p", "x3p", Header::X3pXml);
}

#[test]
fn metropro_survives_mutation() {
    // header_size, the intensity and phase grids and byte counts, the scale factors, phase_res.
    let fields = vec![6, 52, 56, 60, 68, 72, 164, 168, 176, 184, 218];
    fuzz("metropro-1.dat", "metropro", Header::Binary(834, fields, |_| {}));
}

#[test]
fn sur_survives_mutation() {
    // special_points, item size, zmin, nx, ny, point count, spacings, scale, units, inversion,
    // comment and private sizes.
    let fields = vec![86, 98, 100, 108, 112, 116, 120, 124, 128, 180, 212, 290, 334];
    fuzz("sur-2.sur", "sur", Header::Binary(512, fields, |_| {}));
}

#[test]
fn al3d_survives_mutation() {
    // The values (30 bytes after each 20-byte key) of TagCount, Cols, Rows and DepthImageOffset.
    let file = "al3d-1.al3d";
    let fields =
        ["TagCount", "Cols", "Rows", "DepthImageOffset"].iter().map(|k| position(file, k.as_bytes())).collect();
    fuzz(file, "al3d", Header::Binary(position(file, b"DepthImageOffset") + 30, fields, |_| {}));
}

#[test]
fn opd_survives_mutation() {
    // The directory's length, the Raw entry's type and length, the Raw block's nx, ny, item size.
    let fields = vec![20, 2 + 5 * 24 + 16, 2 + 5 * 24 + 18, 24020, 24022];
    fuzz("opd-1.opd", "opd", Header::Binary(24030, fields, |_| {}));
}

#[test]
fn plu_survives_mutation() {
    // Pixel sizes, the measurement type, layer and image counts, the layer's ny and nx.
    let fields = vec![404, 408, 428, 488, 492, 500, 504];
    fuzz("plu-1.plu", "plu", Header::Binary(508, fields, |_| {}));
}

#[test]
fn frt_survives_mutation() {
    // The block count, the grid block (its size, nx, ny, bits), the physical size, the height
    // scale and the size of the topography block, which starts at byte 140.
    let fields = [16, 50, 54, 58, 62, 72, 80, 126, 130, 136];
    fuzz("frt-2.frt", "frt", Header::Binary(140, fields.to_vec(), |_| {}));
}

#[test]
fn tmd_survives_mutation() {
    // nx, ny, the lengths and offsets after the 56 bytes of magic and comment.
    fuzz("tmd-1.tmd", "tmd", Header::Binary(80, vec![56, 60, 64, 68, 72, 76], |_| {}));
}

#[test]
fn wsxm_survives_mutation() {
    let keys = &["Image header size", "Number of", "Amplitude", "Maximum", "Minimum"];
    fuzz("top-1.top", "wsxm", Header::Text(position("top-1.top", b"[Header end]\r\n"), keys));
}

#[test]
fn bcr_survives_mutation() {
    // A UTF-16 header of 2048 characters: the values of its sizes and units.
    let file = "bcrf-1.bcrf";
    let utf16 = |s: &str| s.encode_utf16().flat_map(u16::to_le_bytes).collect::<Vec<u8>>();
    let fields =
        ["headersize = ", "xpixels = ", "ypixels = ", "intelmode = ", "xlength = ", "voidpixels = ", "zunit = "]
            .iter()
            .map(|k| position(file, &utf16(k)))
            .collect();
    fuzz(file, "bcr", Header::Binary(4096, fields, |_| {}));
}

#[test]
fn ps_survives_mutation() {
    // The TIFF header and directory (its count, the data and header tags' counts and offsets),
    // then the vendor header at 1050617: grid, scan size, gain, scale, offset, data type.
    let fields =
        [4, 8, 162, 174, 182, 186, 194, 198, 1050717, 1050721, 1050757, 1050765, 1050837, 1050845, 1050853, 1050965];
    fuzz("example_ps.tiff", "ps", Header::Binary(1051197, fields.to_vec(), |_| {}));
}

#[test]
fn mnt_survives_mutation() {
    // The compound file's sector size, allocation sector count, directory and mini-table starts,
    // DIFAT chain, first allocation sector; the directory entry of ScopedContents (the third of
    // the directory in sector 2, at 12544): its first sector and size.
    let fields = vec![0x1C, 0x2C, 0x30, 0x3C, 0x40, 0x44, 0x48, 0x4C, 12544 + 116, 12544 + 120, 12544 + 124];
    fuzz("mnt-1.mnt", "mnt", Header::Binary(12544 + 128, fields, |_| {}));
}

#[test]
fn jpk_survives_mutation() {
    // The first directory (at 8, 38 tags): its count, and each tag's count and value or offset
    // (the grid's lengths and points among them).
    let fields = [4, 8].into_iter().chain((0..38).flat_map(|i| [10 + 12 * i + 4, 10 + 12 * i + 8])).collect();
    fuzz("data-image.jpk-qi-image", "jpk", Header::Binary(470, fields, |_| {}));
}

#[test]
fn datx_survives_mutation() {
    // The HDF5 superblock (its sizes and the root group's addresses) and the object headers after it.
    let fields = vec![8, 12, 16, 24, 32, 40, 48, 56, 64, 72, 80, 88];
    fuzz("zygo_test.datx", "datx", Header::Binary(4096, fields, |_| {}));
}
