//! Bake benchmarks (criterion): the default cumulus [`CloudField`] (5 octaves of improved noise,
//! coverage 0.5) over its layer — an 8 km square from its base to its top — baked unbounded into
//! grids of 64³, 128³ and 256³ samples (z slices in parallel; throughput in samples), and the
//! max grid of 4³-cell blocks (the scenes' default) built from each. 512³ (134 M samples, close
//! to a minute here) is timed once by `cargo xtask bench clouds` instead.

use criterion::{
    BenchmarkId, Criterion, SamplingMode, Throughput, criterion_group, criterion_main,
};
use fray_clouds::bake::{Region, bake};
use fray_clouds::{CloudField, DensityGrid, Unbounded};
use fray_core::MemoryBudget;
use std::hint::black_box;
use std::time::Duration;

const SIDES: [usize; 3] = [64, 128, 256];
/// The max grid's block side.
const BLOCK: usize = 4;

fn region(field: &CloudField) -> Region {
    Region {
        min: [-4000.0, field.base, -4000.0],
        max: [4000.0, field.top, 4000.0],
    }
}

fn baked(field: &CloudField, n: usize, budget: &MemoryBudget) -> DensityGrid {
    bake(field, &Unbounded, region(field), [n; 3], budget, |_, _| {}).expect("within the budget")
}

fn bake_benches(c: &mut Criterion) {
    let field = CloudField::default();
    let budget = MemoryBudget::default();
    let mut g = c.benchmark_group("bake");
    // Each bake is long: the same one iteration per sample.
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .measurement_time(Duration::from_secs(1))
        .warm_up_time(Duration::from_millis(200));
    for n in SIDES {
        g.throughput(Throughput::Elements((n * n * n) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{n}^3")),
            &n,
            |b, &n| b.iter(|| black_box(baked(&field, n, &budget))),
        );
    }
    g.finish();
}

fn max_grid_benches(c: &mut Criterion) {
    let field = CloudField::default();
    let budget = MemoryBudget::default();
    let mut g = c.benchmark_group("max_grid");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(1))
        .warm_up_time(Duration::from_millis(200));
    for n in SIDES {
        let grid = baked(&field, n, &budget);
        g.throughput(Throughput::Elements((n * n * n) as u64));
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{n}^3")),
            &grid,
            |b, grid| b.iter(|| black_box(grid.max_grid(BLOCK))),
        );
    }
    g.finish();
}

criterion_group!(benches, bake_benches, max_grid_benches);
criterion_main!(benches);
