//! Sky benchmarks (criterion), Earth's atmosphere, an eye 2 m above the ground, the sun 30° up:
//!
//! - `tables/transmittance_256x64`: building the transmittance table (once per sky).
//! - `tables/sky_view_192x108_40_steps`: building the sky-view table (once per frame).
//! - `lookup/background`: one `SkyView::background` (table + sun disc) against
//!   `lookup/reference_single_scattering`: one evaluation of the f64 integral, same direction.
//! - `aerial/<steps>`: `Sky::aerial_perspective` from 66 km down to terrain 30 km out, at a few
//!   step counts; the errors against the reference are printed once before timing.

use criterion::{Criterion, criterion_group, criterion_main};
use fray_atmosphere::sky::{Sky, SkyModel, SkySun, SkyTables, TransmittanceTable, reference};
use fray_core::MemoryBudget;
use glam::DVec3;
use std::hint::black_box;
use std::time::Duration;

fn relative(got: DVec3, want: DVec3) -> f64 {
    ((got - want).abs() / want.abs().max(DVec3::splat(1e-300))).max_element()
}

fn benches(c: &mut Criterion) {
    let model = SkyModel::earth();
    let sun = SkySun::from_angles(30f64.to_radians(), 0.0, DVec3::ONE);
    let tables = SkyTables::default();
    let budget = MemoryBudget::unlimited();
    let sky = Sky::new(model, sun, tables, &budget).expect("a valid sky");
    let eye = DVec3::new(0.0, 2.0, 0.0);

    let mut g = c.benchmark_group("tables");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("transmittance_256x64", |b| {
        b.iter(|| TransmittanceTable::new(black_box(&model), 256, 64, &budget).map(|t| t.width()))
    });
    g.bench_function("sky_view_192x108_40_steps", |b| {
        b.iter(|| sky.view(black_box(eye)).table().width())
    });
    g.finish();

    let view = sky.view(eye);
    let d = DVec3::new(0.3, 0.4, 0.5).normalize();
    let want = reference::single_scattering(&model, &sun, eye, d, f64::INFINITY).in_scatter;
    eprintln!(
        "background vs reference along {d}: relative error {:.2e}",
        relative(view.background(d), want)
    );
    let mut g = c.benchmark_group("lookup");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2));
    g.bench_function("background", |b| b.iter(|| view.background(black_box(d))));
    g.bench_function("reference_single_scattering", |b| {
        b.iter(|| reference::single_scattering(&model, &sun, eye, black_box(d), f64::INFINITY))
    });
    g.finish();

    let high = DVec3::new(0.0, 66_000.0, 0.0);
    let ground = DVec3::new(30_000.0, 0.0, 0.0);
    let (dir, t) = ((ground - high).normalize(), (ground - high).length());
    let want = reference::single_scattering(&model, &sun, high, dir, t);
    let mut g = c.benchmark_group("aerial");
    g.sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2));
    for steps in [8u32, 16, 32, 64] {
        let got = sky.aerial_perspective(high, dir, t, steps);
        eprintln!(
            "aerial perspective, 66 km down, {steps} steps: in-scatter error {:.2e}, transmittance error {:.2e}",
            relative(got.in_scatter, want.in_scatter),
            relative(got.transmittance, want.transmittance)
        );
        g.bench_function(format!("{steps}"), |b| {
            b.iter(|| sky.aerial_perspective(high, black_box(dir), t, steps))
        });
    }
    g.finish();
}

criterion_group!(sky_benches, benches);
criterion_main!(sky_benches);
