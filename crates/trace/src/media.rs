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
//!
//! A cloud volume is marched where the ray crosses its box (`fray_clouds::march`, lit by the
//! scene's first sun and its ambient radiance) and inserted at its entry distance `a`: with
//! `whole` the fog and air over the ray (the sky's table of a miss holding the air along all of
//! it) and `front` their part over `[t_near, a]`, the terms are `front ∘ cloud ∘ front⁻¹ ∘ whole`
//! — the light reaching the cloud is what the atmosphere alone would deliver, with the part in
//! front peeled off — so a clear stretch of the box changes nothing, and fog or air inside the
//! box are put behind the cloud (exact where they do not overlap). Light toward surfaces takes
//! the cloud's transmittance (shadows), marched at the view step.

use fray_atmosphere::sky::{ScatterTerms, SkyView};
use fray_atmosphere::{FogLayer, FogLighting, FogModel, FogTerms, Sunlight};
use fray_clouds::march::{self as cloud_march, CloudLight, Density};
use fray_core::{Interval, Ray};
use fray_scene::{Clouds, Light, Scene};
use glam::DVec3;
use std::sync::Arc;

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

/// The clouds of a frame: the scene's volume and how it is lit.
#[derive(Clone, Debug)]
struct CloudMedium {
    clouds: Arc<Clouds>,
    light: CloudLight,
}

/// The scene's media for one frame.
#[derive(Clone, Debug)]
pub struct Media {
    fog: Option<FogMedium>,
    sky: Option<SkyMedium>,
    clouds: Option<CloudMedium>,
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
        if scene.atmosphere.is_empty() && scene.clouds.is_none() {
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
        let clouds = scene.clouds.as_ref().map(|c| {
            let sun_light = scene
                .lights
                .iter()
                .position(|l| matches!(l, Light::Sun { .. }));
            let (sun_direction, mut sun_irradiance) = match sun_light.map(|i| scene.lights[i]) {
                Some(Light::Sun {
                    direction,
                    irradiance,
                }) => (direction, irradiance.as_dvec3()),
                _ => (DVec3::Y, DVec3::ZERO),
            };
            if let Some(s) = sky
                .as_ref()
                .filter(|s| sun_light.is_some() && s.sky.sun_light == sun_light)
            {
                // The sky's sun reaches the volume through the air above its centre.
                let r = &c.volume.region;
                let centre =
                    DVec3::from_array(std::array::from_fn(|a| 0.5 * (r.min[a] + r.max[a])));
                sun_irradiance *= s.sky.sky.transmittance_to_sun(centre, eye);
            }
            CloudMedium {
                light: CloudLight {
                    sun_direction: sun_direction.to_array(),
                    sun_irradiance: sun_irradiance.to_array(),
                    ambient: (scene.ambient.as_dvec3() * c.ambient).to_array(),
                    albedo: c.albedo,
                    phase: c.phase,
                },
                clouds: c.clone(),
            }
        });
        Some(Self {
            fog,
            sky,
            clouds,
            background: scene.background.as_dvec3(),
        })
    }

    /// Whether the media hold a cloud volume (marched per pixel: no media grid).
    pub fn has_clouds(&self) -> bool {
        self.clouds.is_some()
    }

    /// Where in each step the clouds' samples of the camera ray through image point `(x, y)`
    /// lie: the pixel's interleaved gradient noise when the clouds jitter, else midpoints.
    pub fn camera_jitter(&self, (x, y): (f64, f64)) -> f64 {
        match &self.clouds {
            Some(c) if c.clouds.jitter => {
                cloud_march::pixel_jitter(x.max(0.0) as u32, y.max(0.0) as u32)
            }
            _ => 0.5,
        }
    }

    /// [`Media::terms`] with the clouds' samples offset by `jitter` (in `[0, 1)`, a camera
    /// pixel's), adding the cloud march's density samples to `samples`.
    pub fn terms_jittered(
        &self,
        ray: &Ray,
        range: Interval,
        jitter: f64,
        samples: &mut u64,
    ) -> MediaTerms {
        let Some(c) = &self.clouds else {
            return self.atmosphere_terms(ray, range);
        };
        let (o, d) = (ray.origin.to_array(), ray.dir.to_array());
        let region = c.clouds.volume.region();
        let Some((a, b)) = cloud_march::clip(&region, o, d, range.lo, range.hi) else {
            return self.atmosphere_terms(ray, range);
        };
        let settings = fray_clouds::march::MarchSettings {
            jitter,
            ..c.clouds.march
        };
        let marched = cloud_march::march(&c.clouds.volume, o, d, (a, b), &settings, &c.light);
        *samples += u64::from(marched.samples);
        let cloud = MediaTerms {
            transmittance: DVec3::splat(marched.transmittance),
            in_scatter: DVec3::from_array(marched.in_scatter),
        };
        // What the fog and air alone deliver to the eye (from a surface, or from the background,
        // which holds the sky's air along the whole ray), and their part in front of the cloud.
        // The light reaching the cloud's entry is the whole with the front peeled off:
        // `front ∘ cloud ∘ front⁻¹ ∘ whole`, which is `whole` when the cloud is clear.
        let whole = self.atmosphere_terms(ray, range);
        let front = self.atmosphere_terms(ray, Interval::new(range.lo, a));
        if front.transmittance.min_element() <= 1e-12 {
            // Nothing from the cloud gets through what lies in front of it.
            return whole;
        }
        let peel = MediaTerms {
            transmittance: 1.0 / front.transmittance,
            in_scatter: -front.in_scatter / front.transmittance,
        };
        front.then(&cloud).then(&peel).then(&whole)
    }

    /// The media's terms along `ray` over `range`. A finite `range.hi` ends at a surface: fog
    /// and air. `range.hi = ∞` (a ray that hits nothing): the fog alone — the sky's air along
    /// the whole ray is in [`Media::background`].
    pub fn terms(&self, ray: &Ray, range: Interval) -> MediaTerms {
        self.terms_jittered(ray, range, 0.5, &mut 0)
    }

    /// The sky's air over `[0, t]` along `ray` when it is drawn in front of surfaces.
    fn air(&self, ray: &Ray, t: f64) -> Option<MediaTerms> {
        self.sky
            .as_ref()
            .filter(|s| s.sky.aerial_perspective)
            .map(|s| {
                MediaTerms::from(
                    s.sky
                        .sky
                        .aerial_perspective(ray.origin, ray.dir, t, s.sky.steps),
                )
            })
    }

    /// The fog's and air's terms (no clouds), as [`Media::terms`] describes.
    fn atmosphere_terms(&self, ray: &Ray, range: Interval) -> MediaTerms {
        let fog = self.fog.as_ref().map(|f| {
            let terms = f.layer.terms(ray, range, &f.lighting, f.model);
            let starts_inside = f.layer.span(ray, range).is_some_and(|s| s.lo <= range.lo);
            (MediaTerms::from(terms), starts_inside)
        });
        // The air over [0, t]; the near plane's sliver of air is left in.
        let air = if range.hi.is_finite() {
            self.air(ray, range.hi)
        } else {
            None
        };
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
        if let Some(c) = &self.clouds {
            let far = match light {
                Light::Sun { .. } => f64::INFINITY,
                Light::Point { .. } => distance,
            };
            let depth = cloud_march::optical_depth(
                &c.clouds.volume,
                p.to_array(),
                to_light.to_array(),
                (0.0, far),
                c.clouds.march.step,
            );
            through *= (-depth).exp();
        }
        through
    }
}
