//! Meshes under stress on the GPU (`MeshBatch`): the cube `[−1, 1]³` scaled `10^[−2, 4]`,
//! axis-aligned or rotated, a third `10⁵` from the origin; cameras near it, in a face's plane
//! (grazing), `10³`–`10⁴` diagonals away, or inside; rays through its vertices, edges, faces and
//! centre, over `[0, ∞)` or segments. Against an f64 brute force over its triangles: a hit
//! finite, in the range, any-hit true there; `|Δt| cos θ ≤ 4 ε_f32 s` (the rays suite's GPU
//! bound, `s = |camera − centre| + t + diagonal`), a difference beyond it, a miss or an extra hit
//! only within `64 ε_f32 s` of an edge (the reference's, or the cube's silhouette at the GPU's
//! hit) or on a face the ray grazes; a ray from outside through the centre always hits.

use crate::{case_range, cases, relative, seed};
use fray_core::{Interval, Ray};
use fray_gpu::GpuContext;
use fray_gpu::testing::MeshBatch;
use fray_mesh::{Instance, MeshBvh, TriangleMesh};
use fray_test_support::Rng;
use fray_test_support::triangles;
use glam::{DAffine3, DMat3, DQuat, DVec3, EulerRot};
use std::sync::Arc;

pub const MESH_RAYS: usize = 8192;

/// The f64 reference: every triangle of `inst` in world space (Möller–Trumbore, no BVH, not
/// the watertight test either backend uses): `(t, distance to the triangle's nearest edge,
/// |cos θ|)` of the nearest hit in `range`.
fn brute_force(inst: &Instance, ray: &Ray, range: Interval) -> Option<(f64, f64, f64)> {
    let corners = (0..12).map(|i| inst.world_corners(i));
    triangles::nearest_hit(ray.origin, ray.dir, corners, |t| range.contains(t))
}

/// A closed mesh about the origin: the cube `[−1, 1]³` (its 12 triangles).
fn cube() -> MeshBvh {
    let (p, tris) = fray_test_support::triangles::cube();
    MeshBvh::build(TriangleMesh::new(p, tris).expect("a valid mesh"))
}

pub fn meshes(ctx: &GpuContext) -> (u64, f64, u64) {
    let e32 = f64::from(f32::EPSILON);
    // tests/rays.rs's GPU mesh bounds: 4 and 64 units of f32 rounding of the scale.
    let (depth_k, edge_k) = (4.0 * e32, 64.0 * e32);
    let mesh = Arc::new(cube());
    let (mut total, mut worst, mut excused) = (0u64, 0.0f64, 0u64);
    for case in 0..cases(24) {
        let mut rng = Rng(seed(0x3e5, case));
        let scale = rng.log_uniform(-2.0, 4.0);
        let rotation = if case % 2 == 0 {
            DMat3::IDENTITY
        } else {
            DMat3::from_quat(DQuat::from_euler(
                EulerRot::XYZ,
                rng.range(-3.2, 3.2),
                rng.range(-3.2, 3.2),
                rng.range(-3.2, 3.2),
            ))
        };
        let offset = if case % 3 == 0 {
            rng.direction() * 1e5
        } else {
            DVec3::ZERO
        };
        let to_world = DAffine3::from_mat3_translation(rotation * scale, offset);
        let inst = Instance::new(Arc::clone(&mesh), to_world).expect("invertible");
        let diag = inst.bounds().diagonal();
        let family = case % 4;
        let camera = match family {
            0 => offset + rng.direction() * diag * rng.range(0.8, 3.0),
            // In the plane of the top face (world y of the unrotated cube's top): grazing.
            1 => {
                offset
                    + to_world.matrix3 * DVec3::new(rng.range(-4.0, 4.0), 1.0, rng.range(3.0, 6.0))
            }
            2 => offset + rng.direction() * diag * rng.log_uniform(3.0, 4.0),
            _ => offset + rng.direction() * diag * 0.2,
        };
        let rays: Vec<(Ray, Interval)> = (0..MESH_RAYS)
            .map(|i| {
                let local = match i % 4 {
                    0 => DVec3::new(
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                    ),
                    1 => DVec3::new(
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0),
                    ),
                    2 => DVec3::new(rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0)),
                    _ => DVec3::ZERO,
                };
                let target = to_world.transform_point3(local);
                let d = (target - camera).normalize_or(DVec3::Y);
                let range = case_range(&mut rng, (target - camera).length(), diag);
                (Ray::new(camera, d).expect("a unit direction"), range)
            })
            .collect();
        let batch = MeshBatch::new(ctx, &[mesh.as_ref()], &[(0, to_world)], camera)
            .unwrap_or_else(|e| panic!("{e}"));
        let hits = batch
            .cast(ctx, &relative(&rays, camera))
            .unwrap_or_else(|e| panic!("{e}"));
        for (i, ((ray, range), g)) in rays.iter().zip(&hits).enumerate() {
            total += 1;
            let reference = brute_force(&inst, ray, *range);
            let gt = g.is_hit().then_some(f64::from(g.t));
            let fail = |what: String| -> ! {
                panic!(
                    "mesh case {case} (family {family}, scale {scale:e}, offset {offset:?}): {what} for {ray:?} over {range:?}: GPU {g:?}, f64 {reference:?}"
                )
            };
            let s =
                (camera - offset).length() + gt.or(reference.map(|r| r.0)).unwrap_or(0.0) + diag;
            if let Some(t) = gt {
                if !(t.is_finite()
                    && t >= f64::from(range.lo as f32)
                    && t <= range.hi * (1.0 + 1e-6))
                {
                    fail(format!("GPU hit t = {t} outside the range"));
                }
                if !g.any_hit {
                    fail("no any hit where the nearest hit is".into());
                }
            }
            match (gt, reference) {
                (Some(t), Some((tr, edge, cos))) => {
                    let across = (t - tr).abs() * cos;
                    if across > depth_k * s {
                        // The GPU's hit on an edge the f64 ray passes (a silhouette): within
                        // the edge bound of two faces' planes at once.
                        let q = to_world.inverse().transform_point3(ray.at(t)).abs();
                        let mut a = [q.x, q.y, q.z];
                        a.sort_by(|x, y| y.total_cmp(x));
                        let silhouette =
                            (a[0] - 1.0).abs().max((a[1] - 1.0).abs()) * scale <= edge_k * s;
                        if edge >= edge_k * s && cos * diag > 4.0 * depth_k * s && !silhouette {
                            fail(format!("depth off by {across:e} across"));
                        }
                        excused += 1;
                    } else {
                        worst = worst.max(across / (depth_k * s));
                    }
                }
                (None, Some((_, edge, cos))) => {
                    // Missed only at an edge or on a face the ray grazes (within the depth bound
                    // of its plane all across it); a ray through the centre never misses.
                    if (edge >= edge_k * s && cos * diag > 4.0 * depth_k * s)
                        || (i % 4 == 3 && range.lo == 0.0 && family != 3)
                    {
                        fail("missed".into());
                    }
                    excused += 1;
                }
                (Some(t), None) => {
                    // The cube's surface is `|q|∞ = 1` in its own frame: `||q|∞ − 1| · scale`
                    // never exceeds the distance to it.
                    let q = to_world.inverse().transform_point3(ray.at(t));
                    let off = (q.abs().max_element() - 1.0).abs() * scale;
                    if off > edge_k * s {
                        fail(format!("a hit at {t}, {off:e} from the cube's surface"));
                    }
                    excused += 1;
                }
                (None, None) => {}
            }
        }
    }
    (total, worst, excused)
}
