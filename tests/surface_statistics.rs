//! RMS slopes and curvatures of maps and profiles (`topo info`), against the values
//! SurfaceTopography 1.27.1 reports for the same files (`rms_gradient`,
//! `rms_slope_from_profile`, `rms_curvature_from_area`, `rms_curvature_from_profile`), read
//! with its `read_topography(f).topography()`; its values are in the file's unit, converted here.

use std::path::Path;
use std::process::Command;

use asperity::topography::io::{self, ReadOptions};
use asperity::topography::stats::{profile_rms_curvature, profile_rms_slope, slope_curvature};
use asperity::topography::AnyTopography;

fn read(file: &str, height_unit: Option<&str>) -> AnyTopography {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(file);
    let options = ReadOptions { height_unit: height_unit.map(String::from), ..ReadOptions::default() };
    io::read_any(&path, &options).unwrap_or_else(|e| panic!("{e}")).0
}

fn close(what: &str, got: f64, expected: f64) {
    assert!((got / expected - 1.0).abs() < 1e-9, "{what}: {got:e}, SurfaceTopography {expected:e}");
}

#[test]
fn maps_have_surface_topographys_slopes_and_curvatures() {
    // file, metres per its unit; rms_gradient, rms_slope_from_profile [1];
    // rms_curvature_from_area, rms_curvature_from_profile [1/unit].
    let cases = [
        ("si-ball-roughness.gwy", 1.0, 0.06727190036769483, 0.0482823519044096, 304481.4766922735, 378573.9694702846),
        ("nid-1.nid", 1.0, 0.04974564282879412, 0.04007325353728425, 102791.4528852791, 45163.96025468161),
        ("di-1.di", 1e-9, 0.7666516654816506, 0.211647179324163, 0.5707705019709515, 0.0870156064695591),
        ("x3p-2.x3p", 1.0, 0.06207007399844295, 0.05561061711853133, 111566.12196886608, 186735.03272074382),
        ("sdf-1.sdf", 1e-6, 0.01692315868861365, 0.014387752121548063, 0.009299170527525547, 0.0191638273839022),
    ];
    for (file, unit, gradient, slope, area, profile) in cases {
        let AnyTopography::Map(t) = read(file, None) else { panic!("{file} is a map") };
        let g = slope_curvature(&t).unwrap_or_else(|e| panic!("{e}"));
        close(&format!("{file} rms gradient"), g.rms_gradient, gradient);
        close(&format!("{file} rms slope along x"), g.rms_slope_from_profile, slope);
        close(&format!("{file} rms curvature"), g.rms_curvature_from_area_per_m, area / unit);
        close(&format!("{file} rms curvature along x"), g.rms_curvature_from_profile_per_m, profile / unit);
    }
}

#[test]
fn profiles_have_surface_topographys_slopes_and_curvatures() {
    // Non-uniform profiles whose files state no unit, read in µm (a length in metres is
    // refused as no measured profile); SurfaceTopography's curvatures are per the file's unit.
    for (file, slope, curvature) in [
        ("xy-1.txt", 0.4382415170673911, 0.29648560831949383),
        ("nonuniform.asc", 0.45366851430012456, 0.14908236707035205),
    ] {
        let AnyTopography::Profile(p) = read(file, Some("um")) else { panic!("{file} is a profile") };
        assert!(p.step().is_none(), "{file} is not uniform");
        close(&format!("{file} rms slope"), profile_rms_slope(&p).unwrap(), slope);
        close(&format!("{file} rms curvature"), profile_rms_curvature(&p).unwrap(), curvature / 1e-6);
    }
}

#[test]
fn topo_info_reports_them() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/si-ball-roughness.gwy");
    let run = |json: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_asperity"));
        c.args(["topo", "info"]).arg(&file);
        if json {
            c.arg("--json");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let info: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    close("rms_gradient", info["rms_gradient"].as_f64().unwrap(), 0.06727190036769483);
    close("rms_curvature_from_area_per_m", info["rms_curvature_from_area_per_m"].as_f64().unwrap(), 304481.4766922735);
    let text = run(false);
    assert!(text.contains("rms slope    0.0673 (gradient; 0.0483 along x)"), "{text}");
    assert!(text.contains("rms curv.    3.0448e5 1/m (half the Laplacian; 3.7857e5 1/m along x)"), "{text}");
}

/// `topo info --psd-fit --json` of `file`: its `psd_fit`.
fn psd_fit(file: &Path) -> serde_json::Value {
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "info", "--psd-fit", "--json"])
        .arg(file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str::<serde_json::Value>(&String::from_utf8(o.stdout).unwrap()).unwrap()["psd_fit"].clone()
}

#[test]
fn topo_info_fits_the_psd() {
    // A generated surface written as .gsf reads back as a non-periodic map: the Hann window
    // and its scatter (≈ 0.07 decades), from 3 × 2π/L.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("rough.gsf");
    let o = Command::new(env!("CARGO_BIN_EXE_asperity"))
        .args(["topo", "generate", "--size", "10um", "--grid", "512", "--hurst", "0.6", "--rms", "10nm"])
        .args(["--rolloff", "1um", "--seed", "4"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fit = psd_fit(&file);
    let h = fit["hurst"].as_f64().unwrap_or_else(|| panic!("{fit}"));
    let lambda = fit["rolloff_wavelength_m"].as_f64().unwrap_or_else(|| panic!("{fit}"));
    println!("generated: H {h}, λ_r {lambda}: {fit}");
    assert!((h - 0.6).abs() < 0.05 && (lambda / 1e-6 - 1.0).abs() < 0.15, "{fit}");
    assert_eq!(fit["psd_unit"], "m4");
    // The vendored ball: a short cut-off at λ ≈ 0.38 µm inside the window, no power law.
    let fit = psd_fit(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/si-ball-roughness.gwy"));
    println!("ball: {fit}");
    assert!(fit["hurst"].is_null() && fit["refusal"].as_str().unwrap().contains("not a power law"), "{fit}");
}
