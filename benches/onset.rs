//! The onset of sliding on 2.25 million contact elements (a 1500 × 1500 map all in
//! contact, as the paper's surfaces at their highest loads): target ≤ 0.5 s.

use std::hint::black_box;
use std::time::Duration;

use asperity::friction::{Curve, ElementLoads, FrictionLaw, Loading, Onset};
use criterion::{criterion_group, criterion_main, Criterion};
use ndarray::Array2;

/// A random pressure field in (0.1, 1.1) GPa from a SplitMix64 sequence (no contact-free pixel).
fn pressure(n: usize) -> Array2<f64> {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    Array2::from_shape_simple_fn((n, n), || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        1e8 + 1e9 * (z >> 11) as f64 / (1u64 << 53) as f64
    })
}

fn bench(c: &mut Criterion) {
    let p = pressure(1500);
    let area = (20.75e-9f64).powi(2);
    let law = FrictionLaw::new(0.6, 0.4).unwrap();
    let mut g = c.benchmark_group("onset_2.25M");
    g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(4));
    g.bench_function("pressure_to_onset", |b| {
        b.iter(|| Onset::new(&ElementLoads::from_pressure(black_box(&p), area).unwrap(), &law))
    });
    let loads = ElementLoads::from_pressure(&p, area).unwrap();
    let onset = Onset::new(&loads, &law);
    g.bench_function("class_and_stress_ratio_maps", |b| {
        b.iter(|| (onset.class_map(black_box(&p), area), onset.stress_ratio_map(&p, area, 1.0).unwrap()))
    });
    g.bench_function("curves_both_modes_2000_rows", |b| {
        b.iter(|| Loading::ALL.map(|m| Curve::new(black_box(&loads), &law, m, 2000)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
