//! Exactness of the pyramid search with LOD bias 0 and bilinear patches against the exact
//! ray/bilinear-patch intersection by brute force over every cell (f64): ≥ 10⁵ random rays —
//! general, grazing (1e-6 … 1e-2 rad off horizontal), along cell edges and axes, vertical,
//! starting inside the box — must agree to ≤ 1e-6 of the cell size; and the per-cell quadratic
//! solve itself is checked against an independent dense-sampling + bisection root.

mod common;

use common::{Rng, rough_map};
use fray_core::{Interval, Ray};
use fray_terrain::{BicubicCell, HitKind, Interpolation, Placement, Terrain, TerrainOptions};
use glam::{DMat3, DVec2, DVec3};

const CELL_BOUND: f64 = 1e-6;

fn terrain(origin: DVec3, interpolation: Interpolation) -> Terrain {
    let placement = Placement::new(origin, DVec2::new(1.3, 0.7), 0.5)
        .unwrap()
        .with_rotation(DMat3::from_rotation_y(0.4))
        .unwrap();
    let options = TerrainOptions {
        interpolation,
        ..TerrainOptions::default()
    };
    Terrain::new(rough_map(33, 29, 7), placement, options).unwrap()
}

/// A ray of one of the hard families, aimed at the terrain.
fn random_ray(t: &Terrain, rng: &mut Rng, kind: usize) -> Ray {
    let (lo, hi) = t.map_box();
    let p = t.placement();
    let target = DVec3::new(
        rng.range(lo.x, hi.x),
        rng.range(lo.y, hi.y),
        rng.range(lo.z, hi.z),
    );
    let world_target = p.to_world(target);
    let dir = match kind {
        // General directions from anywhere around.
        0 => {
            let d = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 0.3),
                rng.range(-1.0, 1.0),
            );
            if d.length() < 1e-3 { -DVec3::Y } else { d }
        }
        // Grazing: 1e-6 … 1e-2 rad off the horizontal.
        1 => {
            let a = rng.range(0.0, std::f64::consts::TAU);
            let e = 10f64.powf(rng.range(-6.0, -2.0)) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
            DVec3::new(a.cos(), e, a.sin())
        }
        // Along a cell edge: u or v an exact integer, moving along the other axis (in the map's
        // own frame), tilted down a little.
        2 => {
            let along_u = rng.unit() < 0.5;
            let edge = rng.below(29) as f64;
            let mut m = target;
            if along_u {
                m.y = edge.min(hi.y);
            } else {
                m.x = edge.min(hi.x);
            }
            let local = if along_u { DVec3::X } else { DVec3::Z };
            let d = p.rotation() * (local * rng.range(-1.0, 1.0).signum())
                - DVec3::Y * rng.range(0.0, 0.5);
            let start = p.to_world(m) - d * 40.0;
            return Ray::new(start, d).unwrap();
        }
        // Vertical, down or up.
        3 => {
            if rng.unit() < 0.8 {
                -DVec3::Y
            } else {
                DVec3::Y
            }
        }
        // Starting inside the box.
        _ => {
            let d = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            return Ray::new(world_target, d).unwrap();
        }
    };
    let dir = dir.normalize();
    Ray::new(world_target - dir * rng.range(5.0, 60.0), dir).unwrap()
}

fn check(origin: DVec3, n: usize, seed: u64) -> (f64, usize) {
    let t = terrain(origin, Interpolation::Bilinear);
    let cell = t.placement().spacing().min_element();
    let mut rng = Rng(seed);
    let (mut worst, mut hits) = (0.0f64, 0usize);
    for k in 0..n {
        let ray = random_ray(&t, &mut rng, k % 5);
        let range = Interval::new(0.0, f64::INFINITY);
        let got = t.cast(&ray, range, 1e-9);
        let want = t.cast_brute_force(&ray, range, 1e-9);
        match (got, want) {
            (Some(g), Some(w)) => {
                hits += 1;
                let err = (g.t - w.t).abs() / cell;
                assert!(
                    err <= CELL_BOUND,
                    "ray {k} {ray:?}: t {} vs {} ({err} cells)",
                    g.t,
                    w.t
                );
                assert!(g.t >= 0.0 && g.normal.is_finite(), "ray {k}: {g:?}");
                worst = worst.max(err);
            }
            (None, None) => {}
            (g, w) => panic!("ray {k} {ray:?}: pyramid {g:?}, brute force {w:?}"),
        }
    }
    (worst, hits)
}

#[test]
fn pyramid_hit_equals_the_exact_patch_hit_on_100k_rays_to_1e_6_cells() {
    let (worst, hits) = check(DVec3::new(3.0, -2.0, 1.0), 100_000, 1);
    println!("100000 rays, {hits} hits: max |Δt| = {worst:e} cells");
    assert!(hits > 30_000, "too few hits to mean anything: {hits}");
}

#[test]
fn far_from_the_origin_the_hit_is_still_exact_to_1e_6_cells() {
    let (worst, hits) = check(DVec3::new(3.0e6, 120.0, -2.5e6), 20_000, 2);
    println!("20000 rays 4e6 m from the origin, {hits} hits: max |Δt| = {worst:e} cells");
    assert!(hits > 5_000);
}

/// The first `t` where the ray is at or below the bilinear surface, by dense sampling and
/// bisection on the sampled bracket — independent of the quadratic solve.
fn bisect_reference(t: &Terrain, ray: &Ray, t_end: f64) -> Option<f64> {
    let m = t.placement().map_ray(ray);
    let (lo, hi) = t.map_box();
    let f = |s: f64| {
        let p = m.at(s);
        if p.x < lo.x || p.y < lo.y || p.x > hi.x || p.y > hi.y || p.z < lo.z || p.z > hi.z {
            return None;
        }
        t.surface(p.x, p.y).map(|h| p.z - h)
    };
    let steps = 20_000;
    let mut prev: Option<(f64, f64)> = None;
    for k in 0..=steps {
        let s = t_end * k as f64 / steps as f64;
        match f(s) {
            Some(v) if v <= 0.0 => {
                let (mut a, mut b) = match prev {
                    Some((sp, _)) => (sp, s),
                    None => return Some(s),
                };
                for _ in 0..200 {
                    let mid = 0.5 * (a + b);
                    if f(mid).is_some_and(|v| v <= 0.0) {
                        b = mid
                    } else {
                        a = mid
                    }
                }
                return Some(b);
            }
            Some(v) => prev = Some((s, v)),
            None => prev = None,
        }
    }
    None
}

#[test]
fn quadratic_patch_solve_matches_independent_bisection_to_1e_9_cells() {
    let t = terrain(DVec3::ZERO, Interpolation::Bilinear);
    let mut rng = Rng(3);
    let cell = t.placement().spacing().min_element();
    let mut compared = 0;
    for k in 0..2_000 {
        let ray = random_ray(&t, &mut rng, k % 2);
        let Some(hit) = t.cast(&ray, Interval::new(0.0, f64::INFINITY), 1e-9) else {
            continue;
        };
        if hit.kind != HitKind::Surface {
            continue;
        }
        // Bisection on a dense grid up to a bit past the hit: it finds the same crossing unless
        // the ray dips below and back up between two samples (then the solve is earlier).
        let reference = bisect_reference(&t, &ray, hit.t * 1.001 + 1e-6).unwrap();
        assert!(
            hit.t <= reference + 1e-9 * cell,
            "ray {k}: {} after {reference}",
            hit.t
        );
        if (hit.t - reference).abs() > 1e-9 * cell {
            continue; // a dip between samples: the solve found the earlier, true root
        }
        compared += 1;
    }
    assert!(compared > 500, "{compared}");
}

#[test]
fn bicubic_hits_lie_on_the_surface_and_no_earlier_crossing_exists() {
    let t = terrain(DVec3::new(-5.0, 1.0, 2.0), Interpolation::Bicubic);
    let mut rng = Rng(4);
    let eps = 1e-9;
    let mut hits = 0;
    for k in 0..3_000 {
        let ray = random_ray(&t, &mut rng, k % 5);
        let range = Interval::new(0.0, f64::INFINITY);
        let got = t.cast(&ray, range, eps);
        let brute = t.cast_brute_force(&ray, range, eps);
        match (got, brute) {
            (Some(g), Some(b)) => {
                assert!(
                    (g.t - b.t).abs() <= 2.0 * eps,
                    "ray {k}: {} vs {}",
                    g.t,
                    b.t
                );
                if g.kind == HitKind::Surface {
                    let p = t.placement().map_ray(&ray).at(g.t);
                    // On the hit cell's own patch (at the map border neighbouring patches may
                    // differ along their shared edge, see `Interpolation`).
                    let [i, j] = g.cell.map(|c| c as usize);
                    let patch = BicubicCell::new(t.map(), i, j);
                    let (su, sv) = (p.x - i as f64, p.y - j as f64);
                    let s = patch.eval_with_slope(su, sv).0;
                    // Entering a cell through an edge where the border patches step up is a
                    // (tiny) wall, not a root: only interior points must be on the patch.
                    let edge = [su, sv]
                        .iter()
                        .any(|c| c.abs() < 1e-12 || (c - 1.0).abs() < 1e-12);
                    if edge {
                        hits += 1;
                        continue;
                    }
                    // |f| ≤ |f'|·ε with |f'| ≤ 1/σ + slopes: a loose 1e-6 raw units.
                    assert!(
                        (p.z - s).abs() < 1e-6,
                        "ray {k}: off the surface by {} at {p} {g:?}",
                        p.z - s
                    );
                }
                hits += 1;
            }
            (None, None) => {}
            (g, b) => panic!("ray {k}: pyramid {g:?}, brute force {b:?}"),
        }
    }
    assert!(hits > 800, "{hits}");
}

#[test]
fn no_nan_and_nothing_behind_the_start_on_degenerate_rays() {
    let t = terrain(DVec3::ZERO, Interpolation::Bilinear);
    let top = t.placement().to_world(DVec3::new(16.0, 14.0, 40.0));
    let dirs = [
        DVec3::X,
        -DVec3::X,
        DVec3::Z,
        -DVec3::Z,
        -DVec3::Y,
        DVec3::Y,
        DVec3::new(1.0, -1e-300, 0.0),
        DVec3::new(1e-300, -1.0, 1e-300),
    ];
    for d in dirs {
        for origin in [top, top - DVec3::Y * 35.0, top - DVec3::Y * 100.0] {
            let ray = Ray::new(origin, d).unwrap();
            if let Some(h) = t.cast(&ray, Interval::new(0.0, 1e9), 1e-9) {
                assert!(
                    h.t >= 0.0 && h.t.is_finite() && h.normal.is_finite(),
                    "{d}: {h:?}"
                );
                let b = t
                    .cast_brute_force(&ray, Interval::new(0.0, 1e9), 1e-9)
                    .unwrap();
                assert_eq!(h.t, b.t);
            }
        }
    }
}

#[test]
fn lod_hits_are_never_later_than_exact_hits_and_never_miss_them() {
    // LOD bias and pixel footprint stop at coarse max columns, which contain the surface.
    let exact = terrain(DVec3::ZERO, Interpolation::Bilinear);
    let coarse = |lod_bias| {
        let options = TerrainOptions {
            lod_bias,
            ..TerrainOptions::default()
        };
        Terrain::new(exact.map().clone(), *exact.placement(), options).unwrap()
    };
    let (biased, pixel) = (coarse(2), coarse(0));
    let mut rng = Rng(5);
    let range = Interval::new(0.0, f64::INFINITY);
    for k in 0..20_000 {
        let ray = random_ray(&exact, &mut rng, k % 5);
        let Some(e) = exact.cast(&ray, range, 1e-9) else {
            continue;
        };
        for (what, h) in [
            ("bias 2", biased.cast(&ray, range, 1e-9)),
            ("pixel", pixel.cast_lod(&ray, range, 1e-9, 0.05)),
        ] {
            let h = h.unwrap_or_else(|| panic!("ray {k}: {what} missed an exact hit"));
            assert!(
                h.t <= e.t,
                "ray {k}: {what} hit at {} after the exact {}",
                h.t,
                e.t
            );
        }
    }
}
