//! GPU frame time (dispatch + readback; pipeline and work list built once beforehand) of
//! data/scenes/csg.ron and turboprop.ron at 1024², with the quadtree work list (`culled`) and
//! with every tile and every object (`unculled`), plus the host-side work-list build, on whatever
//! adapter wgpu finds; the adapter's name is printed and put into the benchmark id. Without an
//! adapter the benchmark says so and measures nothing. Where the device has timestamp queries,
//! each frame benchmark also prints the mean GPU kernel time of the frames it ran (the compute
//! passes alone, `PassOutput::kernel_time`) next to their mean frame time, so that one run tells
//! kernel from host and transfer time.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_geometry::gpu_layout::GpuSolids;
use fray_gpu::{GpuRenderer, GpuSettings, GpuWork};
use std::cell::Cell;
use std::path::Path;
use std::time::{Duration, Instant};

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
        let mut solids = GpuSolids::new(fray_gpu::params::reference_point(&scene.camera));
        for object in &scene.objects {
            solids.push(&object.solid, |_| 0);
        }
        group.bench_function(format!("{name}_work_list"), |b| {
            b.iter(|| GpuWork::culled(&scene, &solids).map(|w| w.items.len()))
        });
        for culling in [true, false] {
            let settings = GpuSettings {
                culling,
                ..GpuSettings::for_scene(&scene)
            };
            let pass = gpu
                .prepare(&scene, &settings)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let label = if culling { "culled" } else { "unculled" };
            let id = format!("{name}_shaded_{label}");
            // (frames, their wall time, their kernel time) over every frame criterion ran.
            let totals = Cell::new((0u32, Duration::ZERO, Duration::ZERO));
            group.bench_function(&id, |b| {
                b.iter(|| {
                    let start = Instant::now();
                    let out = pass.run(gpu.context());
                    let wall = start.elapsed();
                    let (n, w, k) = totals.get();
                    let kernel = out.as_ref().ok().and_then(|o| o.kernel_time);
                    totals.set((n + 1, w + wall, k + kernel.unwrap_or_default()));
                    out.map(|o| o.hits)
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
                    "gpu bench: {id} [{adapter}]: mean of {n} frames: frame {:.2} ms, GPU kernel {kernel}",
                    ms(wall)
                );
            }
        }
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
