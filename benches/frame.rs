//! End-to-end benchmarks through the `fray-render` facade: 1024² frames of the demo scenes on the
//! CPU backend (parse once; time render only), and Whitted frame time by recursion depth. Report
//! medians; compare variants as ratios in one run.

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

/// Whitted frame time by depth: the glass-and-mirror scene (free forms, a 75k-triangle glass
/// bunny, a textured floor) at 512 × 320 on the CPU with `max_depth` 0 (local shading only) to 6.
fn whitted_by_depth(c: &mut Criterion) {
    let mut group = c.benchmark_group("whitted_depth_512x320");
    group.sample_size(10);
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes/whitted_glass_mirror.ron");
    let mut scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let renderer = Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        width: Some(512),
        height: Some(320),
        ..Default::default()
    });
    for depth in [0, 1, 2, 4, 6] {
        scene.settings.max_depth = depth;
        group.bench_function(format!("depth_{depth}"), |b| {
            b.iter(|| renderer.render(&scene).map(|f| f.stats.secondary_rays))
        });
    }
    group.finish();
}

criterion_group!(benches, frames, whitted_by_depth);
criterion_main!(benches);
