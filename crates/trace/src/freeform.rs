//! Free forms as a primitive kind: a scene object's CSG solid, cast by `fray-geometry`'s
//! [`RayCaster`] — whole, or restricted to a work item's [`ActiveSet`] (the leaves and
//! perturbations the tile's rays may meet) — and the batched cast of a tile's camera rays.

use crate::primitive::{KindHit, PART_PENDING, Primitive, Surface, TraceContext};
use fray_core::{Aabb, CameraRay, Interval, Ray, Rgb};
use fray_geometry::{ActiveSet, CastPlan};
use fray_scene::Object;
use glam::DVec3;

/// One free-form object, cast whole (`active: None`) or restricted to a conservative subset.
#[derive(Clone, Copy, Debug)]
pub struct FreeFormPrimitive<'a> {
    pub object: &'a Object,
    /// The leaves and perturbations that may matter for the rays cast (a work item's); `None`:
    /// all of them. Only valid for the rays it was made for.
    pub active: Option<&'a ActiveSet>,
}

impl Primitive for FreeFormPrimitive<'_> {
    fn bounds(&self) -> Aabb {
        self.object.solid.bounds()
    }

    #[inline]
    fn nearest_hit(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<KindHit> {
        let solid = &self.object.solid;
        let t = match self.active {
            Some(active) => {
                ctx.caster
                    .cast_with(solid, ray, range, eps, active, &mut ctx.counts.cast)
            }
            None => ctx
                .caster
                .cast(solid, ray, range, eps, &mut ctx.counts.cast),
        }?;
        Some(pending(t))
    }

    fn transmittance(&self, ray: &Ray, range: Interval, eps: f64, ctx: &mut TraceContext) -> Rgb {
        // Opaque: any point of the solid on the range blocks all light, so the any-hit query
        // (the GPU's `occluded_by_solids` runs the same).
        let solid = &self.object.solid;
        let stats = &mut ctx.counts.cast;
        if ctx
            .caster
            .occludes(solid, ray, range, eps, self.active, stats)
        {
            Rgb::ZERO
        } else {
            Rgb::ONE
        }
    }

    #[inline]
    fn surface(&self, ray: &Ray, hit: &KindHit) -> Surface {
        let (normal, leaf) = if hit.part == PART_PENDING {
            self.normal_and_leaf(ray, hit.t)
        } else {
            (hit.detail, hit.part)
        };
        Surface {
            geometric_normal: normal,
            shading_normal: normal,
            part: leaf,
            uv: None,
        }
    }
}

impl FreeFormPrimitive<'_> {
    /// The outward normal and the leaf at the hit `t` on `ray` (the active subset's, when
    /// culling: bit-identical, since every perturbation left out is zero there).
    #[inline(always)]
    pub(crate) fn normal_and_leaf(&self, ray: &Ray, t: f64) -> (DVec3, u32) {
        let p = ray.at(t);
        let solid = &self.object.solid;
        match self.active {
            Some(active) => solid.surface_at_with(p, -ray.dir, active),
            None => solid.surface_at(p, -ray.dir),
        }
    }

    /// Narrows each pixel's hit (`pixels`: camera ray and best hit so far, `index` the object's)
    /// with this object: the same casts [`Primitive::nearest_hit`] makes, each over
    /// `[t_near, best so far]`, with what depends on the solid alone decided once for the tile
    /// (a [`CastPlan`]). Pixels inner: consecutive casts are independent, so the processor
    /// overlaps their long dependent chains (root, square root, division, certification).
    #[inline]
    pub(crate) fn narrow_tile(
        &self,
        index: u32,
        pixels: &mut [(Option<CameraRay>, Option<crate::SceneHit>)],
        eps: f64,
        ctx: &mut TraceContext,
    ) {
        let mut plan = CastPlan::new(&self.object.solid, self.active);
        let id = fray_scene::PrimitiveId::free_form(index);
        for (camera_ray, hit) in pixels.iter_mut() {
            let Some(c) = camera_ray else {
                continue;
            };
            let hi = hit.map_or(f64::INFINITY, |h| h.hit.t);
            let segment = Interval { lo: c.t_near, hi };
            let found =
                ctx.caster
                    .cast_planned(&mut plan, &c.ray, segment, eps, &mut ctx.counts.cast);
            if let Some(t) = found
                && hit.is_none_or(|h| t < h.hit.t)
            {
                *hit = Some(crate::SceneHit {
                    primitive: id,
                    hit: pending(t),
                });
            }
        }
    }
}

/// A free-form hit at `t` whose leaf and normal are still to come.
#[inline]
fn pending(t: f64) -> KindHit {
    KindHit {
        t,
        part: PART_PENDING,
        detail: DVec3::ZERO,
    }
}
