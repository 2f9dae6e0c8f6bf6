//! Fog against an independent reference: each backend's transmittance and optical depth of the
//! fog data scenes' layers against a composite Simpson quadrature of the extinction.

use crate::Backend;
use crate::backend::CaseRay;
use crate::cases::{data_scene, fan};
use crate::cpu::Cpu;
use crate::gpu::Gpu;
use fray_atmosphere::gpu_layout::GpuFog;
use fray_atmosphere::{FogLayer, FogLighting, FogModel, Sunlight};
use fray_gpu::testing::{FogBatch, GpuFogRay};
use fray_scene::Fog;
use glam::DVec3;

/// A ray through a fog layer, starting at the camera, with a sun.
#[derive(Clone, Copy, Debug)]
pub struct FogRay {
    pub ray: CaseRay,
    /// Unit vector toward the sun.
    pub sun: DVec3,
}

/// What a fog layer did to a ray (per unit albedo, ambient and irradiance).
#[derive(Clone, Copy, Debug)]
pub struct FogAnswer {
    /// `e^{−τ}` over the ray's range (`FogLayer::terms`).
    pub transmittance: f64,
    /// The ambient light's in-scatter factor, `1 − e^{−τ}`.
    pub ambient: f64,
    /// The sun's in-scatter factor, phase included, by the layer's model.
    pub sun: f64,
    /// The optical depth `τ` (`≥ 1e30` or `∞`: unbounded).
    pub optical_depth: f64,
    /// The transmittance toward the sun from the ray's origin.
    pub sun_transmittance: f64,
    /// `e^{−τ}` again, by the segment's optical depth (the point-light path).
    pub segment_transmittance: f64,
}

impl FogAnswer {
    /// The answers in [`FOG_NAMES`]' order.
    pub fn values(&self) -> [f64; 6] {
        [
            self.transmittance,
            self.ambient,
            self.sun,
            self.optical_depth,
            self.sun_transmittance,
            self.segment_transmittance,
        ]
    }
}

/// [`FogAnswer`]'s fields, in [`FogAnswer::values`]' order.
pub const FOG_NAMES: [&str; 6] = [
    "transmittance",
    "ambient factor",
    "sun factor",
    "optical depth",
    "sun transmittance",
    "segment transmittance",
];

/// What a backend of the suite answers for the fog layer.
pub trait FogBackend {
    /// What `layer` (by `model`) does to each ray; every ray starts at the camera, at height
    /// `camera_y` (a backend that works relative to it takes heights from there).
    fn fog(
        &self,
        layer: &FogLayer,
        model: FogModel,
        camera_y: f64,
        rays: &[FogRay],
    ) -> Vec<FogAnswer>;
    /// How far its fog answers may be from the reference: `abs + rel · |reference|`.
    fn medium_bounds(&self) -> (f64, f64);
}

impl FogBackend for Cpu {
    fn fog(
        &self,
        layer: &FogLayer,
        model: FogModel,
        _camera_y: f64,
        rays: &[FogRay],
    ) -> Vec<FogAnswer> {
        // Unit albedo, ambient and irradiance: the in-scatter is the factor itself.
        let layer = FogLayer {
            albedo: DVec3::ONE,
            ..*layer
        };
        let ambient = FogLighting {
            suns: Vec::new(),
            ambient: DVec3::ONE,
        };
        rays.iter()
            .map(|f| {
                let (ray, range) = (&f.ray.ray, f.ray.range);
                let sunlight = Sunlight {
                    direction: f.sun,
                    irradiance: DVec3::ONE,
                };
                let lit = FogLighting {
                    suns: vec![sunlight],
                    ambient: DVec3::ZERO,
                };
                let a = layer.terms(ray, range, &ambient, model);
                let s = layer.terms(ray, range, &lit, model);
                FogAnswer {
                    transmittance: a.transmittance,
                    ambient: a.in_scatter.x,
                    sun: s.in_scatter.x,
                    optical_depth: layer.optical_depth(ray, range),
                    sun_transmittance: layer.sun_transmittance(ray.origin, &sunlight, model),
                    segment_transmittance: layer.transmittance(ray, range),
                }
            })
            .collect()
    }

    fn medium_bounds(&self) -> (f64, f64) {
        // The closed form against the quadrature: measured ≤ 2e-13 relative.
        (1e-13, 1e-11)
    }
}

impl FogBackend for Gpu {
    fn fog(
        &self,
        layer: &FogLayer,
        model: FogModel,
        camera_y: f64,
        rays: &[FogRay],
    ) -> Vec<FogAnswer> {
        let ctx = self.context();
        let block = GpuFog::new(layer, model, camera_y);
        let batch = FogBatch::new(ctx, &block).unwrap_or_else(|e| panic!("{e}"));
        let gpu_rays: Vec<GpuFogRay> = rays
            .iter()
            .map(|f| {
                let d = f.ray.ray.dir.as_vec3();
                let s = f.sun.as_vec3();
                let hi = f.ray.range.hi.min(1e30) as f32;
                // Camera-relative: every ray starts at the camera.
                [
                    [0.0, 0.0, 0.0, f.ray.range.lo as f32],
                    [d.x, d.y, d.z, hi],
                    [s.x, s.y, s.z, 0.0],
                ]
            })
            .collect();
        batch
            .terms(ctx, &gpu_rays)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|t| FogAnswer {
                transmittance: f64::from(t.transmittance),
                ambient: f64::from(t.ambient),
                sun: f64::from(t.sun),
                optical_depth: f64::from(t.depth),
                sun_transmittance: f64::from(t.sun_transmittance),
                segment_transmittance: f64::from(t.segment_transmittance),
            })
            .collect()
    }

    fn medium_bounds(&self) -> (f64, f64) {
        // The parity bound (fog_parity.rs: f32, camera-relative heights).
        (1e-6, 5e-5)
    }
}

/// The reference optical depth of `fog` on `r`: composite Simpson over the part of the range in
/// the layer (4096 intervals) of the extinction at each height — not the closed form either
/// backend evaluates; `∞` where the ray stays in the layer for ever.
fn reference_depth(fog: &Fog, r: &CaseRay) -> f64 {
    let layer = &fog.layer;
    let (y, dy) = (r.ray.origin.y, r.ray.dir.y);
    let (mut lo, mut hi) = (r.range.lo, r.range.hi);
    if dy != 0.0 {
        let a = (layer.base - y) / dy;
        let b = (layer.top - y) / dy;
        lo = lo.max(a.min(b));
        hi = hi.min(a.max(b));
    } else if !(layer.base..=layer.top).contains(&y) {
        return 0.0;
    }
    if lo >= hi || layer.extinction == 0.0 {
        return 0.0;
    }
    if hi.is_infinite() {
        return f64::INFINITY;
    }
    const N: usize = 4096;
    let h = (hi - lo) / N as f64;
    let f = |t: f64| layer.density((y + dy * t).clamp(layer.base, layer.top));
    let mut sum = f(lo) + f(hi);
    for k in 1..N {
        sum += f(lo + h * k as f64) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// The fog cases: the fog data scenes' layers seen from their cameras, from inside the layer
/// and from its top, along a fan of elevations (straight down to straight up, the horizontal
/// exactly), ranges ending 1 m to 20 km away or never.
pub fn suite(backend: &dyn Backend) {
    let (abs, rel) = backend.medium_bounds();
    let mut rays_checked = 0;
    let mut worst = 0.0f64;
    for name in ["fog_aircraft_low_sun.ron", "fog_aircraft_high_sun.ron"] {
        let scene = data_scene(name);
        let fog = scene.atmosphere.fog.expect("a fog scene");
        let layer = &fog.layer;
        let camera = fray_gpu::params::reference_point(&scene.camera);
        for eye_y in [camera.y, 0.5 * (layer.base + layer.top), layer.top] {
            let eye = DVec3::new(camera.x, eye_y, camera.z);
            let rays = fan(
                eye,
                &[-90.0, -30.0, -5.0, -0.5, 0.0, 0.5, 5.0, 30.0, 90.0],
                &[0.0, 70.0, 200.0],
                &[1.0, 100.0, 2e3, 2e4, f64::INFINITY],
            );
            // No sun: its factor is not checked here (the parity cases compare it).
            let fog_rays: Vec<FogRay> = rays
                .iter()
                .map(|&ray| FogRay { ray, sun: DVec3::Y })
                .collect();
            let answers = backend.fog(layer, fog.model, eye_y, &fog_rays);
            for (r, m) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let depth = reference_depth(&fog, r);
                let transmittance = (-depth).exp();
                // Both of a backend's transmittances: its terms' and its segment's.
                for (what, value) in [
                    ("transmittance", m.transmittance),
                    ("segment transmittance", m.segment_transmittance),
                ] {
                    let off_t = (value - transmittance).abs();
                    assert!(
                        off_t <= abs + rel * transmittance,
                        "{} {name}: {what} {value} against {transmittance} on {r:?}",
                        backend.name(),
                    );
                    worst = worst.max(off_t / (abs + rel * transmittance));
                }
                if depth.is_finite() && m.optical_depth < 1e29 {
                    let off = (m.optical_depth - depth).abs();
                    assert!(
                        off <= abs + rel * depth,
                        "{} {name}: optical depth {} against {depth} on {r:?}",
                        backend.name(),
                        m.optical_depth
                    );
                    worst = worst.max(off / (abs + rel * depth));
                } else {
                    assert!(
                        depth.is_infinite()
                            == (m.optical_depth >= 1e29 || m.optical_depth.is_infinite()),
                        "{} {name}: optical depth {} against {depth} on {r:?}",
                        backend.name(),
                        m.optical_depth
                    );
                }
            }
        }
    }
    eprintln!(
        "{}: fog, {rays_checked} rays; worst difference {worst:.3e} of the bound",
        backend.name()
    );
}
