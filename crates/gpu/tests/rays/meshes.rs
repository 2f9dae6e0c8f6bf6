//! Meshes against an independent reference: each backend's nearest hit, geometric normal and
//! any-hit answer on the mesh data scenes' camera rays and from a camera 10³ back, against a
//! brute force over every triangle in world space.

use crate::Backend;
use crate::backend::CaseRay;
use crate::cases::{camera_rays, data_scene, far_rays};
use crate::cpu::{Cpu, triangle_normal};
use crate::gpu::Gpu;
use fray_core::Interval;
use fray_mesh::Instance;
use fray_test_support::triangles::moller_trumbore;
use glam::{DVec2, DVec3};

/// A backend's mesh bounds against the reference, each `k · scale` (world units).
#[derive(Clone, Copy, Debug)]
pub struct MeshBounds {
    pub depth: f64,
    pub edge: f64,
    pub normal: f64,
}

/// What a backend found on a ray through mesh instances.
#[derive(Clone, Copy, Debug)]
pub struct MeshAnswer {
    /// The nearest hit's distance, `None` for a miss.
    pub t: Option<f64>,
    /// The instance and its mesh's triangle hit.
    pub instance: u32,
    pub triangle: u32,
    /// The triangle's corners' barycentric weights at the hit.
    pub barycentric: [f64; 3],
    /// The world geometric normal (zero for a miss) ...
    pub normal: DVec3,
    /// ... and the world shading normal, the vertex normals interpolated by the weights.
    pub shading_normal: DVec3,
    /// The vertex uvs interpolated by the weights (zero where the mesh has none).
    pub uv: DVec2,
    /// The any-hit answer over the same range.
    pub any: bool,
}

/// What a backend of the suite answers for meshes.
pub trait MeshBackend {
    /// Nearest hit over the mesh `instances` (an earlier instance keeps a tie), where on which
    /// triangle, its world normals and the any-hit answer, for each ray.
    fn meshes(&self, instances: &[Instance], reference: DVec3, rays: &[CaseRay])
    -> Vec<MeshAnswer>;
    /// How far its mesh hits may be from the reference: across the triangle's plane, and from
    /// an edge where a ray may go either way (at a scale `scale`: the lengths its positions are
    /// rounded relative to); and its normals.
    fn mesh_bounds(&self) -> MeshBounds;
}

impl MeshBackend for Cpu {
    fn meshes(
        &self,
        instances: &[Instance],
        _reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<MeshAnswer> {
        rays.iter()
            .map(|r| {
                let mut best: Option<(usize, fray_mesh::MeshHit)> = None;
                for (k, instance) in instances.iter().enumerate() {
                    let range = Interval::new(r.range.lo, best.map_or(r.range.hi, |b| b.1.t));
                    let hit = instance.nearest_hit(&r.ray, range);
                    if let Some(h) = hit.filter(|h| best.is_none_or(|b| h.t < b.1.t)) {
                        best = Some((k, h));
                    }
                }
                let any = instances.iter().any(|i| i.any_hit(&r.ray, r.range));
                let Some((k, h)) = best else {
                    return MeshAnswer {
                        t: None,
                        instance: 0,
                        triangle: 0,
                        barycentric: [0.0; 3],
                        normal: DVec3::ZERO,
                        shading_normal: DVec3::ZERO,
                        uv: DVec2::ZERO,
                        any,
                    };
                };
                // The CPU's way: mesh-space normals through the instance's normal matrix.
                let instance = &instances[k];
                let mesh = instance.mesh.mesh();
                let corners = mesh.corners(h.triangle as usize);
                let vertices = mesh.triangles[h.triangle as usize];
                let shading = (0..3)
                    .map(|i| mesh.normals[vertices[i] as usize] * h.barycentric[i])
                    .fold(DVec3::ZERO, |s, x| s + x);
                let uv = mesh.uvs.as_ref().map_or(DVec2::ZERO, |uvs| {
                    (0..3)
                        .map(|i| uvs[vertices[i] as usize] * h.barycentric[i])
                        .fold(DVec2::ZERO, |s, x| s + x)
                });
                MeshAnswer {
                    t: Some(h.t),
                    instance: k as u32,
                    triangle: h.triangle,
                    barycentric: h.barycentric,
                    normal: instance.world_normal(triangle_normal(&corners)),
                    shading_normal: instance.world_normal(shading),
                    uv,
                    any,
                }
            })
            .collect()
    }

    fn mesh_bounds(&self) -> MeshBounds {
        // f64 throughout: a few units of rounding of the scale.
        MeshBounds {
            depth: 1e-12,
            edge: 1e-12,
            normal: 1e-9,
        }
    }
}

impl MeshBackend for Gpu {
    fn meshes(
        &self,
        instances: &[Instance],
        reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<MeshAnswer> {
        let batch = self.mesh_batch(instances, reference);
        self.mesh_answers(&batch, reference, rays)
    }

    fn mesh_bounds(&self) -> MeshBounds {
        // The parity bounds (mesh_parity.rs): DEPTH_K = 4 and EDGE_K = 64 units of f32
        // rounding of the scale; geometric normals within 1e-4.
        let e = f64::from(f32::EPSILON);
        MeshBounds {
            depth: 4.0 * e,
            edge: 64.0 * e,
            normal: 1e-4,
        }
    }
}

/// The reference for meshes: every triangle of every instance, in world space, in f64 — no BVH,
/// and not the watertight test either backend uses (Möller–Trumbore): `(t, instance, triangle,
/// the hit's distance to the triangle's nearest edge)` of the nearest hit.
fn reference_mesh_hit(instances: &[Instance], r: &CaseRay) -> Option<(f64, usize, usize, f64)> {
    let mut best: Option<(f64, usize, usize, f64)> = None;
    for (k, instance) in instances.iter().enumerate() {
        if instance.bounds().clip_ray(&r.ray, r.range).is_none() {
            continue;
        }
        for i in 0..instance.mesh.mesh().triangles.len() {
            let c = instance.world_corners(i);
            let Some(t) = moller_trumbore(r.ray.origin, r.ray.dir, &c) else {
                continue;
            };
            if !r.range.contains(t) {
                continue;
            }
            if best.is_some_and(|b| b.0 <= t) {
                continue;
            }
            let hit = r.ray.at(t);
            best = Some((t, k, i, edge_distance(&c, hit)));
        }
    }
    best
}

/// The distance from `p` (on the triangle's plane) to the triangle's nearest edge line.
fn edge_distance(c: &[DVec3; 3], p: DVec3) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            let e = (b - a).normalize_or_zero();
            let w = p - a;
            (w - e * w.dot(e)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The distance from `p` to the nearest triangle of `instances` (a backend's hit where the
/// reference has none must lie on one, within the edge bound).
fn distance_to_meshes(instances: &[Instance], p: DVec3) -> f64 {
    let mut best = f64::INFINITY;
    for instance in instances {
        for i in 0..instance.mesh.mesh().triangles.len() {
            best = best.min(point_triangle_distance(p, &instance.world_corners(i)));
        }
    }
    best
}

/// The distance from `p` to triangle `c` (its plane inside it, else its nearest edge segment).
fn point_triangle_distance(p: DVec3, c: &[DVec3; 3]) -> f64 {
    let n = triangle_normal(c);
    let q = p - n * (p - c[0]).dot(n);
    let inside = (0..3).all(|k| {
        let (a, b) = (c[k], c[(k + 1) % 3]);
        (b - a).cross(q - a).dot(n) >= 0.0
    });
    if inside && n != DVec3::ZERO {
        return (p - q).length();
    }
    (0..3)
        .map(|k| {
            let (a, b) = (c[k], c[(k + 1) % 3]);
            let ab = b - a;
            let s = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            (p - (a + ab * s)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The mesh cases: camera rays of the mesh data scenes and the same from a camera 10³ back, the
/// nearest hits against [`reference_mesh_hit`].
pub fn suite(backend: &dyn Backend) {
    let b = backend.mesh_bounds();
    let (mut rays_checked, mut hits, mut edges) = (0usize, 0usize, 0usize);
    let (mut worst_depth, mut worst_normal) = (0.0f64, 0.0f64);
    let mut failures = Vec::new();
    for name in ["mesh_bunny_freeform.ron", "mesh_aircraft_pair.ron"] {
        let scene = data_scene(name);
        let instances: Vec<Instance> = scene.meshes.iter().map(|m| m.instance.clone()).collect();
        let reference = fray_gpu::params::reference_point(&scene.camera);
        let camera = camera_rays(&scene, 40, 30);
        let (far_eye, far) = far_rays(&camera, reference, 1e3, 3.0);
        let diagonal = instances
            .iter()
            .map(|i| i.bounds().diagonal())
            .fold(0.0, f64::max);
        for (kind, rays, reference) in [("camera", camera, reference), ("far", far, far_eye)] {
            let answers = backend.meshes(&instances, reference, &rays);
            for (r, a) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let truth = reference_mesh_hit(&instances, r);
                let t_any = a.t.or(truth.map(|t| t.0)).unwrap_or(0.0);
                let scale = r.ray.origin.distance(reference) + t_any + diagonal;
                let describe =
                    |what: &str| format!("{name} {kind}: {what} on {r:?}: {a:?} vs {truth:?}");
                match (a.t, truth) {
                    (Some(t), Some((t_ref, k, i, edge))) => {
                        hits += 1;
                        let at_edge = edge < b.edge * scale;
                        let n = triangle_normal(&instances[k].world_corners(i));
                        let across = (t - t_ref).abs() * n.dot(r.ray.dir).abs();
                        if across > b.depth * scale {
                            // Another triangle past an edge (a silhouette's) is excused there.
                            if at_edge {
                                edges += 1;
                            } else {
                                failures
                                    .push(describe(&format!("depth off by {across:.3e} across")));
                            }
                            continue;
                        }
                        worst_depth = worst_depth.max(across / (b.depth * scale));
                        let off = (a.normal - n).length();
                        if off > b.normal {
                            // A neighbour's normal is excused at an edge.
                            if at_edge {
                                edges += 1;
                            } else {
                                failures.push(describe(&format!("normal off by {off:.3e}")));
                            }
                        } else {
                            worst_normal = worst_normal.max(off);
                        }
                        if !a.any {
                            failures.push(describe("no any hit"));
                        }
                    }
                    (None, Some((_, _, _, edge))) => {
                        if edge >= b.edge * scale {
                            failures.push(describe("missed"));
                        } else {
                            edges += 1;
                        }
                    }
                    (Some(t), None) => {
                        let d = distance_to_meshes(&instances, r.ray.at(t));
                        if d > b.edge * scale {
                            failures.push(describe(&format!("a hit {d:.3e} from every triangle")));
                        } else {
                            edges += 1;
                        }
                    }
                    (None, None) => {
                        if a.any {
                            failures.push(describe("an any hit on a miss"));
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "{}: meshes, {rays_checked} rays, {hits} hits; {edges} differences excused at edges; worst \
         depth {worst_depth:.3e} of its bound, worst normal {worst_normal:.2e}",
        backend.name()
    );
    assert!(
        failures.is_empty(),
        "{}: {} mesh rays off, e.g. {:?}",
        backend.name(),
        failures.len(),
        &failures[..failures.len().min(4)]
    );
}
