//! The Zygo `.datx`, SRTM `.hgt`, NT-MDT `.mdt`, JPK QI image and NMM readers on real files
//! (`tests/data`, origin and licence in its README): the values their source projects' tests
//! assert, exactly, and what another reader computes from them, as a cross-check; a current
//! never read as heights; damaged copies refused in one line naming the file; and the near
//! misses (a Gwyddion 1 file, a Nanofocus `.nms`) refused with their real reason.

mod common;

use std::path::{Path, PathBuf};

use asperity::topography::io::{read, read_any, read_listing, ReadOptions};
use asperity::topography::prepare::Preparation;
use asperity::topography::stats::profile_height;
use asperity::topography::{AnyTopography, Topography};

fn rel(got: f64, want: f64) -> f64 {
    ((got - want) / want).abs()
}

/// Mean and standard deviation (population) of the points measured.
fn mean_std(t: &Topography) -> (f64, f64) {
    let defined: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
    let n = defined.len() as f64;
    let mean = defined.iter().sum::<f64>() / n;
    (mean, (defined.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt())
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// An error on one line that names the file.
fn refused(path: &Path, opts: &ReadOptions) -> String {
    let e = read_any(path, opts).map(|_| ()).expect_err(&path.display().to_string()).to_string();
    assert!(!e.contains('\n') && e.contains(&*path.file_name().unwrap().to_string_lossy()), "{e}");
    e
}

#[test]
fn a_zygo_datx_reads_its_surface_in_metres_from_fringes() {
    let t = read(&common::sample("zygo_test.datx"), &ReadOptions::default()).unwrap();
    assert_eq!((t.provenance.format.as_str(), t.channel.as_str()), ("datx", "Surface"));
    assert!(t.height_unit_known);
    // 259 rows × 33 columns at the lateral resolution of 1 mm (0.001 as float32).
    assert_eq!((t.nx(), t.ny()), (33, 259));
    let (lx, ly) = t.physical_size.unwrap();
    let step = f64::from(0.001f32);
    assert!(rel(lx, 33.0 * step) < 1e-15 && rel(ly, 259.0 * step) < 1e-15, "{lx} x {ly}");
    // The no-data value 1.797e308 marks 776 cells; 7 771 are measured.
    assert_eq!(t.missing_points(), 776);
    // A fringe is the wavelength (632.8 nm, as float64 in the file) times the scale factor 0.5.
    let fringe = 6.32799981e-07 * 0.5;
    assert!(rel(t.heights[[0, 0]], 0.39611427 * fringe) < 1e-8, "{:e}", t.heights[[0, 0]]);
    let (mean, std) = mean_std(&t);
    assert!(rel(mean, 2.8696e-08) < 1e-4 && rel(std, 8.0818e-08) < 1e-4, "{mean:e} {std:e}");
}

#[test]
fn srtm_tiles_read_in_metres_with_voids_missing_and_north_first() {
    // The tile gzip-compressed in tests/data: the gzip layer serves every format.
    let t = read(&common::sample("N44W072.hgt.gz"), &ReadOptions::default()).unwrap();
    assert_eq!((t.provenance.format.as_str(), t.nx(), t.ny()), ("hgt", 1201, 1201));
    assert_eq!(t.provenance.height_unit.as_deref(), Some("m"));
    assert!(t.height_unit_known && t.physical_size.is_none());
    // srtm.py asserts 341 m at 44°N 72°W, the tile's south-west corner: the last row, first column.
    assert_eq!(t.heights[[1200, 0]], 341.0);
    let min = t.heights.iter().copied().fold(f64::INFINITY, f64::min);
    let max = t.heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    assert_eq!((min, max, t.missing_points()), (115.0, 1908.0, 0));
    // Inside a zip, as the tiles are distributed; its voids (−32768) are missing points.
    let zipped = read(&common::data_dir().join("N22W160v2.3a.hgt.zip#N22W160.hgt"), &ReadOptions::default()).unwrap();
    assert_eq!((zipped.nx(), zipped.ny(), zipped.missing_points()), (1201, 1201, 4279));
    // Contact needs a physical size, which a tile does not give: it asks for one.
    let e = Preparation::default().apply(t).map(drop).unwrap_err().to_string();
    assert!(e.contains("states no physical size"), "{e}");
}

#[test]
fn an_ntmdt_current_frame_is_listed_and_never_read_as_heights() {
    let path = common::sample("test_mdt.mdt.gz");
    // By default: refused in one line that names the frame and its unit.
    let e = read(&path, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("no channel holds heights") && e.contains("'1F:Iprobe' (nA)"), "{e}");
    assert!(!e.contains('\n'), "{e}");
    // Named: read as stored, in nA, its height unit unknown.
    let opts = ReadOptions { channel: Some("1F:Iprobe".into()), ..Default::default() };
    let (t, names) = read_listing(&path, &opts).unwrap();
    assert_eq!(names, ["1F:Iprobe"]);
    assert_eq!((t.provenance.format.as_str(), t.provenance.height_unit.as_deref()), ("mdt", Some("nA")));
    assert!(!t.height_unit_known);
    assert_eq!((t.nx(), t.ny()), (256, 256));
    // SciFiReaders indexes its image [x, y], y counted from the last stored row: its
    // image[i, j] is our row 255 − j, column i (its test's values, exactly).
    let sci = |i: usize, j: isize| t.heights[[(255 - j.rem_euclid(256)) as usize, i]];
    assert_eq!(sci(134, 12), -0.021743940479999998);
    assert_eq!(sci(18, 0), -0.00267030848);
    assert_eq!(sci(206, -5), -0.02784750272);
    // 256 pixels of 0.011768 µm; SciFiReaders' span from the first pixel to the last is 3.0008 µm.
    let (lx, ly) = t.physical_size.unwrap();
    assert!(rel(lx, 256.0 * 0.011767974683082529e-6) < 1e-12 && lx == ly, "{lx}");
    assert!(rel(lx * 255.0 / 256.0, 3.0008e-6) < 1e-4, "{lx}");
}

#[test]
fn a_jpk_qi_image_reads_its_calibrated_height_with_invalid_pixels_missing() {
    let (t, names) = read_listing(&common::sample("data-image.jpk-qi-image"), &ReadOptions::default()).unwrap();
    assert_eq!(names, ["Vertical Deflection", "Slope", "Adhesion", "Height", "Height (measured)"]);
    assert_eq!((t.provenance.format.as_str(), t.channel.as_str()), ("jpk", "Height"));
    assert_eq!(t.provenance.height_unit.as_deref(), Some("m"));
    assert_eq!((t.nx(), t.ny()), (128, 128));
    let (lx, ly) = t.physical_size.unwrap();
    assert!(rel(lx, 5e-6) < 1e-12 && rel(ly, 5e-6) < 1e-12, "{lx} x {ly}");
    assert_eq!(t.missing_points(), 2);
    // The "calibrated" slot: raw · −1.149342477896219e-16 + 5.9061266512808265e-06.
    assert!(rel(t.heights[[0, 0]], 6.02451e-06) < 1e-5, "{:e}", t.heights[[0, 0]]);
    let (mean, std) = mean_std(&t);
    assert!(rel(mean, 5.91429e-06) < 1e-5 && rel(std, 1.14737e-07) < 1e-4, "{mean:e} {std:e}");
}

#[test]
fn an_nmm_line_scan_reads_as_surface_topography_read_it() {
    let (any, names) = read_any(&common::sample("nmm-1.zip"), &ReadOptions::default()).unwrap();
    assert_eq!(names, ["-Lz+Az"]);
    let AnyTopography::Profile(p) = any else { panic!("nmm-1.zip must read as a line profile") };
    assert_eq!((p.provenance.format.as_str(), p.points()), ("nmm", 20001));
    assert!(p.position_unit_known && p.height_unit_known);
    // SurfaceTopography's asserted values: the x extent and rms_height_from_profile.
    assert!(rel(p.length(), 0.0007071105772375498) < 1e-12, "{:e}", p.length());
    let (_, rms) = profile_height(&p).unwrap();
    assert!((rms - 1.135232e-06).abs() <= 5e-13, "{rms:e}");
}

#[test]
fn damaged_copies_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    for (file, reason) in [
        ("zygo_test.datx", "unexpected end of data"),
        ("data-image.jpk-qi-image", "truncated"),
        // A zip cut short has lost its directory of members.
        ("nmm-1.zip", "a zip container"),
    ] {
        let bytes = std::fs::read(common::sample(file)).unwrap();
        for cut in [40, 700, bytes.len() / 2] {
            let e = refused(&write(dir.path(), file, &bytes[..cut]), &opts);
            assert!(e.contains(reason), "{file} cut at {cut}: {e}");
        }
    }
    let mdt = {
        use std::io::Read;
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(&std::fs::read(common::sample("test_mdt.mdt.gz")).unwrap()[..])
            .read_to_end(&mut out)
            .unwrap();
        out
    };
    let named = ReadOptions { channel: Some("1F:Iprobe".into()), ..Default::default() };
    for cut in [20, 800, 40_000, mdt.len() / 2] {
        let e = refused(&write(dir.path(), "test_mdt.mdt", &mdt[..cut]), &named);
        assert!(e.contains("truncated"), "cut at {cut}: {e}");
    }
    // A tile one row short is no SRTM tile.
    let e = refused(&write(dir.path(), "N00E000.hgt", &vec![0u8; 1201 * 1200 * 2]), &opts);
    assert!(e.contains("1201 × 1201 (SRTM3) or 3601 × 3601 (SRTM1)") && e.contains("not 2882400"), "{e}");
}

#[test]
fn near_misses_are_refused_with_their_reason_and_a_pointer_to_the_format_list() {
    let dir = tempfile::tempdir().unwrap();
    let opts = ReadOptions::default();
    let e = refused(&write(dir.path(), "old.gwy", b"GWYOGwyContainer\0\0\0\0\0"), &opts);
    assert!(e.contains("a Gwyddion 1 file") && e.contains("re-save it in Gwyddion 2"), "{e}");
    let e = refused(&write(dir.path(), "scan.nms", &[7u8; 4000]), &opts);
    assert!(e.contains("Nanofocus .nms") && e.contains("without a unit"), "{e}");
    let e = refused(&write(dir.path(), "notes.bin", &[0xAB; 64]), &opts);
    assert!(e.contains("'asperity topo formats' lists the formats it reads") && !e.contains("x3p"), "{e}");
}

#[test]
fn topo_formats_lists_every_format_with_its_extensions_and_instrument() {
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["topo", "formats"])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let json: serde_json::Value = serde_json::from_str(&run(&["--json"])).unwrap();
    let names: Vec<&str> = json.as_array().unwrap().iter().map(|f| f["name"].as_str().unwrap()).collect();
    assert_eq!(names, asperity::topography::io::format_names());
    let datx = json.as_array().unwrap().iter().find(|f| f["name"] == "datx").unwrap();
    assert_eq!(datx["extensions"], serde_json::json!(["datx"]));
    assert_eq!(datx["kind"], "map");
    let text = run(&[]);
    let line = text.lines().find(|l| l.starts_with(".jpk .jpk-qi-image")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains(" jpk ") && line.contains("JPK Instruments"), "{line}");
    assert!(text.lines().any(|l| l.starts_with("(by content)") && l.contains(" nmm ")), "{text}");
}
