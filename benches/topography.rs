//! Speed of synthesis and analysis at the paper's size: 1500 × 1500 points.
//! Target: generating a 1500² surface in ≤ 1 s, so that a study's synthetic balls cost little
//! beside their contact solves.

use std::time::Duration;

use asperity::topography::detrend::subtract_polynomial;
use asperity::topography::stats::{psd, Window};
use asperity::topography::synth::SyntheticSurface;
use criterion::{criterion_group, criterion_main, Criterion};

fn topography(c: &mut Criterion) {
    let ball = SyntheticSurface::default();
    let mut g = c.benchmark_group("topography_1500");
    g.sample_size(10).warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(5));
    g.bench_function("generate_silicon_ball", |b| b.iter(|| ball.generate().unwrap()));
    let topo = ball.generate().unwrap();
    g.bench_function("psd", |b| b.iter(|| psd(&topo, Window::Hann).unwrap()));
    g.bench_function("detrend_plane", |b| {
        b.iter_batched_ref(|| topo.clone(), |t| subtract_polynomial(t, 1).unwrap(), criterion::BatchSize::LargeInput)
    });
    g.finish();
}

criterion_group!(benches, topography);
criterion_main!(benches);
