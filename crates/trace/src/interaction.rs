//! The surface interaction: everything shading needs to know about a hit, in one record made
//! before any shading — and nothing in it is flipped toward the viewer: which side a ray is on
//! is `front_face`, and the integrator decides what to do with it.

use crate::primitive::Surface;
use fray_core::Ray;
use fray_scene::PrimitiveId;
use glam::{DVec2, DVec3};

/// A ray's hit on a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// The ray parameter of the hit (the distance along the unit ray direction).
    pub t: f64,
    /// The hit point.
    pub p: DVec3,
    /// The outward unit normal of the surface hit. Where the ray starts inside the primitive
    /// (`t` at the start of its range: the picture surface cuts the object) the surface is the
    /// cut face, whose normal is `−dir`.
    pub geometric_normal: DVec3,
    /// The outward unit normal to shade with (see [`Surface::shading_normal`]).
    pub shading_normal: DVec3,
    /// Whether the ray arrives from outside the surface (`dir · geometric_normal ≤ 0`).
    pub front_face: bool,
    /// The surface's own texture coordinates, where its kind has them.
    pub uv: Option<DVec2>,
    /// What was hit.
    pub primitive: PrimitiveId,
    /// The part of it (a free form's leaf, 0 for a terrain).
    pub part: u32,
    /// Index into the scene's materials (`Scene::materials`), or past its end for "none" (the
    /// default material).
    pub material: u32,
}

impl SurfaceInteraction {
    /// The interaction of `ray`'s hit at `t` on `surface` of `primitive`; `range_start` is the
    /// start of the range the ray was cast over (a hit there is on the cut face).
    #[inline]
    pub fn new(
        ray: &Ray,
        range_start: f64,
        t: f64,
        primitive: PrimitiveId,
        surface: Surface,
        material: u32,
    ) -> Self {
        let (geometric_normal, shading_normal) = if t <= range_start {
            (-ray.dir, -ray.dir)
        } else {
            (surface.geometric_normal, surface.shading_normal)
        };
        Self {
            t,
            p: ray.at(t),
            geometric_normal,
            shading_normal,
            front_face: ray.dir.dot(geometric_normal) <= 0.0,
            uv: surface.uv,
            primitive,
            part: surface.part,
            material,
        }
    }

    /// The shading normal turned to the side of `w` (a unit vector away from the surface, e.g.
    /// toward the viewer): opaque surfaces are lit on whichever side is seen.
    #[inline]
    pub fn shading_normal_toward(&self, w: DVec3) -> DVec3 {
        if self.shading_normal.dot(w) < 0.0 {
            -self.shading_normal
        } else {
            self.shading_normal
        }
    }
}
