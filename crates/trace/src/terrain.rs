//! Terrains as a primitive kind: a height map cast by `fray-terrain` — camera rays at the
//! terrain's level of detail, everything else exactly.
//!
//! Camera rays use the terrain's [`TerrainLod`]: `Pixel` casts with the camera's pixel footprint
//! made `2^lod_bias` times wider (the bias shifts the pixel level by whole levels), `Exact` with
//! none (the finest level, or `n − lod_bias`). Shadow rays are always exact: a LOD hit lies on a
//! max-column top at or above the surface, so an exact shadow ray from it never starts
//! underground, and shadows keep the true terrain's shape. LOD hits (on flat max-column faces)
//! are shaded with the normal of the surface beneath them, so relief shading survives a coarse
//! level.

use crate::primitive::{KindHit, Primitive, Surface, TraceContext};
use fray_core::{Aabb, Interval, PixelFootprint, Ray, Rgb};
use fray_scene::{TerrainLod, TerrainObject};
use glam::DVec2;

/// One terrain, cast with a pixel footprint (camera rays) or exactly.
#[derive(Clone, Copy, Debug)]
pub struct TerrainPrimitive<'a> {
    pub terrain: &'a TerrainObject,
    /// The footprint its nearest-hit searches use: [`PixelFootprint::ZERO`] casts exactly.
    pub footprint: PixelFootprint,
}

impl<'a> TerrainPrimitive<'a> {
    /// The terrain cast exactly (shadow rays, the per-ray API).
    pub fn exact(terrain: &'a TerrainObject) -> Self {
        Self {
            terrain,
            footprint: PixelFootprint::ZERO,
        }
    }

    /// The terrain as camera rays see it: at its level of detail for the camera's `footprint`.
    pub fn for_camera(terrain: &'a TerrainObject, footprint: PixelFootprint) -> Self {
        let footprint = match terrain.lod {
            TerrainLod::Pixel => footprint.coarser(terrain.terrain.options().lod_bias),
            TerrainLod::Exact => PixelFootprint::ZERO,
        };
        Self { terrain, footprint }
    }
}

impl Primitive for TerrainPrimitive<'_> {
    fn bounds(&self) -> Aabb {
        self.terrain.terrain.bounds()
    }

    fn nearest_hit(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<KindHit> {
        ctx.counts.terrain_rays += 1;
        let h = self.terrain.terrain.cast_footprint(
            ray,
            range,
            eps,
            self.footprint,
            &mut ctx.counts.terrain,
        )?;
        Some(KindHit {
            t: h.t,
            part: h.levels_above_finest,
            detail: h.normal,
        })
    }

    fn transmittance(&self, ray: &Ray, range: Interval, eps: f64, _ctx: &mut TraceContext) -> Rgb {
        if self.terrain.terrain.occluded(ray, range, eps) {
            Rgb::ZERO
        } else {
            Rgb::ONE
        }
    }

    fn surface(&self, ray: &Ray, hit: &KindHit) -> Surface {
        let terrain = &self.terrain.terrain;
        let p = ray.at(hit.t);
        // `part` is the hit's level above the finest: a LOD hit is on a flat max-column face,
        // shaded with the surface's normal beneath (inside the column at a wall).
        let shading_normal = terrain.shading_normal(ray, hit.t, hit.part, hit.detail);
        let q = terrain.placement().to_map(p);
        Surface {
            geometric_normal: hit.detail,
            shading_normal,
            part: 0,
            uv: Some(drape_uv(terrain, q.x, q.y)),
        }
    }

    fn uv_per_world(&self, _part: u32) -> f64 {
        drape_uv_per_world(&self.terrain.terrain)
    }
}

/// The texture coordinates of map point `(u, v)` (column, row) for an image draped over the
/// map: texel centres on the samples, the image's top row on the map's row 0
/// (`fray_mesh::texture::Drape`).
pub(crate) fn drape_uv(terrain: &fray_terrain::Terrain, u: f64, v: f64) -> DVec2 {
    let map = terrain.map();
    DVec2::new(
        (u + 0.5) / map.width().max(1) as f64,
        1.0 - (v + 0.5) / map.height().max(1) as f64,
    )
}

/// The drape's uv per world unit: the larger of the two axes' (one image per map).
fn drape_uv_per_world(terrain: &fray_terrain::Terrain) -> f64 {
    let map = terrain.map();
    let spacing = terrain.placement().spacing();
    (1.0 / (map.width().max(1) as f64 * spacing.x))
        .max(1.0 / (map.height().max(1) as f64 * spacing.y))
}
