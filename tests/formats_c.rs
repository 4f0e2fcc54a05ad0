//! gzip, zip containers and the readers of `.npz`, NetCDF `.nc` and Mitutoyo `.xlsx`, against
//! what SurfaceTopography 1.27.1 reports for the same files (`read_topography`; a `.gz` read
//! through `gzip.open`, a container's member extracted). Statistics within 1e-9 relative;
//! bombs and path tricks refused in one line naming the file.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use asperity::limits::Limits;
use asperity::topography::io::{container_members, read, read_any, MemberContent, ReadOptions};
use asperity::topography::stats::{profile_height, profile_rms_slope};
use asperity::topography::{AnyTopography, Topography};

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs().max(1e-300)
}

/// Mean, standard deviation, min and max of the defined heights [m].
fn stats(t: &Topography) -> [f64; 4] {
    let h: Vec<f64> = t.heights.iter().copied().filter(|h| !h.is_nan()).collect();
    let n = h.len() as f64;
    let mean = h.iter().sum::<f64>() / n;
    let std = (h.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
    [mean, std, h.iter().copied().fold(f64::INFINITY, f64::min), h.iter().copied().fold(f64::NEG_INFINITY, f64::max)]
}

/// A map: its grid (nx, ny), size [m] and statistics [m] as SurfaceTopography gives them (its
/// unit converted to metres by `metres`).
fn assert_map(path: &Path, grid: (usize, usize), size: (f64, f64), want: [f64; 4], metres: f64) {
    let t = read(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((t.nx(), t.ny()), grid, "{}", path.display());
    let (lx, ly) = t.physical_size.unwrap();
    assert!(close(lx, size.0 * metres, 1e-12) && close(ly, size.1 * metres, 1e-12), "{lx} {ly}");
    let got = stats(&t);
    for (i, what) in ["mean", "std", "min", "max"].iter().enumerate() {
        // A mean near zero (detrended, or nc-1's 0) differs by rounding in the order of the sum:
        // it is compared within 1e-9 of the spread of the heights.
        let scale = if i == 0 { want[1] * metres } else { want[i] * metres };
        let ok = (got[i] - want[i] * metres).abs() <= 1e-9 * scale.abs();
        assert!(ok, "{}: {what} {:e} vs {:e}", path.display(), got[i], want[i] * metres);
    }
}

#[test]
fn gzip_is_transparent() {
    // SurfaceTopography on gzip.open("matrix-4.txt.gz"): 75 × 305, in m.
    assert_map(
        &common::sample("matrix-4.txt.gz"),
        (75, 305),
        (2.773965e-05, 0.00011280791),
        [-1.1915104367256354e-15, 1.1745891510991089e-07, -2.968808672092e-07, 2.929150022256e-07],
        1.0,
    );
    let t = read(&common::sample("matrix-4.txt.gz"), &ReadOptions::default()).unwrap();
    assert_eq!(t.provenance.format, "matrix", "detected from the name less .gz");
}

/// A gzip file of `n` zeros' worth of text lines ("0 0\n"), about a thousandth of that long.
fn gz_bomb(path: &Path, n: usize) {
    let mut w = flate2::write::GzEncoder::new(std::fs::File::create(path).unwrap(), flate2::Compression::best());
    let line = b"0 0\n".repeat(1 << 16);
    for _ in 0..n / line.len() {
        w.write_all(&line).unwrap();
    }
    w.finish().unwrap();
}

#[test]
fn decompression_bombs_are_refused_within_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let bomb = dir.path().join("bomb.txt.gz");
    gz_bomb(&bomb, 256 << 20);
    assert!(std::fs::metadata(&bomb).unwrap().len() < 1 << 20);
    // 1000 points allow 16 MiB + 128 000 bytes: inflating stops there, not at 256 MiB.
    let limits = Limits::new(1000, "--max-points").unwrap();
    let e = read(&bomb, &ReadOptions { limits, ..ReadOptions::default() }).unwrap_err().to_string();
    assert!(e.starts_with(&bomb.display().to_string()) && !e.contains('\n'), "{e}");
    assert!(e.contains(&format!("inflates past {} bytes", limits.max_file_bytes())), "{e}");
    // The same bomb as a container's member, and the CLI's one line and exit status.
    let zip = dir.path().join("scans.zip");
    let mut w = zip::ZipWriter::new(std::fs::File::create(&zip).unwrap());
    w.start_file("bomb.txt.gz", zip::write::SimpleFileOptions::default()).unwrap();
    w.write_all(&std::fs::read(&bomb).unwrap()).unwrap();
    w.finish().unwrap();
    let member = format!("{}#bomb.txt.gz", zip.display());
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "info", &member, "--max-points", "1000"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && stderr.lines().count() == 1, "{stderr}");
    assert!(stderr.contains(&member) && stderr.contains("gzip: inflates past"), "{stderr}");
}

#[test]
fn netcdf_is_read_as_surface_topography_reads_it() {
    let path = common::sample("nc-1.nc");
    // heights(x, y): 5 points along x, 10 along y, in nm; sizes 5 nm × 10 nm.
    assert_map(&path, (5, 10), (5.0, 10.0), [0.0, 5.744562646538029, -9.0, 9.0], 1e-9);
    // Orientation: the file's heights[i][j] = 9 − 2j nm at x index i, y index j.
    let t = read(&path, &ReadOptions::default()).unwrap();
    for (j, i) in [(0, 0), (0, 4), (9, 0), (3, 2)] {
        assert!(close(t.heights[[j, i]], (9.0 - 2.0 * j as f64) * 1e-9, 1e-12), "({j}, {i})");
    }
    assert_eq!(t.provenance.height_unit.as_deref(), Some("nm"));
}

/// A profile read whole: (points, length [m], mean, rms height [m], rms slope) as
/// SurfaceTopography's `mean()`, `rms_height_from_profile()`, `rms_slope_from_profile()` in µm.
fn assert_profile(path: &Path, points: usize, uniform: bool, um: [f64; 4], slope: f64) {
    let (t, _) = read_any(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let AnyTopography::Profile(p) = t else { panic!("{}: not a profile", path.display()) };
    assert_eq!((p.points(), p.step().is_some()), (points, uniform), "{}", path.display());
    let (mean, rms) = profile_height(&p).unwrap();
    let [length, want_mean, want_rms, _] = um;
    for (what, got, want) in [("length", p.length(), length), ("mean", mean, want_mean), ("rms", rms, want_rms)] {
        assert!(close(got, want * 1e-6, 1e-9), "{}: {what} {got:e} vs {:e}", path.display(), want * 1e-6);
    }
    let got = profile_rms_slope(&p).unwrap();
    assert!(close(got, slope, 1e-9), "{}: slope {got} vs {slope}", path.display());
    // A profile is never a map: contact's gate refuses it.
    assert!(read(path, &ReadOptions::default()).unwrap_err().to_string().contains("line profile"));
}

#[test]
fn mitutoyo_spreadsheets_are_profiles_as_surface_topography_reads_them() {
    // Positions in mm (the cut-off's unit), heights in µm (Ra's).
    assert_profile(
        &common::sample("mitutoyo_mock.xlsx"),
        960,
        true,
        [480.0, 0.047769026324304596, 0.16866328079293708, 0.0],
        0.48052916568879783,
    );
    assert_profile(
        &common::sample("mitutoyo_2_mock.xlsx"),
        6664,
        true,
        [9996.0, -0.05774936974789915, 3.9688974167760445, 0.0],
        0.15593245613399986,
    );
    assert_profile(
        &common::sample("mitutoyo_nonuniform_mock.xlsx"),
        960,
        false,
        [479.5, 0.04771973402671663, 0.1371261153644389, 0.0],
        0.4805323961694857,
    );
}

#[test]
fn npz_arrays_are_channels() {
    // numpy.savez_compressed of a 1-D "x" (left out) and a 3 × 4 "heights" (tools/make_generated_npz.py).
    let path = common::sample("generated-two-arrays.npz");
    let opts = ReadOptions { physical_size: Some((4e-6, 3e-6)), height_unit: Some("nm".into()), ..Default::default() };
    let t = read(&path, &opts).unwrap();
    assert_eq!((t.channel.as_str(), t.nx(), t.ny(), t.provenance.format.as_str()), ("heights", 4, 3, "npz"));
    assert!(close(t.heights[[1, 2]], 6e-9, 1e-12) && close(t.heights[[2, 3]], 11e-9, 1e-12));
    let e = read(&path, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("physical size"), "{e}");
}

fn container() -> PathBuf {
    common::sample("container-2.zip")
}

fn member(name: &str) -> PathBuf {
    PathBuf::from(format!("{}#{name}", container().display()))
}

#[test]
fn a_container_lists_its_members_and_reads_each() {
    let members = container_members(&container(), &Limits::default()).unwrap().unwrap();
    let names: Vec<&str> = members.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "80_Scale10.472_FIXEDv2p1_D7eHXiT.asc",
            "gain_control_uncd_35_z03tr3R.001",
            "LICENSE-ccby-4.0.txt",
            "meta.yml",
            "uncd_stylus_300um_5mar_3_k0HpKJt.txt"
        ]
    );
    assert_eq!(members[1].content, Ok(MemberContent { format: "nanoscope", kind: "map", grid: (512, 512) }));
    assert_eq!(members[4].content, Ok(MemberContent { format: "profile", kind: "profile", grid: (3001, 1) }));
    assert!(members[3].content.as_ref().unwrap_err().contains("not a topography file"));
    // A file of one topography is not a container; nor is a member named.
    assert_eq!(container_members(&common::sample("nc-1.nc"), &Limits::default()).unwrap(), None);
    assert_eq!(container_members(&member("meta.yml"), &Limits::default()).unwrap(), None);

    // The NanoScope member as SurfaceTopography reads the extracted file (nm).
    assert_map(
        &member("gain_control_uncd_35_z03tr3R.001"),
        (512, 512),
        (100.0, 100.0),
        [-1702.8306273658927, 27.794175935431255, -1760.8187900635942, -1647.5104203382875],
        1e-9,
    );
    // The archive itself is not one topography: refused with the way to name a member.
    let e = read(&container(), &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("zip container") && e.contains("container-2.zip#MEMBER"), "{e}");
    let e = read(&member("nothing.txt"), &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("no member 'nothing.txt'") && e.contains("meta.yml"), "{e}");
}

#[test]
fn a_gzipped_container_is_listed_and_read() {
    let dir = tempfile::tempdir().unwrap();
    let gz = dir.path().join("scans.zip.gz");
    let mut w = flate2::write::GzEncoder::new(std::fs::File::create(&gz).unwrap(), flate2::Compression::fast());
    w.write_all(&std::fs::read(container()).unwrap()).unwrap();
    w.finish().unwrap();
    let members = container_members(&gz, &Limits::default()).unwrap().unwrap();
    assert_eq!(members.len(), 5);
    let member = PathBuf::from(format!("{}#gain_control_uncd_35_z03tr3R.001", gz.display()));
    let t = read(&member, &ReadOptions::default()).unwrap();
    assert_eq!((t.nx(), t.ny(), t.provenance.format.as_str()), (512, 512, "nanoscope"));
}

#[test]
fn topo_info_lists_a_container() {
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "info", "--json", container().to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["kind"], "container");
    assert_eq!(v["members"][1]["format"], "nanoscope");
    assert_eq!(v["members"][1]["nx"], 512);
    assert!(v["members"][2]["error"].is_string());
}

#[test]
fn path_tricks_in_a_container_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let zip = dir.path().join("tricks.zip");
    let mut w = zip::ZipWriter::new(std::fs::File::create(&zip).unwrap());
    for name in ["../../etc/passwd", "/abs.txt", "ok.txt"] {
        w.start_file(name, zip::write::SimpleFileOptions::default()).unwrap();
        w.write_all(b"1 2 3 4\n5 6 7 8\n9 10 11 12\n").unwrap();
    }
    w.finish().unwrap();
    for member in ["../../etc/passwd", "/abs.txt"] {
        let path = PathBuf::from(format!("{}#{member}", zip.display()));
        let e = read(&path, &ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("unsafe name") && !e.contains('\n'), "{e}");
    }
    // The safe member of the same archive reads.
    let t = read(&PathBuf::from(format!("{}#ok.txt", zip.display())), &ReadOptions::default()).unwrap();
    assert_eq!((t.nx(), t.ny()), (4, 3));
    let e = container_members(&zip, &Limits::default()).unwrap_err().to_string();
    assert!(e.contains("unsafe name"), "{e}");
}

#[test]
fn a_study_names_a_member_through_the_same_reading_path() {
    let dir = tempfile::tempdir().unwrap();
    // scans.zip holding a bare 8 × 8 array: the study reads it, and refuses it for its size.
    let mut npy = Vec::new();
    ndarray_npy::WriteNpyExt::write_npy(&ndarray::Array2::<f64>::zeros((8, 8)), &mut npy).unwrap();
    let mut w = zip::ZipWriter::new(std::fs::File::create(dir.path().join("scans.zip")).unwrap());
    w.start_file("ball.npy", zip::write::SimpleFileOptions::default()).unwrap();
    w.write_all(&npy).unwrap();
    w.finish().unwrap();
    let study = |file: &str| {
        format!(
            "[[topography]]\nname = \"ball\"\nfile = \"{file}\"\n\n[loads]\nmin = \"0.1 mN\"\nmax = \"1 mN\"\ncount = \
             2\n\n[[law]]\npreset = \"hold 100 s\"\n"
        )
    };
    let run = |file: &str| {
        std::fs::write(dir.path().join("study.toml"), study(file)).unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
            .args(["run", "study.toml", "--out", "out"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(!o.status.success());
        String::from_utf8(o.stderr).unwrap()
    };
    // The member was read (a bare array: it asks for its size), and a missing one is named.
    let stderr = run("scans.zip#ball.npy");
    assert!(stderr.contains("scans.zip#ball.npy") && stderr.contains("physical size"), "{stderr}");
    let stderr = run("scans.zip#other.npy");
    assert!(stderr.contains("no member 'other.npy'"), "{stderr}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn hdf5_datasets_are_channels_of_a_bare_map() {
    // Two root datasets, float64 256 × 256 and float32 640 × 480 (h5py's shapes); no size, no
    // unit: SurfaceTopography asks for the size too.
    let path = common::sample("multiple_data_sets.h5");
    let e = read(&path, &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("physical size") && !e.contains('\n'), "{e}");
    let opts = |channel: &str| ReadOptions {
        physical_size: Some((1e-6, 1e-6)),
        channel: Some(channel.into()),
        ..ReadOptions::default()
    };
    for (channel, (nx, ny), want, corners) in [
        (
            "dataset1",
            (256, 256),
            [-0.5588049271074124, 0.033215426493512654, -0.6299615478515626, -0.4643220520019532],
            [-0.49869003295898445, -0.5122423553466797, -0.5981623077392578],
        ),
        (
            "dataset2",
            (480, 640),
            [-0.0002719687105871079, 1.850009003891213e-05, -0.00035255696275271475, 0.0005772949662059546],
            [-0.0002655062125995755, -0.00028399284929037094, -0.0002564632741268724],
        ),
    ] {
        let t = read(&path, &opts(channel)).unwrap();
        assert_eq!((t.nx(), t.ny(), t.provenance.format.as_str()), (nx, ny, "hdf5"), "{channel}");
        let got = stats(&t);
        for i in 0..4 {
            let scale: f64 = if i == 0 { want[1] } else { want[i] };
            let tol = 1e-9 * scale.abs();
            assert!((got[i] - want[i]).abs() <= tol, "{channel}: {} vs {}", got[i], want[i]);
        }
        // h5py's [0, 0], [0, -1] and [-1, 0]: rows are the dataset's first index.
        let (a, b, c) = (t.heights[[0, 0]], t.heights[[0, nx - 1]], t.heights[[ny - 1, 0]]);
        assert_eq!([a, b, c], corners, "{channel}");
    }
    let (_, names) = asperity::topography::io::read_listing(&path, &opts("0")).unwrap();
    assert_eq!(names, ["dataset1", "dataset2"]);
}

#[test]
fn matlab_variables_are_channels() {
    // scipy.io.savemat, uncompressed and compressed (tools/make_generated_mat.py): 2-D numeric
    // variables in file order, a string left out; SurfaceTopography lists the same two.
    for file in ["generated-matlab.mat", "generated-matlab-compressed.mat"] {
        let path = common::sample(file);
        let e = read(&path, &ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("physical size"), "{e}");
        let opts = |channel: &str| ReadOptions {
            physical_size: Some((1e-6, 1e-6)),
            channel: Some(channel.into()),
            ..ReadOptions::default()
        };
        let (t, names) = asperity::topography::io::read_listing(&path, &opts("heights")).unwrap();
        assert_eq!(names, ["heights", "small"], "{file}");
        // MATLAB's A(row, column) at [row, column]: 0 … 11 row by row.
        assert_eq!((t.nx(), t.ny(), t.provenance.format.as_str()), (4, 3, "mat"), "{file}");
        assert_eq!(t.heights.iter().copied().collect::<Vec<_>>(), (0..12).map(f64::from).collect::<Vec<_>>());
        let s = read(&path, &opts("small")).unwrap();
        assert_eq!((s.nx(), s.ny()), (3, 2));
        assert_eq!((s.heights[[0, 2]], s.heights[[1, 2]]), (3.25, -6.75), "{file}");
    }
}
