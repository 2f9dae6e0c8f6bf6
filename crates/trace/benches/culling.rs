//! Criterion benchmarks of quadtree culling on the CPU backend: 1024² frames of csg.ron and
//! turboprop.ron on 2 threads with culling on and off (primary visibility + normals: shadows
//! off), and a scene with 256 perturbations of which only a few touch any region against the
//! same scene with 8 perturbations (also with every ray searched, the like-for-like ratio).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_trace::{CastMethod, TraceSettings, render};
use std::path::Path;

fn load(name: &str) -> fray_scene::Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/scenes")
        .join(name);
    fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A slab seen from above with `nx × nz` small bumps spread over it on a grid, so only a
/// handful of bumps touch any tile.
fn bumps(nx: u32, nz: u32, size: u32) -> fray_scene::Scene {
    let mut perts = String::new();
    for i in 0..nx {
        for j in 0..nz {
            let x = -4.0 + 8.0 * (f64::from(i) + 0.5) / f64::from(nx);
            let z = -4.0 + 8.0 * (f64::from(j) + 0.5) / f64::from(nz);
            perts.push_str(&format!(
                "(form_factor: 3.0, quadric: Ellipsoid(center: ({x}, 0.2, {z}), radii: (0.22, 0.3, 0.22))),\n"
            ));
        }
    }
    let src = format!(
        r#"Scene(
            image: (width: {size}, height: {size}),
            camera: Pinhole(eye: (0, 9, -4), look_at: (0, 0, 0), fov_y: 50),
            lights: [Sun(direction: (0.3, 1, -0.5), irradiance: (3, 3, 3))],
            settings: (shadows: false),
            objects: [(shape: FreeForm(base: Ellipsoid(center: (0, 0, 0), radii: (4.5, 0.3, 4.5)),
                                       perturbations: [{perts}]))],
        )"#
    );
    fray_scene::parse(&src, "bumps.ron").unwrap_or_else(|e| panic!("{e}"))
}

fn settings(scene: &fray_scene::Scene, culling: bool) -> TraceSettings {
    let mut s = TraceSettings::for_scene(scene);
    s.threads = Some(2);
    s.shadows = false;
    s.culling = culling;
    s
}

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("culling");
    group.sample_size(10);
    for name in ["csg.ron", "turboprop.ron"] {
        let mut scene = load(name);
        scene.width = 1024;
        scene.height = 1024;
        for culling in [false, true] {
            let s = settings(&scene, culling);
            let label = format!(
                "{}_1024_{}",
                name.trim_end_matches(".ron"),
                if culling { "culled" } else { "plain" }
            );
            group.bench_function(label, |b| {
                b.iter(|| render(&scene, &s, None).map(|f| f.stats.hits))
            });
        }
    }
    for (nx, nz) in [(4u32, 2u32), (16, 16)] {
        let count = nx * nz;
        let scene = bumps(nx, nz, 512);
        for culling in [false, true] {
            let s = settings(&scene, culling);
            let label = format!(
                "bumps{count}_512_{}",
                if culling { "culled" } else { "plain" }
            );
            group.bench_function(label, |b| {
                b.iter(|| render(&scene, &s, None).map(|f| f.stats.hits))
            });
        }
        // Culled, with every ray searched: the like-for-like ratio of 256 to 8 perturbations
        // (by default, the tiles that no bump touches are answered in closed form, and with 8
        // bumps that is most of them).
        let s = TraceSettings {
            method: CastMethod::Halving,
            ..settings(&scene, true)
        };
        group.bench_function(format!("bumps{count}_512_culled_halving"), |b| {
            b.iter(|| render(&scene, &s, None).map(|f| f.stats.hits))
        });
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
