//! One ray-by-ray suite, written once and run by both backends (as fidget runs one suite against
//! every evaluator): each backend answers the same rays — nearest hit, its normal, the any-hit
//! answer over the same range — and each answer is checked against an **independent reference**,
//! not against the other backend: the solids' own function `F` (`Solid::eval`, inside where
//! `F ≥ 0`) sampled in f64 along the ray (2048 samples per box diagonal of each solid), every sign
//! change refined by bisection to 1e-12 — no interval bound, closed form or search of either
//! caster. (The CPU caster's full contract, every span at least `ε` thick found, is proven
//! against a double-double reference in `fray-geometry`'s accuracy tests.)
//!
//! A backend states its bounds ([`Bounds`]): `depth(t)`, how far its hit may be from where the
//! reference's first inside span begins, and `sliver(t)`, the thickness of a span it may step
//! over (the CPU's contract: every span at least `ε` long is found; the GPU's leaves are not
//! widened by their f32 rounding, so grazing rays may miss a span a few `ε_gpu` thick). The
//! checks, per ray:
//! - **hit**: no reference span at least `sliver` thick (and not grazed) begins more than
//!   `depth / |cos θ|` before it, and
//!   the point is within `depth / |cos θ|` of an inside point (a reference span, or `F ≥ 0` at one of 64
//!   points around it: the reference's sampling may step over a sliver the backend found);
//! - **miss**: every reference span is thinner than `sliver` or entered at a grazing angle
//!   (`|cos θ| < 0.05` to the surface: a ray that runs just inside a surface for a long way);
//! - **normal**: within `normal` of the reference's (`Solid::surface_at` at the reference hit),
//!   where both points have the same deciding leaf and the surface is not grazed;
//! - **any hit**: true wherever the nearest hit is outside a grazed span, and wherever a span the
//!   backend must find lies on the range.
//!
//! Meshes: each backend's nearest hit and geometric normal against a brute force over every
//! triangle of every instance in world space (f64 Möller–Trumbore: no BVH, and not the
//! watertight test either backend uses), on camera rays of the mesh data scenes
//! (`mesh_bunny_freeform.ron`, `mesh_aircraft_pair.ron`) and from a camera 10³ back: the depth
//! across the triangle's plane within `depth · scale`, the normal within `normal`, a hit/miss or
//! triangle difference only within `edge · scale` of an edge (`scale`: the lengths f32 positions
//! are rounded relative to — `tests/mesh_parity.rs`'s bounds on the GPU, which also holds the
//! harder mesh cases: rays from inside the closed bunny, mirrored and far instances).
//!
//! Terrains: each backend's exact hit and normal on the DEM scenes (`terrain_low.ron`,
//! `terrain_high.ron`: from 1.25 km and from 66 km up) and from a camera 10⁴ back, against the
//! map's interpolated height (`Terrain::surface`) sampled at an eighth of a cell along the ray
//! and bisected, and its central differences for the normal (away from cell edges, where the
//! bilinear patches' normals jump): a hit within `depth(t) / |cos θ|` of where the ray goes
//! under, or within `depth(t)` above a ridge it skims; a miss only of a span shorter than 50
//! depth bounds.
//!
//! Media: each backend's transmittance and optical depth of the fog data scenes' layers against
//! a composite Simpson quadrature of the extinction (4096 intervals), from the scenes' cameras,
//! from inside the layer and from its top, over a fan of elevations (the horizontal exactly) and
//! ranges of 1 m to 20 km or unbounded: 810 rays. The sky's aerial perspective (transmittance,
//! in-scatter) and transmittance to the sun against its adaptive-quadrature reference, from the
//! sky scenes' cameras and 10 km above them: 240 rays. The clouds' march transmittance and
//! optical depth against the volume's density integrated at a 64th of the step: 534 rays of the
//! cloud scenes, from inside the cloud among them.
//!
//! Cases: camera rays of the free-form data scenes (`csg.ron`, `turboprop.ron`), grazing rays
//! (along the tangent plane at each hit, just outside the surface), and far rays (the camera
//! rays started 10⁴ back along themselves: long `t`, f32 positions far from the reference on the
//! GPU). The case counts are printed. The GPU runs in f32 relative to the camera
//! (`fray_gpu::testing::FreeFormBatch`), the CPU in f64 (`fray_geometry::RayCaster`).
//!
//! Uses the libtest-mimic harness: the GPU's run is ignored without an adapter and a failure
//! under `FRAY_REQUIRE_GPU=1`; the CPU's always runs.

mod common;

use fray_atmosphere::gpu_layout::GpuFog;
use fray_clouds::march::{self, CloudLight};
use fray_core::{Interval, Ray};
use fray_geometry::{CastStats, RayCaster, Solid};
use fray_gpu::testing::{
    CloudsBatch, FogBatch, FreeFormBatch, GpuCloudRay, GpuFogRay, GpuRay, GpuSkyQuery, MeshBatch,
    SkyBatch, SkySeen, TerrainBatch,
};
use fray_mesh::{Instance, MeshBvh};
use fray_scene::Fog;
use fray_scene::Scene;
use fray_terrain::Terrain;
use glam::DVec3;
use std::path::Path;

/// One ray of a case: world space, unit direction, over `range`.
#[derive(Clone, Copy, Debug)]
struct CaseRay {
    ray: Ray,
    range: Interval,
}

/// What a backend found on a ray.
#[derive(Clone, Copy, Debug)]
struct Answer {
    /// The nearest hit's distance, `None` for a miss.
    t: Option<f64>,
    /// The outward unit normal there (zero for a miss).
    normal: DVec3,
    /// The any-hit answer over the same range.
    any: bool,
}

/// What a backend holds its answers to, against the reference.
#[derive(Clone, Copy, Debug)]
struct Bounds {
    /// How far (world units) a hit may be from where the reference's first span begins, at `t`.
    depth: fn(f64, &Tolerance) -> f64,
    /// The thickness of a span the backend may step over, at `t`.
    sliver: fn(f64, &Tolerance) -> f64,
    /// How far its unit normal may be from the reference's.
    normal: f64,
}

/// The tolerances a case is cast with: the scene's ε and the GPU's (`fray_gpu::gpu_epsilon`).
#[derive(Clone, Copy, Debug)]
struct Tolerance {
    eps: f64,
    eps_gpu: f64,
}

/// A backend of the suite.
trait Backend {
    fn name(&self) -> &'static str;
    fn bounds(&self) -> Bounds;
    /// Nearest hit over `solids`, its normal and the any-hit answer, for each ray; `reference`
    /// is the point a backend that works relative to one (the GPU) takes positions from.
    fn free_forms(
        &self,
        solids: &[&Solid],
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer>;
    /// Nearest hit over the mesh `instances`, its world geometric normal and the any-hit answer,
    /// for each ray.
    fn meshes(&self, instances: &[Instance], reference: DVec3, rays: &[CaseRay]) -> Vec<Answer>;
    /// How far its mesh hits may be from the reference: across the triangle's plane, and from
    /// an edge where a ray may go either way (at a scale `scale`: the lengths its positions are
    /// rounded relative to); and its normals.
    fn mesh_bounds(&self) -> MeshBounds;
    /// Nearest hit on `terrain` (exact: no level of detail) and its normal, for each ray, with
    /// the backend's ε as the bicubic root tolerance.
    fn terrain(
        &self,
        terrain: &Terrain,
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer>;
    /// How far its terrain hits may be from the reference (`depth(t)`, as [`Bounds::depth`])
    /// and its normals.
    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64);
    /// The transmittance and optical depth of `fog` over each ray's range; every ray starts at
    /// the camera, at height `camera_y` (a backend that works relative to it takes heights from
    /// there).
    fn fog(&self, fog: &Fog, camera_y: f64, rays: &[CaseRay]) -> Vec<Medium>;
    /// How far its fog answers may be from the reference: `abs + rel · |reference|`.
    fn medium_bounds(&self) -> (f64, f64);
    /// The sky seen from `eye` along each ray (its origin the eye) to its range's end: the
    /// aerial perspective's transmittance and in-scatter (RGB), and the transmittance to the sun
    /// at the ray's point at `min(end, 10⁴)`.
    fn sky(&self, sky: &fray_scene::Sky, eye: DVec3, rays: &[CaseRay]) -> Vec<SkyAnswer>;
    /// The cloud march's transmittance and the optical depth (at the march's step) of each ray
    /// through `clouds` lit by `light`; `reference` as for [`Backend::free_forms`].
    fn clouds(
        &self,
        clouds: &fray_scene::Clouds,
        light: &CloudLight,
        reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<Medium>;
}

/// What the sky gave a ray.
#[derive(Clone, Copy, Debug)]
struct SkyAnswer {
    transmittance: DVec3,
    in_scatter: DVec3,
    to_sun: DVec3,
}

/// The point along `r` the sky's transmittance to the sun is asked at.
fn sun_point(r: &CaseRay) -> DVec3 {
    r.ray.at(r.range.hi.min(1e4))
}

/// A backend's mesh bounds, each `k · scale` (world units).
#[derive(Clone, Copy, Debug)]
struct MeshBounds {
    depth: f64,
    edge: f64,
    normal: f64,
}

/// What a medium did to a ray.
#[derive(Clone, Copy, Debug)]
struct Medium {
    transmittance: f64,
    optical_depth: f64,
}

/// The f64 CPU backend: `fray_geometry::RayCaster` at the scene's ε.
struct Cpu;

impl Backend for Cpu {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            // The caster's contract: never past a span at least ε long by more than ε, up to the
            // f64 rounding of `F` it widens every leaf by (which the reference's own evaluation
            // shares), conditioned by the gradient along the ray. The rounding grows with the
            // terms, as the square of the distance from a quadric's origin and faster for a
            // perturbation's cube: measured up to 2.6e-9·t near the camera and 1.4e-2 at t = 10⁴
            // (turboprop's far rays: 1.4e-14·t³).
            depth: |t, tol| tol.eps + 1e-8 * t + 2e-14 * t * t * t,
            sliver: |t, tol| tol.eps + 1e-8 * t + 2e-14 * t * t * t,
            normal: 1e-6,
        }
    }

    fn free_forms(
        &self,
        solids: &[&Solid],
        _reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer> {
        let mut caster = RayCaster::new();
        let mut stats = CastStats::default();
        rays.iter()
            .map(|r| {
                let mut best: Option<(f64, usize)> = None;
                for (k, solid) in solids.iter().enumerate() {
                    let range = Interval::new(r.range.lo, best.map_or(r.range.hi, |b| b.0));
                    let hit = caster.cast(solid, &r.ray, range, tol.eps, &mut stats);
                    if let Some(t) = hit.filter(|&t| best.is_none_or(|b| t < b.0)) {
                        best = Some((t, k));
                    }
                }
                let normal = best.map_or(DVec3::ZERO, |(t, k)| {
                    solids[k].surface_at(r.ray.at(t), -r.ray.dir).0
                });
                let any = solids
                    .iter()
                    .any(|s| caster.occludes(s, &r.ray, r.range, tol.eps, None, &mut stats));
                Answer {
                    t: best.map(|b| b.0),
                    normal,
                    any,
                }
            })
            .collect()
    }

    fn meshes(&self, instances: &[Instance], _reference: DVec3, rays: &[CaseRay]) -> Vec<Answer> {
        rays.iter()
            .map(|r| {
                let mut best: Option<(f64, usize, u32)> = None;
                for (k, instance) in instances.iter().enumerate() {
                    let range = Interval::new(r.range.lo, best.map_or(r.range.hi, |b| b.0));
                    let hit = instance.nearest_hit(&r.ray, range);
                    if let Some(h) = hit.filter(|h| best.is_none_or(|b| h.t < b.0)) {
                        best = Some((h.t, k, h.triangle));
                    }
                }
                // The CPU's way: the mesh-space normal through the instance's normal matrix.
                let normal = best.map_or(DVec3::ZERO, |(_, k, triangle)| {
                    let local =
                        triangle_normal(&instances[k].mesh.mesh().corners(triangle as usize));
                    instances[k].world_normal(local)
                });
                Answer {
                    t: best.map(|b| b.0),
                    normal,
                    any: instances.iter().any(|i| i.any_hit(&r.ray, r.range)),
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

    fn terrain(
        &self,
        terrain: &Terrain,
        _reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer> {
        let eps = tol.eps;
        rays.iter()
            .map(|r| {
                let hit = terrain.cast(&r.ray, r.range, eps);
                Answer {
                    t: hit.map(|h| h.t),
                    normal: hit.map_or(DVec3::ZERO, |h| h.normal),
                    any: terrain.occluded(&r.ray, r.range, eps),
                }
            })
            .collect()
    }

    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64) {
        // Each cell's surface solved in f64 (bilinear: a quadratic; bicubic to ε): measured
        // ≤ 0.05 of the depth bound, normals within 2.6e-9 of the central differences.
        (|t, tol| tol.eps + 1e-9 * t, 1e-7)
    }

    fn fog(&self, fog: &Fog, _camera_y: f64, rays: &[CaseRay]) -> Vec<Medium> {
        rays.iter()
            .map(|r| Medium {
                transmittance: fog.layer.transmittance(&r.ray, r.range),
                optical_depth: fog.layer.optical_depth(&r.ray, r.range),
            })
            .collect()
    }

    fn medium_bounds(&self) -> (f64, f64) {
        // The closed form against the quadrature: measured ≤ 2e-13 relative.
        (1e-13, 1e-11)
    }

    fn clouds(
        &self,
        clouds: &fray_scene::Clouds,
        light: &CloudLight,
        _reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<Medium> {
        rays.iter()
            .map(|r| {
                let (o, d) = (r.ray.origin.to_array(), r.ray.dir.to_array());
                let range = (r.range.lo, r.range.hi);
                let m = march::march(&clouds.volume, o, d, range, &clouds.march, light);
                Medium {
                    transmittance: m.transmittance,
                    optical_depth: march::optical_depth(
                        &clouds.volume,
                        o,
                        d,
                        range,
                        clouds.march.step,
                    ),
                }
            })
            .collect()
    }

    fn sky(&self, sky: &fray_scene::Sky, eye: DVec3, rays: &[CaseRay]) -> Vec<SkyAnswer> {
        rays.iter()
            .map(|r| {
                let air = sky
                    .sky
                    .aerial_perspective(eye, r.ray.dir, r.range.hi, sky.steps);
                SkyAnswer {
                    transmittance: air.transmittance,
                    in_scatter: air.in_scatter,
                    to_sun: sky.sky.transmittance_to_sun(sun_point(r), eye),
                }
            })
            .collect()
    }
}

/// The GPU backend: `freeform.wgsl` in f32, positions relative to the case's reference point
/// (the camera), at the GPU's ε (`fray_gpu::gpu_epsilon`).
struct Gpu {
    renderer: fray_gpu::GpuRenderer,
}

impl Backend for Gpu {
    fn name(&self) -> &'static str {
        "gpu"
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            // The frames' depth bound (tests/parity.rs): DEPTH_REL·t + 4·ε_gpu.
            depth: |t, tol| 2e-5 * t + 4.0 * tol.eps_gpu,
            sliver: |t, tol| 2e-5 * t + 4.0 * tol.eps_gpu,
            // f32 gradients: measured up to 6.7e-5 on csg's quadrics, 1.6e-2 on the turboprop's
            // perturbations (cubic terms cancelling near their support's edge).
            normal: 2e-2,
        }
    }

    fn free_forms(
        &self,
        solids: &[&Solid],
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer> {
        let ctx = self.renderer.context();
        let batch = FreeFormBatch::new(ctx, solids, reference).unwrap_or_else(|e| panic!("{e}"));
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
        let gpu_rays: Vec<GpuRay> = rays
            .iter()
            .map(|r| {
                let o = f(r.ray.origin - reference);
                let d = f(r.ray.dir);
                let hi = r.range.hi.min(1e30) as f32;
                [
                    [o[0], o[1], o[2], r.range.lo as f32],
                    [d[0], d[1], d[2], hi],
                ]
            })
            .collect();
        let hits = batch
            .cast(ctx, &gpu_rays, tol.eps_gpu as f32)
            .unwrap_or_else(|e| panic!("{e}"));
        hits.iter()
            .map(|h| Answer {
                t: h.is_hit().then_some(f64::from(h.t)),
                normal: DVec3::from(h.normal.map(f64::from)),
                any: h.any_hit,
            })
            .collect()
    }

    fn meshes(&self, instances: &[Instance], reference: DVec3, rays: &[CaseRay]) -> Vec<Answer> {
        let ctx = self.renderer.context();
        // Each distinct mesh once, as the resident scene uploads them.
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
        let batch = MeshBatch::new(ctx, &distinct, &placements, reference)
            .unwrap_or_else(|e| panic!("{e}"));
        let gpu_rays = relative_rays(rays, reference);
        batch
            .cast(ctx, &gpu_rays)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|h| Answer {
                t: h.is_hit().then_some(f64::from(h.t)),
                normal: DVec3::from(h.normal.map(f64::from)),
                any: h.any_hit,
            })
            .collect()
    }

    fn mesh_bounds(&self) -> MeshBounds {
        // tests/mesh_parity.rs's: DEPTH_K = 4 and EDGE_K = 64 units of f32 rounding of the
        // scale; geometric normals within 1e-4.
        let e = f64::from(f32::EPSILON);
        MeshBounds {
            depth: 4.0 * e,
            edge: 64.0 * e,
            normal: 1e-4,
        }
    }

    fn terrain(
        &self,
        terrain: &Terrain,
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
    ) -> Vec<Answer> {
        let ctx = self.renderer.context();
        let batch = TerrainBatch::new(ctx, terrain, reference)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_epsilon(tol.eps_gpu);
        batch
            .cast_hits(ctx, &relative_rays(rays, reference))
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|h| Answer {
                t: h.is_hit().then_some(f64::from(h.t)),
                normal: DVec3::from(h.normal.map(f64::from)),
                // The terrain's shadow test is the frame's shade pass's (tests/parity.rs).
                any: h.is_hit(),
            })
            .collect()
    }

    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64) {
        // tests/terrain_parity.rs's: depth within 1e-5·t, normals within 3e-4.
        (|t, tol| 1e-5 * t + 4.0 * tol.eps_gpu, 3e-4)
    }

    fn fog(&self, fog: &Fog, camera_y: f64, rays: &[CaseRay]) -> Vec<Medium> {
        let ctx = self.renderer.context();
        let block = GpuFog::new(&fog.layer, fog.model, camera_y);
        let batch = FogBatch::new(ctx, &block).unwrap_or_else(|e| panic!("{e}"));
        let gpu_rays: Vec<GpuFogRay> = rays
            .iter()
            .map(|r| {
                let d = r.ray.dir.as_vec3();
                let hi = r.range.hi.min(1e30) as f32;
                // Camera-relative: every ray starts at the camera. No sun (its factor is not
                // checked here).
                [
                    [0.0, 0.0, 0.0, r.range.lo as f32],
                    [d.x, d.y, d.z, hi],
                    [0.0, 1.0, 0.0, 0.0],
                ]
            })
            .collect();
        batch
            .terms(ctx, &gpu_rays)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|t| Medium {
                transmittance: f64::from(t.transmittance),
                optical_depth: f64::from(t.depth),
            })
            .collect()
    }

    fn medium_bounds(&self) -> (f64, f64) {
        // tests/fog_parity.rs's bound (f32, camera-relative heights; measured here 3e-3 of it).
        (1e-6, 5e-5)
    }

    fn clouds(
        &self,
        clouds: &fray_scene::Clouds,
        light: &CloudLight,
        reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<Medium> {
        let ctx = self.renderer.context();
        let block = fray_clouds::gpu_layout::GpuClouds::new(
            &clouds.volume,
            light,
            &clouds.march,
            true,
            reference.to_array(),
        );
        let batch = CloudsBatch::new(ctx, &clouds.volume, &block).unwrap_or_else(|e| panic!("{e}"));
        let queries: Vec<GpuCloudRay> = relative_rays(rays, reference)
            .into_iter()
            .map(|[a, b]| [a, b, [clouds.march.jitter as f32, 0.0, 0.0, 0.0]])
            .collect();
        batch
            .terms(ctx, &queries)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|t| Medium {
                transmittance: f64::from(t.transmittance),
                optical_depth: f64::from(t.optical_depth),
            })
            .collect()
    }

    fn sky(&self, sky: &fray_scene::Sky, eye: DVec3, rays: &[CaseRay]) -> Vec<SkyAnswer> {
        let ctx = self.renderer.context();
        let options = fray_atmosphere::gpu_layout::GpuSkyOptions {
            sun_disc: sky.sun_disc,
            aerial_perspective: true,
            steps: sky.steps,
            sun_light: Some(0),
        };
        let block = fray_atmosphere::gpu_layout::GpuSky::new(&sky.sky, eye.y, options);
        let view = sky.sky.view(eye);
        let batch = SkyBatch::new(ctx).unwrap_or_else(|e| panic!("{e}"));
        let seen = SkySeen {
            block: &block,
            transmittance: sky.sky.transmittance_table(),
            view: view.table(),
        };
        let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
        let queries: Vec<GpuSkyQuery> = rays
            .iter()
            .map(|r| {
                let d = f(r.ray.dir);
                let p = f(sun_point(r) - eye);
                let t = r.range.hi.min(1e30) as f32;
                // Eye-relative: the origin is the eye; no table query (h = 0, μ = 1).
                [
                    [0.0, 0.0, 0.0, t],
                    [d[0], d[1], d[2], 0.0],
                    [p[0], p[1], p[2], 1.0],
                ]
            })
            .collect();
        let rgb = |v: [f32; 3]| DVec3::from(v.map(f64::from));
        batch
            .answers(ctx, seen, &queries)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|a| SkyAnswer {
                transmittance: rgb(a.transmittance),
                in_scatter: rgb(a.in_scatter),
                to_sun: rgb(a.to_sun),
            })
            .collect()
    }
}

/// `rays` as the GPU's batches take them: f32, relative to `reference`, `t_hi` at most 1e30.
fn relative_rays(rays: &[CaseRay], reference: DVec3) -> Vec<GpuRay> {
    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
    rays.iter()
        .map(|r| {
            let o = f(r.ray.origin - reference);
            let d = f(r.ray.dir);
            let hi = r.range.hi.min(1e30) as f32;
            [
                [o[0], o[1], o[2], r.range.lo as f32],
                [d[0], d[1], d[2], hi],
            ]
        })
        .collect()
}

/// The unit normal of a triangle by its winding.
fn triangle_normal(c: &[DVec3; 3]) -> DVec3 {
    (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero()
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
            let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
            let p = r.ray.dir.cross(e2);
            let det = e1.dot(p);
            if det == 0.0 {
                continue;
            }
            let s = r.ray.origin - c[0];
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = r.ray.dir.dot(q) / det;
            let t = e2.dot(q) / det;
            if u < 0.0 || v < 0.0 || u + v > 1.0 || !r.range.contains(t) {
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
fn mesh_suite(backend: &dyn Backend) {
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

/// The reference's spans of `r` under `terrain`'s surface (inside the map's rectangle, below the
/// interpolated height — `Terrain::surface`, sampled at an eighth of a cell along the ray and
/// bisected; not the per-cell solve of either backend).
fn terrain_spans(terrain: &Terrain, r: &CaseRay) -> Vec<(f64, f64)> {
    let Some(range) = terrain.bounds().clip_ray(&r.ray, r.range) else {
        return Vec::new();
    };
    let m = terrain.placement().map_ray(&r.ray);
    let (lo, hi) = terrain.height_range();
    let extent = (hi - lo).max(1e-9);
    let below = |t: f64| {
        let p = m.origin + m.dir * t;
        terrain.surface(p.x, p.y).is_some_and(|h| p.z <= h)
    };
    let rate = m.dir.x.abs().max(m.dir.y.abs()).max(m.dir.z.abs() / extent);
    let step = 0.125 / rate.max(1e-12);
    let n = ((range.hi - range.lo) / step).ceil().clamp(1.0, 1e6) as usize;
    let h = (range.hi - range.lo) / n as f64;
    let mut spans = Vec::new();
    let mut prev = (range.lo, below(range.lo));
    let mut entry = prev.1.then_some(range.lo);
    for k in 1..=n {
        let t = if k == n {
            range.hi
        } else {
            range.lo + h * k as f64
        };
        let inside = below(t);
        if inside != prev.1 {
            let edge = bisect(&|u: f64| if below(u) { 1.0 } else { -1.0 }, prev.0, t);
            match entry.take() {
                Some(a) => spans.push((a, edge)),
                None => entry = Some(edge),
            }
        }
        prev = (t, inside);
    }
    if let Some(a) = entry {
        spans.push((a, range.hi));
    }
    spans
}

/// The reference normal of `terrain`'s surface at the map point under `p`: central differences
/// of the interpolated height; `None` within 10⁻³ of a cell's edge (where the bilinear patches'
/// normals jump) or off the surface.
fn terrain_normal(terrain: &Terrain, p: DVec3) -> Option<DVec3> {
    let q = terrain.placement().to_map(p);
    let near_edge = |x: f64| (x - x.round()).abs() < 1e-3;
    if near_edge(q.x) || near_edge(q.y) {
        return None;
    }
    let h = 1e-5;
    let s = |u: f64, v: f64| terrain.surface(u, v);
    let su = (s(q.x + h, q.y)? - s(q.x - h, q.y)?) / (2.0 * h);
    let sv = (s(q.x, q.y + h)? - s(q.x, q.y - h)?) / (2.0 * h);
    Some(terrain.placement().surface_normal(glam::DVec2::new(su, sv)))
}

/// The terrain cases: camera rays of the DEM scenes (exact, no level of detail), and the same
/// points seen from a camera 10⁴ back.
fn terrain_suite(backend: &dyn Backend) {
    let (depth_bound, normal_bound) = backend.terrain_bounds();
    let (mut rays_checked, mut hits, mut normals) = (0usize, 0usize, 0usize);
    let (mut worst_depth, mut worst_normal) = (0.0f64, 0.0f64);
    let mut failures = Vec::new();
    for name in ["terrain_low.ron", "terrain_high.ron"] {
        let scene = data_scene(name);
        let terrain = scene.terrains[0].terrain.clone();
        let reference = fray_gpu::params::reference_point(&scene.camera);
        let tol = Tolerance {
            eps: scene.epsilon(),
            eps_gpu: fray_gpu::gpu_epsilon(&scene, scene.epsilon()),
        };
        let camera = camera_rays(&scene, 40, 30);
        let (far_eye, far) = far_rays(&camera, reference, 1e4, 100.0);
        let far_tol = Tolerance {
            eps_gpu: tol.eps_gpu.max(fray_gpu::EPSILON_FLOOR * 1e4),
            ..tol
        };
        for (kind, rays, reference, tol) in [
            ("camera", camera, reference, tol),
            ("far", far, far_eye, far_tol),
        ] {
            let answers = backend.terrain(&terrain, reference, &rays, &tol);
            for (r, a) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let spans = terrain_spans(&terrain, r);
                let describe =
                    |what: &str| format!("{name} {kind}: {what} on {r:?}: {a:?} vs {spans:?}");
                let m = terrain.placement().map_ray(&r.ray);
                let vertical = terrain.placement().vertical_scale();
                // How far above the surface the ray is at `u` (world units; negative below).
                let clearance = |u: f64| {
                    let q = m.origin + m.dir * u;
                    terrain.surface(q.x, q.y).map(|h| (q.z - h) * vertical)
                };
                let grazing = |n: DVec3| 1.0 / n.dot(r.ray.dir).abs().max(0.02);
                // A span a backend must find: longer than its depth bound at a grazing angle.
                let thick = |s: &(f64, f64)| s.1 - s.0 > depth_bound(s.0, &tol) * 50.0;
                match a.t {
                    Some(t) => {
                        hits += 1;
                        let bound = |entry: f64| {
                            let n = terrain_normal(&terrain, r.ray.at(entry));
                            depth_bound(t, &tol) * n.map_or(50.0, grazing)
                        };
                        if let Some(s) = spans.iter().find(|s| s.0 < t - bound(s.0) && thick(s)) {
                            failures
                                .push(describe(&format!("a span at {:.3} before the hit", s.0)));
                            continue;
                        }
                        // The hit is on a span, or on a sliver the reference stepped over.
                        let reach = depth_bound(t, &tol) * 50.0;
                        let on_span = spans.iter().find(|s| (s.0 - t).abs() <= bound(s.0));
                        // A ridge skimmed within the depth bound counts as touched.
                        let touch = depth_bound(t, &tol);
                        let near = (0..=64).any(|k| {
                            let u = t - reach + 2.0 * reach * f64::from(k) / 64.0;
                            clearance(u).is_some_and(|c| c <= touch)
                        });
                        let Some(&(entry, _)) = on_span else {
                            if !near {
                                failures.push(describe("no surface within the bound near the hit"));
                            }
                            continue;
                        };
                        worst_depth = worst_depth.max((t - entry).abs() / bound(entry));
                        let n_ref = terrain_normal(&terrain, r.ray.at(entry));
                        if let Some(n) = n_ref.filter(|&n| grazing(n) < 20.0) {
                            normals += 1;
                            let off = (a.normal - n).length();
                            worst_normal = worst_normal.max(off);
                            if off > normal_bound {
                                failures.push(describe(&format!("normal off by {off:.3e}")));
                            }
                        }
                        if !a.any {
                            failures.push(describe("no any hit"));
                        }
                    }
                    None => {
                        if spans.iter().any(thick) {
                            failures.push(describe("missed"));
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "{}: terrains, {rays_checked} rays, {hits} hits ({normals} normals compared); worst \
         depth {worst_depth:.3e} of its bound, worst normal {worst_normal:.2e}",
        backend.name()
    );
    assert!(
        failures.is_empty(),
        "{}: {} terrain rays off, e.g. {:?}",
        backend.name(),
        failures.len(),
        &failures[..failures.len().min(4)]
    );
}

/// The reference's inside spans of the union of `solids` on `r`: `F` sampled over each solid's
/// box interval at `SAMPLES` per box diagonal (or `step`, if coarser), each sign change refined
/// by bisection: every span thicker than the step is found.
fn reference_spans(solids: &[&Solid], r: &CaseRay, step: f64) -> Vec<(f64, f64)> {
    const SAMPLES: f64 = 2048.0;
    let mut spans = Vec::new();
    for solid in solids {
        let bounds = solid.bounds();
        let Some(range) = bounds.clip_ray(&r.ray, r.range) else {
            continue;
        };
        let f = |t: f64| solid.eval(r.ray.at(t));
        let step = step.max(bounds.diagonal() / SAMPLES);
        let n = ((range.hi - range.lo) / step).ceil().max(1.0) as usize;
        let h = (range.hi - range.lo) / n as f64;
        let mut prev = (range.lo, f(range.lo));
        let mut entry = (prev.1 >= 0.0).then_some(range.lo);
        for k in 1..=n {
            let t = if k == n {
                range.hi
            } else {
                range.lo + h * k as f64
            };
            let v = f(t);
            if (v >= 0.0) != (prev.1 >= 0.0) {
                let edge = bisect(&f, prev.0, t);
                match entry.take() {
                    Some(a) => spans.push((a, edge)),
                    None => entry = Some(edge),
                }
            }
            prev = (t, v);
        }
        if let Some(a) = entry {
            spans.push((a, range.hi));
        }
    }
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    spans
}

/// Where `f` changes sign in `[a, b]` (it does at the ends), to 1e-12 relative.
fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let inside_a = f(a) >= 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b || (b - a) <= 1e-12 * b.abs().max(1.0) {
            break;
        }
        if (f(m) >= 0.0) == inside_a {
            a = m;
        } else {
            b = m;
        }
    }
    // The first inside point of the pair.
    if inside_a { a } else { b }
}

/// The camera rays of `scene` through the pixel centres of a `width × height` grid.
fn camera_rays(scene: &Scene, width: u32, height: u32) -> Vec<CaseRay> {
    let mut rays = Vec::new();
    for py in 0..height {
        for px in 0..width {
            if let Some(c) = scene.camera.pixel_ray(px, py, width, height) {
                rays.push(CaseRay {
                    ray: c.ray,
                    range: Interval::new(c.t_near, f64::INFINITY),
                });
            }
        }
    }
    rays
}

/// A camera `back` behind `reference` along the mean of `camera`'s directions, and its rays
/// through the points `at` along each of them (a view of the same things from far away:
/// positions relative to that camera, long `t`).
fn far_rays(camera: &[CaseRay], reference: DVec3, back: f64, at: f64) -> (DVec3, Vec<CaseRay>) {
    let forward = camera.iter().map(|r| r.ray.dir).sum::<DVec3>().normalize();
    let eye = reference - forward * back;
    let rays = camera
        .iter()
        .filter_map(|r| {
            Some(CaseRay {
                ray: Ray::new(eye, r.ray.at(at) - eye)?,
                range: Interval::new(0.0, f64::INFINITY),
            })
        })
        .collect();
    (eye, rays)
}

/// Rays from `eye` at every `elevations` × `azimuths` (degrees, Y up) to each of `ends`.
fn fan(eye: DVec3, elevations: &[f64], azimuths: &[f64], ends: &[f64]) -> Vec<CaseRay> {
    let mut rays = Vec::new();
    for elevation in elevations {
        for azimuth in azimuths {
            let (e, a) = (elevation.to_radians(), azimuth.to_radians());
            let dir = DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin());
            for &end in ends {
                rays.push(CaseRay {
                    ray: Ray::new(eye, dir).expect("a unit direction"),
                    range: Interval::new(0.0, end),
                });
            }
        }
    }
    rays
}

/// A case: solids, the point the rays are relative to on a backend that needs one, the rays.
struct Case {
    name: String,
    /// Whether normals are checked: not on the far rays, whose f32 positions 10⁴ from the
    /// camera leave the GPU's normals to the pixel footprint (the frames' colour bound covers
    /// them).
    normals: bool,
    solids: Vec<Solid>,
    reference: DVec3,
    rays: Vec<CaseRay>,
    tol: Tolerance,
}

fn data_scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/scenes")
        .join(name);
    fray_scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The camera rays of `name` on a `width`-wide grid, the grazing rays at their CPU hits, and the
/// same camera rays started 10⁴ back.
fn cases(name: &str, width: u32) -> Vec<Case> {
    let scene = data_scene(name);
    let height = (u64::from(scene.height) * u64::from(width) / u64::from(scene.width)) as u32;
    let solids: Vec<Solid> = scene.objects.iter().map(|o| o.solid.clone()).collect();
    let refs: Vec<&Solid> = solids.iter().collect();
    let tol = Tolerance {
        eps: scene.epsilon(),
        eps_gpu: fray_gpu::gpu_epsilon(&scene, scene.epsilon()),
    };
    let reference = fray_gpu::params::reference_point(&scene.camera);
    let camera = camera_rays(&scene, width, height);
    // Grazing rays: through each hit's neighbourhood along the tangent plane, just outside.
    let hits = Cpu.free_forms(&refs, reference, &camera, &tol);
    let mut grazing = Vec::new();
    for (r, a) in camera.iter().zip(&hits) {
        let Some(t) = a.t else { continue };
        let p = r.ray.at(t);
        let n = a.normal;
        let tangent = (r.ray.dir - n * r.ray.dir.dot(n)).normalize_or_zero();
        if tangent == DVec3::ZERO {
            continue;
        }
        let lift = 4.0 * tol.eps_gpu.max(tol.eps);
        let origin = p + n * lift - tangent * 2.0;
        if let Some(ray) = Ray::new(origin, tangent) {
            grazing.push(CaseRay {
                ray,
                range: Interval::new(0.0, 4.0),
            });
        }
    }
    // The camera 10⁴ back: a flight view of a model far ahead.
    let (far_eye, far) = far_rays(&camera, reference, 1e4, 10.0);
    let far_tol = Tolerance {
        eps_gpu: tol.eps_gpu.max(fray_gpu::EPSILON_FLOOR * 1e4),
        ..tol
    };
    [
        ("camera", camera, reference, tol),
        ("grazing", grazing, reference, tol),
        ("far", far, far_eye, far_tol),
    ]
    .into_iter()
    .map(|(kind, rays, reference, tol)| Case {
        name: format!("{name} {kind}"),
        normals: kind != "far",
        solids: solids.clone(),
        reference,
        rays,
        tol,
    })
    .collect()
}

/// What a run of the suite found wrong, per check.
#[derive(Debug, Default)]
struct Failures {
    rays: usize,
    hits: usize,
    early: Vec<String>,
    far_from_inside: Vec<String>,
    missed: Vec<String>,
    normal: Vec<String>,
    any: Vec<String>,
    worst_depth: f64,
    worst_normal: f64,
}

/// The suite: every case through `backend`, each answer against the reference.
fn free_form_suite(backend: &dyn Backend) {
    let bounds = backend.bounds();
    let mut total = Failures::default();
    for name in ["csg.ron", "turboprop.ron"] {
        for case in cases(name, 48) {
            let solids: Vec<&Solid> = case.solids.iter().collect();
            let answers = backend.free_forms(&solids, case.reference, &case.rays, &case.tol);
            let mut f = Failures::default();
            for (r, a) in case.rays.iter().zip(&answers) {
                check_ray(&solids, r, a, &case, &bounds, &mut f);
            }
            eprintln!(
                "{} {}: {} rays, {} hits; worst |Δt| {:.3e} of its bound, worst normal {:.2e}",
                backend.name(),
                case.name,
                f.rays,
                f.hits,
                f.worst_depth,
                f.worst_normal
            );
            total.rays += f.rays;
            total.hits += f.hits;
            total.worst_depth = total.worst_depth.max(f.worst_depth);
            total.worst_normal = total.worst_normal.max(f.worst_normal);
            for (all, these) in [
                (&mut total.early, f.early),
                (&mut total.far_from_inside, f.far_from_inside),
                (&mut total.missed, f.missed),
                (&mut total.normal, f.normal),
                (&mut total.any, f.any),
            ] {
                all.extend(these.into_iter().map(|s| format!("{}: {s}", case.name)));
            }
        }
    }
    eprintln!(
        "{}: free forms, {} rays, {} hits",
        backend.name(),
        total.rays,
        total.hits
    );
    for (what, list) in [
        ("a span began before the hit", &total.early),
        (
            "the hit is not near an inside point",
            &total.far_from_inside,
        ),
        ("a span at least the sliver thick was missed", &total.missed),
        ("normal off", &total.normal),
        ("any hit disagrees", &total.any),
    ] {
        assert!(
            list.is_empty(),
            "{}: {what} on {} rays, e.g. {:?}",
            backend.name(),
            list.len(),
            &list[..list.len().min(5)]
        );
    }
}

/// The reference's outward normal at the start of span `s` (of the solid most inside there) and
/// its deciding leaf, and `1 / max(|cos θ|, 0.02)` for the ray's angle θ to it: how much a
/// distance error along the ray grows at a grazing angle.
fn reference_surface(solids: &[&Solid], r: &CaseRay, t: f64) -> (DVec3, u32, usize, f64) {
    let p = r.ray.at(t);
    let k = (0..solids.len())
        .max_by(|&x, &y| solids[x].eval(p).total_cmp(&solids[y].eval(p)))
        .expect("a solid");
    let (n, leaf) = solids[k].surface_at(p, -r.ray.dir);
    (n, leaf, k, 1.0 / n.dot(r.ray.dir).abs().max(0.02))
}

fn check_ray(
    solids: &[&Solid],
    r: &CaseRay,
    a: &Answer,
    case: &Case,
    bounds: &Bounds,
    f: &mut Failures,
) {
    let tol = &case.tol;
    f.rays += 1;
    let spans = reference_spans(solids, r, 0.25 * tol.eps.min(tol.eps_gpu));
    // A span a backend must find: at least the sliver long, entered at an angle (|cos θ| ≥ 0.05
    // to the surface's normal): a grazing ray may run just inside a surface for a long way.
    let thick = |s: &(f64, f64)| {
        s.1 - s.0 >= (bounds.sliver)(s.0, tol) && reference_surface(solids, r, s.0).3 < 20.0
    };
    let describe = |what: &str| {
        format!(
            "{what}: origin {:?} dir {:?} answer {:?} spans {:?}",
            r.ray.origin,
            r.ray.dir,
            a.t,
            &spans[..spans.len().min(3)]
        )
    };
    match a.t {
        Some(t) => {
            f.hits += 1;
            // The depth bound across the surface, along the ray at its angle to it.
            let along =
                |s: &(f64, f64)| (bounds.depth)(t, tol) * reference_surface(solids, r, s.0).3;
            if let Some(s) = spans.iter().find(|s| s.0 < t - along(s) && thick(s)) {
                f.early.push(describe(&format!(
                    "span at {:.9} ({:.3e} thick)",
                    s.0,
                    s.1 - s.0
                )));
            }
            let nearest = spans
                .iter()
                .min_by(|x, y| (x.0 - t).abs().total_cmp(&(y.0 - t).abs()));
            let depth = nearest.map_or((bounds.depth)(t, tol), along);
            let near_span = spans.iter().any(|s| s.0 <= t + depth && s.1 >= t - depth);
            let near_point = (0..=64).any(|k| {
                let u = t - depth + 2.0 * depth * f64::from(k) / 64.0;
                solids.iter().any(|s| s.eval(r.ray.at(u)) >= 0.0)
            });
            if !near_span && !near_point {
                f.far_from_inside
                    .push(describe("no inside point within the depth bound"));
            }
            if let Some(s) = nearest.filter(|s| (s.0 - t).abs() <= depth) {
                f.worst_depth = f.worst_depth.max((s.0 - t).abs() / depth);
                // The normal where both points have the same deciding leaf, off grazing rays.
                let (n_ref, leaf_ref, k, grazing) = reference_surface(solids, r, s.0);
                let (_, leaf_hit) = solids[k].surface_at(r.ray.at(t), -r.ray.dir);
                if case.normals && leaf_ref == leaf_hit && grazing < 20.0 {
                    let off = (a.normal - n_ref).length();
                    f.worst_normal = f.worst_normal.max(off);
                    if off > bounds.normal {
                        f.normal.push(describe(&format!("normal off by {off:.3e}")));
                    }
                }
            }
            if !a.any && nearest.is_none_or(thick) {
                f.any.push(describe("a nearest hit but no any hit"));
            }
        }
        None => {
            if let Some(s) = spans.iter().find(|s| thick(s)) {
                f.missed.push(describe(&format!(
                    "span at {:.9} ({:.3e} thick)",
                    s.0,
                    s.1 - s.0
                )));
            }
            if spans.iter().any(thick) && !a.any {
                f.any
                    .push(describe("a span at least the sliver thick but no any hit"));
            }
        }
    }
}

/// The reference optical depth of `fog` on `r`: composite Simpson over the part of the range in
/// the layer (4096 intervals) of the extinction at each height — not the closed form either
/// backend evaluates; `∞` where the ray stays in the layer for ever.
fn reference_depth(fog: &Fog, r: &CaseRay) -> f64 {
    let layer = &fog.layer;
    let (y, dy) = (r.ray.origin.y, r.ray.dir.y);
    let (mut lo, mut hi) = (r.range.lo, r.range.hi);
    if dy != 0.0 {
        let a = (layer.base - y) / dy;
        let b = (layer.top - y) / dy;
        lo = lo.max(a.min(b));
        hi = hi.min(a.max(b));
    } else if !(layer.base..=layer.top).contains(&y) {
        return 0.0;
    }
    if lo >= hi || layer.extinction == 0.0 {
        return 0.0;
    }
    if hi.is_infinite() {
        return f64::INFINITY;
    }
    const N: usize = 4096;
    let h = (hi - lo) / N as f64;
    let f = |t: f64| layer.density((y + dy * t).clamp(layer.base, layer.top));
    let mut sum = f(lo) + f(hi);
    for k in 1..N {
        sum += f(lo + h * k as f64) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// The fog cases: the fog data scenes' layers seen from their cameras, from inside the layer
/// and from its top, along a fan of elevations (straight down to straight up, the horizontal
/// exactly), ranges ending 1 m to 20 km away or never.
fn fog_suite(backend: &dyn Backend) {
    let (abs, rel) = backend.medium_bounds();
    let mut rays_checked = 0;
    let mut worst = 0.0f64;
    for name in ["fog_aircraft_low_sun.ron", "fog_aircraft_high_sun.ron"] {
        let scene = data_scene(name);
        let fog = scene.atmosphere.fog.expect("a fog scene");
        let layer = &fog.layer;
        let camera = fray_gpu::params::reference_point(&scene.camera);
        for eye_y in [camera.y, 0.5 * (layer.base + layer.top), layer.top] {
            let eye = DVec3::new(camera.x, eye_y, camera.z);
            let rays = fan(
                eye,
                &[-90.0, -30.0, -5.0, -0.5, 0.0, 0.5, 5.0, 30.0, 90.0],
                &[0.0, 70.0, 200.0],
                &[1.0, 100.0, 2e3, 2e4, f64::INFINITY],
            );
            let answers = backend.fog(&fog, eye_y, &rays);
            for (r, m) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let depth = reference_depth(&fog, r);
                let transmittance = (-depth).exp();
                let off_t = (m.transmittance - transmittance).abs();
                assert!(
                    off_t <= abs + rel * transmittance,
                    "{} {name}: transmittance {} against {transmittance} on {r:?}",
                    backend.name(),
                    m.transmittance
                );
                worst = worst.max(off_t / (abs + rel * transmittance));
                if depth.is_finite() && m.optical_depth < 1e29 {
                    let off = (m.optical_depth - depth).abs();
                    assert!(
                        off <= abs + rel * depth,
                        "{} {name}: optical depth {} against {depth} on {r:?}",
                        backend.name(),
                        m.optical_depth
                    );
                    worst = worst.max(off / (abs + rel * depth));
                } else {
                    assert!(
                        depth.is_infinite()
                            == (m.optical_depth >= 1e29 || m.optical_depth.is_infinite()),
                        "{} {name}: optical depth {} against {depth} on {r:?}",
                        backend.name(),
                        m.optical_depth
                    );
                }
            }
        }
    }
    eprintln!(
        "{}: fog, {rays_checked} rays; worst difference {worst:.3e} of the bound",
        backend.name()
    );
}

/// The sky cases: the sky data scenes' models seen from their cameras and from 10 km up, along a
/// fan of directions (down, at the horizon, up, toward the sun), to surfaces 100 m to 20 km away
/// or to the sky; each answer against the sky's numerical reference (`fray_atmosphere::sky::
/// reference`: adaptive Gauss–Kronrod quadrature, no table) — within [`SKY_TRANSMITTANCE`],
/// [`SKY_IN_SCATTER`] and [`SKY_TO_SUN`]: the method's own error (its march and its table),
/// both backends alike.
fn sky_suite(backend: &dyn Backend) {
    use fray_atmosphere::sky::reference;
    let (mut rays_checked, mut worst_t, mut worst_s, mut worst_sun) =
        (0usize, 0.0f64, 0.0f64, 0.0f64);
    for name in ["sunset.ron", "haze_dem_high.ron"] {
        let scene = data_scene(name);
        let sky = scene.atmosphere.sky.clone().expect("a sky scene");
        let model = sky.sky.model();
        let sun = sky.sky.sun();
        let camera = fray_gpu::params::reference_point(&scene.camera);
        for eye in [camera, camera + DVec3::Y * 1e4] {
            let rays = fan(
                eye,
                &[-30.0, -2.0, 0.5, 5.0, 45.0],
                &[0.0, 120.0, 240.0],
                &[100.0, 2e3, 2e4, f64::INFINITY],
            );
            let answers = backend.sky(&sky, eye, &rays);
            for (r, a) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let truth = reference::single_scattering(model, sun, eye, r.ray.dir, r.range.hi);
                let to_sun = reference::transmittance_to_sun(model, sun, sun_point(r), eye);
                let describe =
                    |what: &str| format!("{} {name}: {what} on {r:?}: {a:?}", backend.name());
                let dt = (a.transmittance - truth.transmittance).abs().max_element();
                let bright = truth.in_scatter.max_element().max(1e-3);
                let ds = (a.in_scatter - truth.in_scatter).abs().max_element() / bright;
                let dsun = (a.to_sun - to_sun).abs().max_element();
                worst_t = worst_t.max(dt);
                worst_s = worst_s.max(ds);
                worst_sun = worst_sun.max(dsun);
                assert!(
                    dt <= SKY_TRANSMITTANCE,
                    "{}",
                    describe(&format!("transmittance off by {dt:.3e}"))
                );
                assert!(
                    ds <= SKY_IN_SCATTER,
                    "{}",
                    describe(&format!("in-scatter off by {ds:.3e}"))
                );
                assert!(
                    dsun <= SKY_TO_SUN,
                    "{}",
                    describe(&format!("transmittance to the sun off by {dsun:.3e}"))
                );
            }
        }
    }
    eprintln!(
        "{}: sky, {rays_checked} rays; worst transmittance {worst_t:.3e}, in-scatter {worst_s:.3e} \
         of the brightest channel, transmittance to the sun {worst_sun:.3e}",
        backend.name()
    );
}

/// The aerial perspective's transmittance against the reference, absolute: the scenes' march
/// (16 steps) — measured 2.8e-3 on both backends.
const SKY_TRANSMITTANCE: f64 = 5e-3;
/// The aerial perspective's in-scatter against the reference, relative to its brightest
/// channel: the same march — measured 2.8e-2 on both backends (`cargo xtask bench atmosphere`
/// trades steps for it).
const SKY_IN_SCATTER: f64 = 5e-2;
/// The transmittance to the sun against the reference, absolute: the transmittance table's
/// interpolation — measured 4.1e-4 on both backends.
const SKY_TO_SUN: f64 = 1e-3;

/// The cloud cases: the cloud data scenes' volumes from their cameras (inside the cloud in
/// `clouds_aircraft_inside.ron`) along a fan of directions, to 100 m and 2 km or through the
/// whole volume; each backend's march transmittance and optical depth against a fine-step
/// reference — the optical depth of the volume's own density (its trilinear interpolation) at a
/// 64th of the march's step, `exp(−τ)` for the transmittance — within [`CLOUD_BOUND`] (the
/// march's step error, both backends alike; the GPU's f32 adds ≤ 1.6e-6, tests/clouds_parity.rs).
fn cloud_suite(backend: &dyn Backend) {
    let mut rays_checked = 0usize;
    let (mut worst_t, mut worst_depth) = (0.0f64, 0.0f64);
    for name in ["clouds_aircraft_inside.ron", "clouds_envelope.ron"] {
        let scene = data_scene(name);
        let clouds = scene.clouds.clone().expect("a cloud scene");
        let eye = fray_gpu::params::reference_point(&scene.camera);
        let light = fray_gpu::cloud_light(&scene, &clouds, eye);
        let mut rays = fan(
            eye,
            &[-60.0, -10.0, 0.0, 10.0, 60.0],
            &[0.0, 72.0, 144.0, 216.0, 288.0],
            &[100.0, 2e3, f64::INFINITY],
        );
        // And every camera ray of a coarse grid.
        rays.extend(camera_rays(&scene, 16, 12));
        let answers = backend.clouds(&clouds, &light, eye, &rays);
        for (r, m) in rays.iter().zip(&answers) {
            rays_checked += 1;
            let (o, d) = (r.ray.origin.to_array(), r.ray.dir.to_array());
            let range = (r.range.lo, r.range.hi);
            let depth = march::optical_depth(&clouds.volume, o, d, range, clouds.march.step / 64.0);
            let dt = (m.transmittance - (-depth).exp()).abs();
            let dd = (m.optical_depth - depth).abs() / depth.max(1.0);
            worst_t = worst_t.max(dt);
            worst_depth = worst_depth.max(dd);
            assert!(
                dt <= CLOUD_BOUND && dd <= CLOUD_BOUND,
                "{} {name}: transmittance {} / depth {} against {} / {depth} on {r:?}",
                backend.name(),
                m.transmittance,
                m.optical_depth,
                (-depth).exp()
            );
        }
    }
    eprintln!(
        "{}: clouds, {rays_checked} rays; worst transmittance {worst_t:.3e}, optical depth \
         {worst_depth:.3e} (relative, or absolute below 1)",
        backend.name()
    );
}

/// The cloud march against the fine-step reference (transmittance absolute; optical depth
/// relative, or absolute below 1): the scenes' step — measured 1.6e-2 and 2.4e-2 on both
/// backends (`cargo xtask bench clouds` trades the step for it).
const CLOUD_BOUND: f64 = 5e-2;

/// Every case of the suite, on one backend.
fn suite(backend: &dyn Backend) {
    free_form_suite(backend);
    mesh_suite(backend);
    terrain_suite(backend);
    fog_suite(backend);
    sky_suite(backend);
    cloud_suite(backend);
}

fn the_suite_on_the_cpu() {
    suite(&Cpu);
}

fn the_suite_on_the_gpu() {
    suite(&Gpu {
        renderer: common::gpu("the_suite_on_the_gpu"),
    });
}

fn main() {
    common::run(
        &[("the_suite_on_the_gpu", the_suite_on_the_gpu)],
        &[("the_suite_on_the_cpu", the_suite_on_the_cpu)],
    );
}
