//! Every pixel-centre ray of a cell lies in the cell's bundle, for all projector kinds (extreme
//! fields of view included), and a box the bundle is said to miss is missed by every such ray.

use fray_core::{Aabb, Interval, Parallel, Pinhole, Projector, SphereSurface};
use fray_quadtree::{PixelCoverage, RayBundle};
use glam::DVec3;

fn projectors() -> Vec<Projector> {
    let eye = DVec3::new(0.3, 1.2, -4.0);
    let mut v = Vec::new();
    for fov in [0.01f64, 1.0, 60.0, 120.0, 170.0, 179.9] {
        v.push(Projector::Pinhole(
            Pinhole::new(eye, DVec3::ZERO, DVec3::Y, fov.to_radians(), 0.2).unwrap(),
        ));
    }
    for (h, near) in [(1e-3, 0.0), (8.0, 0.5), (1e4, 2.0)] {
        v.push(Projector::Parallel(
            Parallel::new(eye, DVec3::ZERO, DVec3::Y, h, near).unwrap(),
        ));
    }
    for (fx, fy, amp, freq, off) in [
        (360.0, 180.0, 0.0, 0.0, 0.0),
        (360.0, 180.0, 0.5, 7.0, 0.3),
        (200.0, 100.0, 0.3, 6.0, 0.45),
        (1.0, 0.5, 0.9, 40.0, 0.05),
        (90.0, 179.0, -0.4, 2.5, 0.4),
    ] {
        let centre = DVec3::new(1.0, 2.0, 3.0);
        v.push(Projector::Sphere(
            SphereSurface::new(
                centre + DVec3::new(off, -0.5 * off, 0.2 * off),
                centre,
                DVec3::ZERO,
                DVec3::Y,
                f64::to_radians(fx),
                f64::to_radians(fy),
                1.9,
                amp,
                freq,
            )
            .unwrap(),
        ));
    }
    v
}

/// Cells of several sizes and positions, edges included.
fn cells(w: u32, h: u32) -> Vec<(u32, u32, u32, u32)> {
    let mut v = vec![(0, 0, w, h), (0, 0, 1, 1), (w - 1, h - 1, w, h)];
    for size in [2, 5, 16, 33] {
        for (x, y) in [(0, 0), (w / 3, h / 2), (w - size.min(w), h - size.min(h))] {
            v.push((x, y, (x + size).min(w), (y + size).min(h)));
        }
    }
    v
}

#[test]
fn every_pixel_centre_ray_is_inside_its_cells_bundle() {
    let (w, h) = (97, 61);
    for p in projectors() {
        for cell in cells(w, h) {
            let b = RayBundle::of_cell(&p, (w, h), cell);
            for y in cell.1..cell.3 {
                for x in cell.0..cell.2 {
                    let r = p.pixel_ray(x, y, w, h).unwrap();
                    assert!(
                        b.contains(&r.ray),
                        "{p:?} cell {cell:?} pixel ({x}, {y}): {b:?}"
                    );
                }
            }
        }
    }
}

/// With [`PixelCoverage::Area`] the bundle holds the rays through every point of the cell's
/// pixels — their corners and random points, where anti-aliasing samples go — not only the
/// centres.
#[test]
fn every_ray_through_a_cells_pixels_is_inside_its_area_bundle() {
    let (w, h) = (97, 61);
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for p in projectors() {
        for cell in cells(w, h) {
            let b = RayBundle::covering(&p, (w, h), cell, PixelCoverage::Area);
            let (x0, y0, x1, y1) = (
                f64::from(cell.0),
                f64::from(cell.1),
                f64::from(cell.2),
                f64::from(cell.3),
            );
            let mut points = vec![(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
            for _ in 0..64 {
                points.push((x0 + (x1 - x0) * next(), y0 + (y1 - y0) * next()));
            }
            for (x, y) in points {
                let Some(r) = p.ray(x, y, w, h) else {
                    continue;
                };
                assert!(
                    b.contains(&r.ray),
                    "{p:?} cell {cell:?} point ({x}, {y}): {b:?}"
                );
            }
        }
    }
}

#[test]
fn boxes_the_bundle_misses_are_missed_by_every_pixel_ray() {
    let (w, h) = (64, 48);
    let mut seed = 7u64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut culled = 0;
    for p in projectors() {
        for cell in cells(w, h) {
            let b = RayBundle::of_cell(&p, (w, h), cell);
            for _ in 0..20 {
                let c = DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 20.0;
                let half = DVec3::new(rnd(), rnd(), rnd()) * 2.0;
                let bx = Aabb::from_center_half(c, half);
                if b.box_range(&bx).is_some() {
                    continue;
                }
                culled += 1;
                for y in cell.1..cell.3 {
                    for x in cell.0..cell.2 {
                        let r = p.pixel_ray(x, y, w, h).unwrap();
                        let hit = bx.clip_ray(&r.ray, Interval::new(0.0, f64::INFINITY));
                        assert!(hit.is_none(), "{p:?} {cell:?} ({x}, {y}) {bx:?}");
                    }
                }
            }
        }
    }
    assert!(culled > 100, "the test should cull something: {culled}");
}

#[test]
fn depth_ranges_hold_the_box_entries() {
    let p = projectors()[2];
    let (w, h) = (64, 48);
    let bx = Aabb::new(DVec3::splat(-0.5), DVec3::splat(0.5));
    let cell = (24, 16, 40, 32);
    let b = RayBundle::of_cell(&p, (w, h), cell);
    let range = b.box_range(&bx).unwrap();
    for y in cell.1..cell.3 {
        for x in cell.0..cell.2 {
            let r = p.pixel_ray(x, y, w, h).unwrap();
            if let Some(t) = bx.clip_ray(&r.ray, Interval::new(0.0, f64::INFINITY)) {
                assert!(range.lo <= t.lo && t.hi <= range.hi);
            }
        }
    }
}

/// Sphere-surface cells carry side planes (two wedges over the cell's picture points), and they
/// cull boxes the direction cone alone keeps — soundly, by the test above.
#[test]
fn sphere_surface_side_planes_cull_more_than_the_cone() {
    let (w, h) = (64, 48);
    let (mut with_planes, mut cone_only, mut cells_with_planes) = (0, 0, 0);
    for p in projectors() {
        if !matches!(p, Projector::Sphere(_)) {
            continue;
        }
        for cell in cells(w, h) {
            let b = RayBundle::of_cell(&p, (w, h), cell);
            if b.planes.iter().any(|(n, _)| *n != DVec3::ZERO) {
                cells_with_planes += 1;
            }
            let cone = RayBundle {
                planes: [(DVec3::ZERO, DVec3::ZERO); 4],
                ..b
            };
            for i in 0..400 {
                let t = f64::from(i);
                let c = DVec3::new((t * 0.37).sin(), (t * 0.73).cos(), (t * 1.3).sin()) * 8.0;
                let half = DVec3::new(0.05 + 0.4 * (t * 0.5).cos().abs(), 0.05, 1.5);
                let bx = Aabb::from_center_half(c + DVec3::new(1.0, 2.0, 3.0), half);
                with_planes += usize::from(b.box_range(&bx).is_none());
                cone_only += usize::from(cone.box_range(&bx).is_none());
            }
        }
    }
    assert!(cells_with_planes > 20, "{cells_with_planes}");
    assert!(
        with_planes > cone_only + cone_only / 10,
        "planes cull {with_planes}, the cone alone {cone_only}"
    );
    eprintln!("sphere cells: planes cull {with_planes} boxes, the cone alone {cone_only}");
}
