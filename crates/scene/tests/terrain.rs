//! Terrain objects in scene files: the DEM scenes resolve with the terrain built once (shared by
//! `Arc`), the feature set lists `terrain`, and every bad value or asset is a located error
//! naming the field (and, for a bad file, its path and the reason).

use std::path::Path;

fn scenes() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes")
}

#[test]
fn the_dem_scenes_resolve_with_their_terrain() {
    for name in ["terrain_low.ron", "terrain_high.ron"] {
        let s = fray_scene::load(&scenes().join(name)).unwrap();
        assert_eq!(s.terrains.len(), 1, "{name}");
        assert!(s.features.terrain && s.features.names().contains(&"terrain"));
        let t = &s.terrains[0];
        assert_eq!(
            (t.terrain.map().width(), t.terrain.map().height()),
            (403, 344)
        );
        assert_eq!(s.materials[t.material as usize].name, "land");
        // The level of detail a terrain user expects: the pixel footprint (the default).
        assert_eq!(t.lod, fray_scene::TerrainLod::Pixel, "{name}");
        // The scene box holds the terrain: 402 × 74 m by 343 × 93 m.
        let b = s.bounds();
        assert!(
            b.max.x >= 402.0 * 74.0 - 1e-6 && b.max.z >= 343.0 * 93.0 - 1e-6,
            "{b:?}"
        );
    }
    let low = fray_scene::load(&scenes().join("terrain_low.ron")).unwrap();
    assert!(low.features.free_forms && low.objects.len() == 1);
}

fn error(src: &str) -> String {
    // Relative paths resolve against the (virtual) scene file's folder.
    let file = scenes().join("inline.ron");
    fray_scene::parse(src, &file.display().to_string())
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_terrain_values_and_assets_are_located_errors() {
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", spacing: (0, 1))),\n])",
    );
    assert!(
        e.contains(":2:") && e.contains("objects[0].shape.spacing[0]: must be > 0, got 0"),
        "{e}"
    );
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", vertical_scale: -2)),\n])",
    );
    assert!(
        e.contains("objects[0].shape.vertical_scale: must be > 0"),
        "{e}"
    );
    let e = error("(objects: [\n (shape: Terrain(path: \"nowhere.png\")),\n])");
    assert!(
        e.contains(":2:")
            && e.contains("objects[0].shape.path:")
            && e.contains("nowhere.png")
            && e.contains("cannot read"),
        "{e}"
    );
    let e = error("(objects: [\n (shape: Terrain(path: \"csg.ron\")),\n])");
    assert!(
        e.contains("objects[0].shape.path:") && e.contains("unsupported height-map format"),
        "{e}"
    );
    let e = error("(objects: [\n (shape: Terrain(path: \"../terrain/README.md.png\")),\n])");
    assert!(e.contains("objects[0].shape.path:"), "{e}");
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", threshold: 5000)),\n])",
    );
    assert!(
        e.contains("objects[0].shape.threshold:") && e.contains("no cell"),
        "{e}"
    );
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", lod_bias: 99)),\n])",
    );
    assert!(
        e.contains("objects[0].shape.lod_bias: must be in 0..=16, got 99"),
        "{e}"
    );
    let e =
        error("(objects: [\n (shape: Union([Sphere(radius: 1), Terrain(path: \"x.png\")])),\n])");
    assert!(
        e.contains("objects[0].shape[1]: a Terrain can only be an object's whole shape"),
        "{e}"
    );
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", interpolation: Cubic)),\n])",
    );
    assert!(
        e.contains("objects[0].shape.interpolation: unknown variant `Cubic`"),
        "{e}"
    );
    let e = error(
        "(objects: [\n (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\", lod: Fast)),\n])",
    );
    assert!(
        e.contains(":2:") && e.contains("objects[0].shape.lod: unknown variant `Fast`"),
        "{e}"
    );
    let e = error(
        "(objects: [\n (material: \"rock\", shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\")),\n])",
    );
    assert!(
        e.contains("objects[0].material: unknown material `rock`"),
        "{e}"
    );
}

/// The 32768 × 2 height map of issue 10 (here a `.npy`, 128 KiB) resolves in a scene with a
/// small pyramid (rectangular levels: 65 534 values, not a padded square's 1.4 × 10⁹) and the
/// scene's work list culls with it.
#[test]
fn a_long_thin_map_resolves_with_a_small_pyramid() {
    let dir = std::env::temp_dir().join(format!("fray-scene-thin-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (w, h) = (32768usize, 2usize);
    let samples: Vec<u8> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            let v = 1000.0 + 400.0 * (i as f64 * 0.01).sin() + 50.0 * j as f64;
            (v as u16).to_le_bytes()
        })
        .collect();
    let bytes = fray_terrain::npy::encode("<u2", h, w, &samples);
    std::fs::write(dir.join("thin.npy"), &bytes).unwrap();
    let src = "Scene(image: (width: 64, height: 36), \
        camera: Pinhole(eye: (490000, 3000, 400), look_at: (480000, 1000, 15)), \
        objects: [(shape: Terrain(path: \"thin.npy\", spacing: (30, 30)))])";
    let file = dir.join("thin.ron");
    let s = fray_scene::parse(src, &file.display().to_string()).unwrap();
    let t = &s.terrains[0].terrain;
    assert_eq!((t.map().width(), t.map().height()), (32768, 2));
    assert_eq!(t.max_pyramid().levels(), 15);
    assert_eq!(t.max_pyramid().values().len(), 65_534);
    let list = fray_scene::work_list(&s, 8).unwrap();
    assert!(!list.items.is_empty());
}
