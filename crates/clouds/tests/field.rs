//! A cloud layer's field and its bake: deterministic per seed and different across seeds; zero
//! outside the layer, outside the envelope and below the threshold; more coverage, more cloud;
//! the baked grid holds the field at its cell centres exactly, reports every slice, and refuses a
//! grid past the budget.

use fray_clouds::bake::{Region, bake};
use fray_clouds::{CloudField, Envelope, Unbounded};
use fray_core::MemoryBudget;

/// A ball of radius 1500 m around (0, 2500, 0).
struct Ball;

impl Envelope for Ball {
    fn depth(&self, p: [f64; 3]) -> f64 {
        1500.0 - (p[0] * p[0] + (p[1] - 2500.0).powi(2) + p[2] * p[2]).sqrt()
    }

    fn cost(&self) -> u64 {
        1
    }
}

fn points(n: usize) -> Vec<[f64; 3]> {
    let mut state = 42u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            [
                next() * 8000.0 - 4000.0,
                1000.0 + next() * 3000.0,
                next() * 8000.0 - 4000.0,
            ]
        })
        .collect()
}

#[test]
fn the_field_is_deterministic_bounded_and_cut() {
    let field = CloudField::default();
    let other = CloudField { seed: 7, ..field };
    let (mut same, mut differ, mut nonzero) = (true, 0, 0);
    for p in points(20_000) {
        let d = field.density(p, &Unbounded);
        same &= d == field.density(p, &Unbounded);
        differ += usize::from(d != other.density(p, &Unbounded));
        nonzero += usize::from(d > 0.0);
        // Within the scale, and only inside the layer.
        assert!((0.0..=field.density_scale).contains(&d));
        if d > 0.0 {
            assert!((field.base..=field.top).contains(&p[1]));
        }
        // The envelope: nothing outside the ball.
        if Ball.depth(p) <= 0.0 {
            assert_eq!(field.density(p, &Ball), 0.0);
        }
    }
    assert!(same);
    assert!(differ > 1000, "{differ}");
    assert!(nonzero > 500, "{nonzero}");
    // Coverage: none is clear sky; more coverage, more cloud.
    let clear = CloudField {
        coverage: 0.0,
        ..field
    };
    let more = CloudField {
        coverage: 0.8,
        ..field
    };
    let count = |f: &CloudField| {
        points(5000)
            .iter()
            .filter(|&&p| f.density(p, &Unbounded) > 0.0)
            .count()
    };
    assert_eq!(count(&clear), 0);
    assert!(count(&more) > count(&field));
}

#[test]
fn the_threshold_cuts_thin_parts() {
    let field = CloudField {
        envelope_fade: 0.0,
        ..CloudField::default()
    };
    for p in points(20_000) {
        let d = field.density(p, &Unbounded);
        // A kept density is at least the threshold's share of the scale.
        assert!(
            d == 0.0 || d >= field.threshold * field.density_scale - 1e-15,
            "{d}"
        );
    }
}

#[test]
fn the_bake_holds_the_field_at_cell_centres_and_reports_each_slice() {
    let field = CloudField::default();
    let region = Region {
        min: [-4000.0, 1000.0, -4000.0],
        max: [4000.0, 4000.0, 4000.0],
    };
    let size = [24, 12, 20];
    let reports = std::sync::Mutex::new(Vec::new());
    let grid = bake(
        &field,
        &Ball,
        region,
        size,
        &MemoryBudget::default(),
        |done, total| reports.lock().unwrap().push((done, total)),
    )
    .unwrap();
    // Slices finish on several threads: each count is reported once, in any order.
    let mut reports = reports.into_inner().unwrap();
    reports.sort();
    assert_eq!(reports, (1..=20).map(|k| (k, 20)).collect::<Vec<_>>());
    // The parallel bake is the serial one.
    let serial = fray_clouds::DensityGrid::from_fn(size, &MemoryBudget::default(), |i, j, k| {
        field.density(region.cell_centre(size, [i, j, k]), &Ball) as f32
    })
    .unwrap();
    assert_eq!(grid, serial);
    for (i, j, k) in [(0, 0, 0), (12, 6, 10), (23, 11, 19), (5, 9, 3)] {
        let centre = region.cell_centre(size, [i, j, k]);
        let unit = [
            (i as f64 + 0.5) / 24.0,
            (j as f64 + 0.5) / 12.0,
            (k as f64 + 0.5) / 20.0,
        ];
        assert_eq!(
            grid.sample(unit),
            f64::from(field.density(centre, &Ball) as f32)
        );
    }
    let small = MemoryBudget::new(4096);
    assert!(bake(&field, &Ball, region, [64, 64, 64], &small, |_, _| {}).is_err());
}
