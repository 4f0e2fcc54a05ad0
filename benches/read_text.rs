//! Reading the text and Gwyddion Simple Field samples (target: ≤ 50 ms for any sample).

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};

use asperity::topography::io::{read, ReadOptions};

fn read_samples(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut group = c.benchmark_group("read");
    for name in ["matrix-3.txt", "wafer-roughness.gsf", "sdf-1.sdf", "xyz-2.txt", "gwyddion-export-english.txt"] {
        let path = dir.join(name);
        group.bench_function(name, |b| b.iter(|| read(&path, &ReadOptions::default()).unwrap()));
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_millis(300))
        .measurement_time(std::time::Duration::from_secs(1));
    targets = read_samples
}
criterion_main!(benches);
