//! End-to-end benchmarks through the `fray-render` facade: 1024² frames of the demo scenes on the
//! CPU backend (parse once; time render only). Report medians; compare variants as ratios in one run.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_render::{Backend, RenderOptions, Renderer};
use std::path::Path;

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("frame_1024");
    group.sample_size(10);
    for name in ["csg", "turboprop"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("data/scenes/{name}.ron"));
        let scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        for (label, shadows) in [("shaded", true), ("primary_only", false)] {
            let renderer = Renderer::new(RenderOptions {
                // The CPU backend (GPU frame times: crates/gpu/benches/gpu.rs).
                backend: Backend::Cpu,
                width: Some(1024),
                height: Some(1024),
                shadows: Some(shadows),
                ..Default::default()
            });
            group.bench_function(format!("{name}_{label}"), |b| {
                b.iter(|| renderer.render(&scene).map(|f| f.stats.hits))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
