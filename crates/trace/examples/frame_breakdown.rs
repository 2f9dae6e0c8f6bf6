//! Diagnostic: where a CPU frame's time goes (quadtree build, tracing) and how many candidates
//! each pixel's ray tests. `cargo run --release -p fray-trace --example frame_breakdown -- SCENE
//! [THREADS] [REPETITIONS]`; `TILE=n` sets the cell size, `PER_OBJECT=1` adds per-object counts,
//! `SHADING=0` measures visibility + normals only (issue 3's speed target), `SHADOWS=1` adds
//! shadow rays to the shaded frame, `FRESH=1` allocates a new frame each time instead of
//! rendering into the last one. For the instruction
//! profile behind docs/cpu-profile.md: `SHADING=0 valgrind --tool=callgrind
//! target/release/examples/frame_breakdown data/scenes/csg.ron 1 1`.
use fray_trace::{TraceSettings, render, render_into, work_list};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).cloned().unwrap_or("data/scenes/csg.ron".into());
    let threads: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let reps: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(7);
    let mut scene = match fray_scene::load(std::path::Path::new(&path)) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    scene.width = 1024;
    scene.height = 1024;
    let t = Instant::now();
    let list = work_list(&scene, 16).expect("work list");
    let build = t.elapsed();
    let (mut pixels, mut pairs, mut leaves) = (0u64, 0u64, 0u64);
    for it in &list.items {
        let n = u64::from((it.x1 - it.x0) * (it.y1 - it.y0));
        pixels += n;
        for c in list.candidates_of(it) {
            pairs += n;
            leaves += n * u64::from(c.leaf_count);
        }
    }
    println!(
        "quadtree {:.2} ms, {} items, {} px in items, {:.2} candidates and {:.2} leaves per covered px",
        build.as_secs_f64() * 1e3,
        list.items.len(),
        pixels,
        pairs as f64 / pixels as f64,
        leaves as f64 / pixels as f64
    );
    if std::env::var_os("PER_OBJECT").is_some() {
        per_object(&scene);
    }
    let tile: u32 = std::env::var("TILE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(16);
    let settings = TraceSettings {
        tile_size: tile,
        threads: Some(threads),
        shadows: std::env::var("SHADOWS").is_ok_and(|v| v == "1"),
        shading: std::env::var("SHADING").map_or(true, |v| v != "0"),
        ..TraceSettings::for_scene(&scene)
    };
    // Frame after frame into the same buffers, as an animation would (`FRESH=1`: a new frame
    // each time, which adds the kernel's cost of supplying the pages).
    let fresh = std::env::var("FRESH").is_ok_and(|v| v == "1");
    let mut frame = render(&scene, &settings, None).expect("render");
    let mut times = Vec::new();
    for _ in 0..reps {
        if fresh {
            frame = render(&scene, &settings, None).expect("render");
        } else {
            render_into(&scene, &settings, None, &mut frame).expect("render");
        }
        times.push(frame.stats.elapsed.as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "render median {:.1} ms (min {:.1})",
        times[times.len() / 2],
        times[0]
    );
}

/// Per object: casts, hits, and evaluations per cast, over every pixel's ray (no culling).
#[allow(dead_code)]
pub fn per_object(scene: &fray_scene::Scene) {
    use fray_core::Interval;
    use fray_geometry::{CastStats, RayCaster};
    let mut caster = RayCaster::new();
    for (k, o) in scene.objects.iter().enumerate() {
        let (mut casts, mut hits, mut st) = (0u64, 0u64, CastStats::default());
        for py in 0..scene.height {
            for px in 0..scene.width {
                let Some(cr) = scene.camera.pixel_ray(px, py, scene.width, scene.height) else {
                    continue;
                };
                let range = Interval::new(cr.t_near, f64::INFINITY);
                if o.solid.bounds().clip_ray(&cr.ray, range).is_none() {
                    continue;
                }
                casts += 1;
                let before = st;
                if caster
                    .cast(&o.solid, &cr.ray, range, scene.epsilon(), &mut st)
                    .is_some()
                {
                    hits += 1;
                }
                let _ = before;
            }
        }
        println!(
            "{k} {:>18}: {casts:>7} casts {hits:>7} hits, {:.2} bound + {:.2} point per cast",
            o.name,
            st.bound_evaluations as f64 / casts.max(1) as f64,
            st.point_evaluations as f64 / casts.max(1) as f64
        );
    }
}
