//! GPU terrain pass time (ray upload + dispatch + readback; pipeline and pyramid uploaded once)
//! for the DEM scenes' camera rays at their own resolution (terrain_low 640 × 360 and
//! terrain_high 512 × 512, both with bilinear patches), on
//! whatever adapter wgpu finds (named in the benchmark id); without one it says so and measures
//! nothing. The CPU reference casts of the same rays are timed alongside (one thread).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_core::Interval;
use fray_gpu::GpuRenderer;
use fray_gpu::testing::{GpuRay, TerrainBatch};
use fray_terrain::{Interpolation, Terrain, TerrainOptions};
use std::path::Path;
use std::time::Duration;

fn terrain_pass(c: &mut Criterion) {
    let gpu = match GpuRenderer::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("gpu terrain bench: skipped: no GPU adapter ({e})");
            return;
        }
    };
    let adapter = gpu.context().adapter_name.clone();
    let mut group = c.benchmark_group(format!("gpu_terrain [{adapter}]"));
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    for name in ["terrain_low", "terrain_high"] {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../data/scenes/{name}.ron"));
        let scene = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let t = &scene.terrains[0].terrain;
        let bilinear = TerrainOptions {
            interpolation: Interpolation::Bilinear,
            ..*t.options()
        };
        let terrain = Terrain::new(t.map().clone(), *t.placement(), bilinear).expect("terrain");
        let (w, h) = (scene.width, scene.height);
        let camera: Vec<_> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter_map(|(x, y)| scene.camera.pixel_ray(x, y, w, h))
            .collect();
        let eye = camera[0].ray.origin;
        let rays: Vec<GpuRay> = camera
            .iter()
            .map(|c| {
                let (o, d) = (c.ray.origin - eye, c.ray.dir);
                [
                    [o.x as f32, o.y as f32, o.z as f32, c.t_near as f32],
                    [d.x as f32, d.y as f32, d.z as f32, f32::MAX],
                ]
            })
            .collect();
        let pass = TerrainBatch::new(gpu.context(), &terrain, eye).expect("terrain pass");
        group.bench_function(format!("{name}_{w}x{h}_gpu"), |b| {
            b.iter(|| pass.cast(gpu.context(), &rays).map(|v| v.len()))
        });
        group.bench_function(format!("{name}_{w}x{h}_cpu_1_thread"), |b| {
            b.iter(|| {
                camera
                    .iter()
                    .filter(|c| {
                        let range = Interval::new(c.t_near, f64::INFINITY);
                        terrain.cast(&c.ray, range, 1e-6).is_some()
                    })
                    .count()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, terrain_pass);
criterion_main!(benches);
