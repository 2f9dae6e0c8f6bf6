//! Terrain benchmarks (criterion), all on one fixed screen of 128 × 128 pinhole rays looking
//! obliquely (≈ 35° down) over a 30 km square of terrain:
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
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use glam::{DVec2, DVec3};
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

const EXTENT: f64 = 30_000.0;
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

fn hash(i: i64, j: i64, octave: u32) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ u64::from(octave).wrapping_mul(0x1656_67B1_9E37_79F9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}

/// Bilinearly interpolated hashed lattice noise with lattice period `period` samples.
fn value_noise(x: f64, y: f64, period: f64, octave: u32) -> f64 {
    let (fx, fy) = (x / period, y / period);
    let (i, j) = (fx.floor(), fy.floor());
    let (s, t) = (fx - i, fy - j);
    let (i, j) = (i as i64, j as i64);
    let a = hash(i, j, octave) * (1.0 - s) + hash(i + 1, j, octave) * s;
    let b = hash(i, j + 1, octave) * (1.0 - s) + hash(i + 1, j + 1, octave) * s;
    a * (1.0 - t) + b * t
}

/// The DEM upsampled to `n × n` by its B-spline, with fractal detail below its resolution,
/// placed over the same `EXTENT`² square for every `n`.
fn terrain(base: &Terrain, n: usize, options: TerrainOptions) -> Terrain {
    let (cw, ch) = base.map().cells();
    let scale = (n - 1) as f64;
    let samples = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            let (u, v) = (i / scale * cw as f64, j / scale * ch as f64);
            let mut h = base.surface(u, v).unwrap_or(0.0);
            // Detail at periods of 16, 8, 4, 2 samples of this map, ≈ 74 m / … amplitude.
            for octave in 0..4u32 {
                let period = f64::from(16 >> octave);
                if period * 0.5 > n as f64 / 403.0 {
                    continue; // only below the DEM's own resolution
                }
                h += 12.0 * 0.5f64.powi(octave as i32) * value_noise(i, j, period, octave);
            }
            h as f32
        })
        .collect();
    let map = Heightmap::from_samples(n, n, samples).expect("generated map");
    let spacing = EXTENT / scale;
    let placement = Placement::new(DVec3::ZERO, DVec2::splat(spacing), 1.0).expect("placement");
    Terrain::new(map, placement, options).expect("generated terrain")
}

/// The fixed screen: a pinhole at a corner, 4 km up, looking at the centre (≈ 35° down).
fn rays() -> Vec<Ray> {
    let eye = DVec3::new(-4_000.0, 14_000.0, -4_000.0);
    let target = DVec3::new(0.5 * EXTENT, 600.0, 0.5 * EXTENT);
    let fwd = (target - eye).normalize();
    let right = fwd.cross(DVec3::Y).normalize();
    let up = right.cross(fwd);
    let half = (25f64).to_radians().tan();
    let mut out = Vec::with_capacity(SCREEN * SCREEN);
    for y in 0..SCREEN {
        for x in 0..SCREEN {
            let sx = ((x as f64 + 0.5) / SCREEN as f64 * 2.0 - 1.0) * half;
            let sy = (1.0 - (y as f64 + 0.5) / SCREEN as f64 * 2.0) * half;
            out.push(Ray::new(eye, fwd + right * sx + up * sy).expect("ray"));
        }
    }
    out
}

/// World size of a pixel per unit distance on the fixed screen (50° field of view).
fn pixel_footprint() -> f64 {
    2.0 * 25f64.to_radians().tan() / SCREEN as f64
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
    let (mut sum, mut max, mut n, mut flips) = (0.0, 0.0f64, 0usize, 0usize);
    for (a, b) in reference.iter().zip(got) {
        match (a, b) {
            (Some(a), Some(b)) => {
                let e = (a - b).abs() / cell;
                sum += e;
                max = max.max(e);
                n += 1;
            }
            (None, None) => {}
            _ => flips += 1,
        }
    }
    (sum / n.max(1) as f64, max, flips)
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
    let cell = EXTENT / (n - 1) as f64;
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
        let march = |r: &Ray| reference_terrain.march(r, all, step);
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
