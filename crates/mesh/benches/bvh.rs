//! fray-mesh's BVH on the bunny (75 408 triangles): build time (the binned SAH build and the
//! f64 refit), and single-ray throughput of the f64 reference traversal — primary rays of a 256²
//! pinhole view framing the bunny (a quarter-resolution sample of the 1024² view, the same
//! rays per pixel), nearest hit and any hit, on one thread.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use fray_core::{Interval, MemoryBudget, Pinhole, Ray};
use fray_mesh::{MeshBvh, TriangleMesh};
use glam::DVec3;
use std::hint::black_box;

fn bunny() -> TriangleMesh {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/bunny00.obj");
    TriangleMesh::load_obj(&path, &MemoryBudget::default()).expect("the bunny loads")
}

fn rays(bvh: &MeshBvh, side: u32) -> Vec<Ray> {
    let b = bvh.bounds();
    let eye = b.center() + DVec3::new(0.0, 0.0, -2.2 * b.diagonal());
    let camera = Pinhole::new(eye, b.center(), DVec3::Y, 25f64.to_radians(), 0.01).expect("camera");
    let projector = fray_core::Projector::Pinhole(camera);
    (0..side * side)
        .filter_map(|i| {
            projector
                .pixel_ray(i % side, i / side, side, side)
                .map(|c| c.ray)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mesh = bunny();
    let mut group = c.benchmark_group("bvh");
    group.sample_size(10);
    group.bench_function("build bunny", |b| {
        b.iter(|| MeshBvh::build(black_box(mesh.clone())))
    });
    let bvh = MeshBvh::build(mesh);
    let rays = rays(&bvh, 256);
    let hits = rays
        .iter()
        .filter(|r| {
            bvh.nearest_hit(r, Interval::new(0.0, f64::INFINITY))
                .is_some()
        })
        .count();
    eprintln!("primary rays: {} of {} hit the bunny", hits, rays.len());
    group.throughput(Throughput::Elements(rays.len() as u64));
    group.bench_function("primary nearest (256², 1 thread)", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| {
                    bvh.nearest_hit(r, Interval::new(0.0, f64::INFINITY))
                        .is_some()
                })
                .count()
        })
    });
    group.bench_function("primary any hit (256², 1 thread)", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| bvh.any_hit(r, Interval::new(0.0, f64::INFINITY)))
                .count()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
