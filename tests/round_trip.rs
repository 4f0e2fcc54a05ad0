//! Topographies written and read back: `.gsf` to float32 precision (the format stores float32:
//! every height comes back as exactly its float32 rounding, a relative error ≤ 2^-24), `.npy`
//! bit for bit.

mod common;

use ndarray::Array2;
use proptest::prelude::*;

use asperity::output::write_npy;
use asperity::topography::io::{read, write_gsf, ReadOptions};
use asperity::topography::{Provenance, Topography};

/// Heights of a rough surface [m]: nanometre roughness on a micrometre offset, with some
/// points missing.
fn heights() -> impl Strategy<Value = Array2<f64>> {
    (2usize..40, 2usize..40).prop_flat_map(|(ny, nx)| {
        let h = prop_oneof![9 => -1e-6..1e-6f64, 1 => Just(f64::NAN)];
        prop::collection::vec(h, nx * ny)
            .prop_map(move |v| Array2::from_shape_vec((ny, nx), v.into_iter().map(|h| 2e-6 + h).collect()).unwrap())
    })
}

fn topography(heights: Array2<f64>, size: (f64, f64)) -> Topography {
    Topography {
        heights,
        physical_size: Some(size),
        periodic: false,
        height_unit_known: true,
        channel: "Height".into(),
        provenance: Provenance::default(),
    }
}

fn same_bits(a: &Array2<f64>, b: &Array2<f64>) -> bool {
    a.dim() == b.dim() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn gsf_keeps_heights_to_float32(h in heights(), lx in 1e-7..1e-3f64, ly in 1e-7..1e-3f64) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("surface.gsf");
        let topo = topography(h, (lx, ly));
        write_gsf(&path, &topo).unwrap();
        let back = read(&path, &ReadOptions::default()).unwrap();
        let as_f32 = topo.heights.mapv(|h| f64::from(h as f32));
        prop_assert!(same_bits(&back.heights, &as_f32));
        for (b, h) in back.heights.iter().zip(&topo.heights) {
            prop_assert!(h.is_nan() && b.is_nan() || (b - h).abs() <= h.abs() * 2f64.powi(-24));
        }
        prop_assert_eq!(back.physical_size, Some((lx, ly)));
        prop_assert_eq!(&back.channel, "Height");
        prop_assert_eq!(back.provenance.height_unit.as_deref(), Some("m"));
        prop_assert_eq!(back.missing_points(), topo.missing_points());
    }

    #[test]
    fn npy_keeps_heights_bit_for_bit(h in heights(), lx in 1e-7..1e-3f64) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("surface.npy");
        write_npy(&path, &h).unwrap();
        let opts = ReadOptions { physical_size: Some((lx, lx)), ..ReadOptions::default() };
        let back = read(&path, &opts).unwrap();
        prop_assert!(same_bits(&back.heights, &h));
        prop_assert_eq!(back.physical_size, Some((lx, lx)));
    }
}

#[test]
fn gsf_written_from_a_sample_reads_back() {
    let sample = common::sample("matrix-3.txt");
    let topo = read(&sample, &ReadOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("matrix-3.gsf");
    write_gsf(&path, &topo).unwrap();
    let back = read(&path, &ReadOptions::default()).unwrap();
    assert_eq!(back.heights, topo.heights.mapv(|h| f64::from(h as f32)));
    assert_eq!(back.physical_size, topo.physical_size);
    assert_eq!(back.channel, "ZSensor");
}
