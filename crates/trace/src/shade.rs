//! The local reflection model: ambient + Lambert (albedo/π) + normalised Phong — what a material
//! reflects of the ambient radiance and of one light's irradiance.

use fray_scene::Material;
use glam::DVec3;

/// A material's reflectance, with the constants every light's evaluation shares.
#[derive(Clone, Copy, Debug)]
pub struct Reflectance {
    ambient: DVec3,
    /// Lambert: albedo / π.
    diffuse: DVec3,
    specular: DVec3,
    shininess: f64,
    /// The normalised Phong lobe's `(n + 2) / 2π`.
    lobe_norm: f64,
}

impl Reflectance {
    pub fn of(material: &Material) -> Self {
        Self {
            ambient: material.ambient.as_dvec3(),
            diffuse: material.diffuse.as_dvec3() / std::f64::consts::PI,
            specular: material.specular.as_dvec3(),
            shininess: material.shininess,
            lobe_norm: (material.shininess + 2.0) / (2.0 * std::f64::consts::PI),
        }
    }

    /// The reflectance with a surface colour `c` (a texture's or ramp's) multiplying the ambient
    /// and diffuse terms: Whitted's `ka·C` and `kd·C`.
    pub fn coloured(material: &Material, c: DVec3) -> Self {
        let mut r = Self::of(material);
        r.ambient *= c;
        r.diffuse *= c;
        r
    }

    /// Outgoing radiance from a uniform ambient radiance.
    #[inline]
    pub fn ambient(&self, ambient: DVec3) -> DVec3 {
        self.ambient * ambient
    }

    /// The BRDF for light arriving from `to_light` at a point with unit normal `n` (on the
    /// viewer's side), seen from `to_viewer`; `cos = n · to_light > 0`.
    #[inline]
    pub fn brdf(&self, n: DVec3, to_light: DVec3, cos: f64, to_viewer: DVec3) -> DVec3 {
        let mut brdf = self.diffuse;
        if self.specular != DVec3::ZERO {
            let reflected = n * (2.0 * cos) - to_light;
            let rv = reflected.dot(to_viewer).max(0.0);
            brdf += self.specular * (self.lobe_norm * rv.powf(self.shininess));
        }
        brdf
    }
}
