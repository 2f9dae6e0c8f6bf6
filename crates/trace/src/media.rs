//! The media between the camera and what it sees, as the CPU integrator meets them: the scene's
//! fog layer lit by its suns and ambient light, and the physically based sky's air. Camera rays
//! take `L = T · L_behind + L_in` over `[t_near, t_hit]`; a ray that hits nothing sees the
//! background (the sky's table and sun disc, or the scene's colour) through the fog; light toward
//! a surface takes the media's transmittance. Built once per frame (the sky's view table for the
//! camera's height); absent media build nothing.
//!
//! Fog and air overlap; they are composed as two layers in the order the ray enters them: the fog
//! in front when the ray starts inside it, the air in front otherwise, and the sun reaches the
//! fog's top through the air above the camera (Klassen's `Ic`). The cross terms this leaves out
//! (air extinction of fog light inside the same stretch) are the air's optical depth over the
//! fog's span: under 1 % for spans under 1 km.

use fray_atmosphere::sky::{ScatterTerms, SkyView};
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

    /// `self` in front of `behind`: `self.apply(behind.apply(L))` for every `L`.
    #[inline]
    pub fn then(&self, behind: &MediaTerms) -> MediaTerms {
        MediaTerms {
            transmittance: self.transmittance * behind.transmittance,
            in_scatter: self.transmittance * behind.in_scatter + self.in_scatter,
        }
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

impl From<ScatterTerms> for MediaTerms {
    fn from(t: ScatterTerms) -> Self {
        Self {
            transmittance: t.transmittance,
            in_scatter: t.in_scatter,
        }
    }
}

/// The fog of a frame: its layer, model and lighting.
#[derive(Clone, Debug)]
struct FogMedium {
    layer: FogLayer,
    model: FogModel,
    lighting: FogLighting,
}

/// The sky of a frame: the scene's sky and its view from the camera.
#[derive(Clone, Debug)]
struct SkyMedium {
    sky: fray_scene::Sky,
    view: SkyView,
    /// The observer the view was built for (the camera's eye).
    eye: DVec3,
}

/// The scene's media for one frame.
#[derive(Clone, Debug)]
pub struct Media {
    fog: Option<FogMedium>,
    sky: Option<SkyMedium>,
    background: DVec3,
}

/// The camera's eye (a parallel projector's centre).
fn eye_of(camera: &fray_core::Projector) -> DVec3 {
    match camera {
        fray_core::Projector::Pinhole(p) => p.eye,
        fray_core::Projector::Parallel(p) => p.eye,
        fray_core::Projector::Sphere(s) => s.eye,
    }
}

impl Media {
    /// The scene's media, or `None` if it has none (nothing is built, nothing runs).
    pub fn of(scene: &Scene) -> Option<Self> {
        if scene.atmosphere.is_empty() {
            return None;
        }
        let eye = eye_of(&scene.camera);
        let sky = scene.atmosphere.sky.as_ref().map(|s| SkyMedium {
            view: s.sky.view(eye),
            sky: s.clone(),
            eye,
        });
        let fog = scene.atmosphere.fog.map(|f| {
            let suns = scene
                .lights
                .iter()
                .enumerate()
                .filter_map(|(i, l)| match *l {
                    Light::Sun {
                        direction,
                        irradiance,
                    } => {
                        let mut irradiance = irradiance.as_dvec3();
                        if let Some(s) = sky.as_ref().filter(|s| s.sky.sun_light == Some(i)) {
                            // The sky's sun reaches the fog's top through the air above it.
                            let top = DVec3::new(eye.x, f.layer.top, eye.z);
                            irradiance *= s.sky.sky.transmittance_to_sun(top, eye);
                        }
                        Some(Sunlight {
                            direction,
                            irradiance,
                        })
                    }
                    Light::Point { .. } => None,
                })
                .collect();
            FogMedium {
                layer: f.layer,
                model: f.model,
                lighting: FogLighting {
                    suns,
                    ambient: scene.ambient.as_dvec3(),
                },
            }
        });
        Some(Self {
            fog,
            sky,
            background: scene.background.as_dvec3(),
        })
    }

    /// The media's terms along `ray` over `range`. A finite `range.hi` ends at a surface: fog
    /// and air. `range.hi = ∞` (a ray that hits nothing): the fog alone — the sky's air along
    /// the whole ray is in [`Media::background`].
    pub fn terms(&self, ray: &Ray, range: Interval) -> MediaTerms {
        let fog = self.fog.as_ref().map(|f| {
            let terms = f.layer.terms(ray, range, &f.lighting, f.model);
            let starts_inside = f.layer.span(ray, range).is_some_and(|s| s.lo <= range.lo);
            (MediaTerms::from(terms), starts_inside)
        });
        let air = self
            .sky
            .as_ref()
            .filter(|s| s.sky.aerial_perspective && range.hi.is_finite())
            .map(|s| {
                // The air over [0, t]; the near plane's sliver of air is left in.
                MediaTerms::from(s.sky.sky.aerial_perspective(
                    ray.origin,
                    ray.dir,
                    range.hi,
                    s.sky.steps,
                ))
            });
        match (fog, air) {
            (None, None) => MediaTerms::CLEAR,
            (Some((fog, _)), None) => fog,
            (None, Some(air)) => air,
            (Some((fog, true)), Some(air)) => fog.then(&air),
            (Some((fog, false)), Some(air)) => air.then(&fog),
        }
    }

    /// The media's largest extinction coefficient (1/m, over the channels) at distance `t` along
    /// `ray`: how fast its terms change with the depth there.
    pub fn extinction_at(&self, ray: &Ray, t: f64) -> f64 {
        let p = ray.at(t);
        let mut sigma = self.fog.as_ref().map_or(0.0, |f| f.layer.density(p.y));
        if let Some(s) = self.sky.as_ref().filter(|s| s.sky.aerial_perspective) {
            let model = s.sky.sky.model();
            // The point's altitude in the sky's frame (the planet's centre below the eye).
            let r0 = model.observer_radius(ray.origin.y);
            let r = (t * t + 2.0 * t * r0 * ray.dir.y + r0 * r0).max(0.0).sqrt();
            sigma += model.extinction(model.altitude(r)).max_element();
        }
        sigma
    }

    /// The radiance of a ray that hits nothing, before the fog: the sky (its table and, if
    /// drawn, the sun's disc) or the scene's background colour.
    pub fn background(&self, ray: &Ray) -> DVec3 {
        match &self.sky {
            Some(s) if s.sky.sun_disc => s.view.background(ray.dir),
            Some(s) => s.view.lookup(ray.dir),
            None => self.background,
        }
    }

    /// The radiance of a camera ray that hits nothing after `t_near`: the background through
    /// the fog.
    pub fn miss(&self, ray: &Ray, t_near: f64) -> DVec3 {
        self.terms(ray, Interval::new(t_near, f64::INFINITY))
            .apply(self.background(ray))
    }

    /// The media's transmittance of light toward the surface point `p` from light `index`,
    /// whose direction from `p` is `to_light` and distance `distance` (∞ for a sun): suns
    /// through the fog as its model sees them (exact: from `p` to the layer's top; the method:
    /// the whole layer), the sky's sun also through the air; point lights along the segment.
    pub fn light_transmittance(
        &self,
        p: DVec3,
        index: usize,
        light: &Light,
        to_light: DVec3,
        distance: f64,
    ) -> DVec3 {
        let mut through = DVec3::ONE;
        if let Some(f) = &self.fog {
            let t = match *light {
                Light::Sun {
                    direction,
                    irradiance,
                } => {
                    let sun = Sunlight {
                        direction,
                        irradiance: irradiance.as_dvec3(),
                    };
                    f.layer.sun_transmittance(p, &sun, f.model)
                }
                Light::Point { .. } => match Ray::new(p, to_light) {
                    Some(ray) => f.layer.transmittance(&ray, Interval::new(0.0, distance)),
                    None => 1.0,
                },
            };
            through *= t;
        }
        if let Some(s) = self.sky.as_ref().filter(|s| s.sky.sun_light == Some(index)) {
            through *= s.sky.sky.transmittance_to_sun(p, s.eye);
        }
        through
    }
}
