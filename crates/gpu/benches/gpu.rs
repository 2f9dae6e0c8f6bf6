//! GPU frame time of data/scenes/csg.ron and turboprop.ron at 1024², with the quadtree work list
//! (`culled`) and with every tile and every object (`unculled`): the scene uploaded once and
//! rendered frame after frame (`resident`: each frame rebases, builds and uploads its work list,
//! runs the passes and reads the frame back), a frame from a moved camera (`moved`), and a
//! whole `render` (upload + pipelines from the cache + frame), on whatever adapter wgpu finds;
//! the adapter's name is printed and put into the benchmark id. Without an adapter the benchmark
//! says so and measures nothing. Where the device has timestamp queries, each frame benchmark
//! also prints the mean GPU time of its passes next to its mean frame time, so that one run
//! tells kernel from host and transfer time.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_gpu::{GpuRenderer, GpuSettings, View};
use std::cell::Cell;
use std::path::Path;
use std::time::Duration;

fn frames(c: &mut Criterion) {
    let gpu = match GpuRenderer::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("gpu bench: skipped: no GPU adapter ({e})");
            return;
        }
    };
    let adapter = gpu.context().adapter_name.clone();
    eprintln!(
        "gpu bench: adapter {adapter} ({}), timestamp queries: {}",
        gpu.context().backend,
        if gpu.context().timestamp_period_ns.is_some() {
            "yes"
        } else {
            "no (no kernel times)"
        }
    );
    let mut group = c.benchmark_group(format!("gpu_frame_1024 [{adapter}]"));
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(10));
    for name in ["csg", "turboprop"] {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../data/scenes/{name}.ron"));
        let mut scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        scene.width = 1024;
        scene.height = 1024;
        for culling in [true, false] {
            let settings = GpuSettings {
                culling,
                ..GpuSettings::for_scene(&scene)
            };
            let mut resident = gpu
                .upload(&scene, &settings)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let view = View::of_scene(&scene, settings.samples);
            let label = if culling { "culled" } else { "unculled" };
            let id = format!("{name}_shaded_{label}_resident");
            // (frames, their wall time, their kernel time) over every frame criterion ran.
            let totals = Cell::new((0u32, Duration::ZERO, Duration::ZERO));
            group.bench_function(&id, |b| {
                b.iter(|| {
                    let frame = resident.render(&view);
                    let (n, w, k) = totals.get();
                    let (wall, kernel) = frame
                        .as_ref()
                        .map(|f| (f.stats.elapsed, f.stats.kernel_time.unwrap_or_default()))
                        .unwrap_or_default();
                    totals.set((n + 1, w + wall, k + kernel));
                    frame.map(|f| f.stats.hits)
                })
            });
            let (n, wall, kernel) = totals.get();
            if n > 0 {
                let ms = |d: Duration| d.as_secs_f64() * 1e3 / f64::from(n);
                let kernel = if gpu.context().timestamp_period_ns.is_some() {
                    format!("{:.2} ms", ms(kernel))
                } else {
                    "n/a (no timestamp queries)".to_owned()
                };
                eprintln!(
                    "gpu bench: {id} [{adapter}]: mean of {n} frames: frame {:.2} ms, GPU passes {kernel}",
                    ms(wall)
                );
            }
            if culling {
                // The camera orbits a little every frame: rebase + quadtree + work list.
                let mut moved = view;
                let mut angle = 0.0f64;
                group.bench_function(format!("{name}_shaded_{label}_moved_camera"), |b| {
                    b.iter(|| {
                        angle += 0.01;
                        moved.camera = orbit(&scene, angle);
                        resident.render(&moved).map(|f| f.stats.hits)
                    })
                });
            }
        }
        group.bench_function(format!("{name}_render_from_scratch"), |b| {
            b.iter(|| {
                gpu.render(&scene, &GpuSettings::for_scene(&scene))
                    .map(|f| f.stats.hits)
            })
        });
    }
    group.finish();
}

/// The scene's pinhole camera turned by `angle` radians about the vertical through its target.
fn orbit(scene: &fray_scene::Scene, angle: f64) -> fray_core::Projector {
    match scene.camera {
        fray_core::Projector::Pinhole(p) => {
            let target = p.eye + p.basis.forward * 10.0;
            let rel = p.eye - target;
            let (s, c) = angle.sin_cos();
            let eye =
                target + glam::DVec3::new(c * rel.x + s * rel.z, rel.y, -s * rel.x + c * rel.z);
            fray_core::Pinhole::new(
                eye,
                target,
                glam::DVec3::Y,
                2.0 * p.tan_half_fov_y.atan(),
                p.near,
            )
            .map(fray_core::Projector::Pinhole)
            .unwrap_or(scene.camera)
        }
        other => other,
    }
}

/// Whitted frame time by depth on the GPU: the bunny, the perturbed free form and the mirror
/// ball (`data/scenes/mesh_bunny_freeform.ron`, made glass so every level spawns both rays) at
/// 512 × 320, resident, `max_depth` 0 (no queue passes' work) to 6.
fn whitted_by_depth(c: &mut Criterion) {
    let Ok(gpu) = GpuRenderer::new() else {
        eprintln!("gpu bench: skipped: no GPU adapter");
        return;
    };
    let adapter = gpu.context().adapter_name.clone();
    let mut group = c.benchmark_group(format!("gpu_whitted_depth_512x320 [{adapter}]"));
    group.sample_size(10);
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/mesh_bunny_freeform.ron");
    let mut scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    (scene.width, scene.height) = (512, 320);
    for m in &mut scene.materials {
        if m.reflect != fray_core::Rgb::ZERO {
            // The mirror ball becomes glass: reflected and refracted rays at every level.
            (m.transmit, m.ior, m.fresnel) = (fray_core::Rgb::splat(0.9), 1.5, true);
        }
    }
    scene.features.transmission = true;
    for depth in [0, 1, 2, 4, 6] {
        scene.settings.max_depth = depth;
        let settings = GpuSettings::for_scene(&scene);
        let mut resident = gpu
            .upload(&scene, &settings)
            .unwrap_or_else(|e| panic!("{e}"));
        let view = View::of_scene(&scene, settings.samples);
        group.bench_function(format!("depth_{depth}"), |b| {
            b.iter(|| resident.render(&view).map(|f| f.stats.secondary_rays))
        });
    }
    group.finish();
}

criterion_group!(benches, frames, whitted_by_depth);
criterion_main!(benches);
