//! Clouds in the CPU integrator, against closed forms: a homogeneous cloud box in front of the
//! background and of a surface transmits `exp(−σL)` (to 1e-6) and scatters the sun's light as
//! single scattering in a homogeneous slab does; the march stops at an object inside the cloud;
//! a cloud's shadow dims a plane by `exp(−σ · path)`; an empty cloud box changes nothing (fog,
//! sky and the sky's peeled-off air included); no NaN with the camera inside the volume or on
//! its boundary; empty-space skipping gives the same bits with fewer samples.

use fray_clouds::march::{DualLobe, GridVolume, MarchSettings};
use fray_clouds::{DensityGrid, bake::Region};
use fray_core::MemoryBudget;
use fray_scene::{CloudSource, Clouds, Scene};
use fray_trace::{TraceSettings, render};
use std::sync::Arc;

mod common;

/// A scene with a (tiny) cloud layer; the tests swap in the volume they need.
const BOX: &str = r#"Scene(
    image: (width: 24, height: 16),
    camera: Pinhole(eye: (0, 5, -40), look_at: (0, 5, 0), fov_y: 30, near: 0.1),
    background: (0.4, 0.5, 0.7),
    ambient: (0, 0, 0),
    lights: [Sun(direction: (0, 1, 0), irradiance: (2, 2, 2))],
    clouds: (region: (min: (-10, 0, -10), max: (10, 10, 10)),
             density: Layer((resolution: (4, 4, 4)))),
)"#;

fn scene(src: &str) -> Scene {
    fray_scene::parse(src, "clouds.ron").unwrap_or_else(|e| panic!("{e}"))
}

/// A box of constant extinction `sigma` over `region`, lit with `albedo` and an isotropic phase.
fn homogeneous(region: Region, sigma: f64, albedo: f64, step: f64) -> Clouds {
    let grid = DensityGrid::from_fn([4, 4, 4], &MemoryBudget::default(), |_, _, _| 1.0).unwrap();
    Clouds {
        volume: GridVolume {
            skip: Some(grid.max_grid(2)),
            grid,
            region,
            scale: sigma,
        },
        source: CloudSource::Volume {
            path: "homogeneous".into(),
        },
        albedo,
        phase: DualLobe::single(0.0),
        ambient: 0.0,
        march: MarchSettings {
            step,
            sun_steps: 4,
            jitter: 0.5,
            min_transmittance: 0.0,
        },
        jitter: false,
        skip_block: Some(2),
    }
}

const REGION: Region = Region {
    min: [-10.0, 0.0, -10.0],
    max: [10.0, 10.0, 10.0],
};

fn close(a: f64, b: f64, rel: f64, what: &str) {
    assert!(
        (a - b).abs() <= rel * b.abs().max(1e-3),
        "{what}: {a} vs {b} (bound {rel} relative)"
    );
}

/// Through a box that absorbs only, each ray's colour is `exp(−σ L) · background`, `L` the
/// ray's chord through the box (bound 1e-6 relative: f32 colour).
#[test]
fn a_homogeneous_box_transmits_exp_minus_sigma_l() {
    let mut s = scene(BOX);
    let sigma = 0.07;
    s.clouds = Some(Arc::new(homogeneous(REGION, sigma, 0.0, 0.5)));
    let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    let mut inside = 0;
    for y in 0..s.height {
        for x in 0..s.width {
            let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
            let chord = fray_clouds::march::clip(
                &REGION,
                c.ray.origin.to_array(),
                c.ray.dir.to_array(),
                c.t_near,
                f64::INFINITY,
            )
            .map_or(0.0, |(a, b)| b - a);
            inside += usize::from(chord > 0.0);
            let t = (-sigma * chord).exp();
            let got = frame.colour.get(x, y);
            for (g, bg) in [(got.x, 0.4), (got.y, 0.5), (got.z, 0.7)] {
                close(f64::from(g), t * bg, 1e-6, &format!("pixel ({x}, {y})"));
            }
        }
    }
    assert!(inside > 100, "{inside} rays crossed the box");
}

/// The sun straight overhead, the camera ray horizontal at height `y` through a box of depth
/// `L`: the sun's path to every point is `top − y`, so single scattering is exactly
/// `ω · p · E · e^{−σ(top − y)} · (1 − e^{−σL})` (isotropic `p = 1/4π`), plus `e^{−σL}` of the
/// background (bound 1e-6 relative). The march's steps integrate a constant density exactly.
#[test]
fn single_scattering_in_a_homogeneous_box_matches_its_closed_form() {
    let mut s = scene(BOX);
    s.background = fray_core::Rgb::ZERO;
    let (sigma, albedo) = (0.05, 0.9);
    s.clouds = Some(Arc::new(homogeneous(REGION, sigma, albedo, 0.7)));
    let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    let (x, y) = (s.width / 2, s.height / 2);
    let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
    let (a, b) = fray_clouds::march::clip(
        &REGION,
        c.ray.origin.to_array(),
        c.ray.dir.to_array(),
        c.t_near,
        f64::INFINITY,
    )
    .unwrap();
    // The centre pixel's ray is nearly horizontal at y ≈ 5: check its height is constant
    // enough for the closed form, then use it exactly.
    assert!(c.ray.dir.y.abs() < 0.02, "{}", c.ray.dir);
    let expected = |t0: f64, t1: f64| {
        // ∫ σω p E e^{−σ(top − y(t))} e^{−σ(t − a)} dt with y(t) = o_y + t d_y: exact.
        let (oy, dy) = (c.ray.origin.y, c.ray.dir.y);
        let k = sigma * (1.0 - dy); // the exponent's slope in t: σ (t − a) + σ (top − oy − t dy)
        let base = (-sigma * (10.0 - oy)).exp() * (sigma * a).exp();
        let p = 1.0 / (4.0 * std::f64::consts::PI);
        sigma * albedo * p * 2.0 * base * ((-k * t0).exp() - (-k * t1).exp()) / k
    };
    let got = f64::from(frame.colour.get(x, y).y);
    // The march takes the density, not its slope, per step: over the small tilt the closed form
    // with the tilt and the exact per-step march agree to the step's second order.
    close(got, expected(a, b), 2e-4, "in-scatter");
    // The horizontal limit (dy = 0): the textbook closed form.
    let level = 2.0 / (4.0 * std::f64::consts::PI)
        * albedo
        * (-sigma * (10.0 - 5.0_f64)).exp()
        * (1.0 - (-sigma * (b - a)).exp());
    close(got, level, 0.05, "in-scatter vs the level closed form");
}

/// A sphere inside the cloud: the march stops at its surface, so the pixel is
/// `e^{−σ(t_hit − a)} · L_surface` (absorbing cloud, no in-scatter).
#[test]
fn the_march_stops_at_an_object_inside_the_cloud() {
    let with_sphere = BOX.replace(
        "    clouds:",
        "    objects: [(shape: Sphere(center: (0, 5, 0), radius: 3))],\n    clouds:",
    );
    let mut s = scene(&with_sphere);
    let clear = {
        let mut s = s.clone();
        s.clouds = None;
        s.features.clouds = false;
        render(&s, &TraceSettings::for_scene(&s), None).unwrap()
    };
    let sigma = 0.05;
    s.clouds = Some(Arc::new(homogeneous(REGION, sigma, 0.0, 0.25)));
    let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    let (x, y) = (s.width / 2, s.height / 2);
    let t_hit = *frame.depth.get(x, y);
    assert!(t_hit.is_finite());
    let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
    let a = (-10.0 - c.ray.origin.z) / c.ray.dir.z;
    // The sphere is lit by the sun through the cloud above it too: compare with the
    // clear frame times both transmittances.
    let p = c.ray.at(t_hit);
    let up = (-sigma * (10.0 - p.y)).exp();
    let expected = f64::from(clear.colour.get(x, y).y) * (-sigma * (t_hit - a)).exp() * up;
    close(
        f64::from(frame.colour.get(x, y).y),
        expected,
        1e-5,
        "the sphere's pixel",
    );
}

/// A plane under a cloud box: its lit points are dimmed by `e^{−σ · path}` toward the sun
/// (here straight up through the box's height), seen from outside the box.
#[test]
fn clouds_cast_shadows_on_surfaces() {
    let src = r#"Scene(
        image: (width: 20, height: 20),
        camera: Pinhole(eye: (0, 50, -30), look_at: (0, 0, 0), fov_y: 30, near: 0.1),
        background: (0, 0, 0),
        ambient: (0, 0, 0),
        lights: [Sun(direction: (0, 1, 0), irradiance: (2, 2, 2))],
        objects: [(shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                                   bounds: (min: (-100, -1, -100), max: (100, 0, 100))))],
        clouds: (region: (min: (-5, 20, -5), max: (5, 25, 5)),
                 density: Layer((resolution: (4, 4, 4)))),
    )"#;
    let mut s = scene(src);
    let clear = {
        let mut s = s.clone();
        s.clouds = None;
        s.features.clouds = false;
        render(&s, &TraceSettings::for_scene(&s), None).unwrap()
    };
    let region = Region {
        min: [-5.0, 20.0, -5.0],
        max: [5.0, 25.0, 5.0],
    };
    let sigma = 0.1;
    s.clouds = Some(Arc::new(homogeneous(region, sigma, 0.0, 0.3)));
    let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    let (mut shadowed, mut lit) = (0, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let c = s.camera.pixel_ray(x, y, s.width, s.height).unwrap();
            let t = *frame.depth.get(x, y);
            if !t.is_finite() {
                continue;
            }
            let p = c.ray.at(t);
            // Camera rays that cross the box see it in front of the plane: skip those.
            if fray_clouds::march::clip(
                &region,
                c.ray.origin.to_array(),
                c.ray.dir.to_array(),
                0.0,
                t,
            )
            .is_some()
            {
                continue;
            }
            let under = p.x.abs() < 5.0 && p.z.abs() < 5.0;
            let factor = if under { (-sigma * 5.0).exp() } else { 1.0 };
            if under {
                shadowed += 1;
            } else {
                lit += 1;
            }
            close(
                f64::from(frame.colour.get(x, y).y),
                f64::from(clear.colour.get(x, y).y) * factor,
                1e-5,
                &format!("({x}, {y}) under the cloud: {under}"),
            );
        }
    }
    assert!(shadowed > 5 && lit > 5, "{shadowed} shadowed, {lit} lit");
}

/// An empty cloud box (density 0) changes no pixel beyond rounding — with fog, and with the
/// sky, whose air in front of the box is peeled off the sky's table and put back.
#[test]
fn an_empty_cloud_box_changes_nothing_among_fog_and_sky() {
    for atmosphere in [
        "atmosphere: (fog: (base: -5, top: 8, extinction: 0.02)),",
        "atmosphere: (sky: (haze: 4)),",
        "atmosphere: (fog: (base: -5, top: 8, extinction: 0.02), sky: ()),",
    ] {
        let src = BOX
            .replace(
                "    clouds:",
                &format!(
                    "    {atmosphere}\n    objects: [(shape: Sphere(center: (0, 3, 0), radius: 3))],\n    clouds:"
                ),
            )
            .replace("ambient: (0, 0, 0)", "ambient: (0.1, 0.1, 0.1)");
        let mut s = scene(&src);
        let clear = {
            let mut s = s.clone();
            s.clouds = None;
            s.features.clouds = false;
            render(&s, &TraceSettings::for_scene(&s), None).unwrap()
        };
        s.clouds = Some(Arc::new(homogeneous(REGION, 0.0, 0.9, 0.5)));
        let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
        let mut worst = 0.0f64;
        for (a, b) in frame.colour.pixels().iter().zip(clear.colour.pixels()) {
            for (u, v) in [(a.x, b.x), (a.y, b.y), (a.z, b.z)] {
                worst = worst.max(f64::from((u - v).abs()) / f64::from(v.abs()).max(1e-3));
            }
        }
        assert!(worst < 2e-5, "{atmosphere}: worst relative change {worst}");
    }
}

/// Every pixel finite and non-negative with the camera inside the cloud box, exactly on its
/// faces and edges, and looking along a face (grazing) — on every cloud scene in `data/scenes`.
#[test]
fn no_nan_with_the_camera_inside_or_on_the_volume() {
    let scenes: Vec<_> = common::data_scenes()
        .into_iter()
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("clouds_"))
        })
        .collect();
    assert!(!scenes.is_empty());
    for path in scenes {
        let mut base = common::load_at_height(&path, 12);
        // Without skipping, so that the sample count shows the rays went through the box.
        let mut clouds = (**base.clouds.as_ref().unwrap()).clone();
        clouds.volume.skip = None;
        base.clouds = Some(Arc::new(clouds));
        let region = base.clouds.as_ref().unwrap().volume.region;
        let [x0, y0, z0] = region.min;
        let [x1, y1, z1] = region.max;
        let (cx, cy, cz) = (0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1));
        let (ex, ey, ez) = (x1 - x0, y1 - y0, z1 - z0);
        let cases = [
            ("inside", [cx, cy, cz], [cx + ex / 4.0, cy, cz + ez / 4.0]),
            (
                "on the base, along it",
                [cx, y0, cz],
                [cx + ex / 4.0, y0, cz],
            ),
            (
                "on the top, looking down",
                [cx, y1, cz],
                [cx + ex / 8.0, y0, cz + ez / 8.0],
            ),
            ("on a side face", [x0, cy, cz], [cx, cy, cz]),
            ("on an edge", [x0, y0, z0], [x1, y1, cz]),
            ("grazing a face", [x0 - ex, y1, cz], [x1, y1, cz]),
            ("outside, looking in", [cx, y1 + ey, z0 - ez], [cx, cy, cz]),
        ];
        let mut sampled = 0;
        for (what, eye, look_at) in cases {
            let what = format!("{}: {what}", path.display());
            let mut s = base.clone();
            s.camera = fray_core::Projector::Pinhole(
                fray_core::Pinhole::new(
                    glam::DVec3::from_array(eye),
                    glam::DVec3::from_array(look_at),
                    glam::DVec3::Y,
                    60f64.to_radians(),
                    0.05,
                )
                .unwrap(),
            );
            let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
            let bad = frame
                .colour
                .pixels()
                .iter()
                .filter(|c| !(c.is_finite() && c.min_element() >= 0.0))
                .count();
            assert_eq!(bad, 0, "{what}: {bad} pixels not finite or negative");
            sampled += usize::from(frame.stats.cloud_samples > 0);
        }
        // (A camera on the box's lower edge can sit under the terrain: no ray reaches the box.)
        assert!(
            sampled >= 5,
            "{}: only {sampled} of 7 views sampled the cloud",
            path.display()
        );
    }
}

/// Empty-space skipping on the data scene: the same bits as the plain march, with fewer
/// density samples (the measured share is printed).
#[test]
fn empty_space_skipping_gives_the_same_image_with_fewer_samples() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/scenes/clouds_aircraft_inside.ron");
    let skipping = common::load_at_height(&path, 27);
    let mut plain = skipping.clone();
    let mut clouds = (**plain.clouds.as_ref().unwrap()).clone();
    assert!(clouds.volume.skip.is_some());
    clouds.volume.skip = None;
    plain.clouds = Some(Arc::new(clouds));
    let a = render(&skipping, &TraceSettings::for_scene(&skipping), None).unwrap();
    let b = render(&plain, &TraceSettings::for_scene(&plain), None).unwrap();
    let bits = |f: &fray_core::Frame| -> Vec<[u32; 3]> {
        f.colour
            .pixels()
            .iter()
            .map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    println!(
        "density samples: {} skipping vs {} plain",
        a.stats.cloud_samples, b.stats.cloud_samples
    );
    assert!(a.stats.cloud_samples < b.stats.cloud_samples);
}

/// A scene without clouds builds nothing of them, and the stats do not name them.
#[test]
fn a_scene_without_clouds_runs_none_of_them() {
    let mut s = scene(BOX);
    s.clouds = None;
    s.features.clouds = false;
    let frame = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    assert_eq!(frame.stats.cloud_samples, 0);
    assert!(!frame.stats.passes.iter().any(|p| p.contains("clouds")));
    let with = scene(BOX);
    let frame = render(&with, &TraceSettings::for_scene(&with), None).unwrap();
    assert!(frame.stats.passes.iter().any(|p| p == "clouds"));
}
