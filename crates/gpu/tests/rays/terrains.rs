//! Terrains against an independent reference: each backend's exact hit and normal on the DEM
//! scenes and from a camera 10⁴ back, against the map's interpolated height sampled along the
//! ray and bisected, and its central differences for the normal.

use crate::Backend;
use crate::backend::{CaseRay, Tolerance};
use crate::cases::{bisect, camera_rays, data_scene, far_rays};
use crate::cpu::Cpu;
use crate::gpu::{Gpu, relative_rays};
use fray_core::PixelFootprint;
use fray_gpu::testing::TerrainBatch;
use fray_terrain::{Terrain, TerrainHit, TerrainStats};
use glam::DVec3;

/// What a backend found on a ray under a terrain.
#[derive(Clone, Copy, Debug)]
pub struct TerrainAnswer {
    /// The hit: distance, normal, kind, cell and level.
    pub hit: Option<TerrainHit>,
    /// The any-hit (shadow) answer over the same range.
    pub any: bool,
}

/// What a backend of the suite answers for terrains.
pub trait TerrainBackend {
    /// Nearest hit on `terrain` with the pixel footprint `footprint` (`ZERO`: exact), for each
    /// ray, with the backend's ε of `tol` as the bicubic root tolerance.
    fn terrain(
        &self,
        terrain: &Terrain,
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
        footprint: PixelFootprint,
    ) -> Vec<TerrainAnswer>;
    /// How far its exact terrain hits may be from the reference (`depth(t)`, as
    /// [`Bounds::depth`]) and its normals.
    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64);
}

impl TerrainBackend for Cpu {
    fn terrain(
        &self,
        terrain: &Terrain,
        _reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
        footprint: PixelFootprint,
    ) -> Vec<TerrainAnswer> {
        let eps = tol.eps;
        let mut stats = TerrainStats::default();
        rays.iter()
            .map(|r| TerrainAnswer {
                hit: terrain.cast_footprint(&r.ray, r.range, eps, footprint, &mut stats),
                any: terrain.occluded(&r.ray, r.range, eps),
            })
            .collect()
    }

    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64) {
        // Each cell's surface solved in f64 (bilinear: a quadratic; bicubic to ε): measured
        // ≤ 0.05 of the depth bound, normals within 2.6e-9 of the central differences.
        (|t, tol| tol.eps + 1e-9 * t, 1e-7)
    }
}

impl TerrainBackend for Gpu {
    fn terrain(
        &self,
        terrain: &Terrain,
        reference: DVec3,
        rays: &[CaseRay],
        tol: &Tolerance,
        footprint: PixelFootprint,
    ) -> Vec<TerrainAnswer> {
        let ctx = self.context();
        let batch = TerrainBatch::with_pixel_lod(ctx, terrain, reference, footprint)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_epsilon(tol.eps_gpu);
        batch
            .cast_hits(ctx, &relative_rays(rays, reference))
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|h| TerrainAnswer {
                hit: h.is_hit().then(|| TerrainHit {
                    t: f64::from(h.t),
                    normal: DVec3::from(h.normal.map(f64::from)),
                    cell: h.cell,
                    kind: h.hit_kind(),
                    levels_above_finest: h.levels_above_finest,
                }),
                // The terrain's shadow test is the frame's shade pass's (tests/parity.rs).
                any: h.is_hit(),
            })
            .collect()
    }

    fn terrain_bounds(&self) -> (fn(f64, &Tolerance) -> f64, f64) {
        // The parity bounds (terrain_parity.rs): depth within 1e-5·t, normals within 3e-4.
        (|t, tol| 1e-5 * t + 4.0 * tol.eps_gpu, 3e-4)
    }
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
pub fn suite(backend: &dyn Backend) {
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
            let answers = backend.terrain(&terrain, reference, &rays, &tol, PixelFootprint::ZERO);
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
                match a.hit.map(|h| (h.t, h.normal)) {
                    Some((t, normal)) => {
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
                            let off = (normal - n).length();
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
