//! Clouds against an independent reference: each backend's march transmittance and optical
//! depth through the cloud data scenes' volumes, against the density integrated at a 64th of
//! the march's step.

use crate::Backend;
use crate::backend::CaseRay;
use crate::cases::{camera_rays, data_scene, fan};
use crate::cpu::Cpu;
use crate::gpu::{Gpu, relative_rays};
use fray_clouds::gpu_layout::GpuClouds;
use fray_clouds::march::{self, CloudLight, Density, GridVolume, MarchSettings};
use fray_gpu::testing::{CloudsBatch, GpuCloudRay};
use glam::DVec3;

/// A ray through a cloud volume, with the march's jitter and a pixel.
#[derive(Clone, Copy, Debug)]
pub struct CloudQuery {
    pub ray: CaseRay,
    pub jitter: f64,
    pub pixel: (u32, u32),
}

/// What a cloud volume did to a ray.
#[derive(Clone, Copy, Debug)]
pub struct CloudAnswer {
    /// The march: `L = transmittance · L_behind + in_scatter`, over `samples` density samples.
    pub transmittance: f64,
    pub in_scatter: DVec3,
    pub samples: u32,
    /// The optical depth at the march's step.
    pub optical_depth: f64,
    /// The extinction at the ray's origin.
    pub density: f64,
    /// `pixel_jitter` of the query's pixel.
    pub pixel_jitter: f64,
}

/// What a backend of the suite answers for the clouds.
pub trait CloudBackend {
    /// The cloud march (at `settings`, each query's jitter) through `volume` lit by `light`,
    /// its optical depth at the march's step, the density at the origin and the pixel's jitter;
    /// `reference` as for [`crate::free_forms::FreeFormBackend::free_forms`].
    fn clouds(
        &self,
        volume: &GridVolume,
        light: &CloudLight,
        settings: &MarchSettings,
        reference: DVec3,
        queries: &[CloudQuery],
    ) -> Vec<CloudAnswer>;
}

impl CloudBackend for Cpu {
    fn clouds(
        &self,
        volume: &GridVolume,
        light: &CloudLight,
        settings: &MarchSettings,
        _reference: DVec3,
        queries: &[CloudQuery],
    ) -> Vec<CloudAnswer> {
        queries
            .iter()
            .map(|q| {
                let (o, d) = (q.ray.ray.origin.to_array(), q.ray.ray.dir.to_array());
                let range = (q.ray.range.lo, q.ray.range.hi);
                let s = MarchSettings {
                    jitter: q.jitter,
                    ..*settings
                };
                let m = march::march(volume, o, d, range, &s, light);
                CloudAnswer {
                    transmittance: m.transmittance,
                    in_scatter: DVec3::from_array(m.in_scatter),
                    samples: m.samples,
                    optical_depth: march::optical_depth(volume, o, d, range, settings.step),
                    density: volume.density(o),
                    pixel_jitter: march::pixel_jitter(q.pixel.0, q.pixel.1),
                }
            })
            .collect()
    }
}

impl CloudBackend for Gpu {
    fn clouds(
        &self,
        volume: &GridVolume,
        light: &CloudLight,
        settings: &MarchSettings,
        reference: DVec3,
        queries: &[CloudQuery],
    ) -> Vec<CloudAnswer> {
        let ctx = self.context();
        let block = GpuClouds::new(volume, light, settings, true, reference.to_array());
        let batch = CloudsBatch::new(ctx, volume, &block).unwrap_or_else(|e| panic!("{e}"));
        let rays: Vec<CaseRay> = queries.iter().map(|q| q.ray).collect();
        let gpu_queries: Vec<GpuCloudRay> = relative_rays(&rays, reference)
            .into_iter()
            .zip(queries)
            .map(|([a, b], q)| {
                let (px, py) = (q.pixel.0 as f32, q.pixel.1 as f32);
                [a, b, [q.jitter as f32, px, py, 0.0]]
            })
            .collect();
        batch
            .terms(ctx, &gpu_queries)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|t| CloudAnswer {
                transmittance: f64::from(t.transmittance),
                in_scatter: DVec3::from(t.in_scatter.map(f64::from)),
                samples: t.samples,
                optical_depth: f64::from(t.optical_depth),
                density: f64::from(t.density),
                pixel_jitter: f64::from(t.pixel_jitter),
            })
            .collect()
    }
}

/// The cloud cases: the cloud data scenes' volumes from their cameras (inside the cloud in
/// `clouds_aircraft_inside.ron`) along a fan of directions, to 100 m and 2 km or through the
/// whole volume; each backend's march transmittance and optical depth against a fine-step
/// reference — the optical depth of the volume's own density (its trilinear interpolation) at a
/// 64th of the march's step, `exp(−τ)` for the transmittance — within [`CLOUD_BOUND`] (the
/// march's step error, both backends alike; the GPU's f32 adds ≤ 1.6e-6, [`crate::clouds_parity`]).
pub fn suite(backend: &dyn Backend) {
    let mut rays_checked = 0usize;
    let (mut worst_t, mut worst_depth) = (0.0f64, 0.0f64);
    for name in ["clouds_aircraft_inside.ron", "clouds_envelope.ron"] {
        let scene = data_scene(name);
        let clouds = scene.clouds.clone().expect("a cloud scene");
        let eye = fray_gpu::params::reference_point(&scene.camera);
        let light = fray_gpu::cloud_light(&scene, &clouds, eye);
        let mut rays = fan(
            eye,
            &[-60.0, -10.0, 0.0, 10.0, 60.0],
            &[0.0, 72.0, 144.0, 216.0, 288.0],
            &[100.0, 2e3, f64::INFINITY],
        );
        // And every camera ray of a coarse grid.
        rays.extend(camera_rays(&scene, 16, 12));
        // The scene's jitter, pixel (0, 0).
        let queries: Vec<CloudQuery> = rays
            .iter()
            .map(|&ray| CloudQuery {
                ray,
                jitter: clouds.march.jitter,
                pixel: (0, 0),
            })
            .collect();
        let answers = backend.clouds(&clouds.volume, &light, &clouds.march, eye, &queries);
        for (r, m) in rays.iter().zip(&answers) {
            rays_checked += 1;
            let (o, d) = (r.ray.origin.to_array(), r.ray.dir.to_array());
            let range = (r.range.lo, r.range.hi);
            let depth = march::optical_depth(&clouds.volume, o, d, range, clouds.march.step / 64.0);
            let dt = (m.transmittance - (-depth).exp()).abs();
            let dd = (m.optical_depth - depth).abs() / depth.max(1.0);
            worst_t = worst_t.max(dt);
            worst_depth = worst_depth.max(dd);
            assert!(
                dt <= CLOUD_BOUND && dd <= CLOUD_BOUND,
                "{} {name}: transmittance {} / depth {} against {} / {depth} on {r:?}",
                backend.name(),
                m.transmittance,
                m.optical_depth,
                (-depth).exp()
            );
        }
    }
    eprintln!(
        "{}: clouds, {rays_checked} rays; worst transmittance {worst_t:.3e}, optical depth \
         {worst_depth:.3e} (relative, or absolute below 1)",
        backend.name()
    );
}

/// The cloud march against the fine-step reference (transmittance absolute; optical depth
/// relative, or absolute below 1): the scenes' step — measured 1.6e-2 and 2.4e-2 on both
/// backends (`cargo xtask bench clouds` trades the step for it).
const CLOUD_BOUND: f64 = 5e-2;
