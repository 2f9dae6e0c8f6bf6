//! The media between the camera and what it sees, as the CPU integrator meets them: the scene's
//! fog layer lit by its suns and ambient light. Camera rays take `L = T · L_behind + L_in` over
//! `[t_near, t_hit]` (to infinity for a ray that hits nothing); light toward a surface takes
//! the media's transmittance. Built once per frame; absent media build nothing.

use fray_atmosphere::{FogLayer, FogLighting, FogModel, FogTerms, Sunlight};
use fray_core::{Interval, Ray};
use fray_scene::{Light, Scene};
use glam::DVec3;

/// What the media do to a ray segment: `L_eye = transmittance · L_behind + in_scatter`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediaTerms {
    pub transmittance: DVec3,
    pub in_scatter: DVec3,
}

impl MediaTerms {
    /// No medium on the segment.
    pub const CLEAR: Self = Self {
        transmittance: DVec3::ONE,
        in_scatter: DVec3::ZERO,
    };

    /// The radiance at the segment's near end when `behind` leaves its far end.
    #[inline]
    pub fn apply(&self, behind: DVec3) -> DVec3 {
        behind * self.transmittance + self.in_scatter
    }
}

impl From<FogTerms> for MediaTerms {
    fn from(t: FogTerms) -> Self {
        Self {
            transmittance: DVec3::splat(t.transmittance),
            in_scatter: t.in_scatter,
        }
    }
}

/// The scene's media for one frame.
#[derive(Clone, Debug)]
pub struct Media {
    fog: Option<(FogLayer, FogModel, FogLighting)>,
    background: DVec3,
}

impl Media {
    /// The scene's media, or `None` if it has none (nothing is built, nothing runs).
    pub fn of(scene: &Scene) -> Option<Self> {
        if scene.atmosphere.is_empty() {
            return None;
        }
        let fog = scene.atmosphere.fog.map(|f| {
            let suns = scene
                .lights
                .iter()
                .filter_map(|l| match *l {
                    Light::Sun {
                        direction,
                        irradiance,
                    } => Some(Sunlight {
                        direction,
                        irradiance: irradiance.as_dvec3(),
                    }),
                    Light::Point { .. } => None,
                })
                .collect();
            let lighting = FogLighting {
                suns,
                ambient: scene.ambient.as_dvec3(),
            };
            (f.layer, f.model, lighting)
        });
        Some(Self {
            fog,
            background: scene.background.as_dvec3(),
        })
    }

    /// The media's terms along `ray` over `range` (`range.hi = ∞`: a ray that hits nothing).
    pub fn terms(&self, ray: &Ray, range: Interval) -> MediaTerms {
        match &self.fog {
            Some((layer, model, lighting)) => layer.terms(ray, range, lighting, *model).into(),
            None => MediaTerms::CLEAR,
        }
    }

    /// The radiance of a camera ray that hits nothing after `t_near`: the background through
    /// the media.
    pub fn miss(&self, ray: &Ray, t_near: f64) -> DVec3 {
        self.terms(ray, Interval::new(t_near, f64::INFINITY))
            .apply(self.background)
    }

    /// The media's transmittance of light toward the surface point `p` from `light`, whose
    /// direction from `p` is `to_light` and distance `distance` (∞ for a sun): suns through the
    /// fog as its model sees them (exact: from `p` to the layer's top; the method: the whole
    /// layer), point lights along the segment.
    pub fn light_transmittance(
        &self,
        p: DVec3,
        light: &Light,
        to_light: DVec3,
        distance: f64,
    ) -> DVec3 {
        let Some((layer, model, _)) = &self.fog else {
            return DVec3::ONE;
        };
        let t = match *light {
            Light::Sun {
                direction,
                irradiance,
            } => {
                let sun = Sunlight {
                    direction,
                    irradiance: irradiance.as_dvec3(),
                };
                layer.sun_transmittance(p, &sun, *model)
            }
            Light::Point { .. } => match Ray::new(p, to_light) {
                Some(ray) => layer.transmittance(&ray, Interval::new(0.0, distance)),
                None => 1.0,
            },
        };
        DVec3::splat(t)
    }
}
