//! Fog benchmarks (criterion): one ray's terms through a 300 m layer (B = 2e-3 /m, a sun at 20°,
//! the observer 100 m above the layer looking 10° down to the ground):
//!
//! - `fog/exact`: exact single scattering in closed form, homogeneous; `fog/exact_falloff` with
//!   an exponential falloff; `fog/method`: the method's formula;
//! - `fog/reference`: the nested Gauss–Kronrod reference (what the closed form saves);
//! - `fog/transmittance`: the optical depth alone (what a shadow ray through fog costs).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLayer, FogLighting, FogModel, Sunlight};
use fray_core::{Interval, Ray};
use glam::DVec3;
use std::hint::black_box;
use std::time::Duration;

fn benches(c: &mut Criterion) {
    let fog = FogLayer {
        top: 300.0,
        extinction: 2e-3,
        ..FogLayer::default()
    };
    let falloff = FogLayer {
        falloff: Some(120.0),
        ..fog
    };
    let sun = 20f64.to_radians();
    let light = FogLighting {
        suns: vec![Sunlight {
            direction: DVec3::new(sun.cos(), sun.sin(), 0.0),
            irradiance: DVec3::splat(3.0),
        }],
        ambient: DVec3::splat(0.1),
    };
    let view = 10f64.to_radians();
    let ray = Ray::new(
        DVec3::new(0.0, 400.0, 0.0),
        DVec3::new(view.cos() * 0.6, -view.sin(), view.cos() * 0.8),
    )
    .expect("a unit direction");
    let range = Interval::new(0.0, 400.0 / view.sin());
    let mut g = c.benchmark_group("fog");
    g.measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500));
    g.bench_function("exact", |b| {
        b.iter(|| black_box(&fog).terms(black_box(&ray), range, &light, FogModel::Exact))
    });
    g.bench_function("exact_falloff", |b| {
        b.iter(|| black_box(&falloff).terms(black_box(&ray), range, &light, FogModel::Exact))
    });
    g.bench_function("method", |b| {
        b.iter(|| black_box(&fog).terms(black_box(&ray), range, &light, FogModel::Method))
    });
    g.bench_function("transmittance", |b| {
        b.iter(|| black_box(&fog).transmittance(black_box(&ray), range))
    });
    g.sample_size(10);
    g.bench_function("reference", |b| {
        b.iter(|| single_scattering(black_box(&fog), black_box(&ray), range, &light))
    });
    g.finish();
}

criterion_group!(fog_benches, benches);
criterion_main!(fog_benches);
