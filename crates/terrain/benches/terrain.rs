//! Terrain benchmarks (criterion), all on one fixed screen of 128 × 128 pinhole rays looking
//! obliquely (≈ 35° down) over a 30 km square of terrain (the setup is `fray_terrain::sweep`,
//! shared with `cargo xtask bench`):
//!
//! - `size/<N>`: the pyramid search (bilinear, LOD bias 0) on maps of N² samples, N = 256 …
//!   4096, covering the same ground: the Jacksboro DEM upsampled with the B-spline plus
//!   deterministic fractal detail (4 octaves of hashed value noise below the DEM's resolution).
//!   The target: 4096² within 1.5× of 256². `size/<N>_pixel_lod` is the same with the
//!   pixel-footprint level of detail ([`Terrain::cast_lod`], one pixel of the fixed screen).
//! - `lod/<bias>`: time against error over the LOD bias on the 1024² map; the errors (against
//!   the exact bias-0 hits) are printed once before timing.
//! - `march/<step>`: a plain fixed-step march (with a final secant step) at steps of a few
//!   cell sizes down to a tenth of one, errors printed likewise — to compare at equal error.
//! - `shadow/{max,min+max}`: shadow rays from the primary hits toward a low sun with and
//!   without the min pyramid (which proves a ray is underground at a coarse level).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_core::{Interval, Ray};
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions, sweep};
use glam::{DVec2, DVec3};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

const SCREEN: usize = 128;

fn dem() -> Terrain {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/terrain/jacksboro_fault_dem.png");
    let map = Heightmap::load(&path).expect("the DEM in data/terrain");
    let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0).expect("placement");
    let options = TerrainOptions {
        interpolation: Interpolation::Bicubic,
        ..TerrainOptions::default()
    };
    Terrain::new(map, placement, options).expect("DEM terrain")
}

fn terrain(base: &Terrain, n: usize, options: TerrainOptions) -> Terrain {
    sweep::upsampled(base, n, options).expect("generated terrain")
}

fn rays() -> Vec<Ray> {
    sweep::screen_rays(SCREEN)
}

fn pixel_footprint() -> f64 {
    sweep::screen_footprint(SCREEN)
}

fn cast_all(t: &Terrain, rays: &[Ray]) -> usize {
    let all = Interval::new(0.0, f64::INFINITY);
    rays.iter()
        .filter(|r| t.cast(r, all, 1e-6).is_some())
        .count()
}

fn cast_all_lod(t: &Terrain, rays: &[Ray]) -> usize {
    let all = Interval::new(0.0, f64::INFINITY);
    let f = pixel_footprint();
    rays.iter()
        .filter(|r| t.cast_lod(r, all, 1e-6, f).is_some())
        .count()
}

/// Mean and max |Δt| in cells against `reference` (hits both), and hit/miss disagreements.
fn error(reference: &[Option<f64>], got: &[Option<f64>], cell: f64) -> (f64, f64, usize) {
    let e = sweep::DepthError::of(reference, got, cell);
    (e.mean, e.max, e.flips)
}

fn benches(c: &mut Criterion) {
    let base = dem();
    let rays = rays();
    let all = Interval::new(0.0, f64::INFINITY);
    let exact = TerrainOptions::default();

    let mut g = c.benchmark_group("size");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for n in [256, 512, 1024, 2048, 4096] {
        let t = terrain(&base, n, exact);
        eprintln!(
            "size {n}²: {} of {} rays hit",
            cast_all(&t, &rays),
            rays.len()
        );
        g.bench_function(format!("{n}"), |b| {
            b.iter(|| cast_all(black_box(&t), &rays))
        });
        g.bench_function(format!("{n}_pixel_lod"), |b| {
            b.iter(|| cast_all_lod(black_box(&t), &rays))
        });
    }
    g.finish();

    let n = 1024;
    let cell = sweep::cell_size(n);
    let reference_terrain = terrain(&base, n, exact);
    let reference: Vec<Option<f64>> = rays
        .iter()
        .map(|r| reference_terrain.cast(r, all, 1e-6).map(|h| h.t))
        .collect();
    let mut g = c.benchmark_group("lod");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    for bias in 0..=4u32 {
        let t = terrain(
            &base,
            n,
            TerrainOptions {
                lod_bias: bias,
                ..exact
            },
        );
        let got: Vec<Option<f64>> = rays
            .iter()
            .map(|r| t.cast(r, all, 1e-6).map(|h| h.t))
            .collect();
        let (mean, max, flips) = error(&reference, &got, cell);
        eprintln!(
            "lod bias {bias}: mean |Δt| {mean:.3e} cells, max {max:.3e}, {flips} hit/miss flips"
        );
        g.bench_function(format!("{bias}"), |b| {
            b.iter(|| cast_all(black_box(&t), &rays))
        });
    }
    g.finish();

    let got: Vec<Option<f64>> = rays
        .iter()
        .map(|r| {
            reference_terrain
                .cast_lod(r, all, 1e-6, pixel_footprint())
                .map(|h| h.t)
        })
        .collect();
    let (mean, max, flips) = error(&reference, &got, cell);
    eprintln!("pixel lod: mean |Δt| {mean:.3e} cells, max {max:.3e}, {flips} hit/miss flips");

    let mut g = c.benchmark_group("march");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for cells in [4.0, 1.0, 0.25, 0.1, 0.03] {
        let step = cells * cell;
        let march = |r: &Ray| {
            reference_terrain
                .march(r, all, step)
                .expect("the bench's steps are within MAX_MARCH_STEPS")
        };
        let got: Vec<Option<f64>> = rays.iter().map(march).collect();
        let (mean, max, flips) = error(&reference, &got, cell);
        eprintln!(
            "march step {cells} cells: mean |Δt| {mean:.3e} cells, max {max:.3e}, {flips} hit/miss flips"
        );
        g.bench_function(format!("{cells}"), |b| {
            b.iter(|| rays.iter().filter(|r| march(r).is_some()).count())
        });
    }
    g.finish();

    // Shadow rays from the primary hits toward a sun 20° up.
    let sun = DVec3::new(-0.6, 20f64.to_radians().tan() * 0.85, 0.55).normalize();
    let shadow: Vec<Ray> = rays
        .iter()
        .filter_map(|r| {
            let h = reference_terrain.cast(r, all, 1e-6)?;
            Ray::new(r.at(h.t) + h.normal * 1e-3, sun)
        })
        .collect();
    let with_min = terrain(
        &base,
        n,
        TerrainOptions {
            min_pyramid: true,
            ..exact
        },
    );
    let lit = |t: &Terrain| shadow.iter().filter(|r| !t.occluded(r, all, 1e-6)).count();
    assert_eq!(
        lit(&reference_terrain),
        lit(&with_min),
        "the min pyramid changes no answer"
    );
    eprintln!("shadow: {} rays, {} lit", shadow.len(), lit(&with_min));
    let mut g = c.benchmark_group("shadow");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    g.bench_function("max", |b| b.iter(|| lit(black_box(&reference_terrain))));
    g.bench_function("min+max", |b| b.iter(|| lit(black_box(&with_min))));
    g.finish();
}

criterion_group!(terrain_benches, benches);
criterion_main!(terrain_benches);
