//! Meshes against an independent reference: each backend's nearest hit, geometric normal and
//! any-hit answer on the mesh data scenes' camera rays and from a camera 10³ back, against a
//! brute force over every triangle in world space.

use crate::Backend;
use crate::backend::CaseRay;
use crate::cases::{assert_none_off, camera_rays, data_scene, far_rays};
use crate::cpu::Cpu;
use crate::gpu::{Gpu, relative_rays};
use fray_core::Interval;
use fray_gpu::testing::MeshBatch;
use fray_mesh::{Instance, MeshBvh};
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
        // The parity bounds (`parity` below): DEPTH_K = 4 and EDGE_K = 64 units of f32
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
    // Outside it: the nearest edge segment.
    fray_test_support::triangles::edge_distance(c, p)
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
    assert_none_off(backend.name(), "mesh", &failures);
}

/// The unit normal of a triangle by its winding.
pub fn triangle_normal(c: &[DVec3; 3]) -> DVec3 {
    (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero()
}

/// The GPU's mesh kernel as the suite uses it.
impl Gpu {
    /// The mesh kernel over `instances`, each distinct mesh once (as the resident scene uploads
    /// them), positions relative to `reference`.
    pub fn mesh_batch(&self, instances: &[Instance], reference: DVec3) -> MeshBatch {
        let mut distinct: Vec<&MeshBvh> = Vec::new();
        let mut placements = Vec::new();
        for instance in instances {
            let index = distinct
                .iter()
                .position(|m| std::ptr::eq(*m, instance.mesh.as_ref()))
                .unwrap_or_else(|| {
                    distinct.push(instance.mesh.as_ref());
                    distinct.len() - 1
                });
            placements.push((index as u32, instance.to_world()));
        }
        MeshBatch::new(self.context(), &distinct, &placements, reference)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// `batch`'s answers to `rays` (relative to the reference point it was built or rebased at).
    pub fn mesh_answers(
        &self,
        batch: &MeshBatch,
        reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<MeshAnswer> {
        let v = |a: [f32; 3]| DVec3::from(a.map(f64::from));
        batch
            .cast(self.context(), &relative_rays(rays, reference))
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|h| MeshAnswer {
                t: h.is_hit().then_some(f64::from(h.t)),
                instance: h.instance,
                triangle: h.triangle,
                barycentric: h.barycentric.map(f64::from),
                normal: v(h.normal),
                shading_normal: v(h.shading_normal),
                uv: DVec2::new(f64::from(h.uv[0]), f64::from(h.uv[1])),
                any: h.any_hit,
            })
            .collect()
    }
}

pub mod parity {
    //! Mesh parity: the GPU's mesh kernel (`mesh.wgsl` through the batch pass `MeshBatch`) against
    //! the f64 CPU (`fray_mesh::Instance::nearest_hit`/`any_hit` over `MeshBvh`) on the same rays —
    //! a GPU-vs-CPU bound, the f32 arithmetic's, tighter than the independent reference allows.
    //!
    //! Rays (f32 on the GPU, relative to a reference point — the camera — as the frame will cast
    //! them; f64 on the CPU): pinhole camera rays (256², 192²) and random rays at the bunny
    //! (`data/meshes/bunny00.obj`, 75 408 triangles) and the boeing (`data/meshes/boeing.obj`),
    //! shadow-ray and next-hit segments around the CPU's hits (ranges ending 10⁻³ before and after
    //! the hit, and starting 10⁻³ past it), 236 522 rays from inside the closed bunny (from its
    //! anchor aimed exactly at every f32 vertex as uploaded, from eight inside points at an edge
    //! midpoint of every triangle, and in random directions: **none escapes**), four instances
    //! sharing one set of buffers (the boeing rotated, scaled non-uniformly, translated and
    //! mirrored, the bunny scaled up among them), a mesh whose vertices sit ~10⁵ from the origin,
    //! an instance translated by ~10⁶, and a pass moved to another reference point by rewriting its
    //! instance blocks only. The bounds, with `scale = |o − ref| + |ref − instance centre| + t |d| +
    //! instance radius` (the lengths f32 positions are rounded relative to) and θ the angle between
    //! the ray and the triangle's normal:
    //! - **hit/miss**: the same on every ray except those passing within `EDGE_K = 64` ε_f32 · scale
    //!   of an edge of the triangle hit (on the side that hit); measured: 0 flips in ~770 000 rays;
    //! - **triangle**: the same (instance, triangle) except, again, within that distance of an edge,
    //!   or where the GPU's triangle is hit at the CPU's depth (a shared vertex: ties go to the
    //!   smaller index on the GPU, to the first found on the CPU); measured on the ~530 000 rays
    //!   from outside: 3, all within 0.1 ε scale of an edge; on the rays aimed at vertices and
    //!   edges from inside, the explained distances reach 55 ε scale;
    //! - **depth** on rays both hit on the same triangle: `|Δt| |d| |cos θ| ≤ DEPTH_K = 4` ε_f32 ·
    //!   scale (measured ≤ 1.39), hence `|Δt| |d| ≤ 10⁻⁵ (t |d| + |o − ref|)` wherever
    //!   `|cos θ| ≥ 0.05` (measured ≤ 1.1·10⁻⁶; plain max `|Δt|/t` 7·10⁻⁶ over every ray from
    //!   outside, grazing ones included); grazing hits (`|cos θ| < 0.05`, ~0.2 % of them) are held to the cosine
    //!   bound only (measured up to `|Δt|/t` = 9·10⁻⁴ there, the plane's ill conditioning);
    //! - **barycentrics**: the points the two sides' weights name on the triangle within
    //!   `BARY_K = 4` ε_f32 · scale / |cos θ| (measured ≤ 1.35; the weights differ by ≤ 1.2·10⁻³ on
    //!   the boeing's scaled slivers, ≤ 4·10⁻⁴ elsewhere off grazing rays);
    //! - **normals**: world geometric normals within 10⁻⁴ (measured 2.3·10⁻⁵), interpolated shading
    //!   normals within 5·10⁻⁴ off grazing rays (measured 7.6·10⁻⁵);
    //! - **uvs** (the bunny with planar uvs, alone and under a mirroring instance): the GPU's uv is
    //!   the CPU's interpolation at the GPU's own weights within `UV_K = 4` ε_f32 · max |uv| (measured
    //!   1.52; `|Δuv|` from the CPU's answer ≤ 1.1·10⁻⁵ for uvs of a few units);
    //! - **any hit** = the CPU's any hit over the same range on every ray (the same edge exception;
    //!   measured: no difference), and = the GPU's own nearest hit.
    //!
    //! Stack depth: the bunny's BVH is 21 deep, the boeing's 19 (the GPU stack holds 64). The same
    //! bunny moved by 4·10⁵ in its vertices builds a BVH ~200 deep (`MeshBvh::build` takes its
    //! topology from f32 triangles, which collapse that far out): `MeshBatch::new` refuses it as
    //! `GpuError::TooLarge` (tested), as it would any BVH deeper than `MESH_STACK − 1`.
    //!
    //! Measured on lavapipe (llvmpipe, no FMA contraction). The edge functions' signs come from
    //! comparisons of rounded products, which a contracting driver cannot fuse; that part is not
    //! exercised here.
    //!
    //! The edge distance the acceptance rule uses is unit-tested without a GPU (the `edge::*` trials).

    use crate::backend::CaseRay;
    use crate::cpu::Cpu;
    use crate::gpu::gpu;
    use crate::meshes::MeshAnswer;
    use crate::meshes::MeshBackend;
    use fray_core::{Aabb, Interval, MemoryBudget, Ray};
    use fray_core::{Pinhole, Projector};
    use fray_mesh::{Instance, MeshBvh, TriangleMesh};
    use fray_test_support::Rng;
    use glam::{DAffine3, DQuat, DVec2, DVec3};
    use std::path::Path;
    use std::sync::{Arc, OnceLock};

    /// The machine epsilon of f32.
    const F32_EPS: f64 = f32::EPSILON as f64;
    /// Depths agree within `DEPTH_REL · (t + |origin − reference|)` on every ray both sides hit on
    /// the same triangle at an angle: `|cos θ| ≥ GRAZING_COS` ...
    const DEPTH_REL: f64 = 1e-5;
    const GRAZING_COS: f64 = 0.05;
    /// ... and within `DEPTH_K · ε_f32 · scale / |cos θ|` (θ between the ray and the triangle's
    /// normal; `scale` as in [`tolerance`]): the bound that holds for grazing rays too.
    const DEPTH_K: f64 = 4.0;
    /// Rays that pass within `EDGE_K · ε_f32 · scale` ([`tolerance`]) of a triangle's edge may hit
    /// on one side only, or another triangle.
    const EDGE_K: f64 = 64.0;
    /// The points the two sides' barycentric weights name on the triangle agree within
    /// `BARY_K · ε_f32 · scale / |cos θ|` (on rays both hit on the same triangle; the weights
    /// themselves differ by that over the triangle's size).
    const BARY_K: f64 = 4.0;
    /// World geometric normals agree within this ...
    const NORMAL_BOUND: f64 = 1e-4;
    /// ... and interpolated shading normals within this.
    const SHADING_NORMAL_BOUND: f64 = 5e-4;
    /// The GPU's uv is the CPU's interpolation at the GPU's own weights within
    /// `UV_K · ε_f32 · max |uv|` of the triangle's corners: its f32 corners, three f32 products and
    /// two sums, about 2 ε with weights in `[0, 1]` (the weights themselves are held by
    /// [`BARY_K`]). Measured 1.52 on the bunny with planar uvs.
    const UV_K: f64 = 4.0;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/meshes")
            .join(name)
    }

    fn load(name: &str) -> TriangleMesh {
        TriangleMesh::load_obj(&data(name), &MemoryBudget::default())
            .unwrap_or_else(|e| panic!("{e}"))
    }

    fn bunny() -> Arc<MeshBvh> {
        static BUNNY: OnceLock<Arc<MeshBvh>> = OnceLock::new();
        BUNNY
            .get_or_init(|| Arc::new(MeshBvh::build(load("bunny00.obj"))))
            .clone()
    }

    fn boeing() -> Arc<MeshBvh> {
        static BOEING: OnceLock<Arc<MeshBvh>> = OnceLock::new();
        BOEING
            .get_or_init(|| Arc::new(MeshBvh::build(load("boeing.obj"))))
            .clone()
    }

    /// Meshes placed in the world, on both sides.
    struct World {
        instances: Vec<Instance>,
    }

    impl World {
        fn new(meshes: Vec<Arc<MeshBvh>>, placements: &[(u32, DAffine3)]) -> Self {
            let instances = placements
                .iter()
                .map(|&(m, to_world)| Instance::new(meshes[m as usize].clone(), to_world).unwrap())
                .collect();
            Self { instances }
        }

        /// The GPU's mesh kernel over the instances, relative to `reference`.
        fn pass(&self, reference: DVec3) -> fray_gpu::testing::MeshBatch {
            gpu().mesh_batch(&self.instances, reference)
        }

        /// The world box of instance `k`.
        fn instance_bounds(&self, k: usize) -> Aabb {
            let b = self.instances[k].mesh.bounds();
            let m = self.instances[k].to_world();
            (0..8).fold(Aabb::EMPTY, |acc, c| {
                let p = DVec3::new(
                    if c & 1 == 0 { b.min.x } else { b.max.x },
                    if c & 2 == 0 { b.min.y } else { b.max.y },
                    if c & 4 == 0 { b.min.z } else { b.max.z },
                );
                let q = m.transform_point3(p);
                acc.union(&Aabb::new(q, q))
            })
        }

        fn bounds(&self) -> Aabb {
            (0..self.instances.len())
                .fold(Aabb::EMPTY, |acc, k| acc.union(&self.instance_bounds(k)))
        }

        /// Triangle `tri` of instance `k` in the world.
        fn corners(&self, k: u32, tri: u32) -> [DVec3; 3] {
            self.instances[k as usize].world_corners(tri as usize)
        }

        /// The rounding scale of a hit on instance `k` at `t`: the lengths f32 positions are
        /// rounded relative to — the ray's origin from the reference, the reference from the
        /// instance, the point along the ray, the instance's size.
        fn scale(&self, k: u32, q: &CaseRay, t: f64, reference: DVec3) -> f64 {
            let b = self.instance_bounds(k as usize);
            (q.ray.origin - reference).length()
                + (reference - b.center()).length()
                + t.abs() * q.ray.dir.length()
                + b.diagonal() * 0.5
        }
    }

    /// The distance between the line `o + t d` and the segment `a b`.
    fn line_segment_distance(o: DVec3, d: DVec3, a: DVec3, b: DVec3) -> f64 {
        let e = b - a;
        let w = o - a;
        let (aa, bb, cc) = (d.dot(d), d.dot(e), e.dot(e));
        let (dd, ee) = (d.dot(w), e.dot(w));
        let denom = aa * cc - bb * bb;
        let s = if cc == 0.0 || denom <= 1e-300 * aa * cc {
            0.0
        } else {
            ((aa * ee - bb * dd) / denom).clamp(0.0, 1.0)
        };
        let p = a + e * s;
        let t = (p - o).dot(d) / aa;
        (o + d * t - p).length()
    }

    /// How close the ray passes to an edge of the triangle `corners`.
    fn edge_distance(ray: &Ray, corners: [DVec3; 3]) -> f64 {
        (0..3)
            .map(|i| line_segment_distance(ray.origin, ray.dir, corners[i], corners[(i + 1) % 3]))
            .fold(f64::INFINITY, f64::min)
    }

    /// What a comparison measured.
    #[derive(Debug, Default)]
    struct Figures {
        rays: usize,
        both: usize,
        /// Hit on one side only: all, and those not within the edge tolerance.
        flips: usize,
        flips_unexplained: usize,
        /// Both hit, another (instance, triangle): all, those at the same depth (coincident or
        /// touching triangles), those not explained by an edge or the same depth.
        others: usize,
        others_same_depth: usize,
        others_unexplained: usize,
        /// Same triangle: max |Δt| / t, max |Δt| / (t + |o − ref|), how many over DEPTH_REL, the
        /// largest |Δt| |cos θ| / (ε scale), max barycentric and normal differences.
        worst_rel_t: f64,
        worst_rel: f64,
        over: usize,
        /// The same for grazing hits (|cos θ| < GRAZING_COS), held only to the |cos θ| bound.
        worst_rel_grazing: f64,
        grazing: usize,
        worst_cos_scaled: f64,
        worst_bary: f64,
        worst_normal: f64,
        worst_shading_normal: f64,
        worst_grazing_bary: f64,
        /// The largest |Δp| |cos θ| / (ε scale) between the points the weights name.
        worst_bary_point: f64,
        worst_grazing_shading_normal: f64,
        /// The largest edge distance / (ε scale) among the explained disagreements.
        worst_edge_ratio: f64,
        any_differ: usize,
        any_unexplained: usize,
        /// Every GPU miss (for the rays from inside a closed mesh: none may escape).
        gpu_misses: usize,
        /// Same triangle, on a mesh with uvs: how many, the largest `|Δuv|` from the CPU's, and the
        /// largest difference from the CPU's interpolation at the GPU's own weights, over
        /// `ε_f32 · max |uv|` of the triangle's corners.
        uvs: usize,
        worst_uv: f64,
        worst_uv_arithmetic: f64,
    }

    /// The GPU's answers to `queries` (`cast`, timed) against the CPU's.
    fn measure(
        what: &str,
        world: &World,
        queries: &[CaseRay],
        reference: DVec3,
        cast: impl FnOnce() -> Vec<MeshAnswer>,
    ) -> Figures {
        let start = std::time::Instant::now();
        let hits = cast();
        let gpu_time = start.elapsed();
        let cpu = Cpu.meshes(&world.instances, reference, queries);
        let mut f = Figures {
            rays: queries.len(),
            ..Figures::default()
        };
        for ((q, c), g) in queries.iter().zip(&cpu).zip(&hits) {
            compare_one(world, q, c, g, reference, &mut f);
        }
        eprintln!(
            "{what}: {} rays ({:.0} krays/s on the GPU), {} both hit; max |Δt|/t {:.2e}, max |Δt|/(t + |o − ref|) \
         {:.2e} ({} over {DEPTH_REL:.0e}; grazing: {} hits, max {:.2e}), max |Δt| |cos θ|/(ε scale) {:.2}; hit/miss flips {} ({} \
         unexplained), other triangle {} (same depth {}, unexplained {}), worst edge distance {:.1} ε scale; \
         max |Δbary| {:.2e} (|Δp| |cos θ|/(ε scale) {:.2}), max |Δn| {:.2e} (shading {:.2e}; grazing: |Δbary| {:.2e}, shading |Δn| {:.2e}); uvs {} (max |Δuv| {:.2e}, at the GPU's weights {:.2} ε max|uv|); any-hit differs {} ({} unexplained); GPU misses {}",
            f.rays,
            f.rays as f64 / gpu_time.as_secs_f64() / 1e3,
            f.both,
            f.worst_rel_t,
            f.worst_rel,
            f.over,
            f.grazing,
            f.worst_rel_grazing,
            f.worst_cos_scaled,
            f.flips,
            f.flips_unexplained,
            f.others,
            f.others_same_depth,
            f.others_unexplained,
            f.worst_edge_ratio,
            f.worst_bary,
            f.worst_bary_point,
            f.worst_normal,
            f.worst_shading_normal,
            f.worst_grazing_bary,
            f.worst_grazing_shading_normal,
            f.uvs,
            f.worst_uv,
            f.worst_uv_arithmetic,
            f.any_differ,
            f.any_unexplained,
            f.gpu_misses,
        );
        f
    }

    fn compare_one(
        world: &World,
        q: &CaseRay,
        c: &MeshAnswer,
        g: &MeshAnswer,
        reference: DVec3,
        f: &mut Figures,
    ) {
        // The CPU's hit: (instance, its triangle, t, weights).
        let cpu = c.t.map(|t| (c.instance, c.triangle, t, c.barycentric));
        let gpu_hit = g.t.is_some();
        f.gpu_misses += usize::from(!gpu_hit);
        // Within the edge tolerance of triangle `tri` of instance `k` at `t`?
        let edge_ratio = |k: u32, tri: u32, t: f64| {
            edge_distance(&q.ray, world.corners(k, tri))
                / (F32_EPS * world.scale(k, q, t, reference))
        };
        // Within the edge tolerance, recording the distance of the disagreements it explains.
        let near_edge = |k: u32, tri: u32, t: f64, f: &mut Figures| {
            let ratio = edge_ratio(k, tri, t);
            let near = ratio <= EDGE_K;
            if near {
                f.worst_edge_ratio = f.worst_edge_ratio.max(ratio);
            }
            near
        };
        let t_gpu = g.t.unwrap_or(0.0);
        // Any hit: the CPU's over the same range; a difference is explained where the nearest
        // hits differ explainably (checked below) or a hit lies at the range's end.
        if c.any != g.any {
            f.any_differ += 1;
            let explained = match (cpu, gpu_hit) {
                (Some((k, tri, t, _)), _) if near_edge(k, tri, t, f) => true,
                (_, true) if near_edge(g.instance, g.triangle, t_gpu, f) => true,
                _ => false,
            };
            f.any_unexplained += usize::from(!explained);
        } else if g.any != gpu_hit {
            // The GPU's own two queries disagree: never explained.
            f.any_differ += 1;
            f.any_unexplained += 1;
        }
        match (cpu, gpu_hit) {
            (None, false) => {}
            (Some((k, tri, t, _)), false) => {
                f.flips += 1;
                f.flips_unexplained += usize::from(!near_edge(k, tri, t, f));
            }
            (None, true) => {
                f.flips += 1;
                f.flips_unexplained += usize::from(!near_edge(g.instance, g.triangle, t_gpu, f));
            }
            (Some((k, tri, t_cpu, weights)), true) => {
                f.both += 1;
                if (k, tri) != (g.instance, g.triangle) {
                    f.others += 1;
                    let scale = world.scale(k, q, t_cpu, reference);
                    let same_depth = same_depth_elsewhere(world, q, g, t_cpu, scale);
                    f.others_same_depth += usize::from(same_depth);
                    let explained = same_depth
                        || near_edge(k, tri, t_cpu, f)
                        || near_edge(g.instance, g.triangle, t_gpu, f);
                    f.others_unexplained += usize::from(!explained);
                    return;
                }
                let dt = (t_gpu - t_cpu).abs();
                f.worst_rel_t = f.worst_rel_t.max(dt / t_cpu.abs().max(1e-300));
                let len = q.ray.dir.length();
                let rel = dt * len / (t_cpu.abs() * len + (q.ray.origin - reference).length());
                let [a, b, c3] = world.corners(k, tri);
                let n = (b - a).cross(c3 - a).normalize();
                let cos = n.dot(q.ray.dir.normalize()).abs();
                if cos >= GRAZING_COS {
                    f.worst_rel = f.worst_rel.max(rel);
                    f.over += usize::from(rel > DEPTH_REL);
                } else {
                    f.worst_rel_grazing = f.worst_rel_grazing.max(rel);
                    f.grazing += 1;
                }
                let scale = world.scale(k, q, t_cpu, reference);
                f.worst_cos_scaled = f
                    .worst_cos_scaled
                    .max(dt * q.ray.dir.length() * cos / (F32_EPS * scale));
                // Where on the triangle (barycentrics, the shading normal interpolated by them): held
                // to the bounds at an angle; a grazing hit's position along the surface moves by
                // |Δt| (up to 1/|cos θ| of the rounding), so only reported there.
                let grazing = cos < GRAZING_COS;
                let db = (0..3)
                    .map(|i| (g.barycentric[i] - weights[i]).abs())
                    .fold(0.0, f64::max);
                // The points the two sets of weights name on the (f64, world) triangle.
                // (relative to corner a: weights that do not sum to 1 exactly must not count
                // the triangle's distance from the origin).
                let at = |w: [f64; 3]| (b - a) * w[1] + (c3 - a) * w[2];
                let dp = (at(g.barycentric) - at(weights)).length();
                f.worst_bary_point = f.worst_bary_point.max(dp * cos / (F32_EPS * scale));
                // Normals: the CPU instance's world normals of the face and of the interpolated
                // vertex normals.
                f.worst_normal = f.worst_normal.max((g.normal - c.normal).length());
                let dn = (g.shading_normal - c.shading_normal).length();
                // The uvs: the CPU's interpolation (f64) at the GPU's own weights, against the GPU's
                // (f32 corners, f32 sums); the weights themselves are held by the bound above.
                let mesh = world.instances[k as usize].mesh.mesh();
                if let Some(uvs) = &mesh.uvs {
                    let corners = mesh.triangles[tri as usize].map(|v| uvs[v as usize]);
                    let uv_at =
                        |w: [f64; 3]| (0..3).fold(DVec2::ZERO, |s, i| s + corners[i] * w[i]);
                    let size = corners
                        .iter()
                        .map(|u| u.abs().max_element())
                        .fold(0.0, f64::max);
                    f.uvs += 1;
                    f.worst_uv = f.worst_uv.max((g.uv - c.uv).abs().max_element());
                    let off = (g.uv - uv_at(g.barycentric)).abs().max_element();
                    f.worst_uv_arithmetic = f
                        .worst_uv_arithmetic
                        .max(off / (F32_EPS * size.max(f64::MIN_POSITIVE)));
                }
                if grazing {
                    f.worst_grazing_bary = f.worst_grazing_bary.max(db);
                    f.worst_grazing_shading_normal = f.worst_grazing_shading_normal.max(dn);
                } else {
                    f.worst_bary = f.worst_bary.max(db);
                    f.worst_shading_normal = f.worst_shading_normal.max(dn);
                }
            }
        }
    }

    /// Whether the GPU's triangle is hit by the f64 test at (nearly) the CPU's depth: coincident or
    /// touching triangles, where which one wins is a tie.
    fn same_depth_elsewhere(
        world: &World,
        q: &CaseRay,
        g: &MeshAnswer,
        t_cpu: f64,
        scale: f64,
    ) -> bool {
        let inst = &world.instances[g.instance as usize];
        let local = Ray {
            origin: inst.to_world().inverse().transform_point3(q.ray.origin),
            dir: inst.to_world().inverse().transform_vector3(q.ray.dir),
        };
        let frame = fray_mesh::triangle::RayFrame::new(&local);
        let corners = inst.mesh.mesh().corners(g.triangle as usize);
        fray_mesh::triangle::intersect(
            &frame,
            corners,
            Interval::new(f64::NEG_INFINITY, f64::INFINITY),
        )
        .is_some_and(|h| (h.t - t_cpu).abs() * q.ray.dir.length() <= DEPTH_K * F32_EPS * scale)
    }

    /// The bounds every comparison keeps (see the module docs), disagreements (explained ones)
    /// on at most 0.2 % of the rays.
    fn check(what: &str, f: &Figures) {
        check_within(what, f, MAX_DISAGREEING);
    }

    /// At most this fraction of the rays hit on one side only or hit another triangle (all of them
    /// explained), except rays aimed at vertices and edges.
    const MAX_DISAGREEING: f64 = 2e-3;

    /// The bounds, disagreements on at most `disagreeing` of the rays.
    fn check_within(what: &str, f: &Figures, disagreeing: f64) {
        assert!(
            f.both * 10 > f.rays,
            "{what}: too few hits to compare ({} of {})",
            f.both,
            f.rays
        );
        assert_eq!(
            f.flips_unexplained, 0,
            "{what}: hit/miss flips away from edges"
        );
        assert_eq!(
            f.others_unexplained, 0,
            "{what}: another triangle away from edges"
        );
        assert_eq!(
            f.over, 0,
            "{what}: depths beyond {DEPTH_REL}·(t + |o − ref|)"
        );
        assert!(
            f.worst_cos_scaled <= DEPTH_K,
            "{what}: |Δt| |cos θ| = {} ε scale",
            f.worst_cos_scaled
        );
        assert!(
            f.worst_bary_point <= BARY_K,
            "{what}: barycentric points differ by {} ε scale / |cos θ|",
            f.worst_bary_point
        );
        assert!(
            f.worst_normal <= NORMAL_BOUND && f.worst_shading_normal <= SHADING_NORMAL_BOUND,
            "{what}: normals differ by {} (shading {})",
            f.worst_normal,
            f.worst_shading_normal
        );
        assert!(
            f.worst_uv_arithmetic <= UV_K,
            "{what}: uvs off the CPU's interpolation at the GPU's weights by {} ε max|uv|",
            f.worst_uv_arithmetic
        );
        assert_eq!(
            f.any_unexplained, 0,
            "{what}: any-hit differs away from edges"
        );
        // Disagreements are rare even where explained.
        assert!(
            (f.flips + f.others) as f64 <= disagreeing * f.rays as f64,
            "{what}: {} flips and {} other triangles in {} rays",
            f.flips,
            f.others,
            f.rays
        );
    }

    /// Every pixel's camera ray of a `size × size` pinhole view from `eye` toward `at`.
    fn camera_queries(eye: DVec3, at: DVec3, fov_deg: f64, size: u32) -> Vec<CaseRay> {
        let camera = Projector::Pinhole(
            Pinhole::new(eye, at, DVec3::Y, fov_deg.to_radians(), 1e-3).unwrap(),
        );
        let mut out = Vec::with_capacity((size * size) as usize);
        for y in 0..size {
            for x in 0..size {
                let c = camera.pixel_ray(x, y, size, size).expect("camera ray");
                out.push(CaseRay {
                    ray: c.ray,
                    range: Interval::new(c.t_near, f64::INFINITY),
                });
            }
        }
        out
    }

    /// `n` rays from a sphere around `b` (1.5 to 3 half-diagonals out) toward random points of it.
    fn random_queries(rng: &mut Rng, b: &Aabb, n: usize) -> Vec<CaseRay> {
        let r = b.diagonal() * 0.5;
        (0..n)
            .map(|_| {
                let o = b.center() + rng.direction() * r * (1.5 + 1.5 * rng.unit());
                let ray = Ray::new(o, rng.in_box(b.min, b.max) - o).unwrap();
                CaseRay {
                    ray,
                    range: Interval::new(0.0, f64::INFINITY),
                }
            })
            .collect()
    }

    /// Shadow-ray and next-hit segments around the CPU's hits of `queries`: `(lo, t(1 − 1e-3))`
    /// (nothing), `(lo, t(1 + 1e-3))` (the hit) and `(t(1 + 1e-3), ∞)` (what lies behind it).
    fn segments(world: &World, queries: &[CaseRay]) -> Vec<CaseRay> {
        let mut out = Vec::new();
        let hits = Cpu.meshes(&world.instances, DVec3::ZERO, queries);
        for (q, h) in queries.iter().zip(&hits) {
            if let Some(t) = h.t {
                for range in [
                    Interval::new(q.range.lo, t * (1.0 - 1e-3)),
                    Interval::new(q.range.lo, t * (1.0 + 1e-3)),
                    Interval::new(t * (1.0 + 1e-3), f64::INFINITY),
                ] {
                    out.push(CaseRay { ray: q.ray, range });
                }
            }
        }
        out
    }

    fn run_case(what: &str, world: &World, queries: &[CaseRay], reference: DVec3) -> Figures {
        let f = measure(what, world, queries, reference, || {
            gpu().meshes(&world.instances, reference, queries)
        });
        check(what, &f);
        f
    }

    pub fn bunny_camera_and_random_rays() {
        let world = World::new(vec![bunny()], &[(0, DAffine3::IDENTITY)]);
        let b = world.bounds();
        let eye = DVec3::new(0.4, 0.5, 2.2);
        let camera = camera_queries(eye, b.center(), 35.0, 256);
        run_case("bunny, camera 256²", &world, &camera, eye);
        let mut rng = Rng(1);
        let random = random_queries(&mut rng, &b, 40_000);
        run_case(
            "bunny, random rays",
            &world,
            &random,
            b.center() + DVec3::new(0.0, 0.0, 3.0),
        );
        let segs = segments(&world, &camera[..camera.len() / 2]);
        run_case("bunny, segments around the camera hits", &world, &segs, eye);
    }

    pub fn boeing_camera_and_random_rays() {
        let world = World::new(vec![boeing()], &[(0, DAffine3::IDENTITY)]);
        let b = world.bounds();
        let eye = DVec3::new(20.0, 14.0, 30.0);
        let camera = camera_queries(eye, b.center(), 40.0, 256);
        run_case("boeing, camera 256²", &world, &camera, eye);
        let mut rng = Rng(2);
        let random = random_queries(&mut rng, &b, 40_000);
        run_case("boeing, random rays", &world, &random, DVec3::ZERO);
        let segs = segments(&world, &random);
        run_case(
            "boeing, segments around the random hits",
            &world,
            &segs,
            DVec3::ZERO,
        );
    }

    /// A point inside the closed bunny: an odd number of crossings along three rays.
    fn inside(bvh: &MeshBvh, p: DVec3) -> bool {
        [DVec3::X, DVec3::Y, DVec3::new(0.3, -0.5, 0.8)]
            .iter()
            .all(|&d| {
                let ray = Ray::new(p, d).unwrap();
                let (mut n, mut lo) = (0, 0.0);
                while let Some(h) = bvh.nearest_hit(&ray, Interval::new(lo, f64::INFINITY)) {
                    n += 1;
                    lo = h.t;
                }
                n % 2 == 1
            })
    }

    /// From inside the closed bunny no ray escapes on the GPU either: rays from the mesh's anchor
    /// aimed exactly at every f32 vertex as uploaded (the origin is 0 in the mesh's f32 frame and the
    /// direction the vertex itself, so the f32 ray passes through it exactly), at an edge midpoint
    /// of every triangle, and in random directions from eight inside points.
    pub fn no_ray_escapes_the_closed_bunny() {
        let bvh = bunny();
        let world = World::new(vec![bvh.clone()], &[(0, DAffine3::IDENTITY)]);
        let anchor = {
            let b = bvh.bounds();
            (b.min + b.max) * 0.5
        };
        assert!(inside(&bvh, anchor), "the anchor is inside the bunny");
        let mut pass = world.pass(anchor);
        let mesh = bvh.mesh();
        // Vertex-aimed, exactly in f32.
        let vertex_queries: Vec<CaseRay> = mesh
            .positions
            .iter()
            .map(|p| {
                let d = (*p - anchor).as_vec3().as_dvec3();
                CaseRay {
                    ray: Ray {
                        origin: anchor,
                        dir: d,
                    },
                    range: Interval::new(0.0, f64::INFINITY),
                }
            })
            .collect();
        let f = measure(
            "bunny from inside, aimed at every f32 vertex",
            &world,
            &vertex_queries,
            anchor,
            || gpu().mesh_answers(&pass, anchor, &vertex_queries),
        );
        assert_eq!(f.gpu_misses, 0, "rays escaped the bunny through a vertex");
        check_within("bunny from inside, vertices", &f, 1.0);
        let mut escaped = f.gpu_misses;
        let mut rays = f.rays;
        // Eight inside points: edge midpoints and random directions, relative to each point.
        let mut rng = Rng(7);
        let mut origins = vec![anchor];
        while origins.len() < 8 {
            let o = anchor + rng.direction() * 0.05;
            if inside(&bvh, o) {
                origins.push(o);
            }
        }
        for (k, &o) in origins.iter().enumerate() {
            pass.rebase(gpu().context(), o).unwrap();
            let mut queries: Vec<CaseRay> = mesh
                .triangles
                .iter()
                .enumerate()
                .skip(k)
                .step_by(origins.len())
                .flat_map(|(t, tri)| {
                    let p = tri.map(|v| mesh.positions[v as usize]);
                    [
                        (p[t % 3] + p[(t + 1) % 3]) * 0.5,
                        (p[(t + 1) % 3] + p[(t + 2) % 3]) * 0.5,
                    ]
                })
                .map(|target| CaseRay {
                    ray: Ray::new(o, target - o).unwrap(),
                    range: Interval::new(0.0, f64::INFINITY),
                })
                .collect();
            queries.extend((0..6_000).map(|_| CaseRay {
                ray: Ray::new(o, rng.direction()).unwrap(),
                range: Interval::new(0.0, f64::INFINITY),
            }));
            let f = measure(
                &format!("bunny from inside point {k}, edge midpoints and random"),
                &world,
                &queries,
                o,
                || gpu().mesh_answers(&pass, o, &queries),
            );
            check_within("bunny from inside", &f, 1.0);
            escaped += f.gpu_misses;
            rays += f.rays;
        }
        eprintln!("bunny from inside: {rays} rays, {escaped} escaped");
        assert_eq!(
            escaped, 0,
            "{escaped} of {rays} rays escaped the closed bunny on the GPU"
        );
        assert!(rays >= 100_000, "{rays}");
    }

    /// Several meshes and instances share one set of buffers: the boeing three times (rotated,
    /// scaled non-uniformly, translated; one mirrored) and the bunny scaled up among them.
    pub fn instances_rotated_scaled_translated() {
        let placements = [
            (0, DAffine3::IDENTITY),
            (
                0,
                DAffine3::from_scale_rotation_translation(
                    DVec3::new(0.5, 1.5, 2.0),
                    DQuat::from_euler(glam::EulerRot::YXZ, 0.7, -0.3, 0.2),
                    DVec3::new(30.0, -4.0, 7.0),
                ),
            ),
            (
                0,
                DAffine3::from_scale_rotation_translation(
                    DVec3::new(-1.0, 1.0, 1.0),
                    DQuat::from_rotation_z(1.1),
                    DVec3::new(-25.0, 6.0, -10.0),
                ),
            ),
            (
                1,
                DAffine3::from_scale_rotation_translation(
                    DVec3::splat(8.0),
                    DQuat::from_rotation_x(-0.4),
                    DVec3::new(5.0, 20.0, -15.0),
                ),
            ),
        ];
        let world = World::new(vec![boeing(), bunny()], &placements);
        let b = world.bounds();
        let eye = b.center() + DVec3::new(5.0, 25.0, 55.0);
        let camera = camera_queries(eye, b.center(), 45.0, 256);
        run_case("instances, camera 256²", &world, &camera, eye);
        let mut rng = Rng(5);
        let random = random_queries(&mut rng, &b, 40_000);
        run_case("instances, random rays", &world, &random, b.center());
        // Which instance is hit: every one of them is seen.
        let hits = gpu().meshes(&world.instances, eye, &camera);
        for k in 0..placements.len() as u32 {
            assert!(
                hits.iter().any(|h| h.t.is_some() && h.instance == k),
                "instance {k} never hit"
            );
        }
    }

    /// The bunny with planar uvs, `(4x + 1, 4z − 2)`: a few units, not centred on 0.
    fn uv_bunny() -> MeshBvh {
        let m = bunny().mesh().clone();
        let uvs = m
            .positions
            .iter()
            .map(|p| DVec2::new(4.0 * p.x + 1.0, 4.0 * p.z - 2.0))
            .collect();
        let mesh =
            TriangleMesh::with_attributes(m.positions, m.triangles, Some(m.normals), Some(uvs))
                .unwrap();
        MeshBvh::build(mesh)
    }

    /// Uvs: the bunny with planar uvs, as it is and mirrored, scaled and turned by a second
    /// instance, on camera and random rays — the GPU's uv on every ray both hit on the same triangle
    /// is the CPU's interpolation at the GPU's own weights within [`UV_K`] (and every other bound
    /// holds).
    pub fn uvs_are_interpolated_like_the_cpu() {
        let placements = [
            (0, DAffine3::IDENTITY),
            (
                0,
                DAffine3::from_scale_rotation_translation(
                    DVec3::new(-2.0, 2.0, 2.0),
                    DQuat::from_rotation_y(0.8),
                    DVec3::new(0.6, 0.0, 0.0),
                ),
            ),
        ];
        let world = World::new(vec![Arc::new(uv_bunny())], &placements);
        let b = world.bounds();
        let eye = b.center() + DVec3::new(0.4, 0.5, 2.2);
        let camera = camera_queries(eye, b.center(), 40.0, 192);
        let mut rng = Rng(11);
        let random = random_queries(&mut rng, &b, 20_000);
        for (what, queries, reference) in [
            ("bunny with uvs, camera 192²", camera, eye),
            ("bunny with uvs, random rays", random, b.center()),
        ] {
            let f = run_case(what, &world, &queries, reference);
            assert!(
                f.uvs * 10 > f.both * 9,
                "{what}: {} uvs of {} hits",
                f.uvs,
                f.both
            );
        }
    }

    /// The bunny with its vertices moved by `offset`.
    fn moved_bunny(offset: DVec3) -> MeshBvh {
        let m = bunny().mesh().clone();
        let moved = TriangleMesh::with_attributes(
            m.positions.iter().map(|p| *p + offset).collect(),
            m.triangles.clone(),
            Some(m.normals.clone()),
            None,
        )
        .unwrap();
        MeshBvh::build(moved)
    }

    /// A mesh far from the origin: the bunny with its vertices moved by ~10⁵ (where f32's spacing
    /// is 1/128, a hundredth of the bunny's size: absolute f32 positions would put depths off by
    /// ~10⁻³ of t) seen from a camera near it, and the bunny placed by an instance translation of
    /// ~10⁶ — f32 positions relative to the mesh's anchor and the instance maps relative to the
    /// camera, both from f64, keep the near-origin bounds.
    ///
    /// Further out the stack policy answers: `MeshBvh::build` takes its topology from the f32
    /// triangles, which at 4·10⁵ collapse onto a few f32 points, and the BVH it builds is ~200
    /// deep — refused as `TooLarge` (more stack entries than `MESH_STACK`), not traversed wrongly.
    pub fn a_mesh_far_from_the_origin() {
        let deep = moved_bunny(DVec3::new(0.68, -0.32, 1.0) * 4e5);
        let depth = deep.max_depth();
        if depth + 1 > fray_mesh::gpu_layout::MESH_STACK {
            let e = fray_gpu::testing::MeshBatch::new(
                gpu().context(),
                &[&deep],
                &[(0, DAffine3::IDENTITY)],
                DVec3::ZERO,
            )
            .unwrap_err();
            assert!(
                matches!(e, fray_gpu::GpuError::TooLarge { needed, .. } if needed == u64::from(depth) + 1),
                "{e}"
            );
            eprintln!("bunny moved by 4e5 in its vertices: BVH depth {depth}, refused: {e}");
        }
        let offset = DVec3::new(0.68, -0.32, 1.0) * 1e5;
        let world = World::new(
            vec![Arc::new(moved_bunny(offset))],
            &[(0, DAffine3::IDENTITY)],
        );
        let b = world.bounds();
        let eye = b.center() + DVec3::new(0.4, 0.5, 2.2);
        let camera = camera_queries(eye, b.center(), 35.0, 192);
        run_case("bunny moved by 1e5 in its vertices", &world, &camera, eye);
        let placed = World::new(
            vec![bunny()],
            &[(
                0,
                DAffine3::from_rotation_translation(
                    DQuat::from_rotation_y(0.3),
                    DVec3::new(-1e6, 3e5, 7e5),
                ),
            )],
        );
        let b = placed.bounds();
        let eye = b.center() + DVec3::new(0.4, 0.5, 2.2);
        let camera = camera_queries(eye, b.center(), 35.0, 192);
        run_case("bunny placed at 1e6 by its instance", &placed, &camera, eye);
    }

    /// A moved camera rewrites only the instance blocks (`MeshBatch::rebase`): the same world rays,
    /// relative to the new reference, hit the same triangles.
    pub fn rebased_instances_hit_the_same() {
        let world = World::new(vec![boeing()], &[(0, DAffine3::from_rotation_y(0.4))]);
        let b = world.bounds();
        let eye = DVec3::new(20.0, 14.0, 30.0);
        let camera = camera_queries(eye, b.center(), 40.0, 128);
        let mut pass = world.pass(eye);
        let first = gpu().mesh_answers(&pass, eye, &camera);
        let moved = eye + DVec3::new(3.0, -1.0, 2.0);
        let written = pass.rebase(gpu().context(), moved).unwrap();
        assert_eq!(written, 64, "one instance block rewritten");
        let f = measure(
            "boeing, rebased to a moved reference",
            &world,
            &camera,
            moved,
            || gpu().mesh_answers(&pass, moved, &camera),
        );
        check("boeing, rebased", &f);
        let second = gpu().mesh_answers(&pass, moved, &camera);
        let same = first
            .iter()
            .zip(&second)
            .filter(|(a, b)| (a.instance, a.triangle) == (b.instance, b.triangle))
            .count();
        assert!(
            same as f64 >= 0.999 * camera.len() as f64,
            "{same} of {}",
            camera.len()
        );
    }

    /// The edge distance the acceptance rule uses: from the ray's line to the nearest edge segment.
    pub fn edge_distance_is_from_the_line_to_the_nearest_segment() {
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        // A ray down the z axis through (0.5, 0.1): 0.1 from the edge on the x axis.
        let ray = Ray::new(DVec3::new(0.5, 0.1, 5.0), -DVec3::Z).unwrap();
        assert!((edge_distance(&ray, tri) - 0.1).abs() < 1e-12);
        // Past the end of a segment: the distance to its end point.
        let ray = Ray::new(DVec3::new(-0.3, -0.4, 5.0), -DVec3::Z).unwrap();
        assert!((edge_distance(&ray, tri) - 0.5).abs() < 1e-12);
        // A ray parallel to an edge.
        let ray = Ray::new(DVec3::new(0.0, -0.2, 1.0), DVec3::X).unwrap();
        let want = (0.2f64 * 0.2 + 1.0).sqrt();
        assert!((edge_distance(&ray, tri) - want).abs() < 1e-12);
    }
}
