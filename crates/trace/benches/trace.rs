//! Criterion benchmark of the CPU backend: a 512² frame of the turboprop aircraft.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_trace::{TraceSettings, render};
use std::path::Path;

fn aircraft_frame(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/turboprop.ron");
    let mut scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.width = 512;
    scene.height = 512;
    let settings = TraceSettings::for_scene(&scene);
    let mut group = c.benchmark_group("trace");
    group.sample_size(10);
    group.bench_function("turboprop_512x512", |b| {
        b.iter(|| render(&scene, &settings, None).map(|f| f.stats.hits))
    });
    group.finish();
}

criterion_group!(benches, aircraft_frame);
criterion_main!(benches);
