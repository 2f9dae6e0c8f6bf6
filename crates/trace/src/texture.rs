//! Surface colour from a material's texture or ramp — Whitted's `C` — at a surface interaction:
//! the lookup's coordinates (the mapping's projection, or the surface's own uv), its width from
//! the camera pixel's footprint at the ray's path length, the cosine between ray and surface and
//! the uv per world unit there (`fray_mesh::texture::Footprint`: the ellipse's longer axis,
//! stretch capped), read with the material's wrap and filter.

use crate::hit::AnyPrimitive;
use crate::interaction::SurfaceInteraction;
use crate::primitive::Primitive;
use fray_core::PixelFootprint;
use fray_mesh::texture::{Filter, Footprint};
use fray_scene::{Material, Scene, TextureSlot};
use glam::{DVec2, DVec3, Vec4};

/// The colour `C` that multiplies `material`'s ambient and diffuse reflectance at `si`, seen
/// along `dir` after a path of `distance` from the camera (1 without texture or ramp).
pub(crate) fn surface_colour(
    scene: &Scene,
    footprint: PixelFootprint,
    material: &Material,
    si: &SurfaceInteraction,
    dir: DVec3,
    distance: f64,
) -> DVec3 {
    let mut colour = DVec3::ONE;
    if let Some(slot) = &material.texture {
        let pixel = footprint.at(distance);
        let cos = dir.dot(si.geometric_normal).abs();
        colour *= lookup(scene, slot, si, pixel, cos).truncate().as_dvec3();
    }
    if let Some(ramp) = &material.ramp {
        colour *= ramp.colour(si.p.y, si.shading_normal).as_dvec3();
    }
    colour
}

fn lookup(
    scene: &Scene,
    slot: &TextureSlot,
    si: &SurfaceInteraction,
    pixel: f64,
    cos: f64,
) -> Vec4 {
    let rule = Footprint::default();
    let texture = &slot.texture;
    match &slot.mapping {
        Some(mapping) => {
            let projected = mapping.project(si.p, si.shading_normal);
            let width = rule.uv_width(pixel, cos, projected.uv_per_world);
            let mut sum = Vec4::ZERO;
            for (uv, &w) in projected.uv.iter().zip(&projected.weight) {
                if w > 0.0 {
                    sum += texture.filtered(*uv, width, slot.wrap, slot.filter) * w as f32;
                }
            }
            sum
        }
        None => match si.uv {
            Some(uv) => {
                let width = rule.uv_width(pixel, cos, uv_per_world(scene, si));
                texture.filtered(uv, width, slot.wrap, slot.filter)
            }
            // No coordinates (a free form without a projected mapping): the image's mean.
            None => texture.filtered(
                DVec2::splat(0.5),
                f64::INFINITY,
                slot.wrap,
                Filter::Trilinear,
            ),
        },
    }
}

/// The uv per world unit of the surface's own coordinates at `si`, as its kind gives it
/// (`Primitive::uv_per_world`).
fn uv_per_world(scene: &Scene, si: &SurfaceInteraction) -> f64 {
    AnyPrimitive::of(scene, si.primitive, None, PixelFootprint::ZERO)
        .map_or(0.0, |p| p.uv_per_world(si.part))
}
