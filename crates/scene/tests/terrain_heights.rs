//! Terrains whose heights change with time (`animate: Some(Waves(...))`): `Scene::at_time`
//! gives each such terrain the base map's heights at `t` (the waves' own arithmetic,
//! `fray_terrain::Waves::heights_at`) with pyramids equal bit for bit to a terrain built from
//! those heights, leaves the file's scene alone, holds the copy on the scene's budget only as
//! long as the still lives, and every bad value is a located error.

use fray_scene::{SceneError, parse};
use fray_terrain::{Heightmap, Terrain, Wave, Waves};
use glam::DVec2;
use std::path::{Path, PathBuf};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes")
}

fn scene(objects: &str) -> Result<fray_scene::Scene, SceneError> {
    let file = scenes().join("inline.ron");
    parse(
        &format!(
            "Scene(image: (width: 32, height: 24),\n camera: Pinhole(eye: (15000, 2000, 30000), look_at: (15000, 300, 15000)),\n objects: [\n{objects}\n ],\n)"
        ),
        &file.display().to_string(),
    )
}

const LAKE: &str = r#"  (name: "lake", shape: Terrain(path: "../terrain/jacksboro_fault_dem.png", spacing: (74, 93),
    interpolation: Bicubic,
    animate: Some(Waves(level: Some(450), region: Some((40, 60, 200, 150)),
      waves: [(amplitude: 2.5, wavelength: 700, direction: (1, 0.5), speed: 30),
              (amplitude: 1, wavelength: 230, speed: -12)])))),"#;

fn bits(t: &Terrain) -> Vec<u32> {
    t.max_pyramid()
        .values()
        .iter()
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn a_lake_of_waves_moves_its_region_and_its_pyramid_is_a_rebuilt_one() {
    let s = scene(LAKE).unwrap();
    let base = s.terrains[0].terrain.clone();
    assert!(s.terrains[0].heights.is_some());
    let waves = Waves {
        waves: vec![
            Wave {
                amplitude: 2.5,
                wavelength: 700.0,
                direction: DVec2::new(1.0, 0.5).normalize(),
                speed: 30.0,
            },
            Wave {
                amplitude: 1.0,
                wavelength: 230.0,
                direction: DVec2::X,
                speed: -12.0,
            },
        ],
        level: Some(450.0),
        region: Some(fray_terrain::Region::new(40, 60, 240, 210)),
    };
    let charged = s.budget.charged();
    let mut previous: Option<Heightmap> = None;
    for t in [0.0, 1.5, 7.25] {
        let still = s.at_time(t).unwrap();
        let o = &still.terrains[0];
        assert!(o.heights.is_none(), "a still");
        assert!(s.budget.charged() >= charged + base.heap_bytes());
        let expect = waves.heights_at(base.map(), base.placement(), t).unwrap();
        assert_eq!(o.terrain.map(), &expect, "t = {t}");
        let rebuilt = Terrain::new(expect.clone(), *base.placement(), *base.options()).unwrap();
        assert_eq!(bits(&o.terrain), bits(&rebuilt), "t = {t}");
        assert_eq!(o.terrain.height_range(), rebuilt.height_range());
        // Only the region moved, and it moved between times; some of it stays dry land.
        let (w, h) = (base.map().width(), base.map().height());
        let mut moved = 0;
        for j in 0..h {
            for i in 0..w {
                let inside = (40..240).contains(&i) && (60..210).contains(&j);
                let (a, b) = (base.map().at(i, j), o.terrain.map().at(i, j));
                assert!(inside || a == b, "({i}, {j}) outside the region moved");
                moved += usize::from(a != b);
            }
        }
        assert!(
            moved > 1000 && moved < 200 * 150,
            "{moved} samples under water"
        );
        if let Some(p) = &previous {
            assert_ne!(p, o.terrain.map());
        }
        previous = Some(o.terrain.map().clone());
        drop(still);
        assert_eq!(
            s.budget.charged(),
            charged,
            "the still's copy is released with it"
        );
    }
    // The file's terrain is untouched; frames without an `animation:` block are time 0.
    assert!(std::sync::Arc::ptr_eq(&s.terrains[0].terrain, &base));
    assert_eq!(
        s.at_frame(5).unwrap().terrains[0].terrain.map(),
        s.at_time(0.0).unwrap().terrains[0].terrain.map()
    );
}

#[test]
fn a_terrain_without_animate_is_todays() {
    let plain = scene(
        r#"  (shape: Terrain(path: "../terrain/jacksboro_fault_dem.png", spacing: (74, 93))),"#,
    )
    .unwrap();
    let still = plain.at_time(3.0).unwrap();
    assert!(std::sync::Arc::ptr_eq(
        &plain.terrains[0].terrain,
        &still.terrains[0].terrain
    ));
    assert!(still.terrains[0].frame_memory.is_none());
}

#[track_caller]
fn located(animate: &str, field: &str, message: &str) {
    let src = format!(
        "  (shape: Terrain(path: \"../terrain/jacksboro_fault_dem.png\",\n    animate: Some({animate}))),"
    );
    match scene(&src) {
        Err(e @ SceneError::Invalid { .. }) => {
            let text = e.to_string();
            assert!(
                e.line() == Some(5) && e.field() == Some(field) && text.contains(message),
                "{text} (line {:?}, field {:?})",
                e.line(),
                e.field()
            );
        }
        other => panic!("expected a located error at {field}, got {other:?}"),
    }
}

#[test]
fn bad_waves_are_located_errors() {
    let wave = "amplitude: 1, wavelength: 100, speed: 1";
    located(
        &format!("Waves(waves: [({wave}), (amplitude: 1, wavelength: 0, speed: 1)])"),
        "objects[0].shape.animate.waves[1].wavelength",
        "must be > 0, got 0",
    );
    located(
        "Waves(waves: [(amplitude: 1, wavelength: 5, direction: (0, 0), speed: 1)])",
        "objects[0].shape.animate.waves[0].direction",
        "not zero",
    );
    located(
        "Waves(waves: [])",
        "objects[0].shape.animate.waves",
        "give 1 to 16 waves, got 0",
    );
    located(
        &format!("Waves(waves: [({wave})], region: Some((400, 0, 10, 10)))"),
        "objects[0].shape.animate.region",
        "inside the 403 × 344 map",
    );
    located(
        &format!("Waves(waves: [({wave})], region: Some((0, 0, 0, 10)))"),
        "objects[0].shape.animate.region",
        "at least one sample",
    );
    located(
        "Waves(waves: [(amplitude: 1e300, wavelength: 5, speed: 1)])",
        "objects[0].shape.animate.waves",
        "do not fit",
    );
    located(
        &format!("Waves(waves: [({wave})], level: Some(inf))"),
        "objects[0].shape.animate.level",
        "finite",
    );
    // A wave too short for f64 (its phase overflows) fails at the time asked, never panics.
    let s = scene(
        r#"  (shape: Terrain(path: "../terrain/jacksboro_fault_dem.png",
    animate: Some(Waves(waves: [(amplitude: 1, wavelength: 1e-308, speed: 1)])))),"#,
    )
    .unwrap();
    let e = s.at_time(1.0).unwrap_err().to_string();
    assert!(e.contains("at time 1 s") && e.contains("not finite"), "{e}");
}

/// Writes `<name>.npy`, `w × h` `<f4` samples from `f(column, row)`, into `dir`.
fn npy(dir: &Path, name: &str, w: usize, h: usize, f: impl Fn(usize, usize) -> f32) {
    let bytes: Vec<u8> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .flat_map(|(i, j)| f(i, j).to_le_bytes())
        .collect();
    std::fs::write(
        dir.join(format!("{name}.npy")),
        fray_terrain::npy::encode("<f4", h, w, &bytes),
    )
    .unwrap();
}

#[test]
fn a_sequence_of_maps_shows_one_a_frame_updated_where_it_differs() {
    let dir = std::env::temp_dir().join(format!("fray-scene-sequence-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ground = |i: usize, j: usize| (i * 3 + j * 5 % 7) as f32;
    npy(&dir, "base", 20, 14, ground);
    // Frame 0 raises a 3 × 2 patch, frame 1 another, frame 2 is the base again.
    npy(&dir, "f0", 20, 14, |i, j| {
        ground(i, j)
            + if (4..7).contains(&i) && (2..4).contains(&j) {
                9.0
            } else {
                0.0
            }
    });
    npy(&dir, "f1", 20, 14, |i, j| {
        ground(i, j)
            + if (15..20).contains(&i) && (10..14).contains(&j) {
                -4.0
            } else {
                0.0
            }
    });
    npy(&dir, "f2", 20, 14, ground);
    npy(&dir, "small", 19, 14, ground);
    let src = |animate: &str| {
        format!(
            "Scene(objects: [\n (name: \"seq\", shape: Terrain(path: \"base.npy\", interpolation: Bicubic,\n   animate: Some({animate}))),\n])"
        )
    };
    let file = dir.join("seq.ron").display().to_string();
    let s = parse(
        &src("Sequence(paths: [\"f0.npy\", \"f1.npy\", \"f2.npy\"], fps: 4)"),
        &file,
    )
    .unwrap();
    let base = s.terrains[0].terrain.clone();
    let load = |name: &str| Heightmap::load(&dir.join(format!("{name}.npy"))).unwrap();
    for (t, frame) in [
        (-1.0, "f0"),
        (0.0, "f0"),
        (0.3, "f1"),
        (0.5, "f2"),
        (9.0, "f2"),
    ] {
        let still = s.at_time(t).unwrap();
        let terrain = &still.terrains[0].terrain;
        let expect = load(frame);
        assert_eq!(terrain.map(), &expect, "t = {t}");
        let rebuilt = Terrain::new(expect, *base.placement(), *base.options()).unwrap();
        assert_eq!(bits(terrain), bits(&rebuilt), "t = {t}");
        assert_eq!(terrain.height_range(), rebuilt.height_range(), "t = {t}");
    }
    match s.terrains[0].heights.as_deref() {
        Some(fray_scene::Heights::Sequence(q)) => {
            let regions: Vec<_> = q.frames.iter().map(|f| f.1).collect();
            assert_eq!(
                regions,
                [
                    fray_terrain::Region::new(4, 2, 7, 4),
                    fray_terrain::Region::new(15, 10, 20, 14),
                    fray_terrain::Region::default(),
                ]
            );
        }
        other => panic!("{other:?}"),
    }
    let located = |animate: &str, field: &str, message: &str| match parse(&src(animate), &file) {
        Err(e @ SceneError::Invalid { .. }) => {
            let text = e.to_string();
            assert!(
                e.line() == Some(3) && e.field() == Some(field) && text.contains(message),
                "{text}"
            );
        }
        other => panic!("expected an error at {field}, got {other:?}"),
    };
    located(
        "Sequence(paths: [\"f0.npy\", \"small.npy\"], fps: 4)",
        "objects[0].shape.animate.paths[1]",
        "a 19 × 14 map, the terrain's is 20 × 14",
    );
    located(
        "Sequence(paths: [\"f0.npy\", \"nowhere.npy\"], fps: 4)",
        "objects[0].shape.animate.paths[1]",
        "cannot read",
    );
    located(
        "Sequence(paths: [\"f0.npy\"], fps: 0)",
        "objects[0].shape.animate.fps",
        "must be > 0",
    );
    located(
        "Sequence(paths: [], fps: 3)",
        "objects[0].shape.animate.paths",
        "at least one",
    );
    std::fs::remove_dir_all(&dir).ok();
}
