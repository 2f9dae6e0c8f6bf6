//! The terrain pass of the nearest-hit search: the scene's terrains are cast after the free
//! forms, each over `[range.lo, best so far]`, so the nearest hit over all primitive kinds wins
//! (a tie keeps the free form). Terrain hits are reported with object ids after the objects:
//! [`SceneHit::object`] `= scene.objects.len() + k` for `scene.terrains[k]` — the same ids the
//! quadtree work list uses for terrain candidates.

//!
//! Camera rays use each terrain's level of detail ([`TerrainLod`]): `Pixel` casts with the
//! camera's pixel footprint made `2^lod_bias` times wider (the bias shifts the pixel level by
//! whole levels), `Exact` with none (the finest level, or `n − lod_bias`). Shadow rays are
//! always exact: a LOD hit lies on a max-column top at or above the surface, so an exact shadow
//! ray from it never starts underground, and shadows keep the true terrain's shape. LOD hits
//! (on flat max-column faces) are shaded with the normal of the surface beneath them.

use crate::SceneHit;
use fray_core::{Interval, PixelFootprint, Ray};
use fray_scene::{Scene, TerrainLod};
use fray_terrain::{HitKind, TerrainStats};

/// How the terrain pass casts camera rays, and its counters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TerrainCast {
    /// The camera's pixel footprint; [`PixelFootprint::ZERO`] (the default) casts exactly
    /// whatever the terrains' `lod`.
    pub footprint: PixelFootprint,
    /// Terrain casts (one per ray and terrain searched).
    pub rays: u64,
    /// The searches' work.
    pub stats: TerrainStats,
}

impl TerrainCast {
    /// Casting with the camera's footprint (`Pixel` terrains use it).
    pub fn with_footprint(footprint: PixelFootprint) -> Self {
        Self {
            footprint,
            ..Self::default()
        }
    }
}

/// The nearest terrain hit nearer than `best` (if any) among terrain ids `ids` (object ids;
/// ids that are not terrains are skipped).
pub(crate) fn nearer_terrain_hit(
    scene: &Scene,
    ray: &Ray,
    range: Interval,
    eps: f64,
    best: Option<SceneHit>,
    ids: impl Iterator<Item = usize>,
    cast: &mut TerrainCast,
) -> Option<SceneHit> {
    let first = scene.objects.len();
    let mut best = best;
    for id in ids {
        let Some(t) = id.checked_sub(first).and_then(|k| scene.terrains.get(k)) else {
            continue;
        };
        let hi = best.map_or(range.hi, |b| b.t);
        let footprint = match t.lod {
            TerrainLod::Pixel => cast.footprint.coarser(t.terrain.options().lod_bias),
            TerrainLod::Exact => PixelFootprint::ZERO,
        };
        cast.rays += 1;
        let segment = Interval { lo: range.lo, hi };
        if let Some(h) = t
            .terrain
            .cast_footprint(ray, segment, eps, footprint, &mut cast.stats)
            && best.is_none_or(|b| h.t < b.t)
        {
            // A LOD hit is on a flat max-column face: shade it with the surface's normal
            // beneath, so relief shading survives the coarse level.
            let normal = if h.levels_above_finest > 0 && h.kind != HitKind::Start {
                t.terrain.surface_normal_at(ray.at(h.t)).unwrap_or(h.normal)
            } else {
                h.normal
            };
            best = Some(SceneHit {
                t: h.t,
                object: id as u32,
                leaf: 0,
                normal,
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
