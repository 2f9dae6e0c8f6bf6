//! Culling is lossless: every scene renders to identical colour, depth and normal images with
//! the quadtree scheduler on and off (all projector kinds, CSG, many perturbations), with plain
//! rays answered by the search and by the closed form alike.

mod common;

use fray_core::RenderStats;
use fray_trace::{CastMethod, TraceSettings, render};

fn scene(src: &str) -> fray_scene::Scene {
    match fray_scene::parse(src, "test.ron") {
        Ok(s) => s,
        Err(e) => panic!("test scene does not parse: {e}"),
    }
}

/// A slab with `n × n` bumps and dents on a grid, seen obliquely.
fn bumpy(n: u32, camera: &str) -> String {
    let mut perts = String::new();
    for i in 0..n {
        for j in 0..n {
            let x = -4.0 + 8.0 * (f64::from(i) + 0.5) / f64::from(n);
            let z = -4.0 + 8.0 * (f64::from(j) + 0.5) / f64::from(n);
            let f = if (i + j) % 3 == 0 { -0.6 } else { 1.2 };
            let r = 2.0 / f64::from(n);
            perts.push_str(&format!(
                "(form_factor: {f}, quadric: Ellipsoid(center: ({x}, 0.3, {z}), radii: ({r}, {r}, {r}))),\n"
            ));
        }
    }
    format!(
        r#"Scene(
            image: (width: 96, height: 72),
            camera: {camera},
            lights: [Sun(direction: (0.3, 1, -0.5), irradiance: (3, 3, 3))],
            objects: [
              (shape: FreeForm(base: Ellipsoid(center: (0, 0, 0), radii: (4.5, 0.3, 4.5)),
                               perturbations: [{perts}])),
              (shape: Difference(Sphere(center: (0, 1.5, 0), radius: 0.8),
                                 Sphere(center: (0.5, 1.8, -0.5), radius: 0.5))),
            ],
        )"#
    )
}

/// Both ways of answering plain rays, the default (closed form) last.
const METHODS: [CastMethod; 2] = [CastMethod::Halving, CastMethod::ClosedForm];

/// Culling on and off give the same bits, whichever [`CastMethod`] answers plain rays; returns
/// the stats (unculled, culled) of the default method.
fn assert_lossless(scene: &fray_scene::Scene, what: &str) -> (RenderStats, RenderStats) {
    let mut stats = None;
    for method in METHODS {
        stats = Some(assert_lossless_with(
            scene,
            &format!("{what} ({method:?})"),
            method,
        ));
    }
    stats.unwrap_or_default()
}

fn assert_lossless_with(
    scene: &fray_scene::Scene,
    what: &str,
    method: CastMethod,
) -> (RenderStats, RenderStats) {
    let mut settings = TraceSettings::for_scene(scene);
    settings.threads = Some(2);
    settings.method = method;
    settings.culling = false;
    let plain = render(scene, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
    settings.culling = true;
    let culled = render(scene, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        culled.stats.passes.iter().any(|p| p == "quadtree"),
        "{what}"
    );
    assert!(culled.stats.cells_visited > 0, "{what}");
    for y in 0..scene.height {
        for x in 0..scene.width {
            let (a, b) = (plain.depth.get(x, y), culled.depth.get(x, y));
            assert!(
                a.to_bits() == b.to_bits(),
                "{what}: depth differs at ({x}, {y}): {a} vs {b}"
            );
            // Bit for bit (a −0 against a +0 would count as a difference).
            let bits = |v: &glam::Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(
                bits(plain.normals.get(x, y)),
                bits(culled.normals.get(x, y)),
                "{what}: normal differs at ({x}, {y})"
            );
            assert_eq!(
                bits(plain.colour.get(x, y)),
                bits(culled.colour.get(x, y)),
                "{what}: colour differs at ({x}, {y})"
            );
        }
    }
    assert_eq!(plain.stats.hits, culled.stats.hits, "{what}");
    (plain.stats, culled.stats)
}

#[test]
fn every_data_scene_is_identical_with_and_without_culling() {
    for path in common::data_scenes() {
        let mut s = common::load_at_height(&path, 60);
        assert_lossless(&s, &path.display().to_string());
        // Point lights too (shadow rays converge on them; the tile culling keeps what their
        // segments can meet): one above the scene, one low among its objects.
        let centre = s
            .objects
            .iter()
            .fold(None, |acc: Option<fray_core::Aabb>, o| {
                let b = o.solid.bounds();
                Some(acc.map_or(b, |a| a.union(&b)))
            });
        if let Some(b) = centre {
            let (c, size) = (0.5 * (b.min + b.max), (b.max - b.min).length());
            s.lights = vec![
                fray_scene::Light::Point {
                    position: c + glam::DVec3::new(0.2, 0.6, -0.3) * size,
                    intensity: glam::Vec3::splat(50.0),
                },
                fray_scene::Light::Point {
                    position: c + glam::DVec3::new(-0.05, 0.02, 0.04) * size,
                    intensity: glam::Vec3::splat(5.0),
                },
            ];
            s.features.shadows = true;
            assert_lossless(&s, &format!("{} with point lights", path.display()));
        }
    }
}

#[test]
fn every_projector_kind_is_identical_with_and_without_culling() {
    let cameras = [
        "Pinhole(eye: (3, 5, -7), look_at: (0, 0, 0), fov_y: 50)",
        "Pinhole(eye: (0, 1, -0.5), look_at: (0, 0, 3), fov_y: 170)",
        "Pinhole(eye: (0, 9, -1), look_at: (0, 0, 0), fov_y: 2)",
        "Parallel(eye: (5, 6, -7), look_at: (0, 0, 0), up: (0, 1, 0), height: 9, near: 0)",
        "Sphere(eye: (0.3, 2.6, -1.2), centre: (0, 2.5, -1.0), look_at: (0, 0, 0), up: (0, 1, 0), \
         fov_x: 300, fov_y: 150, radius: 1.0, ripple_amplitude: 0.3, ripple_frequency: 5)",
        "Sphere(eye: (0, 3, 0), centre: (0, 3, 0), look_at: (0, 0, 1), up: (0, 1, 0), \
         fov_x: 360, fov_y: 180, radius: 0.5)",
    ];
    for camera in cameras {
        assert_lossless(&scene(&bumpy(4, camera)), camera);
    }
}

/// Anti-aliasing samples lie anywhere in their pixels, and the quadtree's bundles then cover
/// the whole pixels: still lossless, for every projector kind and a data scene.
#[test]
fn anti_aliased_frames_are_identical_with_and_without_culling() {
    for camera in [
        "Pinhole(eye: (3, 5, -7), look_at: (0, 0, 0), fov_y: 50)",
        "Parallel(eye: (5, 6, -7), look_at: (0, 0, 0), up: (0, 1, 0), height: 9, near: 0)",
        "Sphere(eye: (0.3, 2.6, -1.2), centre: (0, 2.5, -1.0), look_at: (0, 0, 0), up: (0, 1, 0), \
         fov_x: 300, fov_y: 150, radius: 1.0, ripple_amplitude: 0.3, ripple_frequency: 5)",
    ] {
        let mut s = scene(&bumpy(4, camera));
        s.settings.samples = fray_core::PixelSamples::new(5).unwrap();
        assert_lossless(&s, &format!("{camera}, 5 samples"));
    }
    let path = common::data_scenes()
        .into_iter()
        .find(|p| p.ends_with("csg.ron"))
        .expect("csg.ron");
    let mut s = common::load_at_height(&path, 40);
    s.settings.samples = fray_core::PixelSamples::new(4).unwrap();
    assert_lossless(&s, "csg.ron, 4 samples");
}

#[test]
fn a_scene_with_256_perturbations_is_identical_with_and_without_culling() {
    let s = scene(&bumpy(
        16,
        "Pinhole(eye: (1, 6, -7), look_at: (0, 0, 0), fov_y: 55)",
    ));
    assert_eq!(s.objects[0].solid.perturbation_count(), 256);
    let (plain, culled) = assert_lossless(&s, "256 perturbations");
    // The search itself is the same (same answers); what culling saves is restricting the
    // perturbations that cannot matter to each ray, and whole objects and tiles.
    assert!(culled.work_items > 0 && culled.bound_evaluations <= plain.bound_evaluations);
    eprintln!(
        "256 perturbations: bound evaluations {} → {}, cells {} visited, {} culled, {} items",
        plain.bound_evaluations,
        culled.bound_evaluations,
        culled.cells_visited,
        culled.cells_culled,
        culled.work_items
    );
}
