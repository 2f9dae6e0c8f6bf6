//! Terrain in the CPU backend: it mixes with free forms (nearest hit over all primitive kinds
//! wins), is shaded (Lambert known answer on a flat map) and shadowed (a sphere's shadow on
//! it), and culling stays lossless on a ring-shaped (holed) terrain seen
//! by every projector kind.

use fray_trace::{TraceSettings, render};
use std::path::{Path, PathBuf};

/// Writes a `.npy` map of `n × n` `<f4` samples from `f(column, row)` into a fresh folder and
/// returns that folder.
fn map_dir(name: &str, n: usize, f: impl Fn(usize, usize) -> f32) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("fray-trace-terrain-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let samples: Vec<u8> = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .flat_map(|(i, j)| f(i, j).to_le_bytes())
        .collect();
    let bytes = fray_terrain::npy::encode("<f4", n, n, &samples);
    std::fs::write(dir.join("map.npy"), bytes).unwrap();
    dir
}

fn scene(dir: &Path, body: &str) -> fray_scene::Scene {
    let path = dir.join("scene.ron");
    std::fs::write(&path, body).unwrap();
    fray_scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn flat_terrain_is_lit_like_a_plane_and_a_sphere_above_shadows_it() {
    // A 33 × 33 flat map at raw height 2 (× 0.5 = 1 m) from (−8, 0, −8), 0.5 m spacing.
    let dir = map_dir("flat", 33, |_, _| 2.0);
    let s = scene(
        &dir,
        r#"Scene(
            image: (width: 40, height: 40),
            camera: Parallel(eye: (0, 10, 0), look_at: (0, 0, 0), up: (0, 0, 1), height: 16),
            ambient: (0, 0, 0),
            lights: [Sun(direction: (1, 1, 0), irradiance: (2, 2, 2))],
            materials: { "grey": (diffuse: (0.5, 0.5, 0.5), ambient: (0, 0, 0)) },
            objects: [
                (material: "grey", shape: Terrain(path: "map.npy", spacing: (0.5, 0.5),
                    vertical_scale: 0.5, origin: (-8, 0, -8), lod: Exact)),
                (shape: Sphere(center: (4, 3, 4), radius: 1)),
            ],
        )"#,
    );
    let f = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    // This view: 0.4 m per pixel, +x to the left, +z up: pixel (px, py) sees
    // x = −(px + 0.5 − 20)·0.4, z = (20 − py − 0.5)·0.4.
    // Far from the sphere (x = −4.2, z = 4.6): depth 9 (eye at 10, ground at 1), Lambert
    // 0.5/π · 2 · cos 45° (the sun is 45° up), no ambient.
    let lit = 0.5 / std::f32::consts::PI * 2.0 * std::f32::consts::FRAC_1_SQRT_2;
    let c = f.colour.get(30, 8);
    assert!(
        (f.depth.get(30, 8) - 9.0).abs() < 1e-9,
        "{}",
        f.depth.get(30, 8)
    );
    assert!((c.x - lit).abs() < 1e-5, "{c} vs {lit}");
    assert!((f.normals.get(30, 8).y - 1.0).abs() < 1e-6);
    // (4.2, 4.2): the sphere is the nearest hit (about 10 − 3 − 0.96).
    assert!(
        (f.depth.get(9, 9) - 6.04).abs() < 0.05,
        "{}",
        f.depth.get(9, 9)
    );
    // (2.2, 4.2): the ground, in the sphere's shadow (the sun is 45° up along +x, the sphere
    // 2 m above the ground, so its shadow is centred at x = 2): black without ambient.
    assert!((f.depth.get(14, 9) - 9.0).abs() < 1e-9);
    assert_eq!(f.colour.get(14, 9).x, 0.0);
}

#[test]
fn terrain_and_free_forms_mix_nearest_wins_both_ways() {
    // A ridge across the view: rows 6..=10 (z from 6 to 10 m) are 8 m high, the rest 0.
    let dir = map_dir(
        "ridge",
        17,
        |_, j| if (6..=10).contains(&j) { 8.0 } else { 0.0 },
    );
    let s = scene(
        &dir,
        r#"Scene(
            image: (width: 64, height: 32),
            camera: Pinhole(eye: (8, 4, -30), look_at: (8, 4, 8), fov_y: 30),
            lights: [Sun(direction: (0.2, 1, -0.5))],
            objects: [
                (shape: Terrain(path: "map.npy")),
                // In front of the map (nearer the camera), and behind the ridge.
                (shape: Sphere(center: (12, 4, -6), radius: 1.5)),
                (shape: Sphere(center: (4, 4, 20), radius: 1.5)),
            ],
        )"#,
    );
    let f = render(&s, &TraceSettings::for_scene(&s), None).unwrap();
    // The front sphere is seen; the one behind the ridge (z = 20, heights ≤ 8 hide it) is not.
    let mut front = false;
    let mut back = false;
    for y in 0..32 {
        for x in 0..64 {
            let d = f.depth.get(x, y);
            if (d - 24.0).abs() < 1.6 {
                front = true;
            }
            if (d - 50.0).abs() < 1.6 {
                back = true;
            }
        }
    }
    assert!(front, "the sphere in front of the ridge must be visible");
    assert!(
        !back,
        "the sphere behind the ridge must be hidden by the terrain"
    );
    assert!(
        f.stats.passes.iter().any(|p| p == "terrain"),
        "{:?}",
        f.stats.passes
    );
}

#[test]
fn culling_is_lossless_on_a_holed_terrain_for_every_projector() {
    let dir = map_dir("ring", 41, |i, j| {
        let r = ((i as f32 - 20.0).powi(2) + (j as f32 - 20.0).powi(2)).sqrt();
        if (8.0..=16.0).contains(&r) {
            3.0 + (i as f32 * 0.7).sin()
        } else {
            -1.0
        }
    });
    let cameras = [
        "Pinhole(eye: (20, 25, -15), look_at: (20, 0, 20), fov_y: 50)",
        "Pinhole(eye: (20, 2, 20), look_at: (40, 1, 20), fov_y: 120)",
        "Parallel(eye: (35, 30, -5), look_at: (20, 0, 20), height: 40)",
        "Sphere(eye: (20, 6, 20), look_at: (30, 0, 20), fov_x: 360, fov_y: 150, radius: 1)",
    ];
    // The default pixel LOD, pixel LOD 2 levels coarser, and a fixed stop level (exact, bias 4)
    // coarser than the cell test's default level 3: LOD hits lie in the tested columns too.
    let lods = ["", "lod_bias: 2", "lod: Exact, lod_bias: 4"];
    for (camera, lod) in cameras
        .iter()
        .flat_map(|c| lods.iter().map(move |l| (c, l)))
    {
        let s = scene(
            &dir,
            &format!(
                r#"Scene(
                    image: (width: 72, height: 48),
                    camera: {camera},
                    lights: [Sun(direction: (0.4, 1, 0.3))],
                    objects: [
                        (shape: Terrain(path: "map.npy", threshold: 0, interpolation: Bicubic, {lod})),
                        (shape: Sphere(center: (20, 2, 20), radius: 2)),
                    ],
                )"#
            ),
        );
        let mut settings = TraceSettings::for_scene(&s);
        settings.culling = false;
        let plain = render(&s, &settings, None).unwrap();
        settings.culling = true;
        let culled = render(&s, &settings, None).unwrap();
        assert!(
            plain.stats.hits > 100,
            "{camera} {lod}: {}",
            plain.stats.hits
        );
        for y in 0..s.height {
            for x in 0..s.width {
                assert_eq!(
                    plain.depth.get(x, y).to_bits(),
                    culled.depth.get(x, y).to_bits(),
                    "{camera} {lod}: ({x}, {y})"
                );
                let bits = |v: &glam::Vec3| v.to_array().map(f32::to_bits);
                assert_eq!(bits(plain.colour.get(x, y)), bits(culled.colour.get(x, y)));
                assert_eq!(
                    bits(plain.normals.get(x, y)),
                    bits(culled.normals.get(x, y))
                );
            }
        }
    }
}

/// The pixel LOD (the default) against exact on a rough map, every projector: a LOD hit is never
/// later than the exact hit and never a miss where exact hits; the LOD really stops coarser
/// somewhere (the stats say so), and exact stops at the finest level only.
#[test]
fn pixel_lod_hits_are_never_later_than_exact_hits() {
    let dir = map_dir("rough", 129, |i, j| {
        4.0 + 3.0 * ((i as f32) * 0.37).sin() * ((j as f32) * 0.23).cos() + (i * j % 7) as f32 * 0.3
    });
    let cameras = [
        "Pinhole(eye: (-20, 40, -20), look_at: (64, 0, 64), fov_y: 50)",
        "Parallel(eye: (64, 80, -40), look_at: (64, 0, 64), height: 200)",
        "Sphere(eye: (64, 12, 64), look_at: (100, 0, 64), fov_x: 360, fov_y: 150, radius: 1)",
    ];
    for camera in cameras {
        let render_with = |lod: &str| {
            let s = scene(
                &dir,
                &format!(
                    r#"Scene(
                        image: (width: 48, height: 32),
                        camera: {camera},
                        objects: [(shape: Terrain(path: "map.npy", lod: {lod}))],
                    )"#
                ),
            );
            render(&s, &TraceSettings::for_scene(&s), None).unwrap()
        };
        let (exact, pixel) = (render_with("Exact"), render_with("Pixel"));
        assert!(exact.stats.terrain_rays > 0 && exact.stats.terrain_stop_levels == 0);
        assert!(
            pixel.stats.terrain_stop_levels > 0,
            "{camera}: {:?}",
            pixel.stats
        );
        for y in 0..32 {
            for x in 0..48 {
                let (e, p) = (*exact.depth.get(x, y), *pixel.depth.get(x, y));
                assert!(p <= e, "{camera}: ({x}, {y}) pixel {p} > exact {e}");
            }
        }
    }
}
