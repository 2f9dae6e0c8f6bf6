//! Local shading: ambient + Lambert (albedo/π) + normalised Phong, with hard shadows.

use crate::hit::occluded;
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
        for light in &self.scene.lights {
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
            if self.shadows && self.in_shadow(caster, point, to_light, distance) {
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

    fn in_shadow(
        &mut self,
        caster: &mut RayCaster,
        point: &SurfacePoint,
        to_light: DVec3,
        distance: f64,
    ) -> bool {
        // Leave the surface along the normal by far more than the hit error (≤ ε), so the shadow
        // ray does not find the surface it starts on.
        let offset = 1e3 * self.epsilon + 1e-12 * point.position.abs().max_element();
        let origin = point.position + point.normal * offset;
        let Some(ray) = Ray::new(origin, to_light) else {
            return false;
        };
        self.shadow_rays += 1;
        let range = Interval::new(0.0, distance);
        occluded(
            self.scene,
            caster,
            &ray,
            range,
            self.epsilon,
            &mut self.cast,
        )
    }
}
