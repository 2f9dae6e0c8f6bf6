//! Queries of rays that leave a surface (Whitted's reflected, refracted and — through
//! transmissive surfaces — shadow rays): the nearest hit where the ray may start *inside* a
//! transmissive free form, whose surface it then leaves (the first hit of the solid's
//! complement, or the face of its clipping box), and the transmittance of a shadow ray that keeps
//! `kt` per transmissive surface it crosses (no caustics: light is not bent toward the light).

use crate::hit::{interaction, nearest_pending};
use crate::interaction::SurfaceInteraction;
use crate::primitive::{KindHit, PART_PENDING, TraceContext};
use fray_core::{Interval, PixelFootprint, Ray, Rgb};
use fray_geometry::Solid;
use fray_scene::{PrimitiveId, PrimitiveKind, Scene};
use glam::DVec3;

/// The most transmissive surfaces a shadow ray passes through before it counts as blocked (a
/// bound on the work of one shadow ray; light through more is below any visible weight).
pub const MAX_SHADOW_CROSSINGS: usize = 32;

/// Per free form of a scene, its complement when a material of it transmits (`None`: opaque —
/// rays never travel inside it). Built once per frame; empty for a scene without transmission.
#[derive(Clone, Debug, Default)]
pub struct Interiors {
    complements: Vec<Option<Solid>>,
}

impl Interiors {
    /// The complements of `scene`'s transmissive free forms.
    pub fn of(scene: &Scene) -> Self {
        if !scene.features.transmission {
            return Self::default();
        }
        let transmits = |m: u32| {
            scene
                .materials
                .get(m as usize)
                .is_some_and(|m| m.transmits())
        };
        let complements = scene
            .objects
            .iter()
            .map(|o| {
                o.leaf_materials
                    .iter()
                    .any(|&m| transmits(m))
                    .then(|| o.solid.complement())
            })
            .collect();
        Self { complements }
    }

    /// For primitive `id` of `scene`, when it is a transmissive free form and `ray.at(range.lo)`
    /// lies inside it: where the ray leaves it within `range` (`Some(None)`: not in `range`).
    /// `None` otherwise: the primitive's own nearest hit applies.
    pub(crate) fn exit_hit(
        &self,
        scene: &Scene,
        id: PrimitiveId,
        ray: &Ray,
        range: Interval,
        eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<Option<KindHit>> {
        if id.kind != PrimitiveKind::FreeForm {
            return None;
        }
        let complement = self.complements.get(id.index as usize)?.as_ref()?;
        let solid = &scene.objects.get(id.index as usize)?.solid;
        (solid.eval(ray.at(range.lo)) >= 0.0).then(|| exit(solid, complement, ray, range, eps, ctx))
    }
}

/// The nearest hit of a ray leaving a surface, over every primitive, terrains exactly: as
/// [`crate::nearest_hit`], except that a ray whose start `ray.at(range.lo)` lies inside a
/// transmissive free form finds where it leaves that solid (its surface, seen from inside:
/// `front_face` false) instead of a hit at the start.
pub fn nearest_hit_from_surface(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    interiors: &Interiors,
) -> Option<SurfaceInteraction> {
    let footprint = PixelFootprint::ZERO;
    let hit = nearest_pending(
        scene,
        ctx,
        ray,
        range,
        eps,
        None,
        footprint,
        Some(interiors),
    )?;
    Some(interaction(scene, ray, range.lo, &hit, None))
}

/// Where a ray starting inside `solid` leaves it within `range`: the first point of its
/// complement, or — a solid cut by its box — the box's far face.
fn exit(
    solid: &Solid,
    complement: &Solid,
    ray: &Ray,
    range: Interval,
    eps: f64,
    ctx: &mut TraceContext,
) -> Option<KindHit> {
    if let Some(t) = ctx
        .caster
        .cast(complement, ray, range, eps, &mut ctx.counts.cast)
    {
        return Some(KindHit {
            t,
            part: PART_PENDING,
            detail: DVec3::ZERO,
        });
    }
    let inside = solid.bounds().clip_ray(ray, range)?;
    (inside.hi < range.hi).then(|| KindHit {
        t: inside.hi,
        // The leaf is decided by the surface pass; the box face is the normal here.
        part: 0,
        detail: solid.bounds().face_normal(ray.at(inside.hi)),
    })
}

/// The RGB transmittance of a shadow ray over `range` through a scene with transmissive
/// materials: the product of `kt` over every surface it crosses (entering and leaving a glass
/// solid are two), 0 at the first opaque one. `step` is how far past a crossing the next search
/// starts (the integrator's surface offset at that point).
pub fn transmittance_through_surfaces(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    interiors: &Interiors,
    step: impl Fn(DVec3) -> f64,
) -> Rgb {
    let mut total = Rgb::ONE;
    let mut lo = range.lo;
    for _ in 0..MAX_SHADOW_CROSSINGS {
        let segment = Interval { lo, hi: range.hi };
        let Some(si) = nearest_hit_from_surface(scene, ctx, ray, segment, eps, interiors) else {
            return total;
        };
        match scene.materials.get(si.material as usize) {
            Some(m) if m.transmits() => total *= m.transmit,
            _ => return Rgb::ZERO,
        }
        if total == Rgb::ZERO {
            return total;
        }
        lo = si.t + step(si.p);
        if lo >= range.hi {
            return total;
        }
    }
    Rgb::ZERO
}
