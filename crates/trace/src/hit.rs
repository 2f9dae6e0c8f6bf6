//! The nearest hit over all objects of a scene: the pair (ray parameter, primitive).

use crate::terrain_hit::{TerrainCast, nearer_terrain_hit, terrain_occludes};
use fray_core::{CameraRay, Interval, Ray};
use fray_geometry::{ActiveSet, CastPlan, CastStats, RayCaster};
use fray_scene::Scene;
use glam::DVec3;

/// The nearest surface along a ray: distance `t`, the object and the leaf (free form) hit, and
/// the outward unit normal there. `object ≥ scene.objects.len()` is terrain
/// `scene.terrains[object − objects.len()]` (leaf 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    pub t: f64,
    pub object: u32,
    pub leaf: u32,
    pub normal: glam::DVec3,
}

/// The nearest hit in `range` over every object of `scene`. Each object is searched only up to
/// the best hit so far, so occluded objects cost little. Terrains are cast exactly.
pub fn nearest_hit(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    stats: &mut CastStats,
) -> Option<SceneHit> {
    let mut exact = TerrainCast::default();
    nearest_hit_lod(scene, caster, ray, range, eps, None, stats, &mut exact)
}

/// [`nearest_hit`] (`candidates: None`) or [`nearest_hit_among`] (`Some`), with the terrains
/// cast at their level of detail for `terrain.footprint` and their work counted into `terrain`.
#[allow(clippy::too_many_arguments)]
pub fn nearest_hit_lod(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    candidates: Option<&[(u32, ActiveSet)]>,
    stats: &mut CastStats,
    terrain: &mut TerrainCast,
) -> Option<SceneHit> {
    let best = match candidates {
        None => {
            let all = (0..scene.objects.len()).map(|i| (i, None));
            nearest_over(scene, caster, ray, range, eps, all, stats)
        }
        Some(candidates) => {
            let listed = candidates
                .iter()
                .map(|(index, active)| (*index as usize, Some(active)));
            nearest_over(scene, caster, ray, range, eps, listed, stats)
        }
    };
    let mut hit = terrain_pass(
        scene,
        ray,
        range,
        eps,
        best.map(pending),
        candidates,
        terrain,
    );
    if let Some(h) = hit.as_mut() {
        finish_surface(scene, ray, candidates, h);
    }
    hit
}

/// The terrains' pass after the free forms: the nearer of `best` and the terrains' hits
/// (terrain candidates have ids after the objects; without candidates, every terrain).
fn terrain_pass(
    scene: &Scene,
    ray: &Ray,
    range: Interval,
    eps: f64,
    best: Option<SceneHit>,
    candidates: Option<&[(u32, ActiveSet)]>,
    terrain: &mut TerrainCast,
) -> Option<SceneHit> {
    if scene.terrains.is_empty() {
        return best; // no terrain pass: skip walking the list again
    }
    match candidates {
        None => {
            let terrains = scene.objects.len()..scene.objects.len() + scene.terrains.len();
            nearer_terrain_hit(scene, ray, range, eps, best, terrains, terrain)
        }
        Some(listed) => {
            let terrains = listed.iter().map(|(index, _)| *index as usize);
            nearer_terrain_hit(scene, ray, range, eps, best, terrains, terrain)
        }
    }
}

/// [`nearest_hit_lod`] for every camera ray of a tile at once (`pixels`: each ray and its hit
/// slot, overwritten) with the same answers — per pixel the same casts in the same order, each
/// ending at that pixel's best so far — except that a free-form hit's surface (normal and leaf)
/// is left for [`finish_surface`], which the frame loop runs over all of a tile's hits
/// afterwards. The loops are candidates outer, pixels inner: a pixel's next cast depends on
/// its last (its range ends at the best hit) while the next pixel's does not, so consecutive
/// casts are independent and the processor overlaps their long chains of dependent arithmetic
/// (root, square root, division, certification); so do consecutive surfaces.
#[allow(clippy::too_many_arguments)]
pub(crate) fn nearest_hits_deferred(
    scene: &Scene,
    caster: &mut RayCaster,
    pixels: &mut [(Option<CameraRay>, Option<SceneHit>)],
    eps: f64,
    candidates: Option<&[(u32, ActiveSet)]>,
    stats: &mut CastStats,
    terrain: &mut TerrainCast,
) {
    for (_, hit) in pixels.iter_mut() {
        *hit = None;
    }
    let mut cast_all = |index: usize, active: Option<&ActiveSet>| {
        let Some(object) = scene.objects.get(index) else {
            return;
        };
        let mut plan = CastPlan::new(&object.solid, active);
        for (camera_ray, hit) in pixels.iter_mut() {
            let Some(c) = camera_ray else {
                continue;
            };
            let hi = hit.map_or(f64::INFINITY, |h| h.t);
            let segment = Interval { lo: c.t_near, hi };
            let found = caster.cast_planned(&mut plan, &c.ray, segment, eps, stats);
            if let Some(t) = found
                && hit.is_none_or(|h| t < h.t)
            {
                *hit = Some(pending((t, index as u32)));
            }
        }
    };
    match candidates {
        None => (0..scene.objects.len()).for_each(|i| cast_all(i, None)),
        Some(listed) => listed
            .iter()
            .for_each(|(index, active)| cast_all(*index as usize, Some(active))),
    }
    if scene.terrains.is_empty() {
        return;
    }
    for (camera_ray, hit) in pixels.iter_mut() {
        if let Some(c) = camera_ray {
            let range = Interval::new(c.t_near, f64::INFINITY);
            *hit = terrain_pass(scene, &c.ray, range, eps, *hit, candidates, terrain);
        }
    }
}

/// Marks a free-form hit whose surface [`finish_surface`] has yet to compute.
const SURFACE_PENDING: u32 = u32::MAX;

/// Completes a hit whose surface is pending: a free-form hit gets the normal and the leaf of
/// its solid at the hit point (evaluated with the candidate's active subset, when culling);
/// terrain hits come complete.
#[inline]
pub(crate) fn finish_surface(
    scene: &Scene,
    ray: &Ray,
    candidates: Option<&[(u32, ActiveSet)]>,
    hit: &mut SceneHit,
) {
    if hit.leaf != SURFACE_PENDING {
        return;
    }
    let Some(object) = scene.objects.get(hit.object as usize) else {
        return;
    };
    let active = candidates.and_then(|c| {
        c.iter()
            .find(|(index, _)| *index == hit.object)
            .map(|(_, active)| active)
    });
    let p = ray.at(hit.t);
    (hit.normal, hit.leaf) = match active {
        Some(active) => object.solid.surface_at_with(p, -ray.dir, active),
        None => object.solid.surface_at(p, -ray.dir),
    };
}

/// [`nearest_hit`] over a subset: only the listed objects (increasing indices), each cast with
/// its [`ActiveSet`]. The same hit as [`nearest_hit`] when the subset is conservative for the ray
/// (objects left out cannot be hit, sets hold what the ray may need) — what a quadtree work item
/// guarantees for the rays of its tile. Terrains are cast exactly.
pub fn nearest_hit_among(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    candidates: &[(u32, ActiveSet)],
    stats: &mut CastStats,
) -> Option<SceneHit> {
    let mut exact = TerrainCast::default();
    let some = Some(candidates);
    nearest_hit_lod(scene, caster, ray, range, eps, some, stats, &mut exact)
}

/// The nearest hit over `candidates` (object index, and the active subset or `None` for all of
/// it): `(t, object)`, the hit's surface still to come. On a tie the earlier object keeps the
/// hit: each later search ends at the best so far.
fn nearest_over<'a>(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    candidates: impl Iterator<Item = (usize, Option<&'a ActiveSet>)>,
    stats: &mut CastStats,
) -> Option<(f64, u32)> {
    let mut best: Option<(f64, u32)> = None;
    let mut hi = range.hi;
    for (index, active) in candidates {
        let Some(object) = scene.objects.get(index) else {
            continue;
        };
        let segment = Interval { lo: range.lo, hi };
        let found = match active {
            Some(active) => caster.cast_with(&object.solid, ray, segment, eps, active, stats),
            None => caster.cast(&object.solid, ray, segment, eps, stats),
        };
        if let Some(t) = found
            && best.is_none_or(|(bt, _)| t < bt)
        {
            hi = t;
            best = Some((t, index as u32));
        }
    }
    best
}

/// A free-form hit `(t, object)` whose surface is still to come.
#[inline]
fn pending((t, object): (f64, u32)) -> SceneHit {
    SceneHit {
        t,
        object,
        leaf: SURFACE_PENDING,
        normal: DVec3::ZERO,
    }
}

/// [`occluded`] testing only the listed objects (increasing indices) and the terrains: the same
/// answer whenever the objects left out cannot be hit by the ray (as `shadow_cull` ensures).
pub fn occluded_among(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    objects: &[u32],
    stats: &mut CastStats,
) -> bool {
    let listed = objects
        .iter()
        .filter_map(|&k| scene.objects.get(k as usize));
    occluded_by(scene, caster, ray, range, eps, listed, stats)
}

/// Whether anything lies on the ray within `range` (for shadow rays): stops at the first hit.
pub fn occluded(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    stats: &mut CastStats,
) -> bool {
    occluded_by(scene, caster, ray, range, eps, scene.objects.iter(), stats)
}

/// Whether one of `objects` or a terrain lies on the ray within `range`.
fn occluded_by<'a>(
    scene: &Scene,
    caster: &mut RayCaster,
    ray: &Ray,
    range: Interval,
    eps: f64,
    mut objects: impl Iterator<Item = &'a fray_scene::Object>,
    stats: &mut CastStats,
) -> bool {
    objects.any(|object| caster.cast(&object.solid, ray, range, eps, stats).is_some())
        || terrain_occludes(scene, ray, range, eps)
}
