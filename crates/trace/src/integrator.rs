//! The CPU integrator: the radiance a ray brings back — the nearest surface over every primitive
//! kind, shaded by its material with each light's direct light times the RGB transmittance of a
//! shadow ray toward it (and of the media on its way), plus Whitted's reflected and refracted
//! rays (`kr · I_r + kt · I_t`, recursively to the scene's maximum depth, each traced only while
//! its weight is above the contribution cut-off and its share of the camera ray's secondary-ray
//! budget is left: [`crate::ray_budget`]), or the background where nothing is hit; then
//! the media along the ray (`T · L + L_in`). Camera rays enter at
//! [`Integrator::surface_radiance`] and [`Integrator::through_media`] with hits the frame loop
//! found a tile at a time; any other ray through [`Integrator::radiance`]. Shading happens here
//! and nowhere else.

use crate::TraceSettings;
use crate::hit::{ShadowKinds, nearest_hit, transmittance_of};
use crate::interaction::SurfaceInteraction;
use crate::media::Media;
use crate::media_grid::{MediaGrid, camera_terms};
use crate::optics::{fresnel_dielectric, reflect, refract};
use crate::primitive::TraceContext;
use crate::ray_budget;
use crate::secondary::{Interiors, nearest_hit_from_surface, transmittance_through_surfaces};
use crate::shade::Reflectance;
use crate::texture::surface_colour;
use fray_core::{Interval, Ray};
use fray_scene::{Light, Material, Scene};
use glam::DVec3;

/// Shading of one scene with one set of settings.
#[derive(Debug)]
pub struct Integrator<'a> {
    scene: &'a Scene,
    /// Cast shadow rays (the settings ask for them and the scene has lights that cast them).
    shadows: bool,
    epsilon: f64,
    /// Used where a part names no material.
    default_material: Material,
    /// The scene's fog (`None`: it has none, and nothing of it runs).
    media: Option<Media>,
    /// The media's terms on a pixel grid, for camera rays (`None`: every ray exactly).
    grid: Option<MediaGrid>,
    /// The transmissive free forms' complements (empty without transmission).
    interiors: Interiors,
    /// Whitted recursion: the deepest secondary ray, and the weight below which none is traced
    /// (`max_depth` 0 when the scene's materials send none, or without shading).
    max_depth: u32,
    min_contribution: f64,
    /// Whitted recursion: the secondary rays one camera ray may trace ([`crate::ray_budget`]).
    max_secondary_rays: u32,
    /// The camera pixel's footprint (texture lookups' width).
    footprint: fray_core::PixelFootprint,
}

impl<'a> Integrator<'a> {
    pub fn new(scene: &'a Scene, settings: &TraceSettings) -> Self {
        Self {
            scene,
            shadows: settings.shading && settings.shadows && scene.features.shadows,
            epsilon: settings.epsilon,
            default_material: Material::default(),
            // Visibility-only frames show normals: no light, no media.
            media: if settings.shading {
                Media::of(scene)
            } else {
                None
            },
            grid: None,
            interiors: if settings.shading {
                Interiors::of(scene)
            } else {
                Interiors::default()
            },
            max_depth: if settings.shading
                && (scene.features.reflection || scene.features.transmission)
            {
                scene.settings.max_depth
            } else {
                0
            },
            min_contribution: scene.settings.min_contribution,
            max_secondary_rays: scene.settings.max_secondary_rays,
            footprint: scene.camera.pixel_footprint(scene.width, scene.height),
        }
    }

    /// Evaluates the media of camera rays on `grid` from now on.
    pub fn set_media_grid(&mut self, grid: MediaGrid) {
        self.grid = Some(grid);
    }

    /// The media grid camera rays use, if any.
    pub fn media_grid(&self) -> Option<&MediaGrid> {
        self.grid.as_ref()
    }

    /// [`Integrator::through_media`] for the camera ray through image point `at` (pixel units):
    /// from the media grid where it interpolates.
    #[inline]
    pub fn camera_through_media(
        &self,
        ctx: &mut TraceContext,
        at: (f64, f64),
        ray: &Ray,
        range: Interval,
        behind: DVec3,
    ) -> DVec3 {
        match &self.media {
            Some(media) => {
                camera_terms(media, self.grid.as_ref(), ctx, at, ray, range).apply(behind)
            }
            None => behind,
        }
    }

    /// [`Integrator::miss_radiance`] for the camera ray through image point `at`.
    #[inline]
    pub fn camera_miss(
        &self,
        ctx: &mut TraceContext,
        at: (f64, f64),
        ray: &Ray,
        t_near: f64,
    ) -> DVec3 {
        let background = match &self.media {
            Some(media) => media.background(ray),
            None => self.scene.background.as_dvec3(),
        };
        self.camera_through_media(
            ctx,
            at,
            ray,
            Interval::new(t_near, f64::INFINITY),
            background,
        )
    }

    /// The frame's media, if the scene has any.
    pub fn media(&self) -> Option<&Media> {
        self.media.as_ref()
    }

    /// The radiance reaching a ray's origin from `range.hi` (a surface hit there, or `∞`) when
    /// `behind` leaves that point: through the media over `range`.
    #[inline]
    pub fn through_media(&self, ray: &Ray, range: Interval, behind: DVec3) -> DVec3 {
        match &self.media {
            Some(media) => media.terms(ray, range).apply(behind),
            None => behind,
        }
    }

    /// The radiance of a ray that hits nothing after `t_near`: the background, through the media.
    #[inline]
    pub fn miss_radiance(&self, ray: &Ray, t_near: f64) -> DVec3 {
        match &self.media {
            Some(media) => media.miss(ray, t_near),
            None => self.scene.background.as_dvec3(),
        }
    }

    /// Whether shading casts shadow rays.
    pub fn shadows(&self) -> bool {
        self.shadows
    }

    /// The radiance arriving along `ray` from `range`: the outgoing radiance of the nearest
    /// surface toward the ray's origin, or the scene's background, through the media.
    pub fn radiance(&self, ctx: &mut TraceContext, ray: &Ray, range: Interval) -> DVec3 {
        match nearest_hit(self.scene, ctx, ray, range, self.epsilon) {
            Some(si) => {
                let surface = self.surface_radiance(ctx, &si, -ray.dir, None);
                self.through_media(ray, Interval::new(range.lo, si.t), surface)
            }
            None => self.miss_radiance(ray, range.lo),
        }
    }

    /// [`Integrator::radiance`] of the camera ray through image point `at` (pixel units): its
    /// media as the frame loop takes them (the media grid, the clouds' per-pixel jitter).
    pub fn camera_radiance(
        &self,
        ctx: &mut TraceContext,
        at: (f64, f64),
        ray: &Ray,
        range: Interval,
    ) -> DVec3 {
        match nearest_hit(self.scene, ctx, ray, range, self.epsilon) {
            Some(si) => {
                let surface = self.surface_radiance(ctx, &si, -ray.dir, None);
                self.camera_through_media(ctx, at, ray, Interval::new(range.lo, si.t), surface)
            }
            None => self.camera_miss(ctx, at, ray, range.lo),
        }
    }

    /// The radiance leaving `si` toward `wo` (unit, away from the surface): the material's
    /// ambient term plus, per light, its BRDF times the irradiance times the transmittance of the
    /// shadow ray toward it. Opaque surfaces are lit on the side `wo` sees. `occluders`: per
    /// light, the only free forms its shadow rays can meet (`None`: all).
    pub fn surface_radiance(
        &self,
        ctx: &mut TraceContext,
        si: &SurfaceInteraction,
        wo: DVec3,
        occluders: Option<&[Vec<u32>]>,
    ) -> DVec3 {
        let path = Path::camera(si.t, self.max_secondary_rays);
        self.shade(ctx, si, wo, occluders, None, path)
    }

    /// [`Integrator::surface_radiance`] where whether a mesh blocks each light's shadow ray
    /// from `si` ([`Integrator::shadow_rays`]) is already known, per light (the frame loop casts
    /// a tile's shadow rays against the meshes as packets): only the other kinds are asked.
    /// The same answer, for a scene without transmission (opaque: a kind blocks or not).
    pub(crate) fn surface_radiance_mesh_shadowed(
        &self,
        ctx: &mut TraceContext,
        si: &SurfaceInteraction,
        wo: DVec3,
        occluders: Option<&[Vec<u32>]>,
        mesh_blocked: &[bool],
    ) -> DVec3 {
        debug_assert!(!self.scene.features.transmission);
        let blocked = Some(mesh_blocked);
        let path = Path::camera(si.t, self.max_secondary_rays);
        self.shade(ctx, si, wo, occluders, blocked, path)
    }

    /// The shadow rays [`Integrator::surface_radiance`] casts from `si` seen along `wo`: per
    /// light, `(light index, ray, range)` where one is cast (lights behind the surface, a point
    /// light at the point, or no shadows at all cast none).
    pub(crate) fn shadow_rays(
        &self,
        si: &SurfaceInteraction,
        wo: DVec3,
        mut cast: impl FnMut(usize, Ray, Interval),
    ) {
        if !self.shadows {
            return;
        }
        let n = si.shading_normal_toward(wo);
        for (index, light) in self.scene.lights.iter().enumerate() {
            let Some((to_light, _, distance)) = toward(light, si.p) else {
                continue;
            };
            if n.dot(to_light) <= 0.0 {
                continue;
            }
            if let Some((ray, range)) = self.shadow_ray(si, n, to_light, distance) {
                cast(index, ray, range);
            }
        }
    }

    /// [`Integrator::surface_radiance`] of a surface reached along `path`.
    fn shade(
        &self,
        ctx: &mut TraceContext,
        si: &SurfaceInteraction,
        wo: DVec3,
        occluders: Option<&[Vec<u32>]>,
        mesh_blocked: Option<&[bool]>,
        path: Path,
    ) -> DVec3 {
        let mut total = self.local_radiance(ctx, si, wo, occluders, mesh_blocked, path.distance);
        if path.depth < self.max_depth {
            total += self.whitted(ctx, si, -wo, path);
        }
        total
    }

    /// Whitted's secondary terms at `si` for a ray arriving along `d` (unit): `kr · I_r + kt ·
    /// I_t`, Fresnel-weighted if the material asks; past the critical angle the transmitted
    /// weight is reflected (total internal reflection). The outside is vacuum (index 1); a ray
    /// inside a transmissive solid leaves into it. The two rays share the path's allowance
    /// ([`crate::ray_budget`]).
    fn whitted(
        &self,
        ctx: &mut TraceContext,
        si: &SurfaceInteraction,
        d: DVec3,
        path: Path,
    ) -> DVec3 {
        let material = self
            .scene
            .materials
            .get(si.material as usize)
            .unwrap_or(&self.default_material);
        if !(material.reflects() || material.transmits()) {
            return DVec3::ZERO;
        }
        // Both normals on the side the ray arrives from.
        let side = if si.front_face { 1.0 } else { -1.0 };
        let ng = si.geometric_normal * side;
        let ns = si.shading_normal * side;
        let ns = if ns.dot(ng) > 0.0 { ns } else { ng };
        let (n_from, n_to) = if si.front_face {
            (1.0, material.ior)
        } else {
            (material.ior, 1.0)
        };
        let mut kr = material.reflect.as_dvec3();
        let mut kt = material.transmit.as_dvec3();
        let mut refracted = None;
        if material.transmits() {
            // A shading normal may bend the refracted ray back to the arriving side: then the
            // face's own normal decides.
            refracted = refract(d, ns, n_from / n_to)
                .filter(|t| t.dot(ng) < 0.0)
                .or_else(|| refract(d, ng, n_from / n_to));
            if material.fresnel {
                let f = fresnel_dielectric(-d.dot(ns), n_from, n_to);
                kr += kt * f;
                kt *= 1.0 - f;
            }
            if refracted.is_none() {
                // Total internal reflection: what would have been transmitted is reflected.
                kr += kt;
                kt = DVec3::ZERO;
            }
        }
        let offset = self.shadow_offset_at(si.p);
        let reflected = (kr != DVec3::ZERO)
            .then(|| {
                let r = reflect(d, ns);
                // Reflected about a shading normal, a grazing ray may point into the surface.
                let r = if r.dot(ng) > 0.0 { r } else { reflect(d, ng) };
                self.child_ray(si.p + ng * offset, r, path.weight * kr)
            })
            .flatten();
        let transmitted = refracted
            .filter(|_| kt != DVec3::ZERO)
            .and_then(|t| self.child_ray(si.p - ng * offset, t, path.weight * kt));
        let [r_share, t_share] =
            ray_budget::shares(path.allowance, [reflected.is_some(), transmitted.is_some()]);
        let mut total = DVec3::ZERO;
        if kr != DVec3::ZERO {
            total += kr * self.secondary(ctx, reflected, path.child(kr, r_share));
        }
        if refracted.is_some() && kt != DVec3::ZERO {
            total += kt * self.secondary(ctx, transmitted, path.child(kt, t_share));
        }
        total
    }

    /// The secondary ray from `origin` along `dir` reached with `weight`, if it is traced by
    /// its weight: not below the cut-off (and a direction at all).
    fn child_ray(&self, origin: DVec3, dir: DVec3, weight: DVec3) -> Option<Ray> {
        if weight.max_element() < self.min_contribution {
            return None;
        }
        Ray::new(origin, dir)
    }

    /// The radiance a secondary ray brings back along `path` (its share of the budget
    /// included): 0 for no ray (below the cut-off) or no share.
    fn secondary(&self, ctx: &mut TraceContext, ray: Option<Ray>, path: Option<Path>) -> DVec3 {
        let (Some(ray), Some(path)) = (ray, path) else {
            return DVec3::ZERO;
        };
        ctx.counts.secondary_rays += 1;
        let range = Interval::new(0.0, f64::INFINITY);
        let (scene, eps) = (self.scene, self.epsilon);
        match nearest_hit_from_surface(scene, ctx, &ray, range, eps, &self.interiors) {
            Some(si) => {
                let path = path.to(si.t);
                let surface = self.shade(ctx, &si, -ray.dir, None, None, path);
                self.through_media(&ray, Interval::new(0.0, si.t), surface)
            }
            None => self.miss_radiance(&ray, 0.0),
        }
    }

    /// The material's local terms at `si`: ambient plus each light's BRDF × irradiance ×
    /// shadow-ray transmittance (`mesh_blocked`: per light, whether a mesh is already known to
    /// block its shadow ray).
    fn local_radiance(
        &self,
        ctx: &mut TraceContext,
        si: &SurfaceInteraction,
        wo: DVec3,
        occluders: Option<&[Vec<u32>]>,
        mesh_blocked: Option<&[bool]>,
        distance: f64,
    ) -> DVec3 {
        let material = self
            .scene
            .materials
            .get(si.material as usize)
            .unwrap_or(&self.default_material);
        let reflectance = if material.texture.is_some() || material.ramp.is_some() {
            let c = surface_colour(self.scene, self.footprint, material, si, -wo, distance);
            Reflectance::coloured(material, c)
        } else {
            Reflectance::of(material)
        };
        let n = si.shading_normal_toward(wo);
        let mut total = reflectance.ambient(self.scene.ambient.as_dvec3());
        for (index, light) in self.scene.lights.iter().enumerate() {
            let Some((to_light, irradiance, distance)) = toward(light, si.p) else {
                continue;
            };
            let cos = n.dot(to_light);
            if cos <= 0.0 {
                continue;
            }
            let mut light_in = irradiance;
            if let Some(media) = &self.media {
                // Not a shadow: the medium dims the light whether or not shadows are on.
                light_in *= media.light_transmittance(si.p, index, light, to_light, distance);
            }
            if self.shadows {
                let lists = occluders.and_then(|l| l.get(index));
                let kinds = match mesh_blocked.and_then(|b| b.get(index)) {
                    Some(true) => {
                        // A mesh blocks the ray: nothing else needs asking.
                        ctx.counts.shadow_rays += 1;
                        continue;
                    }
                    Some(false) => ShadowKinds::AllButMeshes,
                    None => ShadowKinds::All,
                };
                let ray = self.shadow_ray(si, n, to_light, distance);
                let through = self.shadow_transmittance(ctx, ray, lists, kinds);
                if through == DVec3::ZERO {
                    continue;
                }
                light_in *= through;
            }
            total += reflectance.brdf(n, to_light, cos, wo) * light_in * cos;
        }
        total
    }

    /// Where the shadow rays of `si` start, `n` its shading normal on the lit side: off the
    /// surface by far more than the hit error (≤ ε), so a shadow ray does not find the surface
    /// it starts on.
    pub fn shadow_origin(&self, si: &SurfaceInteraction, n: DVec3) -> DVec3 {
        si.p + n * self.shadow_offset_at(si.p)
    }

    /// The distance of [`Integrator::shadow_origin`] from the surface point.
    pub fn shadow_offset(&self, si: &SurfaceInteraction) -> f64 {
        self.shadow_offset_at(si.p)
    }

    /// The shadow rays' offset from a surface point `p`: far beyond the hit error (≤ ε) and
    /// the rounding of `p`'s coordinates.
    #[inline]
    pub fn shadow_offset_at(&self, p: DVec3) -> f64 {
        1e3 * self.epsilon + 1e-12 * p.abs().max_element()
    }

    /// The shadow ray from `si` (`n` its shading normal on the lit side) toward a light
    /// `distance` away in direction `to_light`, and its range.
    #[inline]
    fn shadow_ray(
        &self,
        si: &SurfaceInteraction,
        n: DVec3,
        to_light: DVec3,
        distance: f64,
    ) -> Option<(Ray, Interval)> {
        let ray = Ray::new(self.shadow_origin(si, n), to_light)?;
        Some((ray, Interval::new(0.0, distance)))
    }

    /// The transmittance of a shadow ray over its range (no ray: nothing in the way), through
    /// the listed free forms and the `kinds` asked.
    #[inline]
    fn shadow_transmittance(
        &self,
        ctx: &mut TraceContext,
        ray: Option<(Ray, Interval)>,
        occluders: Option<&Vec<u32>>,
        kinds: ShadowKinds,
    ) -> DVec3 {
        let Some((ray, range)) = ray else {
            return DVec3::ONE;
        };
        ctx.counts.shadow_rays += 1;
        let (scene, eps) = (self.scene, self.epsilon);
        if scene.features.transmission {
            // Through glass: every surface crossed keeps its `kt`.
            let step = |p: DVec3| 2.0 * self.shadow_offset_at(p);
            return transmittance_through_surfaces(
                scene,
                ctx,
                &ray,
                range,
                eps,
                &self.interiors,
                step,
            )
            .as_dvec3();
        }
        let free_forms = occluders.map(Vec::as_slice);
        transmittance_of(scene, ctx, &ray, range, eps, free_forms, kinds).as_dvec3()
    }
}

/// Where a ray of Whitted's tree stands: `depth` secondary rays from the camera, reached with
/// `weight` (the product of the `kr`/`kt` on the way) after a path of `distance` (what a
/// texture's footprint grows with), and the secondary rays its tree may still trace below it
/// (`allowance`, [`crate::ray_budget`]).
#[derive(Clone, Copy, Debug)]
struct Path {
    depth: u32,
    weight: DVec3,
    distance: f64,
    allowance: u32,
}

impl Path {
    /// A camera ray's hit at `t`, with the whole budget.
    fn camera(t: f64, budget: u32) -> Self {
        Self {
            depth: 0,
            weight: DVec3::ONE,
            distance: t,
            allowance: budget,
        }
    }

    /// Its child weighted by `k` with `share` of the allowance (itself included), from the
    /// same point (`None`: no share, the child is not traced).
    fn child(self, k: DVec3, share: u32) -> Option<Self> {
        (share > 0).then(|| Self {
            depth: self.depth + 1,
            weight: self.weight * k,
            distance: self.distance,
            allowance: share - 1,
        })
    }

    /// The same ray's hit `t` farther on.
    fn to(self, t: f64) -> Self {
        Self {
            distance: self.distance + t,
            ..self
        }
    }
}

/// From `p`, the direction toward `light`, the irradiance it sends and its distance (infinite
/// for the sun); `None` for a point light at `p`.
#[inline]
fn toward(light: &Light, p: DVec3) -> Option<(DVec3, DVec3, f64)> {
    match *light {
        Light::Sun {
            direction,
            irradiance,
        } => Some((direction, irradiance.as_dvec3(), f64::INFINITY)),
        Light::Point {
            position,
            intensity,
        } => {
            let d = position - p;
            let r2 = d.length_squared();
            if r2 == 0.0 {
                return None;
            }
            let r = r2.sqrt();
            Some((d / r, intensity.as_dvec3() / r2, r))
        }
    }
}
