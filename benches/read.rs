//! Reading every instrument sample of `tests/data` (the test data, in the repository) through the registry
//! (`topography::io::read`, default channel): each must take at most 50 ms.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use asperity::topography::io::{read, ReadOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn samples(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("manifest.json")).expect("manifest.json")).expect("manifest");
    let mut group = c.benchmark_group("read");
    for entry in manifest["files"].as_array().expect("files") {
        if entry["expect"] == "error" {
            continue;
        }
        let file = entry["file"].as_str().expect("file name");
        let path = dir.join(file);
        // Bare arrays carry no size: give one, as a user must.
        let opts =
            ReadOptions { physical_size: entry.get("array_shape").map(|_| (1e-6, 1e-6)), ..ReadOptions::default() };
        if let Err(e) = read(&path, &opts) {
            eprintln!("skipping {file}: {e}");
            continue;
        }
        group.bench_function(file, |b| b.iter(|| read(black_box(&path), &opts).expect("readable")));
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // No plots: plotters finds no font on a bare machine and would panic on the second run.
    config = Criterion::default()
        .without_plots()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    targets = samples
}
criterion_main!(benches);
