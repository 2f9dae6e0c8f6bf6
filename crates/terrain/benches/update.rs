//! Heights that change: updating the max pyramid only above a changed rectangle
//! (`Pyramid::update_max`) against rebuilding it (`Pyramid::max_of`), and a whole terrain's new
//! heights (`Terrain::with_heights`, the copy of the map and pyramid included) against
//! `Terrain::new` from the same map.
//!
//! - `pyramid/<N>/rebuild`, `pyramid/<N>/update_<p>`: maps of `N²` samples (N = 1024, 4096;
//!   hashed value noise), a centred square of `p` % of the cells (1, 10, 100) given new bounds;
//!   both read the per-cell bounds from the same array.
//! - `terrain/<N>/new`, `terrain/<N>/with_heights_<p>`: bilinear terrains, the same squares of
//!   samples raised by waves (`Waves::heights_at` runs outside the timing).
//!
//! Report medians and the ratios `rebuild / update` of one run (the machine is shared).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use fray_terrain::{Heightmap, Placement, Pyramid, Region, Terrain, TerrainOptions, Wave, Waves};
use glam::{DVec2, DVec3};
use std::hint::black_box;
use std::time::Duration;

const SIZES: [usize; 2] = [1024, 4096];
const PERCENT: [usize; 3] = [1, 10, 100];

/// A deterministic height in `[0, 1000)` (a hash: no structure the pyramid could exploit).
fn noise(i: usize, j: usize) -> f32 {
    let mut h = (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (j as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    h ^= h >> 29;
    h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    h ^= h >> 32;
    (h % 1_000_000) as f32 / 1000.0
}

/// The centred square holding `percent` % of a `side × side` grid.
fn square(side: usize, percent: usize) -> Region {
    let s = ((side * side * percent) as f64 / 100.0).sqrt().round() as usize;
    let s = s.clamp(1, side);
    let x0 = (side - s) / 2;
    Region::new(x0, x0, x0 + s, x0 + s)
}

fn pyramids(c: &mut Criterion) {
    let mut g = c.benchmark_group("pyramid");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for n in SIZES {
        let side = n - 1; // cells
        let cells: Vec<f32> = (0..side * side)
            .map(|k| noise(k % side, k / side))
            .collect();
        let raised: Vec<f32> = cells.iter().map(|v| v + 1.0).collect();
        g.bench_function(BenchmarkId::new(n.to_string(), "rebuild"), |b| {
            b.iter(|| black_box(Pyramid::max_of(side, side, black_box(&raised))))
        });
        let mut p = Pyramid::max_of(side, side, &cells);
        for pct in PERCENT {
            let r = square(side, pct);
            g.bench_function(
                BenchmarkId::new(n.to_string(), format!("update_{pct}")),
                |b| {
                    b.iter(|| {
                        p.update_max(black_box(r), |i, j| raised[j * side + i]);
                        black_box(p.global())
                    })
                },
            );
        }
    }
    g.finish();
}

fn terrains(c: &mut Criterion) {
    let mut g = c.benchmark_group("terrain");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0).expect("placement");
    for n in SIZES {
        let map = Heightmap::from_fn(n, n, noise).expect("map");
        let base =
            Terrain::new(map.clone(), placement, TerrainOptions::default()).expect("terrain");
        g.bench_function(BenchmarkId::new(n.to_string(), "new"), |b| {
            b.iter(|| Terrain::new(black_box(map.clone()), placement, TerrainOptions::default()))
        });
        for pct in PERCENT {
            let region = square(n, pct);
            let waves = Waves {
                waves: vec![Wave {
                    amplitude: 3.0,
                    wavelength: 40.0,
                    direction: DVec2::X,
                    speed: 5.0,
                }],
                level: None,
                region: Some(region),
            };
            let moved = waves.heights_at(&map, &placement, 0.25).expect("waves");
            g.bench_function(
                BenchmarkId::new(n.to_string(), format!("with_heights_{pct}")),
                |b| b.iter(|| base.with_heights(black_box(moved.clone()), region)),
            );
        }
    }
    g.finish();
}

criterion_group!(update_benches, pyramids, terrains);
criterion_main!(update_benches);
