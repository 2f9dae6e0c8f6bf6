//! Diagnostic: GPU frame times of scene files on whatever adapter wgpu finds — the first frame
//! of a freshly uploaded scene, then `REPS` frames of the resident scene from the same camera and
//! from a moving one, and whole renders (upload + frame, pipelines from the cache) — with the
//! passes' GPU time where the device has timestamp queries.
//! `cargo run --release -p fray-gpu --example frame_times -- SIZE REPS SCENE…` (SIZE: image width;
//! the height keeps the aspect ratio).
use fray_gpu::{GpuRenderer, GpuSettings, View};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let width: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(512);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let gpu = match GpuRenderer::new() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("no GPU: {e}");
            std::process::exit(1);
        }
    };
    println!("adapter: {}", gpu.context().adapter_name);
    for path in &args[3.min(args.len())..] {
        let mut scene = match fray_scene::load(std::path::Path::new(path)) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{e}");
                continue;
            }
        };
        scene.height = (u64::from(scene.height) * u64::from(width) / u64::from(scene.width)) as u32;
        scene.width = width;
        let mut settings = GpuSettings::for_scene(&scene);
        if std::env::var("NOSHADOWS").is_ok() {
            settings.shadows = false;
        }
        if std::env::var("NOCULL").is_ok() {
            settings.culling = false;
        }
        let start = Instant::now();
        let mut resident = match gpu.upload(&scene, &settings) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{path}: {e}");
                continue;
            }
        };
        let view = View::of_scene(&scene, settings.samples);
        let first = resident.render(&view).expect("first frame");
        let first_ms = start.elapsed().as_secs_f64() * 1e3;
        let (mut frames, mut kernels, mut moved, mut whole) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut passes = String::new();
        for k in 0..reps {
            let t = Instant::now();
            let f = resident.render(&view).expect("frame");
            frames.push(t.elapsed().as_secs_f64() * 1e3);
            passes = f
                .stats
                .pass_times
                .iter()
                .map(|(l, d)| format!("{l} {:.1}", d.as_secs_f64() * 1e3))
                .collect::<Vec<_>>()
                .join(", ");
            kernels.push(
                f.stats
                    .kernel_time
                    .map_or(f64::NAN, |d| d.as_secs_f64() * 1e3),
            );
            let mut v = view;
            if let fray_core::Projector::Pinhole(mut p) = v.camera {
                p.eye += p.basis.right * (0.01 * (k + 1) as f64);
                v.camera = fray_core::Projector::Pinhole(p);
            }
            let t = Instant::now();
            resident.render(&v).expect("moved frame");
            moved.push(t.elapsed().as_secs_f64() * 1e3);
            let t = Instant::now();
            gpu.render(&scene, &settings).expect("whole render");
            whole.push(t.elapsed().as_secs_f64() * 1e3);
        }
        println!(
            "{path} {width}×{}: first {first_ms:.1} ms ({} pipelines {:.1} ms); resident frame median {:.2} ms (passes {:.2} ms: the last [{passes}]); moved camera median {:.2} ms; whole render (upload + frame) median {:.2} ms",
            scene.height,
            first.stats.pipelines_built,
            first.stats.pipeline_build_time.as_secs_f64() * 1e3,
            median(frames),
            median(kernels),
            median(moved),
            median(whole)
        );
    }
}
