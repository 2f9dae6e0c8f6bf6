//! The terrain pass of the nearest-hit search: the scene's terrains are cast after the free
//! forms, each over `[range.lo, best so far]`, so the nearest hit over all primitive kinds wins
//! (a tie keeps the free form). Terrain hits are reported with object ids after the objects:
//! [`SceneHit::object`] `= scene.objects.len() + k` for `scene.terrains[k]` — the same ids the
//! quadtree work list uses for terrain candidates.

use crate::SceneHit;
use fray_core::{Interval, Ray};
use fray_scene::Scene;

/// The nearest terrain hit nearer than `best` (if any) among terrain ids `ids` (object ids;
/// ids that are not terrains are skipped).
pub(crate) fn nearer_terrain_hit(
    scene: &Scene,
    ray: &Ray,
    range: Interval,
    eps: f64,
    best: Option<SceneHit>,
    ids: impl Iterator<Item = usize>,
) -> Option<SceneHit> {
    let first = scene.objects.len();
    let mut best = best;
    for id in ids {
        let Some(t) = id.checked_sub(first).and_then(|k| scene.terrains.get(k)) else {
            continue;
        };
        let hi = best.map_or(range.hi, |b| b.t);
        if let Some(h) = t.terrain.cast(ray, Interval { lo: range.lo, hi }, eps)
            && best.is_none_or(|b| h.t < b.t)
        {
            best = Some(SceneHit {
                t: h.t,
                object: id as u32,
                leaf: 0,
                normal: h.normal,
            });
        }
    }
    best
}

/// Whether any terrain lies on the ray within `range` (shadow rays).
pub(crate) fn terrain_occludes(scene: &Scene, ray: &Ray, range: Interval, eps: f64) -> bool {
    scene
        .terrains
        .iter()
        .any(|t| t.terrain.occluded(ray, range, eps))
}

/// The material index of a hit on object id `id` (a free form's leaf, or a terrain's).
pub(crate) fn material_of(scene: &Scene, id: u32, leaf: u32) -> Option<u32> {
    let id = id as usize;
    match scene.objects.get(id) {
        Some(o) => o.leaf_materials.get(leaf as usize).copied(),
        None => scene
            .terrains
            .get(id - scene.objects.len())
            .map(|t| t.material),
    }
}
