//! The mesh benchmark: the bunny (75 408 triangles) in a 1024² pinhole view framed so it
//! fills most of the picture, rays handed over as a renderer would — 16×16-pixel tiles, Morton
//! order inside a tile, one tile per rayon task — on pools of 1 and 2 threads. Build times
//! (the SAH build + the f64 refit; the packet data from it), then Mrays/s of primary rays (nearest hit)
//! and of shadow rays (any hit) from the primary hits toward a fixed point light: the f64
//! reference one ray at a time, the packet path one ray per call, and the packet path a tile per
//! call. The view is `bunny_view`, shared with the Embree comparison (`benches/embree/`). One
//! command: `cargo bench -p fray-mesh --bench packet` (docs/mesh-bench.md).

mod bunny_view;

use bunny_view::{TILE_RAYS, bunny, primary_rays, shadow_rays};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use fray_core::Interval;
use fray_mesh::{MeshBvh, PacketBvh};
use rayon::prelude::*;
use std::hint::black_box;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let mesh = bunny();
    let mut group = c.benchmark_group("mesh");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(2))
        .measurement_time(Duration::from_secs(8));
    group.bench_function("build MeshBvh (SAH + f64 refit)", |b| {
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
    let (shadow, shadow_ranges) = shadow_rays(&bvh, &rays, &hits);
    let mut occluded = vec![false; shadow.len()];
    fast.any_hits(&shadow, &shadow_ranges, &mut occluded);
    eprintln!(
        "{}² primary rays: {} of {} hit the bunny ({:.1} %); shadow rays: {} of {} occluded",
        bunny_view::SIDE,
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
