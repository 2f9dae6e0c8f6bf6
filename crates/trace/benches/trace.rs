//! Criterion benchmark of the CPU backend: a 512² frame of the turboprop aircraft.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_geometry::CastMethod;
use fray_trace::{TraceSettings, render, render_into};
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

/// Issue 3's speed target: primary visibility + normals of the 1024² CSG scene (8 quadrics, one
/// perturbation), CPU with culling, 2 threads, no shading. Full shading alongside for the ratio.
fn csg_visibility(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/csg.ron");
    let mut scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    scene.width = 1024;
    scene.height = 1024;
    let mut group = c.benchmark_group("trace");
    group.sample_size(20);
    for (label, shading) in [("visibility", false), ("shaded", true)] {
        let settings = TraceSettings {
            threads: Some(2),
            shading,
            ..TraceSettings::for_scene(&scene)
        };
        // Frame after frame into the same buffers (what an animation does): the figure the
        // target is about.
        let mut frame = render(&scene, &settings, None).expect("csg renders");
        group.bench_function(format!("csg_1024x1024_2threads_{label}"), |b| {
            b.iter(|| render_into(&scene, &settings, None, &mut frame).map(|_| frame.stats.hits))
        });
        // A fresh frame each time: adds the kernel's supplying and zeroing of 32 MB of pages.
        group.bench_function(format!("csg_1024x1024_2threads_{label}_fresh_frame"), |b| {
            b.iter(|| render(&scene, &settings, None).map(|f| f.stats.hits))
        });
    }
    // The same target frame with every ray searched (no closed form): the ratio is what the
    // certified closed form saves.
    let halving = TraceSettings {
        threads: Some(2),
        shading: false,
        method: CastMethod::Halving,
        ..TraceSettings::for_scene(&scene)
    };
    let mut frame = render(&scene, &halving, None).expect("csg renders");
    group.bench_function("csg_1024x1024_2threads_visibility_halving", |b| {
        b.iter(|| render_into(&scene, &halving, None, &mut frame).map(|_| frame.stats.hits))
    });
    group.finish();
}

criterion_group!(benches, aircraft_frame, csg_visibility);
criterion_main!(benches);
