//! Known-answer tests of the CPU backend: radiometry against closed forms, shadows, the
//! picture-surface clip, depth against the closed-form sphere hit, and thread-count determinism.

use fray_core::Interval;
use fray_trace::{TraceSettings, render};
use glam::DVec3;
use std::f64::consts::PI;

fn scene(src: &str) -> fray_scene::Scene {
    match fray_scene::parse(src, "test.ron") {
        Ok(s) => s,
        Err(e) => panic!("test scene does not parse: {e}"),
    }
}

fn settings(s: &fray_scene::Scene) -> TraceSettings {
    TraceSettings::for_scene(s)
}

/// A unit sphere seen head-on with the sun behind the camera: at the centre of the disc the
/// normal faces the sun, so the radiance is exactly `ambient·A + albedo/π · E` (Lambert).
#[test]
fn lambert_sun_radiance_matches_closed_form() {
    let s = scene(
        r#"Scene(
            image: (width: 31, height: 31),
            camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0), fov_y: 30),
            ambient: (0.1, 0.2, 0.3),
            lights: [Sun(direction: (0, 0, -1), irradiance: (2, 3, 4))],
            materials: { "m": (diffuse: (0.5, 0.6, 0.7), ambient: (0.25, 0.25, 0.25)) },
            objects: [(material: "m", shape: Sphere(center: (0, 0, 0), radius: 1))],
        )"#,
    );
    let frame = render(&s, &settings(&s), None).unwrap();
    let got = frame.colour.get(15, 15).as_dvec3();
    let expected = DVec3::new(
        0.25 * 0.1 + 0.5 / PI * 2.0,
        0.25 * 0.2 + 0.6 / PI * 3.0,
        0.25 * 0.3 + 0.7 / PI * 4.0,
    );
    // f32 storage: relative error ≤ 1e-6.
    assert!(
        (got - expected).abs().max_element() <= 1e-6 * expected.max_element(),
        "{got} vs {expected}"
    );
    // Corners miss: background.
    assert_eq!(frame.colour.get(0, 0).as_dvec3(), s.background.as_dvec3());
}

/// A point light of intensity I at distance r along the normal: `L = albedo/π · I / r²`.
#[test]
fn point_light_follows_inverse_square_law() {
    let s = scene(
        r#"Scene(
            image: (width: 21, height: 21),
            camera: Pinhole(eye: (0, 0, -5), look_at: (0, 0, 0), fov_y: 20),
            ambient: (0, 0, 0),
            lights: [Point(position: (0, 0, -3), intensity: (8, 8, 8))],
            materials: { "m": (diffuse: (0.9, 0.9, 0.9)) },
            objects: [(material: "m", shape: Sphere(center: (0, 0, 0), radius: 1))],
        )"#,
    );
    let frame = render(&s, &settings(&s), None).unwrap();
    let got = f64::from(frame.colour.get(10, 10).x);
    let expected = 0.9 / PI * 8.0 / 4.0; // r = 2
    assert!(
        (got - expected).abs() <= 1e-6 * expected,
        "{got} vs {expected}"
    );
}

/// A ball floating over a slab in a 45° sun: its shadow falls on the slab around the origin
/// (ambient only there); a slab point well outside the shadow is lit.
#[test]
fn shadow_rays_darken_occluded_points() {
    let src = |shadows: bool| {
        format!(
            r#"Scene(
                image: (width: 41, height: 41),
                camera: Parallel(eye: (0, 10, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 8),
                ambient: (0.05, 0.05, 0.05),
                lights: [Sun(direction: (1, 1, 0), irradiance: (3, 3, 3))],
                objects: [
                    (name: "ball", shape: Sphere(center: (3, 3, 0), radius: 1)),
                    (name: "slab", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)), bounds: (min: (-5, -1, -5), max: (5, 0, 5)))),
                ],
                settings: (shadows: {shadows}),
            )"#
        )
    };
    let lit_scene = scene(&src(false));
    let shadowed_scene = scene(&src(true));
    let lit = render(&lit_scene, &settings(&lit_scene), None).unwrap();
    let shadowed = render(&shadowed_scene, &settings(&shadowed_scene), None).unwrap();
    // Find the pixel that sees the slab at x = 0 (under nothing) and one next to the ball's shadow.
    let width = 41.0;
    let px_for_x = |x: f64| ((width * 0.5) - x / 8.0 * width) as u32; // camera right is −x here
    let open = px_for_x(-3.0);
    let open_lit = shadowed.colour.get(open, 20).x;
    assert!(open_lit > 0.5, "open slab should be sunlit, got {open_lit}");
    assert!(shadowed.stats.shadow_rays > 0 && lit.stats.shadow_rays == 0);
    // Somewhere the shadowed render is darker than the unshadowed one by the full sun term,
    // and never brighter.
    let mut darker = 0;
    for (a, b) in lit.colour.pixels().iter().zip(shadowed.colour.pixels()) {
        assert!(b.x <= a.x + 1e-7);
        if a.x - b.x > 0.4 {
            darker += 1;
        }
    }
    assert!(
        darker > 5,
        "the ball must cast a shadow on the slab ({darker} pixels)"
    );
    // Shadowed slab pixels have exactly the ambient term left.
    for (a, b) in lit.colour.pixels().iter().zip(shadowed.colour.pixels()) {
        if a.x - b.x > 0.4 {
            assert!(
                (b.x - 0.8 * 0.05).abs() < 1e-6,
                "shadow = ambient only, got {}",
                b.x
            );
        }
    }
}

/// Points between the eye and the picture plane (`w ≤ 1`) are not shown: with the picture plane
/// inside a sphere, the cut face is seen at exactly the near distance.
#[test]
fn picture_surface_clips_what_lies_before_it() {
    let s = scene(
        r#"Scene(
            image: (width: 9, height: 9),
            camera: Pinhole(eye: (0, 0, -1.5), look_at: (0, 0, 0), fov_y: 10, near: 1),
            objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))],
        )"#,
    );
    let frame = render(&s, &settings(&s), None).unwrap();
    let r = s.camera.pixel_ray(4, 4, 9, 9).unwrap();
    assert_eq!(*frame.depth.get(4, 4), r.t_near);
    let n = frame.normals.get(4, 4).as_dvec3();
    assert!(
        (n + r.ray.dir).length() < 1e-6,
        "the cut face faces the viewer"
    );
}

/// Every pixel's depth agrees with the closed-form sphere intersection to within ε.
#[test]
fn depth_matches_closed_form_on_every_pixel() {
    let s = scene(
        r#"Scene(
            image: (width: 64, height: 48),
            camera: Pinhole(eye: (0.3, 0.7, -4), look_at: (0, 0, 0), fov_y: 40),
            objects: [(shape: Ellipsoid(center: (0.1, -0.2, 0.3), radii: (1.2, 0.8, 1.0)))],
        )"#,
    );
    let st = settings(&s);
    let frame = render(&s, &st, None).unwrap();
    let leaf = &s.objects[0].solid.leaves()[0];
    let mut hits = 0;
    for py in 0..48 {
        for px in 0..64 {
            let cr = s.camera.pixel_ray(px, py, 64, 48).unwrap();
            let exact = leaf.closed_form_hit(&cr.ray, Interval::new(cr.t_near, f64::INFINITY));
            let got = *frame.depth.get(px, py);
            match exact {
                Some(t) => {
                    hits += 1;
                    assert!(
                        (got - t).abs() <= st.epsilon,
                        "pixel ({px},{py}): {got} vs {t}"
                    );
                }
                None => assert!(got.is_infinite(), "pixel ({px},{py}) should miss"),
            }
        }
    }
    assert!(hits > 500);
}

/// The same bytes whatever the thread count.
#[test]
fn image_is_independent_of_thread_count() {
    let s = scene(
        r#"Scene(
            image: (width: 48, height: 40),
            camera: Pinhole(eye: (1, 2, -5), look_at: (0, 0, 0)),
            lights: [Sun(direction: (1, 2, -1), irradiance: (3, 3, 3)), Point(position: (-2, 3, -2), intensity: (20, 20, 20))],
            materials: { "shiny": (diffuse: (0.6, 0.5, 0.4), specular: (0.3, 0.3, 0.3), shininess: 30) },
            objects: [
                (material: "shiny", shape: Difference(
                    FreeForm(base: Sphere(center: (0, 0, 0), radius: 1), perturbations: [(form_factor: 0.7, quadric: Sphere(center: (1, 0.5, 0), radius: 0.6))]),
                    Sphere(center: (0, 0, -1), radius: 0.5),
                )),
                (shape: FreeForm(base: HalfSpace(point: (0, -1, 0), normal: (0, 1, 0)), bounds: (min: (-4, -2, -4), max: (4, -1, 4)))),
            ],
        )"#,
    );
    let mut a = settings(&s);
    a.threads = Some(1);
    a.tile_size = 16;
    let mut b = a;
    b.threads = Some(2);
    b.tile_size = 16;
    let fa = render(&s, &a, None).unwrap();
    let fb = render(&s, &b, None).unwrap();
    assert_eq!(fa.colour, fb.colour);
    assert_eq!(fa.depth, fb.depth);
    assert_eq!(fa.normals, fb.normals);
    assert_eq!(fa.stats.bound_evaluations, fb.stats.bound_evaluations);
    // A different tile size changes the schedule but not the image.
    let mut c = a;
    c.tile_size = 7;
    let fc = render(&s, &c, None).unwrap();
    assert_eq!(fa.colour, fc.colour);
}

/// Cameras far from the world origin keep their accuracy: the hit point error stays ≤ ε.
#[test]
fn far_from_origin_scene_keeps_accuracy() {
    let s = scene(
        r#"Scene(
            image: (width: 16, height: 16),
            camera: Pinhole(eye: (1000000, 2000000, -9.5), look_at: (1000000, 2000000, 0.5), fov_y: 20),
            objects: [(shape: Sphere(center: (1000000, 2000000, 0.5), radius: 1))],
        )"#,
    );
    let st = settings(&s);
    let frame = render(&s, &st, None).unwrap();
    let leaf = &s.objects[0].solid.leaves()[0];
    for py in 0..16 {
        for px in 0..16 {
            let cr = s.camera.pixel_ray(px, py, 16, 16).unwrap();
            let exact = leaf.closed_form_hit(&cr.ray, Interval::new(cr.t_near, f64::INFINITY));
            let got = *frame.depth.get(px, py);
            match exact {
                Some(t) => assert!((got - t).abs() <= st.epsilon.max(1e-9), "{got} vs {t}"),
                None => assert!(got.is_infinite()),
            }
        }
    }
}

/// Visibility only (`shading: false`): the same depth and normals as a shaded frame, bit for bit,
/// no shadow ray, the colour `0.5 + 0.5 n` on hits and the background elsewhere, and no light in
/// the passes that ran.
#[test]
fn visibility_only_keeps_depth_and_normals_and_skips_lights() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes/csg.ron");
    let mut s = fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    s.width = 96;
    s.height = 72;
    let shaded = render(&s, &settings(&s), None).unwrap();
    let visibility = TraceSettings {
        shading: false,
        ..settings(&s)
    };
    let frame = render(&s, &visibility, None).unwrap();
    assert_eq!(frame.depth, shaded.depth);
    assert_eq!(frame.normals, shaded.normals);
    assert!(shaded.stats.shadow_rays > 0);
    assert_eq!(frame.stats.shadow_rays, 0);
    for y in 0..s.height {
        for x in 0..s.width {
            let c = *frame.colour.get(x, y);
            if frame.depth.get(x, y).is_finite() {
                let n = *frame.normals.get(x, y);
                assert_eq!(c, glam::Vec3::splat(0.5) + 0.5 * n);
            } else {
                assert_eq!(c, s.background);
            }
        }
    }
    assert!(shaded.stats.passes.iter().any(|p| p == "sun"));
    assert!(
        !frame
            .stats
            .passes
            .iter()
            .any(|p| p == "sun" || p == "shadows")
    );
}
