//! Memory that grows with the input is estimated before it is allocated and refused over a
//! budget, with an error naming what, how much, the limit and the path (issue 10, A2).
//!
//! - A 32768 × 2 height map (a long thin 16-bit PNG) loads and builds its pyramid within 1 MiB —
//!   its rectangular levels hold 65 534 values, where a padded square pyramid would ask for
//!   (4¹⁶ − 1) / 3 ≈ 1.4 × 10⁹ (5.7 GB) — and renders: rays hit where brute force hits.
//! - A map whose decoded image and samples (PNG, `.npy`, EXR), or whose pyramid, exceed a small
//!   budget is refused before the allocation, with the message.
//! - A header that claims 8192 × 8192 samples (256 MiB) over a tiny file is refused by a 64 MiB
//!   budget from the header alone.
//!
//! No test here allocates more than a few MiB.

use fray_core::{Interval, MemoryBudget, PixelFootprint, Ray};
use fray_terrain::{
    Heightmap, HitKind, Placement, Pyramid, Terrain, TerrainError, TerrainOptions, TerrainStats,
};
use glam::{DVec2, DVec3};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fray-terrain-budget-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 16-bit greyscale PNG of `w × h` samples `f(i, j)`.
fn png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u16) {
    let values: Vec<u16> = (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| f(i, j))
        .collect();
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, values)
        .unwrap()
        .save(path)
        .unwrap();
}

/// The budget error of `result`, checked to name `path` (when given), `what` and the limit.
fn refused<T: std::fmt::Debug>(
    result: Result<T, TerrainError>,
    path: Option<&Path>,
    what: &str,
    limit: &str,
) -> String {
    let e = result.unwrap_err();
    let text = e.to_string();
    let TerrainError::Budget { path: p, source } = &e else {
        panic!("not a budget error: {text}");
    };
    assert_eq!(p.as_deref(), path, "{text}");
    if let Some(path) = path {
        assert!(text.starts_with(&format!("{}: ", path.display())), "{text}");
    }
    assert!(source.needed > source.limit, "{text}");
    assert!(text.contains(what), "{text}");
    assert!(
        text.contains(&format!("over the memory budget of {limit}")),
        "{text}"
    );
    text
}

/// Ridges along the map, so rays from above hit everywhere.
fn ridge(i: u32, j: u32) -> u16 {
    (1000.0 + 400.0 * (f64::from(i) * 0.01).sin() + 50.0 * f64::from(j)) as u16
}

#[test]
fn a_32768_by_2_map_builds_in_little_memory_and_renders() {
    let d = dir("thin");
    let path = d.join("thin.png");
    png(&path, 32768, 2, ridge);
    let file = std::fs::metadata(&path).unwrap().len();
    eprintln!("32768 × 2 PNG: {file} bytes");
    // 1 MiB: the file, the decoded 128 KiB and the 256 KiB of f32 samples; then the pyramid's
    // 65 534 values (256 KiB) and the per-cell bounds (128 KiB).
    let budget = MemoryBudget::new(1 << 20);
    let map = Heightmap::load_within(&path, &budget).unwrap();
    assert_eq!((map.width(), map.height()), (32768, 2));
    let placement = Placement::new(DVec3::ZERO, DVec2::new(30.0, 30.0), 1.0).unwrap();
    let terrain = Terrain::new_within(map, placement, TerrainOptions::default(), &budget).unwrap();
    let pyramid = terrain.max_pyramid();
    assert_eq!((pyramid.levels(), pyramid.values().len()), (15, 65_534));
    assert_eq!(Pyramid::len_for(32767, 1), 65_534);
    // A padded square would have needed (4¹⁶ − 1) / 3 values: over any sane budget.
    let padded = ((1u64 << 32) - 1) / 3 * 4;
    assert!(padded > 5_700_000_000);
    // It renders: rays from above and oblique ones along the map hit where brute force hits.
    let (lo, hi) = terrain.map_box();
    let mut hits = 0;
    for k in 0..64 {
        let u = lo.x + (hi.x - lo.x) * (f64::from(k) + 0.5) / 64.0;
        let target = placement.to_world(DVec3::new(u, 0.5, 0.0));
        for dir in [DVec3::new(0.0, -1.0, 0.0), DVec3::new(0.7, -0.2, 0.05)] {
            let ray = Ray::new(target + DVec3::new(0.0, 3000.0, 15.0) - dir * 2000.0, dir).unwrap();
            let range = Interval::new(0.0, f64::INFINITY);
            let got = terrain.cast(&ray, range, 1e-9);
            let want = terrain.cast_brute_force(&ray, range, 1e-9);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "ray {k}");
            hits += usize::from(got.is_some());
            // The pixel footprint's coarse levels (8 × 1 columns at level 3) hold the hit too.
            let footprint = PixelFootprint {
                size: 0.0,
                angle: 2e-3,
            };
            let mut stats = TerrainStats::default();
            let lod = terrain.cast_footprint(&ray, range, 1e-9, footprint, &mut stats);
            if let (Some(l), Some(w)) = (lod, want) {
                assert!(
                    l.t <= w.t + 1e-9,
                    "a LOD hit is never later than the exact one"
                );
            }
            assert_eq!(lod.is_some(), want.is_some());
            assert_ne!(lod.map(|h| h.kind), Some(HitKind::Start));
        }
    }
    assert!(hits >= 64, "{hits} hits");
}

#[test]
fn samples_over_the_budget_are_refused_before_decoding() {
    let d = dir("over");
    // PNG: 512 × 512 16-bit: 512 KiB decoded + 1 MiB of f32.
    let path = d.join("big.png");
    png(&path, 512, 512, |i, j| (i * 3 + j) as u16);
    let small = MemoryBudget::new(1 << 20);
    let text = refused(
        Heightmap::load_within(&path, &small),
        Some(&path),
        "decoding the 512 × 512 PNG height map",
        "1.00 MiB",
    );
    eprintln!("{text}");
    assert!(Heightmap::load_within(&path, &MemoryBudget::new(4 << 20)).is_ok());
    // The file itself over the budget: refused before reading it.
    refused(
        Heightmap::load_within(&path, &MemoryBudget::new(64)),
        Some(&path),
        &format!("the file {}", path.display()),
        "64 bytes",
    );
    // .npy: a header claiming 8192 × 8192 f32 (256 MiB) over a 128-byte file: refused by a
    // 64 MiB budget from the header alone (the default budget would find it truncated).
    let claims = d.join("claims.npy");
    std::fs::write(
        &claims,
        fray_terrain::npy::encode("<f4", 8192, 8192, &[0; 64]),
    )
    .unwrap();
    refused(
        Heightmap::load_within(&claims, &MemoryBudget::new(64 << 20)),
        Some(&claims),
        "decoding the 8192 × 8192 .npy height map",
        "64.0 MiB",
    );
    let e = Heightmap::load(&claims).unwrap_err().to_string();
    assert!(e.contains("truncated"), "{e}");
    // EXR: every channel of the layer is decoded; 256 × 256 × 3 f32 channels + the samples.
    use exr::prelude::*;
    let exr_path = d.join("rgb.exr");
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 0.0f32));
    Image::from_channels((256, 256), channels)
        .write()
        .to_file(&exr_path)
        .unwrap();
    refused(
        // (the file, 518 KiB, fits; its decoded layer does not)
        Heightmap::load_within(&exr_path, &MemoryBudget::new(640 << 10)),
        Some(&exr_path),
        "decoding the 256 × 256 OpenEXR height map (3 channels",
        "640 KiB",
    );
    assert_eq!(
        Heightmap::load_within(&exr_path, &MemoryBudget::new(2 << 20))
            .unwrap()
            .at(5, 7),
        5.0
    );
    // In memory: from_fn's samples.
    refused(
        Heightmap::from_fn_within(600, 600, &small, |i, j| (i + j) as f32),
        None,
        "the 600 × 600 height map's f32 samples",
        "1.00 MiB",
    );
}

#[test]
fn a_pyramid_over_the_budget_is_refused_with_the_message() {
    let map = Heightmap::from_fn(513, 257, |i, j| ((i * 7 + j * 3) % 11) as f32).unwrap();
    let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0).unwrap();
    // 512 × 256 cells: 131 072 bounds + 174 763 pyramid values, 4 bytes each ≈ 1.17 MiB.
    let cells = 512 * 256;
    let need = 4 * (cells + Pyramid::len_for(512, 256)) as u64;
    let text = refused(
        Terrain::new_within(
            map.clone(),
            placement,
            TerrainOptions::default(),
            &MemoryBudget::new(need - 1),
        ),
        None,
        "the terrain's max pyramid over 512 × 256 cells",
        "1.17 MiB",
    );
    eprintln!("{text}");
    assert!(
        Terrain::new_within(
            map.clone(),
            placement,
            TerrainOptions::default(),
            &MemoryBudget::new(need)
        )
        .is_ok()
    );
    // With the min pyramid: twice as much.
    let both = TerrainOptions {
        min_pyramid: true,
        ..TerrainOptions::default()
    };
    refused(
        Terrain::new_within(map, placement, both, &MemoryBudget::new(need)),
        None,
        "max and min pyramids over 512 × 256 cells",
        "1.17 MiB",
    );
}
