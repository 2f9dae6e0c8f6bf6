//! The fog layer against its numerical reference: the exact closed form to 1e-6 relative over a
//! grid of view angles, sun elevations, layer heights and extinctions; the falloff layer's
//! quadrature; the edge cases (horizontal rays, the sun at the horizon, the observer at the top,
//! zero extinction) finite and right.

use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLayer, FogLighting, FogModel, FogTerms, Phase, Sunlight};
use fray_core::{Interval, Ray};
use glam::DVec3;

fn direction(elevation_deg: f64, azimuth_deg: f64) -> DVec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

fn lighting(sun_elevation_deg: f64) -> FogLighting {
    FogLighting {
        suns: vec![Sunlight {
            direction: direction(sun_elevation_deg, 0.0),
            irradiance: DVec3::new(3.0, 2.9, 2.7),
        }],
        ambient: DVec3::new(0.08, 0.09, 0.11),
    }
}

/// The largest relative difference over the channels (and the transmittance).
fn relative(a: &FogTerms, b: &FogTerms) -> f64 {
    let rel = |x: f64, y: f64| {
        if x == y {
            0.0
        } else {
            (x - y).abs() / x.abs().max(y.abs())
        }
    };
    let mut worst = rel(a.transmittance, b.transmittance);
    for c in 0..3 {
        worst = worst.max(rel(a.in_scatter[c], b.in_scatter[c]));
    }
    worst
}

/// The grid: view angles 1°–90° (down onto the layer's bottom from inside, at the top
/// and above; up and out from inside, from the base, and from below it across the whole layer),
/// sun elevations 2°–90°, three layer heights, four extinctions, the sun ahead, across and
/// behind.
#[test]
fn closed_form_matches_the_reference_to_1e_6_over_the_grid() {
    let mut worst = (0.0f64, String::new());
    let mut cases = 0;
    for &height in &[10.0, 100.0, 1000.0] {
        for &extinction in &[1e-4, 1e-3, 1e-2, 1e-1] {
            let fog = FogLayer {
                top: height,
                extinction,
                ..FogLayer::default()
            };
            for &sun in &[2.0, 10.0, 30.0, 60.0, 90.0] {
                let light = lighting(sun);
                for &view in &[1.0, 5.0, 20.0, 45.0, 90.0] {
                    for &azimuth in &[0.0, 90.0, 180.0] {
                        for &(observer, down) in &[
                            (0.5, true),
                            (1.0, true),
                            (1.5, true),
                            (0.5, false),
                            (0.0, false),
                            (-0.5, false),
                        ] {
                            let eye = DVec3::new(0.0, observer * height, 0.0);
                            let elevation = if down { -view } else { view };
                            let ray = Ray::new(eye, direction(elevation, azimuth)).unwrap();
                            // Down: to the bottom (an object there); up: to infinity.
                            let range = if down {
                                Interval::new(0.0, -eye.y / ray.dir.y)
                            } else {
                                Interval::new(0.0, f64::INFINITY)
                            };
                            let exact = fog.terms(&ray, range, &light, FogModel::Exact);
                            let reference = single_scattering(&fog, &ray, range, &light);
                            let r = relative(&exact, &reference);
                            cases += 1;
                            if r > worst.0 {
                                worst = (
                                    r,
                                    format!(
                                        "H {height}, B {extinction}, sun {sun}°, view {elevation}° az {azimuth}°, eye {observer}H"
                                    ),
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    println!(
        "{cases} cases; worst relative difference {:.2e} at {}",
        worst.0, worst.1
    );
    assert!(worst.0 < 1e-6, "{:.3e} at {}", worst.0, worst.1);
}

/// The falloff layer's closed form against the reference.
#[test]
fn falloff_layer_matches_the_reference() {
    let mut worst = 0.0f64;
    for &scale in &[20.0, 100.0, 1000.0] {
        for &extinction in &[1e-3, 1e-2, 5e-2] {
            let fog = FogLayer {
                top: 200.0,
                extinction,
                falloff: Some(scale),
                ..FogLayer::default()
            };
            for &sun in &[2.0, 20.0, 70.0] {
                let light = lighting(sun);
                for &view in &[-30.0, -3.0, 0.0, 4.0, 40.0] {
                    let eye = DVec3::new(0.0, 60.0, 0.0);
                    let ray = Ray::new(eye, direction(view, 30.0)).unwrap();
                    let range = if view < 0.0 {
                        Interval::new(0.5, -eye.y / ray.dir.y)
                    } else {
                        Interval::new(0.5, f64::INFINITY)
                    };
                    let exact = fog.terms(&ray, range, &light, FogModel::Exact);
                    let reference = single_scattering(&fog, &ray, range, &light);
                    worst = worst.max(relative(&exact, &reference));
                }
            }
        }
    }
    println!("falloff: worst relative difference {worst:.2e}");
    assert!(worst < 1e-6, "{worst:.3e}");
}

#[test]
fn edge_cases_are_finite_and_right() {
    let fog = FogLayer {
        top: 100.0,
        extinction: 0.01,
        ..FogLayer::default()
    };
    let all = Interval::new(0.0, f64::INFINITY);
    let finite = |t: &FogTerms| {
        t.transmittance.is_finite()
            && (0.0..=1.0).contains(&t.transmittance)
            && t.in_scatter.is_finite()
            && t.in_scatter.min_element() >= 0.0
    };
    for model in [FogModel::Exact, FogModel::Method] {
        for sun in [0.0, -5.0, 1e-9, 2.0, 90.0] {
            let light = lighting(sun);
            for eye_y in [-20.0, 0.0, 50.0, 100.0 - 1e-9, 100.0, 100.0 + 1e-9, 150.0] {
                for elevation in [-90.0, -1e-7, 0.0, 1e-7, 45.0, 90.0] {
                    let ray =
                        Ray::new(DVec3::new(0.0, eye_y, 0.0), direction(elevation, 0.0)).unwrap();
                    let t = fog.terms(&ray, all, &light, model);
                    assert!(
                        finite(&t),
                        "{model:?} sun {sun} eye {eye_y} view {elevation}: {t:?}"
                    );
                }
            }
        }
    }
    // A horizontal ray inside the layer: nothing gets through, the in-scatter is finite and
    // equals the reference (which cuts the ray where e^{−τ} < e^{−800}).
    let light = lighting(20.0);
    let ray = Ray::new(DVec3::new(0.0, 40.0, 0.0), DVec3::X).unwrap();
    let exact = fog.terms(&ray, all, &light, FogModel::Exact);
    assert_eq!(exact.transmittance, 0.0);
    let reference = single_scattering(&fog, &ray, all, &light);
    assert!(relative(&exact, &reference) < 1e-9);
    // The sun at or below the horizon: only ambient light scatters (1 − T of it).
    for sun in [0.0, -10.0] {
        let t = fog.terms(&ray, all, &lighting(sun), FogModel::Exact);
        let ambient = lighting(sun).ambient * fog.albedo;
        assert!((t.in_scatter - ambient).abs().max_element() < 1e-15);
    }
    // Zero extinction: clear, whatever the geometry.
    let clear = FogLayer {
        extinction: 0.0,
        ..fog
    };
    assert_eq!(
        clear.terms(&ray, all, &light, FogModel::Exact),
        FogTerms::CLEAR
    );
    // An observer exactly at the top looking up sees no fog; looking down, all of it.
    let up = Ray::new(DVec3::new(0.0, 100.0, 0.0), direction(30.0, 0.0)).unwrap();
    let t = fog.terms(&up, all, &light, FogModel::Exact);
    assert_eq!(t.transmittance, 1.0);
    let down = Ray::new(DVec3::new(0.0, 100.0, 0.0), direction(-30.0, 0.0)).unwrap();
    let t = fog.terms(&down, Interval::new(0.0, 200.0), &light, FogModel::Exact);
    assert!((t.transmittance - (-0.01f64 * 200.0).exp()).abs() < 1e-15);
}

/// Where every point of the ray is at the bottom (a ray along the base), the sun's path is the
/// whole layer there, so the method's formula is exact; elsewhere it sees too little sun.
#[test]
fn the_method_is_exact_at_the_bottom_and_too_dark_above_it() {
    let fog = FogLayer {
        top: 100.0,
        extinction: 0.01,
        phase: Phase::Isotropic,
        ..FogLayer::default()
    };
    let light = lighting(30.0);
    let range = Interval::new(0.0, 500.0);
    let along_base = Ray::new(DVec3::ZERO, DVec3::X).unwrap();
    let exact = fog.terms(&along_base, range, &light, FogModel::Exact);
    let method = fog.terms(&along_base, range, &light, FogModel::Method);
    assert!(relative(&exact, &method) < 1e-12);
    let higher = Ray::new(DVec3::new(0.0, 50.0, 0.0), DVec3::X).unwrap();
    let exact = fog.terms(&higher, range, &light, FogModel::Exact);
    let method = fog.terms(&higher, range, &light, FogModel::Method);
    assert!(method.in_scatter.x < exact.in_scatter.x);
    // Its in-scatter is the closed form of eq. (15) times σ_s: E e^{−BH/sin β} p ω (1 − e^{−BL}).
    let expected = light.suns[0].irradiance.x
        * (-0.01f64 * 100.0 / 0.5).exp()
        * (1.0 / (4.0 * std::f64::consts::PI))
        * fog.albedo.x
        * (1.0 - (-0.01f64 * 500.0).exp())
        + fog.albedo.x * light.ambient.x * (1.0 - (-0.01f64 * 500.0).exp());
    assert!((method.in_scatter.x / expected - 1.0).abs() < 1e-12);
}
