//! Terrains whose heights change with time, on the CPU: the frame of `Scene::at_time(t)` (the
//! file's terrain with its heights moved and its pyramid updated only where they moved) is bit
//! for bit the frame of a still scene whose terrain is a map file holding the same heights (its
//! pyramid built from scratch) — colour, depth and normals, at several times, for a lake of
//! waves on the DEM (bicubic, pixel LOD, a region) and waves over a whole bilinear map.

use fray_trace::{TraceSettings, render};
use std::path::{Path, PathBuf};

fn dem() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/terrain/jacksboro_fault_dem.png")
        .canonicalize()
        .unwrap()
}

fn scene_with(dir: &Path, camera: &str, terrain: &str) -> fray_scene::Scene {
    let src = format!(
        r#"Scene(
            image: (width: 64, height: 48),
            camera: {camera},
            ambient: (0.1, 0.1, 0.12),
            lights: [Sun(direction: (-0.7, 0.35, 0.6), irradiance: (3, 3, 3))],
            materials: {{ "land": (diffuse: (0.4, 0.4, 0.3), specular: (0.2, 0.2, 0.2), shininess: 30) }},
            objects: [(name: "lake", material: "land", shape: {terrain})],
        )"#
    );
    let file = dir.join("scene.ron");
    fray_scene::parse(&src, &file.display().to_string()).unwrap_or_else(|e| panic!("{e}"))
}

/// Pixels that differ.
fn differ<T: PartialEq>(a: &[T], b: &[T]) -> usize {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

#[test]
fn an_animated_terrain_renders_as_a_still_terrain_of_the_same_heights() {
    let dir = std::env::temp_dir().join(format!("fray-trace-heights-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dem = dem();
    let cases = [
        (
            "lake",
            // Straight down over the lake's region.
            "Parallel(eye: (10360, 5000, 12555), look_at: (10360, 0, 12555), up: (0, 0, 1), \
             height: 14000)",
            "Bicubic",
            "Pixel",
            "level: Some(450), region: Some((40, 60, 200, 150)), waves: [(amplitude: 6, \
             wavelength: 900, direction: (1, 0.5), speed: 40), (amplitude: 2, wavelength: 300, \
             speed: -15)]",
        ),
        (
            "swell",
            "Pinhole(eye: (10000, 2500, 25000), look_at: (10000, 350, 12000), fov_y: 50)",
            "Bilinear",
            "Exact",
            "waves: [(amplitude: 40, wavelength: 3000, direction: (0.2, 1), speed: 300)]",
        ),
    ];
    for (name, camera, interpolation, lod, waves) in cases {
        let placed = format!("spacing: (74, 93), interpolation: {interpolation}, lod: {lod}");
        let animated = scene_with(
            &dir,
            camera,
            &format!(
                "Terrain(path: {:?}, {placed}, animate: Some(Waves({waves})))",
                dem.display()
            ),
        );
        let base = render(
            &animated.at_time(0.0).unwrap(),
            &TraceSettings::for_scene(&animated),
            None,
        )
        .unwrap();
        for t in [0.0, 2.5, 11.0] {
            let still = animated.at_time(t).unwrap();
            let map = still.terrains[0].terrain.map();
            let samples: Vec<u8> = map.samples().iter().flat_map(|s| s.to_le_bytes()).collect();
            let file = dir.join(format!("{name}_{t}.npy"));
            let npy = fray_terrain::npy::encode("<f4", map.height(), map.width(), &samples);
            std::fs::write(&file, npy).unwrap();
            let reference = scene_with(
                &dir,
                camera,
                &format!("Terrain(path: {:?}, {placed})", file.display()),
            );
            let settings = TraceSettings::for_scene(&still);
            let a = render(&still, &settings, None).unwrap();
            let b = render(&reference, &settings, None).unwrap();
            let depth = |f: &fray_core::Frame| -> Vec<u64> {
                f.depth.pixels().iter().map(|d| d.to_bits()).collect()
            };
            assert_eq!(differ(&depth(&a), &depth(&b)), 0, "{name} at {t} s: depth");
            assert_eq!(
                differ(a.colour.pixels(), b.colour.pixels()),
                0,
                "{name} at {t} s: colour"
            );
            assert_eq!(
                differ(a.normals.pixels(), b.normals.pixels()),
                0,
                "{name} at {t} s: normals"
            );
            let hits = a.depth.pixels().iter().filter(|d| d.is_finite()).count();
            assert!(
                hits > 64 * 48 / 2,
                "{name}: the terrain fills the view ({hits})"
            );
            if t > 0.0 {
                let moved = differ(&depth(&a), &depth(&base));
                eprintln!("{name} at {t} s: {moved} pixels moved");
                assert!(moved > 50, "{name} at {t} s: only {moved} pixels moved");
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
