//! The sky against an independent reference: each backend's aerial perspective and
//! transmittance to the sun from the sky data scenes' cameras, against the sky's adaptive
//! quadrature.

use crate::Backend;
use crate::backend::CaseRay;
use crate::cases::{data_scene, fan};
use crate::cpu::Cpu;
use crate::gpu::Gpu;
use fray_atmosphere::gpu_layout::{GpuSky, GpuSkyOptions};
use fray_atmosphere::sky::{Sky, SkyView};
use fray_gpu::testing::{GpuSkyQuery, SkyBatch, SkySeen};
use glam::DVec3;

/// How a sky is drawn: aerial-perspective steps and whether the background holds the sun's disc.
#[derive(Clone, Copy, Debug)]
pub struct SkyOptions {
    pub steps: u32,
    pub sun_disc: bool,
}

/// A query of a sky seen from an eye, relative to the eye.
#[derive(Clone, Copy, Debug)]
pub struct SkyQuery {
    /// The ray's origin (relative to the eye) and unit direction.
    pub origin: DVec3,
    pub dir: DVec3,
    /// The surface's distance along the ray (`∞`: the whole ray).
    pub t: f64,
    /// A point (relative to the eye) the transmittance to the sun is asked at.
    pub point: DVec3,
    /// The altitude and cosine the transmittance table is asked at.
    pub table: (f64, f64),
}

/// What a sky gave a query (RGB each).
#[derive(Clone, Copy, Debug)]
pub struct SkyAnswer {
    /// The sky-view table along the direction.
    pub view: DVec3,
    /// The background along it: the table and, where drawn, the sun's disc.
    pub background: DVec3,
    /// The aerial perspective over `[0, t]`.
    pub in_scatter: DVec3,
    pub transmittance: DVec3,
    /// The transmittance to the sun at the point.
    pub to_sun: DVec3,
    /// The transmittance table at the altitude and cosine.
    pub table: DVec3,
}

impl SkyAnswer {
    /// The answers in [`SKY_NAMES`]' order.
    pub fn values(&self) -> [DVec3; 6] {
        [
            self.view,
            self.background,
            self.in_scatter,
            self.transmittance,
            self.to_sun,
            self.table,
        ]
    }
}

/// [`SkyAnswer`]'s fields, in [`SkyAnswer::values`]' order.
pub const SKY_NAMES: [&str; 6] = [
    "sky-view table",
    "background",
    "aerial in-scatter",
    "aerial transmittance",
    "transmittance to sun",
    "transmittance table",
];

/// What a backend of the suite answers for the sky.
pub trait SkyBackend {
    /// What `sky`, seen from `eye` (its sky-view table `view`, `Sky::view(eye)`: both backends
    /// look it up), gives each query.
    fn sky(
        &self,
        sky: &Sky,
        view: &SkyView,
        options: SkyOptions,
        eye: DVec3,
        queries: &[SkyQuery],
    ) -> Vec<SkyAnswer>;
}

impl SkyBackend for Cpu {
    fn sky(
        &self,
        sky: &Sky,
        view: &SkyView,
        options: SkyOptions,
        eye: DVec3,
        queries: &[SkyQuery],
    ) -> Vec<SkyAnswer> {
        let ground = sky.model().ground_radius;
        queries
            .iter()
            .map(|q| {
                let air = sky.aerial_perspective(eye + q.origin, q.dir, q.t, options.steps);
                SkyAnswer {
                    view: view.lookup(q.dir),
                    background: if options.sun_disc {
                        view.background(q.dir)
                    } else {
                        view.lookup(q.dir)
                    },
                    in_scatter: air.in_scatter,
                    transmittance: air.transmittance,
                    to_sun: sky.transmittance_to_sun(eye + q.point, eye),
                    table: sky
                        .transmittance_table()
                        .lookup(ground + q.table.0, q.table.1),
                }
            })
            .collect()
    }
}

impl SkyBackend for Gpu {
    fn sky(
        &self,
        sky: &Sky,
        view: &SkyView,
        options: SkyOptions,
        eye: DVec3,
        queries: &[SkyQuery],
    ) -> Vec<SkyAnswer> {
        let ctx = self.context();
        let gpu_options = GpuSkyOptions {
            sun_disc: options.sun_disc,
            aerial_perspective: true,
            steps: options.steps,
            sun_light: Some(0),
        };
        let block = GpuSky::new(sky, eye.y, gpu_options);
        let batch = self
            .sky
            .get_or_init(|| SkyBatch::new(ctx).unwrap_or_else(|e| panic!("{e}")));
        let seen = SkySeen {
            block: &block,
            transmittance: sky.transmittance_table(),
            view: view.table(),
        };
        let f = |v: DVec3| v.as_vec3();
        let gpu_queries: Vec<GpuSkyQuery> = queries
            .iter()
            .map(|q| {
                let (o, d, p) = (f(q.origin), f(q.dir), f(q.point));
                let t = q.t.min(1e30) as f32;
                let (h, mu) = (q.table.0 as f32, q.table.1 as f32);
                [[o.x, o.y, o.z, t], [d.x, d.y, d.z, h], [p.x, p.y, p.z, mu]]
            })
            .collect();
        let rgb = |v: [f32; 3]| DVec3::from(v.map(f64::from));
        batch
            .answers(ctx, seen, &gpu_queries)
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|a| SkyAnswer {
                view: rgb(a.view),
                background: rgb(a.background),
                in_scatter: rgb(a.in_scatter),
                transmittance: rgb(a.transmittance),
                to_sun: rgb(a.to_sun),
                table: rgb(a.table),
            })
            .collect()
    }
}

/// The point along `r` the sky's transmittance to the sun is asked at.
fn sun_point(r: &CaseRay) -> DVec3 {
    r.ray.at(r.range.hi.min(1e4))
}

/// The sky cases: the sky data scenes' models seen from their cameras and from 10 km up, along a
/// fan of directions (down, at the horizon, up, toward the sun), to surfaces 100 m to 20 km away
/// or to the sky; each answer against the sky's numerical reference (`fray_atmosphere::sky::
/// reference`: adaptive Gauss–Kronrod quadrature, no table) — within [`SKY_TRANSMITTANCE`],
/// [`SKY_IN_SCATTER`] and [`SKY_TO_SUN`]: the method's own error (its march and its table),
/// both backends alike.
pub fn suite(backend: &dyn Backend) {
    use fray_atmosphere::sky::reference;
    let (mut rays_checked, mut worst_t, mut worst_s, mut worst_sun) =
        (0usize, 0.0f64, 0.0f64, 0.0f64);
    for name in ["sunset.ron", "haze_dem_high.ron"] {
        let scene = data_scene(name);
        let sky = scene.atmosphere.sky.clone().expect("a sky scene");
        let model = sky.sky.model();
        let sun = sky.sky.sun();
        let camera = fray_gpu::params::reference_point(&scene.camera);
        for eye in [camera, camera + DVec3::Y * 1e4] {
            let rays = fan(
                eye,
                &[-30.0, -2.0, 0.5, 5.0, 45.0],
                &[0.0, 120.0, 240.0],
                &[100.0, 2e3, 2e4, f64::INFINITY],
            );
            // Eye-relative: the origin is the eye; no table query (h = 0, μ = 1).
            let queries: Vec<SkyQuery> = rays
                .iter()
                .map(|r| SkyQuery {
                    origin: DVec3::ZERO,
                    dir: r.ray.dir,
                    t: r.range.hi,
                    point: sun_point(r) - eye,
                    table: (0.0, 1.0),
                })
                .collect();
            let options = SkyOptions {
                steps: sky.steps,
                sun_disc: sky.sun_disc,
            };
            let answers = backend.sky(&sky.sky, &sky.sky.view(eye), options, eye, &queries);
            for (r, a) in rays.iter().zip(&answers) {
                rays_checked += 1;
                let truth = reference::single_scattering(model, sun, eye, r.ray.dir, r.range.hi);
                let to_sun = reference::transmittance_to_sun(model, sun, sun_point(r), eye);
                let describe =
                    |what: &str| format!("{} {name}: {what} on {r:?}: {a:?}", backend.name());
                let dt = (a.transmittance - truth.transmittance).abs().max_element();
                let bright = truth.in_scatter.max_element().max(1e-3);
                let ds = (a.in_scatter - truth.in_scatter).abs().max_element() / bright;
                let dsun = (a.to_sun - to_sun).abs().max_element();
                worst_t = worst_t.max(dt);
                worst_s = worst_s.max(ds);
                worst_sun = worst_sun.max(dsun);
                assert!(
                    dt <= SKY_TRANSMITTANCE,
                    "{}",
                    describe(&format!("transmittance off by {dt:.3e}"))
                );
                assert!(
                    ds <= SKY_IN_SCATTER,
                    "{}",
                    describe(&format!("in-scatter off by {ds:.3e}"))
                );
                assert!(
                    dsun <= SKY_TO_SUN,
                    "{}",
                    describe(&format!("transmittance to the sun off by {dsun:.3e}"))
                );
            }
        }
    }
    eprintln!(
        "{}: sky, {rays_checked} rays; worst transmittance {worst_t:.3e}, in-scatter {worst_s:.3e} \
         of the brightest channel, transmittance to the sun {worst_sun:.3e}",
        backend.name()
    );
}

/// The aerial perspective's transmittance against the reference, absolute: the scenes' march
/// (16 steps) — measured 2.8e-3 on both backends.
const SKY_TRANSMITTANCE: f64 = 5e-3;
/// The aerial perspective's in-scatter against the reference, relative to its brightest
/// channel: the same march — measured 2.8e-2 on both backends (`cargo xtask bench atmosphere`
/// trades steps for it).
const SKY_IN_SCATTER: f64 = 5e-2;
/// The transmittance to the sun against the reference, absolute: the transmittance table's
/// interpolation — measured 4.1e-4 on both backends.
const SKY_TO_SUN: f64 = 1e-3;
