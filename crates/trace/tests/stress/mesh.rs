//! Meshes under stress: small closed meshes (a bumpy UV sphere, an axis-aligned cube) with
//! degenerate triangles added (zero area: a repeated corner, three collinear corners), placed
//! by instances scaled `10^[−3, 6]`, rotated or mirrored, and a third of the time `~10⁵` from
//! the world origin; rays cast with `Instance::nearest_hit` and `any_hit`.
//!
//! The reference is a brute force over every triangle in world space (f64 Möller–Trumbore: no
//! BVH, not the watertight test the instance uses). With `s = |o|∞ + t + diag` (the lengths the
//! computation rounds relative to) and `k = 1e-12` (the CPU's bound in `crates/gpu/tests/
//! rays.rs`), per ray:
//! - **no nonsense**: a hit is a finite number in the range, and any-hit says yes there;
//! - **depth**: where both hit, `|t − t_ref| · |cos θ| ≤ k s` (across the triangle's plane),
//!   or, for an earlier hit, it lies within `k s` of some triangle (one the brute force's own
//!   rounding missed: a grazed one), for a later one the reference's hit is within `k s` of an
//!   edge;
//! - **misses**: the reference hits where the instance does not only within `k s` of an edge
//!   or on a triangle the ray grazes (`|cos θ| · diag ≤ 4 k s`: within the bound of its plane
//!   all across it), and the instance hits where the reference does not only within `k s` of a triangle;
//! - **watertight**: a ray through an inside point of the closed mesh (aimed through a vertex,
//!   an edge or a face; or starting inside) always hits.

use super::runner::{self, Family, Tally};
use fray_core::{Interval, Ray};
use fray_mesh::{Instance, MeshBvh, TriangleMesh};
use fray_test_support::Rng;
use fray_test_support::triangles::{self, edge_distance};
use glam::{DAffine3, DMat3, DQuat, DVec3, EulerRot};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;
use std::sync::Arc;

const FAMILIES: [&str; 7] = [
    "random",
    "grazing",
    "axes",
    "vertex/edge",
    "far camera",
    "inside",
    "segment",
];
const RAYS_PER_CASE: usize = 2048;
const K: f64 = 1e-12;

/// A case: which mesh, its placement and the seed of its rays (and of the sphere's bumps).
#[derive(Clone, Debug)]
pub struct MeshCase {
    cube: bool,
    scale: f64,
    rotation: DVec3,
    mirror: bool,
    far: bool,
    seed: u64,
}

fn mesh_case() -> impl Strategy<Value = MeshCase> {
    (
        any::<bool>(),
        -3.0..6.0f64,
        (-3.2..3.2f64, -3.2..3.2f64, -3.2..3.2f64),
        any::<bool>(),
        0..3u8,
        any::<u64>(),
    )
        .prop_map(|(cube, e, (a, b, c), mirror, far, seed)| MeshCase {
            cube,
            scale: 10f64.powf(e),
            rotation: DVec3::new(a, b, c),
            mirror,
            far: far == 0,
            seed,
        })
}

/// A closed mesh about the origin (radius ~1), its vertices, and degenerate triangles after it.
fn build(cube: bool, rng: &mut Rng) -> (Vec<DVec3>, Vec<[u32; 3]>, usize) {
    let (mut p, mut tris) = if cube {
        fray_test_support::triangles::cube()
    } else {
        let (n_lat, n_lon) = (8u32, 12u32);
        let mut p = vec![DVec3::Y, -DVec3::Y];
        for i in 1..n_lat {
            let th = std::f64::consts::PI * f64::from(i) / f64::from(n_lat);
            for j in 0..n_lon {
                let ph = std::f64::consts::TAU * f64::from(j) / f64::from(n_lon);
                let r = rng.range(0.8, 1.2);
                p.push(r * DVec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
            }
        }
        let v = |i: u32, j: u32| 2 + (i - 1) * n_lon + (j % n_lon);
        let mut tris = Vec::new();
        for j in 0..n_lon {
            tris.push([0, v(1, j + 1), v(1, j)]);
            tris.push([1, v(n_lat - 1, j), v(n_lat - 1, j + 1)]);
            for i in 1..(n_lat - 1) {
                tris.push([v(i, j), v(i, j + 1), v(i + 1, j)]);
                tris.push([v(i, j + 1), v(i + 1, j + 1), v(i + 1, j)]);
            }
        }
        (p, tris)
    };
    let closed = tris.len();
    // Degenerate triangles inside the mesh: no area, so nothing to hit.
    let n = p.len() as u32;
    let a = rng.in_box(DVec3::splat(-0.5), DVec3::splat(0.5));
    let b = rng.in_box(DVec3::splat(-0.5), DVec3::splat(0.5));
    p.extend([a, b, 0.5 * (a + b)]);
    tris.push([n, n + 1, n + 2]);
    tris.push([n, n, n + 1]);
    (p, tris, closed)
}

/// The nearest reference hit: `(t, distance from the hit to the triangle's nearest edge, |cos θ|)`.
fn reference(inst: &Instance, n: usize, ray: &Ray, range: Interval) -> Option<(f64, f64, f64)> {
    let corners = (0..n).map(|i| inst.world_corners(i));
    triangles::nearest_hit(ray.origin, ray.dir, corners, |t| range.contains(t))
}

/// The distance from `p` to the nearest of the first `n` triangles.
fn distance_to_mesh(inst: &Instance, n: usize, p: DVec3) -> f64 {
    (0..n)
        .map(|i| {
            let c = inst.world_corners(i);
            let nrm = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
            let q = p - nrm * (p - c[0]).dot(nrm);
            let inside = (0..3).all(|k| (c[(k + 1) % 3] - c[k]).cross(q - c[k]).dot(nrm) >= 0.0);
            if inside && nrm != DVec3::ZERO {
                (p - q).length()
            } else {
                edge_distance(&c, p)
            }
        })
        .fold(f64::INFINITY, f64::min)
}

fn run_case(case: &MeshCase, tally: &Tally) -> Result<(), TestCaseError> {
    let mut rng = Rng(case.seed);
    let (positions, triangles, closed) = build(case.cube, &mut rng);
    let corners = positions.clone();
    let n_all = triangles.len();
    let mesh = Arc::new(MeshBvh::build(
        TriangleMesh::new(positions, triangles).expect("a valid mesh"),
    ));
    let r = case.rotation;
    let rot = if case.cube && rng.unit() < 0.5 {
        DQuat::IDENTITY
    } else {
        DQuat::from_euler(EulerRot::XYZ, r.x, r.y, r.z)
    };
    let offset = if case.far {
        rng.direction() * rng.range(1e5, 3e5)
    } else {
        DVec3::ZERO
    };
    let mirror = if case.mirror { -1.0 } else { 1.0 };
    let to_world = DAffine3::from_mat3_translation(
        DMat3::from_quat(rot) * DMat3::from_diagonal(DVec3::new(mirror, 1.0, 1.0) * case.scale),
        offset,
    );
    let inst = Instance::new(mesh, to_world).expect("an invertible placement");
    let size = inst.bounds().diagonal();
    let centre = to_world.transform_point3(DVec3::ZERO);
    let mut families = [Family::default(); FAMILIES.len()];
    for i in 0..RAYS_PER_CASE {
        let k = i % FAMILIES.len();
        let d = rng.direction();
        let dist = size * rng.range(1.5, 4.0);
        let full = Interval::new(0.0, f64::INFINITY);
        let vertex = to_world.transform_point3(corners[rng.below(closed.min(corners.len() - 3))]);
        // (origin, direction, range, whether the ray passes through the closed mesh's inside)
        let (o, d, range, through) = match k {
            1 => {
                let c = inst.world_corners(rng.below(closed));
                let nrm = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
                let w = rng.unit();
                let p = c[0] + (c[1] - c[0]) * w + (c[2] - c[0]) * (1.0 - w) * rng.unit();
                let t = (c[1] - c[0]).normalize();
                let delta =
                    size * rng.log_uniform(-15.0, -3.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                (p + nrm * delta - t * dist, t, full, false)
            }
            2 => {
                let mut a = DVec3::ZERO;
                a[rng.below(3)] = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
                let q = if rng.unit() < 0.5 { vertex } else { centre };
                (q - a * dist, a, full, q == centre)
            }
            3 => {
                // Through a vertex or an edge's point, on to the centre: inside on the way.
                let c = inst.world_corners(rng.below(closed));
                let q = if rng.unit() < 0.5 {
                    c[0]
                } else {
                    c[0] + (c[1] - c[0]) * rng.unit()
                };
                let d = (centre - q).normalize();
                (q - d * dist, d, full, true)
            }
            4 => {
                let q = inst.bounds().min + (inst.bounds().max - inst.bounds().min) * rng.unit();
                let d = (centre - q).normalize_or(d);
                (centre - d * 1e5 * rng.range(1.0, 3.0), d, full, true)
            }
            5 => (
                centre + d * size * 0.05 * rng.unit(),
                rng.direction(),
                full,
                true,
            ),
            6 => {
                let lo = dist + size * rng.range(-0.3, 0.3);
                (
                    centre - d * dist,
                    d,
                    Interval::new(lo, lo + size * rng.unit()),
                    false,
                )
            }
            _ => {
                let q = rng.in_box(inst.bounds().min, inst.bounds().max);
                (q - d * dist, d, full, false)
            }
        };
        let ray = Ray::new(o, d).expect("a unit direction");
        let hit = inst.nearest_hit(&ray, range);
        let any = inst.any_hit(&ray, range);
        let fail = |what: String| {
            TestCaseError::fail(format!(
                "{} ray at a {} scaled {:e} (offset {offset:?}): {what} for {ray:?} over {range:?}",
                FAMILIES[k],
                if case.cube { "cube" } else { "sphere" },
                case.scale
            ))
        };
        if let Some(h) = hit {
            if !(h.t.is_finite() && h.t >= range.lo && h.t <= range.hi) {
                return Err(fail(format!("hit t = {} outside the range", h.t)));
            }
            if !any {
                return Err(fail(format!("any-hit said no where the hit is at {}", h.t)));
            }
        }
        let t_scale = |t: f64| K * (o.abs().max_element() + t.abs() + size);
        let reference = reference(&inst, n_all, &ray, range);
        match (hit, reference) {
            (Some(h), Some((t_ref, edge, cos))) => {
                let b = t_scale(t_ref);
                let err = (h.t - t_ref).abs() * cos;
                if edge > b && cos > 1e-3 {
                    families[k].worst = families[k].worst.max(err / b);
                }
                // Earlier: a triangle the brute force's rounding missed (a grazed one) must be
                // there; later: only where the reference's hit is at an edge.
                let explained = if h.t < t_ref {
                    distance_to_mesh(&inst, n_all, ray.at(h.t)) <= b
                } else {
                    edge <= b
                };
                if err > b && !explained {
                    return Err(fail(format!(
                        "hit at {} against the brute force's {t_ref} (cos θ {cos:e}, edge {edge:e}, bound {b:e})",
                        h.t
                    )));
                }
            }
            // A ray within the bound of the triangle's plane all across it (`cos θ · diag`)
            // grazes it: either answer is within rounding.
            (None, Some((t_ref, edge, cos)))
                if edge > t_scale(t_ref) && cos * size > 4.0 * t_scale(t_ref) =>
            {
                return Err(fail(format!(
                    "missed the brute force's hit at {t_ref}, {edge:e} from an edge (cos θ {cos:e})"
                )));
            }
            (Some(h), None) => {
                let dist = distance_to_mesh(&inst, n_all, ray.at(h.t));
                if dist > t_scale(h.t) {
                    return Err(fail(format!(
                        "hit at {} is {dist:e} from every triangle",
                        h.t
                    )));
                }
            }
            _ => {}
        }
        if through && range.lo == 0.0 && hit.is_none() {
            return Err(fail("escaped the closed mesh through its inside".into()));
        }
        families[k].count(hit.is_some());
    }
    tally.add(&families);
    Ok(())
}

#[test]
fn meshes() {
    let name = "meshes";
    let cases = 500;
    let tally = Tally::new(name, &FAMILIES, "depth error ÷ bound");
    runner::run(name, cases, mesh_case(), |case| run_case(&case, &tally));
    let total = tally.report();
    let planned = runner::cases(cases) * RAYS_PER_CASE as u64;
    assert!(total >= planned, "{name}: {total} rays, planned {planned}");
}
