//! Cloud march benchmarks (criterion): 64 rays down through a baked 48×24×48 cumulus field
//! (coverage 0.35), 40 m steps, 6 sun steps — `march/plain` against `march/skipping` (the max
//! grid of 4³-cell blocks; the same results bit for bit, tested in `tests/march.rs`).

use criterion::{Criterion, criterion_group, criterion_main};
use fray_clouds::bake::{Region, bake};
use fray_clouds::march::{CloudLight, DualLobe, GridVolume, MarchSettings, march};
use fray_clouds::{CloudField, Unbounded};
use fray_core::MemoryBudget;
use std::hint::black_box;
use std::time::Duration;

fn benches(c: &mut Criterion) {
    let region = Region {
        min: [-4000.0, 1000.0, -4000.0],
        max: [4000.0, 4000.0, 4000.0],
    };
    let field = CloudField {
        coverage: 0.35,
        ..CloudField::default()
    };
    let grid = bake(
        &field,
        &Unbounded,
        region,
        [48, 24, 48],
        &MemoryBudget::default(),
        |_, _| {},
    )
    .expect("a small grid");
    let plain = GridVolume {
        skip: None,
        grid: grid.clone(),
        region,
        scale: 1.0,
    };
    let skipping = GridVolume {
        skip: Some(grid.max_grid(4)),
        ..plain.clone()
    };
    let settings = MarchSettings {
        step: 40.0,
        ..MarchSettings::default()
    };
    let light = CloudLight {
        sun_direction: [0.0, 1.0, 0.0],
        sun_irradiance: [3.0; 3],
        ambient: [0.05; 3],
        albedo: 0.9,
        phase: DualLobe::single(0.6),
    };
    let rays: Vec<([f64; 3], [f64; 3])> = (0..64)
        .map(|k| {
            let (x, z) = (
                (k % 8) as f64 * 1000.0 - 3500.0,
                (k / 8) as f64 * 1000.0 - 3500.0,
            );
            ([x, 4500.0, z], [0.28, -0.92, 0.28])
        })
        .collect();
    let mut g = c.benchmark_group("march");
    g.measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500));
    for (name, volume) in [("plain", &plain), ("skipping", &skipping)] {
        g.bench_function(name, |b| {
            b.iter(|| {
                for &(o, d) in &rays {
                    black_box(march(volume, o, d, (0.0, f64::INFINITY), &settings, &light));
                }
            })
        });
    }
    g.finish();
}

criterion_group!(march_benches, benches);
criterion_main!(march_benches);
