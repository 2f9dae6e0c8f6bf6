//! Local shading: ambient + Lambert (albedo/π) + normalised Phong, with hard shadows.

use crate::hit::{occluded, occluded_among};
use fray_core::{Interval, Ray};
use fray_geometry::{CastStats, RayCaster};
use fray_scene::{Light, Material, Scene};
use glam::DVec3;

/// What shading needs to know about the surface point.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub position: DVec3,
    /// Unit normal facing the viewer.
    pub normal: DVec3,
    /// Unit vector toward the viewer.
    pub to_viewer: DVec3,
}

/// Counters and switches of the shading stage.
#[derive(Debug)]
pub struct ShadeContext<'a> {
    pub scene: &'a Scene,
    pub shadows: bool,
    pub epsilon: f64,
    pub shadow_rays: u64,
    pub cast: CastStats,
    /// Per light (indexed like `scene.lights`), the only objects its shadow rays can meet (from
    /// `shadow_cull::occluders` for the current tile); `None` tests every object.
    pub occluders: Option<Vec<Vec<u32>>>,
}

impl ShadeContext<'_> {
    /// Outgoing linear radiance at `point` (f64 RGB).
    pub fn radiance(
        &mut self,
        caster: &mut RayCaster,
        point: &SurfacePoint,
        material: &Material,
    ) -> DVec3 {
        let ambient = material.ambient.as_dvec3() * self.scene.ambient.as_dvec3();
        let mut total = ambient;
        let diffuse = material.diffuse.as_dvec3() / std::f64::consts::PI;
        let specular = material.specular.as_dvec3();
        let specular_on = specular != DVec3::ZERO;
        let lobe_norm = (material.shininess + 2.0) / (2.0 * std::f64::consts::PI);
        for (index, light) in self.scene.lights.iter().enumerate() {
            let (to_light, irradiance, distance) = match *light {
                Light::Sun {
                    direction,
                    irradiance,
                } => (direction, irradiance.as_dvec3(), f64::INFINITY),
                Light::Point {
                    position,
                    intensity,
                } => {
                    let d = position - point.position;
                    let r2 = d.length_squared();
                    if r2 == 0.0 {
                        continue;
                    }
                    let r = r2.sqrt();
                    (d / r, intensity.as_dvec3() / r2, r)
                }
            };
            let cos = point.normal.dot(to_light);
            if cos <= 0.0 {
                continue;
            }
            if self.shadows && self.in_shadow(caster, point, index, to_light, distance) {
                continue;
            }
            let mut brdf = diffuse;
            if specular_on {
                let reflected = point.normal * (2.0 * cos) - to_light;
                let rv = reflected.dot(point.to_viewer).max(0.0);
                brdf += specular * (lobe_norm * rv.powf(material.shininess));
            }
            total += brdf * irradiance * cos;
        }
        total
    }

    /// Where the shadow rays of `point` start: off the surface along the normal by far more
    /// than the hit error (≤ ε), so a shadow ray does not find the surface it starts on.
    pub fn shadow_origin(&self, point: &SurfacePoint) -> DVec3 {
        point.position + point.normal * self.shadow_offset(point)
    }

    /// The distance of [`ShadeContext::shadow_origin`] from the surface point.
    pub fn shadow_offset(&self, point: &SurfacePoint) -> f64 {
        1e3 * self.epsilon + 1e-12 * point.position.abs().max_element()
    }

    fn in_shadow(
        &mut self,
        caster: &mut RayCaster,
        point: &SurfacePoint,
        light: usize,
        to_light: DVec3,
        distance: f64,
    ) -> bool {
        let Some(ray) = Ray::new(self.shadow_origin(point), to_light) else {
            return false;
        };
        self.shadow_rays += 1;
        let range = Interval::new(0.0, distance);
        let (scene, eps) = (self.scene, self.epsilon);
        match self.occluders.as_ref().and_then(|lists| lists.get(light)) {
            Some(objects) => {
                occluded_among(scene, caster, &ray, range, eps, objects, &mut self.cast)
            }
            None => occluded(scene, caster, &ray, range, eps, &mut self.cast),
        }
    }
}
