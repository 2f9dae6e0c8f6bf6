//! Threshold outlines: a cell is solid only when all four of its corner samples are at or above
//! the threshold. A ring-shaped mask (an annulus: a hole in the middle, nothing outside) gives a
//! multiply connected outline; rays through the hole and outside the ring pass, rays onto the
//! ring hit it, rays into the hole's side hit the inner wall.

use fray_core::{Interval, Ray};
use fray_terrain::{Heightmap, HitKind, Placement, Terrain, TerrainError, TerrainOptions};
use glam::{DVec2, DVec3};

/// 41 × 41 samples, 1 m apart: height 5 on the ring 8 ≤ r ≤ 16 around (20, 20), −1 elsewhere;
/// threshold 0.
fn ring() -> Terrain {
    let map = Heightmap::from_fn(41, 41, |i, j| {
        let r = ((i as f32 - 20.0).powi(2) + (j as f32 - 20.0).powi(2)).sqrt();
        if (8.0..=16.0).contains(&r) { 5.0 } else { -1.0 }
    })
    .unwrap()
    .with_threshold(0.0)
    .unwrap();
    let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0).unwrap();
    Terrain::new(map, placement, TerrainOptions::default()).unwrap()
}

fn down(x: f64, z: f64) -> Ray {
    Ray::new(DVec3::new(x, 50.0, z), -DVec3::Y).unwrap()
}

#[test]
fn a_ring_mask_has_a_hole_and_an_outside() {
    let t = ring();
    let all = Interval::new(0.0, f64::INFINITY);
    // Centre of the hole, and outside the ring: nothing.
    assert!(t.cast(&down(20.3, 20.1), all, 1e-9).is_none());
    assert!(t.cast(&down(1.5, 1.5), all, 1e-9).is_none());
    // On the ring: the flat top at height 5.
    let h = t.cast(&down(32.5, 20.5), all, 1e-9).unwrap();
    assert!(
        (h.t - 45.0).abs() < 1e-12 && h.kind == HitKind::Surface,
        "{h:?}"
    );
    // Horizontally from the hole's centre towards +x at height 2: the inner wall of the ring,
    // at the first solid cell column (x = 12 .. 13 has all corners on the ring at z ≈ 20).
    let ray = Ray::new(DVec3::new(20.2, 2.0, 20.5), DVec3::X).unwrap();
    let h = t.cast(&ray, all, 1e-9).unwrap();
    assert_eq!(h.kind, HitKind::Wall);
    assert!((h.normal - -DVec3::X).length() < 1e-12, "{h:?}");
    let x = ray.at(h.t).x;
    assert!(
        (x - x.round()).abs() < 1e-12 && (27.0..=29.0).contains(&x),
        "{x}"
    );
}

#[test]
fn every_pixel_of_a_top_view_agrees_with_the_mask_rule() {
    let t = ring();
    let all = Interval::new(0.0, f64::INFINITY);
    let map = t.map();
    let mut solid = 0;
    for j in 0..40 {
        for i in 0..40 {
            let hit = t.cast(&down(i as f64 + 0.5, j as f64 + 0.5), all, 1e-9);
            let all_four = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                .iter()
                .all(|&(a, b)| map.at(a, b) >= 0.0);
            assert_eq!(hit.is_some(), all_four, "cell ({i}, {j})");
            solid += usize::from(all_four);
        }
    }
    // The ring's cells, and the hole and outside are both non-empty.
    assert!(solid > 400 && solid < 1200, "{solid}");
}

#[test]
fn a_threshold_above_everything_is_an_error_not_an_empty_terrain() {
    let map = Heightmap::from_fn(4, 4, |i, _| i as f32)
        .unwrap()
        .with_threshold(10.0)
        .unwrap();
    let placement = Placement::new(DVec3::ZERO, DVec2::ONE, 1.0).unwrap();
    let err = Terrain::new(map, placement, TerrainOptions::default()).unwrap_err();
    assert!(matches!(err, TerrainError::NoSurface { .. }), "{err}");
}
