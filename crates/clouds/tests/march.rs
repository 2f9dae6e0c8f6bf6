//! The cloud march against closed forms: transmittance through a homogeneous volume is
//! `exp(−σL)` to 1e-6 whatever the step; single scattering in a homogeneous slab lit from
//! straight above and seen from straight above equals `ω p(−1) E (1 − e^{−2σH}) / 2` (plus the
//! ambient `ω A (1 − e^{−σH})`), converging at second order in the step; no NaN with the camera
//! inside the volume or on its boundary; the march stops at an opaque hit.

use fray_clouds::DensityGrid;
use fray_clouds::bake::Region;
use fray_clouds::march::{CloudLight, DualLobe, GridVolume, MarchSettings, march};
use fray_core::MemoryBudget;

/// A homogeneous box of extinction `sigma`: a 2³ grid of ones scaled.
fn slab(sigma: f64, region: Region) -> GridVolume {
    GridVolume {
        grid: DensityGrid::from_fn([2, 2, 2], &MemoryBudget::default(), |_, _, _| 1.0).unwrap(),
        region,
        scale: sigma,
        skip: None,
    }
}

const BOX: Region = Region {
    min: [-1000.0, 0.0, -1000.0],
    max: [1000.0, 200.0, 1000.0],
};

fn light(ambient: f64) -> CloudLight {
    CloudLight {
        sun_direction: [0.0, 1.0, 0.0],
        sun_irradiance: [3.0, 3.0, 3.0],
        ambient: [ambient; 3],
        albedo: 0.9,
        phase: DualLobe::single(0.6),
    }
}

#[test]
fn transmittance_through_a_homogeneous_volume_is_beer_lambert() {
    let sigma = 0.01;
    let volume = slab(sigma, BOX);
    for step in [1.0, 7.3, 50.0, 400.0] {
        let settings = MarchSettings {
            step,
            min_transmittance: 0.0,
            ..MarchSettings::default()
        };
        // Obliquely through the slab: L = 200 / sin(30°) = 400 m.
        let d = [30f64.to_radians().cos(), -0.5, 0.0];
        let r = march(
            &volume,
            [-500.0, 300.0, 0.0],
            d,
            (0.0, f64::INFINITY),
            &settings,
            &light(0.0),
        );
        let expected = (-sigma * 400.0f64).exp();
        assert!(
            (r.transmittance - expected).abs() < 1e-6 * expected.max(1e-300) + 1e-12,
            "step {step}: {} vs {expected}",
            r.transmittance
        );
    }
}

#[test]
fn single_scattering_in_a_homogeneous_slab_converges_to_its_closed_form() {
    let (sigma, height) = (0.01, 200.0);
    let volume = slab(sigma, BOX);
    let l = light(0.1);
    let p_back = l.phase.eval(-1.0);
    let closed = 0.9 * p_back * 3.0 * (1.0 - (-2.0 * sigma * height).exp()) / 2.0
        + 0.9 * 0.1 * (1.0 - (-sigma * height).exp());
    let mut errors = Vec::new();
    for steps in [8.0, 16.0, 32.0, 64.0, 128.0] {
        let settings = MarchSettings {
            step: height / steps,
            sun_steps: 4,
            jitter: 0.5,
            min_transmittance: 0.0,
        };
        let r = march(
            &volume,
            [0.0, 250.0, 0.0],
            [0.0, -1.0, 0.0],
            (0.0, f64::INFINITY),
            &settings,
            &l,
        );
        errors.push((r.in_scatter[0] - closed).abs() / closed);
    }
    println!("relative errors at 8…128 steps: {errors:?}");
    for w in errors.windows(2) {
        // Second order: halving the step divides the error by about 4.
        assert!(w[1] < w[0] / 3.0, "{errors:?}");
    }
    assert!(errors[4] < 1e-4, "{errors:?}");
}

#[test]
fn no_nan_inside_or_on_the_boundary_and_the_march_stops_at_a_hit() {
    let volume = slab(0.02, BOX);
    let settings = MarchSettings::default();
    let l = light(0.05);
    for (o, d) in [
        ([0.0, 100.0, 0.0], [0.0, 1.0, 0.0]),       // inside, up
        ([0.0, 100.0, 0.0], [1.0, 0.0, 0.0]),       // inside, horizontal
        ([0.0, 200.0, 0.0], [0.0, -1.0, 0.0]),      // on the top face, down
        ([0.0, 200.0, 0.0], [1.0, 0.0, 0.0]),       // on the top face, along it
        ([1000.0, 0.0, 1000.0], [-0.6, 0.0, -0.8]), // on an edge
        ([0.0, 500.0, 0.0], [0.0, 1.0, 0.0]),       // outside, away
    ] {
        let r = march(&volume, o, d, (0.0, f64::INFINITY), &settings, &l);
        assert!(
            r.transmittance.is_finite() && (0.0..=1.0).contains(&r.transmittance),
            "{o:?} {d:?}"
        );
        assert!(
            r.in_scatter.iter().all(|c| c.is_finite() && *c >= 0.0),
            "{o:?} {d:?}"
        );
    }
    // An opaque hit 50 m into the cloud: only those 50 m count.
    let short = march(
        &volume,
        [0.0, 250.0, 0.0],
        [0.0, -1.0, 0.0],
        (0.0, 100.0),
        &MarchSettings {
            min_transmittance: 0.0,
            ..settings
        },
        &l,
    );
    assert!((short.transmittance - (-0.02f64 * 50.0).exp()).abs() < 1e-9);
}

/// Empty-space skipping is lossless: through a sparse baked field the march with the max grid
/// gives the same transmittance and in-scatter bit for bit as without it, evaluating fewer
/// density samples.
#[test]
fn empty_space_skipping_changes_nothing_and_saves_samples() {
    use fray_clouds::bake::bake;
    use fray_clouds::{CloudField, Unbounded};
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
    .unwrap();
    let plain = GridVolume {
        grid: grid.clone(),
        region,
        scale: 1.0,
        skip: None,
    };
    let skipping = GridVolume {
        skip: Some(grid.max_grid(4)),
        ..plain.clone()
    };
    let settings = MarchSettings {
        step: 40.0,
        min_transmittance: 0.0,
        ..MarchSettings::default()
    };
    let l = light(0.05);
    let mut state = 5u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut evaluated, mut skipped_to) = (0u64, 0u64);
    for _ in 0..400 {
        let o = [next() * 8000.0 - 4000.0, 4500.0, next() * 8000.0 - 4000.0];
        let d = {
            let v = [next() - 0.5, -0.3 - next(), next() - 0.5];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        };
        let a = march(&plain, o, d, (0.0, f64::INFINITY), &settings, &l);
        let b = march(&skipping, o, d, (0.0, f64::INFINITY), &settings, &l);
        assert_eq!(a.transmittance.to_bits(), b.transmittance.to_bits());
        assert_eq!(
            a.in_scatter.map(f64::to_bits),
            b.in_scatter.map(f64::to_bits)
        );
        evaluated += u64::from(a.samples);
        skipped_to += u64::from(b.samples);
    }
    println!("density samples: {evaluated} without skipping, {skipped_to} with");
    assert!(skipped_to * 2 < evaluated, "{skipped_to} vs {evaluated}");
}
