//! The mesh benchmark: the bunny (75 408 triangles) in a 1024² pinhole view framed so it
//! fills most of the picture, rays handed over as a renderer would — 16×16-pixel tiles, Morton
//! order inside a tile, one tile per rayon task — on pools of 1 and 2 threads. Build times
//! (obvhs + the f64 refit; the packet data from it), then Mrays/s of primary rays (nearest hit)
//! and of shadow rays (any hit) from the primary hits toward a fixed point light: the f64
//! reference one ray at a time, the packet path one ray per call, and the packet path a tile per
//! call. One command: `cargo bench -p fray-mesh --bench packet` (docs/mesh-bench.md).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use fray_core::{Interval, MemoryBudget, Pinhole, Projector, Ray};
use fray_mesh::{MeshBvh, PacketBvh, TriangleMesh};
use glam::DVec3;
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Duration;

const SIDE: u32 = 1024;
const TILE: u32 = 16;
const TILE_RAYS: usize = (TILE * TILE) as usize;

fn bunny() -> TriangleMesh {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/meshes/bunny00.obj");
    TriangleMesh::load_obj(&path, &MemoryBudget::default()).expect("the bunny loads")
}

/// The view's rays tile by tile, Morton order inside each tile.
fn primary_rays(bvh: &MeshBvh) -> Vec<Ray> {
    let b = bvh.bounds();
    let eye = b.center() + DVec3::new(0.0, 0.0, -1.2 * b.diagonal());
    let camera = Pinhole::new(eye, b.center(), DVec3::Y, 25f64.to_radians(), 0.01).expect("camera");
    let projector = Projector::Pinhole(camera);
    let mut rays = Vec::with_capacity((SIDE * SIDE) as usize);
    for ty in (0..SIDE).step_by(TILE as usize) {
        for tx in (0..SIDE).step_by(TILE as usize) {
            for i in 0..TILE * TILE {
                let (mut x, mut y) = (0, 0);
                for bit in 0..8 {
                    x |= ((i >> (2 * bit)) & 1) << bit;
                    y |= ((i >> (2 * bit + 1)) & 1) << bit;
                }
                let ray = projector.pixel_ray(tx + x, ty + y, SIDE, SIDE);
                rays.push(ray.expect("a pixel ray").ray);
            }
        }
    }
    rays
}

fn bench(c: &mut Criterion) {
    let mesh = bunny();
    let mut group = c.benchmark_group("mesh");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(2))
        .measurement_time(Duration::from_secs(8));
    group.bench_function("build MeshBvh (obvhs + f64 refit)", |b| {
        b.iter(|| MeshBvh::build(black_box(mesh.clone())))
    });
    let bvh = MeshBvh::build(mesh);
    group.bench_function("build PacketBvh (from a MeshBvh)", |b| {
        b.iter(|| PacketBvh::new(black_box(bvh.clone())))
    });
    let fast = PacketBvh::new(bvh.clone());

    let rays = primary_rays(&bvh);
    let all = vec![Interval::new(0.0, f64::INFINITY); rays.len()];
    let mut hits = vec![None; rays.len()];
    fast.nearest_hits(&rays, &all, &mut hits);
    let b = bvh.bounds();
    let light = b.center() + DVec3::new(1.0, 2.0, -1.5) * b.diagonal();
    let (mut shadow, mut shadow_ranges) = (Vec::new(), Vec::new());
    for (ray, hit) in rays.iter().zip(&hits) {
        if let Some(h) = hit {
            let p = ray.at(h.t);
            let to = light - p;
            shadow.push(Ray::new(p, to).expect("a shadow ray"));
            shadow_ranges.push(Interval::new(1e-6 * b.diagonal(), to.length()));
        }
    }
    let mut occluded = vec![false; shadow.len()];
    fast.any_hits(&shadow, &shadow_ranges, &mut occluded);
    eprintln!(
        "{SIDE}² primary rays: {} of {} hit the bunny ({:.1} %); shadow rays: {} of {} occluded",
        shadow.len(),
        rays.len(),
        100.0 * shadow.len() as f64 / rays.len() as f64,
        occluded.iter().filter(|o| **o).count(),
        shadow.len()
    );

    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let id = |what: &str| BenchmarkId::new(what, format!("{threads} thread(s)"));
        group.throughput(Throughput::Elements(rays.len() as u64));
        group.bench_function(id("primary, f64 reference, one ray at a time"), |b| {
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(TILE_RAYS)
                        .map(|tile| {
                            let all = Interval::new(0.0, f64::INFINITY);
                            tile.iter()
                                .filter(|r| bvh.nearest_hit(r, all).is_some())
                                .count()
                        })
                        .sum::<usize>()
                })
            })
        });
        group.bench_function(id("primary, packet path, one ray per call"), |b| {
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(TILE_RAYS)
                        .map(|tile| {
                            let all = [Interval::new(0.0, f64::INFINITY)];
                            let mut hit = [None];
                            let mut n = 0;
                            for r in tile {
                                fast.nearest_hits(std::slice::from_ref(r), &all, &mut hit);
                                n += usize::from(hit[0].is_some());
                            }
                            n
                        })
                        .sum::<usize>()
                })
            })
        });
        group.bench_function(id("primary, packet path, a 16x16 tile per call"), |b| {
            b.iter(|| {
                pool.install(|| {
                    rays.par_chunks(TILE_RAYS)
                        .zip(all.par_chunks(TILE_RAYS))
                        .map(|(tile, ranges)| {
                            let mut hits = [None; TILE_RAYS];
                            let hits = &mut hits[..tile.len()];
                            fast.nearest_hits(tile, ranges, hits);
                            hits.iter().filter(|h| h.is_some()).count()
                        })
                        .sum::<usize>()
                })
            })
        });
        group.throughput(Throughput::Elements(shadow.len() as u64));
        group.bench_function(id("shadow, f64 reference, one ray at a time"), |b| {
            b.iter(|| {
                pool.install(|| {
                    shadow
                        .par_chunks(TILE_RAYS)
                        .zip(shadow_ranges.par_chunks(TILE_RAYS))
                        .map(|(tile, ranges)| {
                            tile.iter()
                                .zip(ranges)
                                .filter(|(r, g)| bvh.any_hit(r, **g))
                                .count()
                        })
                        .sum::<usize>()
                })
            })
        });
        group.bench_function(id("shadow, packet path, 256 rays per call"), |b| {
            b.iter(|| {
                pool.install(|| {
                    shadow
                        .par_chunks(TILE_RAYS)
                        .zip(shadow_ranges.par_chunks(TILE_RAYS))
                        .map(|(tile, ranges)| {
                            let mut occluded = [false; TILE_RAYS];
                            let occluded = &mut occluded[..tile.len()];
                            fast.any_hits(tile, ranges, occluded);
                            occluded.iter().filter(|o| **o).count()
                        })
                        .sum::<usize>()
                })
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
