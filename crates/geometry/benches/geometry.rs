//! Criterion micro-benchmarks of fray-geometry: point evaluation of a free form, one segment
//! bound, and one ray cast with 0, 8 and 64 perturbations (hit rays and miss rays separately).
//!
//! Run: `cargo bench -p fray-geometry` (add `-- --quick` for a short run). Each cast benchmark
//! cycles through 64 fixed rays of its class, so the time is per ray; ε is the renderer's default
//! `1e-10 × diagonal`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fray_core::{Interval, Ray};
use fray_geometry::{CastStats, FreeForm, Perturbation, Quadric, RayCaster, Solid};
use glam::DVec3;

#[path = "../tests/common/rng.rs"]
mod rng;
use rng::Rng;

/// An ellipsoid with `n` small bumps and dents centred on its surface.
fn object(n: usize) -> Solid {
    let radii = DVec3::new(1.5, 1.0, 0.8);
    let base = Quadric::ellipsoid(DVec3::ZERO, radii);
    let mut rng = Rng(42);
    let perts = (0..n)
        .map(|i| {
            let at = rng.direction() * radii;
            let f = if i % 2 == 0 { 0.4 } else { -0.4 };
            Perturbation::new(f, Quadric::sphere(at, 0.2 + 0.2 * rng.unit()))
        })
        .collect();
    Solid::from_free_form(FreeForm::new(base, perts, None).expect("bounded"))
}

/// 64 rays that hit and 64 that enter the box but miss, from 6 m away.
fn rays(solid: &Solid) -> (Vec<Ray>, Vec<Ray>) {
    let (mut hits, mut misses) = (Vec::new(), Vec::new());
    let mut rng = Rng(7);
    let b = solid.bounds();
    let full = Interval::new(0.0, f64::INFINITY);
    while hits.len() < 64 || misses.len() < 64 {
        let origin = rng.direction() * 6.0;
        let target = b.min + (b.max - b.min) * DVec3::new(rng.unit(), rng.unit(), rng.unit());
        let ray = Ray::new(origin, target - origin).expect("distinct points");
        if b.clip_ray(&ray, full).is_none() {
            continue;
        }
        match solid.cast(&ray, full, 1e-12) {
            Some(_) if hits.len() < 64 => hits.push(ray),
            None if misses.len() < 64 => misses.push(ray),
            _ => {}
        }
    }
    (hits, misses)
}

fn benches(c: &mut Criterion) {
    let full = Interval::new(0.0, f64::INFINITY);
    let solid8 = object(8);
    let leaf = &solid8.leaves()[0];
    let p = DVec3::new(0.9, 0.4, 0.3);
    c.bench_function("free form point eval (8 perturbations)", |b| {
        b.iter(|| leaf.eval(black_box(p)))
    });
    c.bench_function("solid point eval (8 perturbations)", |b| {
        b.iter(|| solid8.eval(black_box(p)))
    });

    let (hits, _) = rays(&solid8);
    let mut caster = RayCaster::new();
    let range = caster
        .prepare_ray(&solid8, &hits[0], full)
        .expect("a hit ray reaches the box");
    let half = Interval::new(range.lo, range.lo + 0.5 * range.width());
    c.bench_function("segment bound (8 perturbations)", |b| {
        b.iter(|| caster.segment_bound(&solid8, black_box(half)))
    });

    for n in [0, 8, 64] {
        let solid = object(n);
        let eps = 1e-10 * solid.bounds().diagonal();
        let (hits, misses) = rays(&solid);
        for (class, set) in [("hit", &hits), ("miss", &misses)] {
            let mut caster = RayCaster::new();
            let mut stats = CastStats::default();
            let mut i = 0;
            c.bench_function(&format!("cast {class} ray ({n} perturbations)"), |b| {
                b.iter(|| {
                    i = (i + 1) % set.len();
                    caster.cast(&solid, black_box(&set[i]), full, eps, &mut stats)
                })
            });
        }
    }
}

criterion_group!(geometry, benches);
criterion_main!(geometry);
