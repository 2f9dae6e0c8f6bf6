//! Fog in the CPU integrator: a lit plane seen through a fog layer has the colour the fog's
//! independent quadrature reference gives (`T · L_surface + L_in`, the sun dimmed on its way
//! down), rays that miss get the background through the fog, culling stays lossless with fog
//! (anti-aliased too), and a scene without fog runs none of it.

use fray_atmosphere::reference::single_scattering;
use fray_atmosphere::{FogLighting, Sunlight};
use fray_core::Interval;
use fray_trace::{TraceContext, TraceSettings, render};
use glam::DVec3;

const FOGGY: &str = r#"Scene(
    image: (width: 48, height: 36),
    camera: Pinhole(eye: (0, 30, -60), look_at: (0, 0, 0), fov_y: 60, near: 0.1),
    background: (0.4, 0.5, 0.7),
    ambient: (0.1, 0.1, 0.12),
    lights: [Sun(direction: (0.3, 0.5, -0.6), irradiance: (3, 2.9, 2.7))],
    materials: { "ground": (diffuse: (0.5, 0.45, 0.35)) },
    atmosphere: (fog: (base: -1, top: 20, extinction: 0.02, phase: HenyeyGreenstein(g: 0.6))),
    objects: [
        (material: "ground", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
            bounds: (min: (-500, -1, -500), max: (500, 0, 500)))),
        (shape: Sphere(center: (5, 8, 10), radius: 6)),
    ],
)"#;

fn scene(src: &str) -> fray_scene::Scene {
    fray_scene::parse(src, "fog.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// A pixel on the bare ground: Lambert under the sun seen through the fog down to the ground
/// and back up, plus the fog's light — every fog term from the quadrature reference.
#[test]
fn the_ground_through_fog_matches_the_reference() {
    let mut s = scene(FOGGY);
    s.settings.shadows = false; // the sphere's shadow is not under test
    let settings = TraceSettings::for_scene(&s);
    let frame = render(&s, &settings, None).unwrap();
    let fog = s.atmosphere.fog.unwrap().layer;
    let (sun_dir, irradiance) = match s.lights[0] {
        fray_scene::Light::Sun {
            direction,
            irradiance,
        } => (direction, irradiance.as_dvec3()),
        _ => unreachable!(),
    };
    let lighting = FogLighting {
        suns: vec![Sunlight {
            direction: sun_dir,
            irradiance,
        }],
        ambient: s.ambient.as_dvec3(),
    };
    let mut checked = 0;
    for (x, y) in [(4, 30), (24, 33), (40, 28), (10, 20)] {
        let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
        let t_ground = -c.ray.origin.y / c.ray.dir.y;
        if (frame.depth.get(x, y) - t_ground).abs() > 1e-6 {
            continue; // the sphere is in front
        }
        // The sun reaches the ground through the whole layer above it (0 → 20), vertically
        // 20 m: τ = B · 20 / sin β, by the reference's own quadrature of the sun's path.
        let down = fray_core::Ray::new(DVec3::new(0.0, 0.0, 0.0), sun_dir).unwrap();
        let sun_at_ground = (-fog.extinction * 20.0 / down.dir.y).exp();
        let albedo = DVec3::new(0.5, 0.45, 0.35);
        let surface = albedo * s.ambient.as_dvec3()
            + albedo / std::f64::consts::PI * irradiance * sun_at_ground * sun_dir.y;
        let terms = single_scattering(&fog, &c.ray, Interval::new(c.t_near, t_ground), &lighting);
        let expected = surface * terms.transmittance + terms.in_scatter;
        let got = frame.colour.get(x, y).as_dvec3();
        assert!(
            ((got - expected) / expected).abs().max_element() < 1e-5,
            "({x}, {y}): {got} vs {expected}"
        );
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} ground pixels checked");
    // A ray that misses (up, over the layer's top) gets the background through the fog.
    let c = s.camera.pixel_ray(24, 0, s.width, s.height).unwrap();
    assert!(frame.depth.get(24, 0).is_infinite());
    let terms = single_scattering(
        &fog,
        &c.ray,
        Interval::new(c.t_near, f64::INFINITY),
        &lighting,
    );
    let expected = s.background.as_dvec3() * terms.transmittance + terms.in_scatter;
    let got = frame.colour.get(24, 0).as_dvec3();
    assert!(((got - expected) / expected).abs().max_element() < 1e-5);
}

#[test]
fn fog_frames_are_identical_with_and_without_culling_and_match_the_integrator() {
    for samples in [1, 4] {
        let mut s = scene(FOGGY);
        s.settings.samples = fray_core::PixelSamples::new(samples).expect("valid count");
        let mut on = TraceSettings::for_scene(&s);
        on.threads = Some(2);
        let mut off = on;
        off.culling = false;
        let (a, b) = (
            render(&s, &on, None).unwrap(),
            render(&s, &off, None).unwrap(),
        );
        for (p, q) in a.colour.pixels().iter().zip(b.colour.pixels()) {
            assert_eq!(
                p.to_array().map(f32::to_bits),
                q.to_array().map(f32::to_bits)
            );
        }
        assert!(a.stats.passes.iter().any(|p| p == "fog"));
        if samples == 1 {
            let integrator = fray_trace::Integrator::new(&s, &on);
            let mut ctx = TraceContext::default();
            for y in 0..s.height {
                for x in 0..s.width {
                    let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
                    let range = Interval::new(c.t_near, f64::INFINITY);
                    let r = integrator.radiance(&mut ctx, &c.ray, range).as_vec3();
                    assert_eq!(r, *a.colour.get(x, y), "({x}, {y})");
                }
            }
        }
    }
}

#[test]
fn fog_dims_the_sun_even_without_shadows_and_a_scene_without_fog_runs_none() {
    let mut s = scene(FOGGY);
    s.settings.shadows = false;
    let settings = TraceSettings::for_scene(&s);
    let foggy = render(&s, &settings, None).unwrap();
    assert!(foggy.stats.passes.iter().any(|p| p == "fog"));
    let mut clear = s.clone();
    clear.atmosphere = fray_scene::Atmosphere::default();
    clear.features.fog = false;
    let frame = render(&clear, &TraceSettings::for_scene(&clear), None).unwrap();
    assert!(!frame.stats.passes.iter().any(|p| p == "fog"));
    // The same ground pixel is darker in the fog's shadowless frame than without fog (the fog
    // is dim against the lit ground at this angle) and differs from it.
    let (x, y) = (24, 33);
    assert!(foggy.colour.get(x, y) != frame.colour.get(x, y));
    // Visibility-only frames run no media.
    let mut vis = TraceSettings::for_scene(&s);
    vis.shading = false;
    let frame = render(&s, &vis, None).unwrap();
    assert!(!frame.stats.passes.iter().any(|p| p == "fog"));
}

/// The method's per-vertex mode: at the grid's nodes it is the exact frame bit for bit (a node
/// is its own interpolation); between them it stays within a small relative error of it; and
/// the sphere's silhouette, where depths disagree, falls back to exact evaluation.
#[test]
fn the_media_grid_is_exact_at_its_nodes_and_close_between_them() {
    // At a size where a cell of 8 pixels spans 2.5°, not the 13° of the small frames above.
    let mut s = scene(FOGGY);
    (s.width, s.height) = (192, 144);
    let exact_settings = TraceSettings::for_scene(&s);
    let exact = render(&s, &exact_settings, None).unwrap();
    let mut worst = 0.0f32;
    for spacing in [2, 4, 8] {
        let mut settings = exact_settings;
        settings.media_grid = Some(spacing);
        let grid = render(&s, &settings, None).unwrap();
        let (i, e) = (grid.stats.media_interpolated, grid.stats.media_exact);
        println!("spacing {spacing}: {i} interpolated, {e} exact");
        assert!(i > 0 && e > 0, "{i} interpolated, {e} exact");
        assert!(
            grid.stats
                .passes
                .iter()
                .any(|p| p.starts_with("media grid"))
        );
        for y in 0..s.height {
            for x in 0..s.width {
                let (a, b) = (*exact.colour.get(x, y), *grid.colour.get(x, y));
                if x % spacing == 0 && y % spacing == 0 {
                    assert_eq!(a, b, "node ({x}, {y}) at spacing {spacing}");
                }
                worst = worst.max(((a - b) / a).abs().max_element());
            }
        }
    }
    println!("media grid: worst relative difference {worst:.2e}");
    assert!(worst < 5e-3, "{worst}");
}

const SKY: &str = r#"Scene(
    image: (width: 48, height: 36),
    camera: Pinhole(eye: (0, 30, -60), look_at: (0, 20, 0), fov_y: 60, near: 0.1),
    ambient: (0.05, 0.05, 0.07),
    lights: [Sun(direction: (-1, 0.08, 0.6), irradiance: (20, 20, 20)),
             Sun(direction: (0.5, 0.5, -0.2), irradiance: (0.5, 0.5, 0.5))],
    atmosphere: (sky: (haze: 2), fog: (base: -1, top: 15, extinction: 0.01)),
    objects: [
        (shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
            bounds: (min: (-500, -1, -500), max: (500, 0, 500)))),
        (shape: Sphere(center: (5, 22, 10), radius: 6)),
    ],
)"#;

/// A sky replaces the background: a ray that hits nothing and never enters the fog is the sky
/// view's radiance (table and sun disc) exactly; frames with sky and fog are identical with and
/// without culling, 1 and 4 samples, and equal the integrator's radiance per ray; the first sun
/// is the sky's and is dimmed by the air, the second is not.
#[test]
fn the_sky_is_the_background_and_culling_stays_lossless() {
    let s = scene(SKY);
    assert!(s.features.sky && s.features.fog);
    let settings = TraceSettings::for_scene(&s);
    let frame = render(&s, &settings, None).unwrap();
    assert!(frame.stats.passes.iter().any(|p| p == "sky"));
    let sky = s.atmosphere.sky.as_ref().unwrap();
    assert_eq!(sky.sun_light, Some(0));
    let view = sky.sky.view(DVec3::new(0.0, 30.0, -60.0));
    let c = s.camera.pixel_ray(24, 0, s.width, s.height).unwrap();
    assert!(frame.depth.get(24, 0).is_infinite() && c.ray.dir.y > 0.0);
    assert_eq!(
        *frame.colour.get(24, 0),
        view.background(c.ray.dir).as_vec3()
    );
    for samples in [1, 4] {
        let mut s = s.clone();
        s.settings.samples = fray_core::PixelSamples::new(samples).expect("valid count");
        let mut on = TraceSettings::for_scene(&s);
        on.threads = Some(2);
        let mut off = on;
        off.culling = false;
        let (a, b) = (
            render(&s, &on, None).unwrap(),
            render(&s, &off, None).unwrap(),
        );
        assert_eq!(a.colour.pixels(), b.colour.pixels());
        if samples == 1 {
            let integrator = fray_trace::Integrator::new(&s, &on);
            let mut ctx = TraceContext::default();
            for y in 0..s.height {
                for x in 0..s.width {
                    let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
                    let range = Interval::new(c.t_near, f64::INFINITY);
                    let r = integrator.radiance(&mut ctx, &c.ray, range).as_vec3();
                    assert_eq!(r, *a.colour.get(x, y), "({x}, {y})");
                }
            }
        }
    }
    // The air dims the sky's sun (low, through much air) at a surface; not the second sun.
    let media = fray_trace::Media::of(&s).unwrap();
    let p = DVec3::new(0.0, 0.0, 0.0);
    let low = media.light_transmittance(p, 0, &s.lights[0], DVec3::X, f64::INFINITY);
    let other = media.light_transmittance(p, 1, &s.lights[1], DVec3::X, f64::INFINITY);
    // The fog's share: the path from y = 0 to the top (15) toward each sun.
    let fog_only = |d: DVec3| (-0.01 * 15.0 / d.normalize().y).exp();
    let second = fog_only(DVec3::new(0.5, 0.5, -0.2));
    assert!(
        (other - DVec3::splat(second)).abs().max_element() < 1e-12,
        "{other}"
    );
    let first = fog_only(DVec3::new(-1.0, 0.08, 0.6));
    assert!(
        low.max_element() < 0.9 * first && low.x > low.z,
        "{low} vs fog {first}"
    );
}
