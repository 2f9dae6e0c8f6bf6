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
use fray_gpu::testing::{GpuSkyQuery, SkyBatch, SkySeen, sky_query};
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

/// The sky the queries of a call see: `sky` from `eye`, with its sky-view table `view`
/// (`Sky::view(eye)`: both backends look it up).
#[derive(Clone, Copy, Debug)]
pub struct SkySeenFrom<'a> {
    pub sky: &'a Sky,
    pub view: &'a SkyView,
    pub options: SkyOptions,
    pub eye: DVec3,
}

/// What a backend of the suite answers for the sky.
pub trait SkyBackend {
    /// What `seen.sky` gives each query.
    fn sky(&self, seen: SkySeenFrom<'_>, queries: &[SkyQuery]) -> Vec<SkyAnswer>;
}

impl SkyBackend for Cpu {
    fn sky(&self, seen: SkySeenFrom<'_>, queries: &[SkyQuery]) -> Vec<SkyAnswer> {
        let (sky, view, options, eye) = (seen.sky, seen.view, seen.options, seen.eye);
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
    fn sky(&self, seen: SkySeenFrom<'_>, queries: &[SkyQuery]) -> Vec<SkyAnswer> {
        let (sky, view, options, eye) = (seen.sky, seen.view, seen.options, seen.eye);
        let ctx = self.context();
        let gpu_options = GpuSkyOptions {
            sun_disc: options.sun_disc,
            aerial_perspective: true,
            steps: options.steps,
            sun_light: Some(0),
        };
        let block = GpuSky::new(sky, eye.y, gpu_options);
        // The sky's kernel (any sky, any eye): built once for the run.
        static BATCH: std::sync::OnceLock<SkyBatch> = std::sync::OnceLock::new();
        let batch = BATCH.get_or_init(|| SkyBatch::new(ctx).unwrap_or_else(|e| panic!("{e}")));
        let seen = SkySeen {
            block: &block,
            transmittance: sky.transmittance_table(),
            view: view.table(),
        };
        let gpu_queries: Vec<GpuSkyQuery> = queries
            .iter()
            .map(|q| sky_query(q.origin, q.dir, q.t, q.point, q.table))
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
            let answers = backend.sky(
                SkySeenFrom {
                    sky: &sky.sky,
                    view: &sky.sky.view(eye),
                    options,
                    eye,
                },
                &queries,
            );
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

pub mod parity {
    //! Sky parity: the GPU's sky (`shaders/sky.wgsl`) against the f64 CPU (`fray_atmosphere::sky`:
    //! `SkyView::{lookup, background}`, `Sky::{aerial_perspective, transmittance_to_sun}`,
    //! `TransmittanceTable::lookup`) on the same queries — a GPU-vs-CPU bound, the f32
    //! arithmetic's. Two models (Earth; hazy air — four times the aerosols, no ozone — over a
    //! ground at −1300 m), eyes on the ground (2 m up), at 1 km, 66 km and above the atmosphere at
    //! 120 km, suns at −2°, 0°, 2°, 10°, 45° and 90°, view directions from the nadir to the zenith
    //! (the dipped horizon ± 0.05° included) at five azimuths from the sun's and into the sun's
    //! disc, surfaces 100 m to 150 km away and the whole ray, ray origins at the eye and off it (a
    //! parallel projector's), the transmittance table on a grid of altitudes and cosines (the
    //! horizon ± 10⁻⁴ included).
    //!
    //! Both backends get the same inputs, rounded to f32 (the eye stays f64: the GPU's block is made
    //! from it), so the check measures the shader's arithmetic. Measures: for radiances (the table,
    //! the background, the in-scatter) the largest channel difference relative to the brightest
    //! channel of the CPU's value (dim channels at sunset are 1/600 of the red: relative to
    //! themselves they measure the f32 rounding of nothing); for transmittances the largest absolute
    //! difference. Bounds: [`BOUNDS`], with the measured figures.

    use crate::cases::direction;
    use crate::cpu::Cpu;
    use crate::gpu::gpu;
    use crate::sky::SkyBackend;
    use crate::sky::{SKY_NAMES, SkyOptions, SkyQuery, SkySeenFrom};
    use fray_atmosphere::sky::{Sky, SkyModel, SkySun, SkyTables};
    use fray_core::MemoryBudget;
    use glam::DVec3;

    /// The allowed difference per quantity (in [`SKY_NAMES`]' order; radiances relative to their
    /// brightest channel, transmittances absolute). Measured on lavapipe over the 25 872 queries
    /// (worst / mean): the sky-view table 5.6e-6 / 1.5e-7 and the background 5.6e-6 / 1.5e-7 (a
    /// dim sky 2° up, away from a sun 2° below the horizon: the f32 bilinear weights); the
    /// aerial in-scatter 7.5e-6 / 2.6e-7 and transmittance 8.2e-6 / 5.4e-7 (a ray 0.05° under
    /// the dipped horizon from 1 km at sunset, 82 km of hazy air to the ground: 16 steps' sums of
    /// f32 exponentials); the transmittance to the
    /// sun 4.1e-7 / 5.7e-8 and the table 2.1e-7 / 5.2e-8 (the f32 rounding of e^{−τ}). The bounds
    /// leave about 4× for other drivers' `exp`, `pow` and `sqrt` (Vulkan allows several ulps);
    /// angles are the shader's own (sky.wgsl's atan2), since a driver's may be 4096 ulps off.
    const BOUNDS: [f64; 6] = [2.5e-5, 2.5e-5, 3e-5, 3e-5, 2e-6, 1e-6];
    /// Radiances below this (W/(m² sr)) count as dark: differences are measured against it.
    const DARK: f64 = 1e-9;
    /// Aerial-perspective steps (the scenes' default).
    const STEPS: u32 = 16;

    fn models() -> Vec<(&'static str, SkyModel)> {
        let earth = SkyModel::earth();
        vec![
            ("Earth", earth),
            (
                "hazy, no ozone, ground at −1300 m",
                SkyModel {
                    ground_elevation: -1300.0,
                    mie_scattering: 4.0 * earth.mie_scattering,
                    mie_absorption: 4.0 * earth.mie_absorption,
                    ozone_absorption: DVec3::ZERO,
                    ..earth
                },
            ),
        ]
    }

    /// Whether quantity `q` is a radiance (else a transmittance).
    fn radiance(q: usize) -> bool {
        q < 3
    }

    /// The queries of one sky seen from `eye` (world), with their names: every input rounded to f32.
    fn queries(label: &str, sky: &Sky, eye: DVec3) -> Vec<(String, SkyQuery)> {
        let model = sky.model();
        let r = model.observer_radius(eye.y);
        // The dipped horizon's elevation (degrees): −acos(R_g / r).
        let dip = -(model.ground_radius / r).min(1.0).acos().to_degrees();
        let mut elevations = vec![
            -90.0, -45.0, -10.0, -3.0, -0.5, 0.0, 0.3, 2.0, 10.0, 30.0, 60.0, 89.0, 90.0,
        ];
        elevations.extend([dip - 0.05, dip + 0.05]);
        let sun = sky.sun().direction;
        let sun_elevation = sun.y.asin().to_degrees();
        let sun_azimuth = sun.z.atan2(sun.x).to_degrees();
        let mut directions: Vec<(String, DVec3)> = Vec::new();
        for &e in &elevations {
            for az in [0.0, 30.0, 90.0, 150.0, 180.0] {
                directions.push((
                    format!("elevation {e:.3}°, azimuth {az}°"),
                    direction(e, sun_azimuth + az),
                ));
            }
        }
        // Into the sun's disc: its centre and halfway to its edge.
        directions.push(("the sun's centre".to_owned(), sun));
        directions.push((
            "half a disc radius off the sun".to_owned(),
            direction(
                sun_elevation + 0.5 * SkySun::ANGULAR_RADIUS.to_degrees(),
                sun_azimuth,
            ),
        ));
        let depths = [100.0, 1e3, 1e4, 3e4, 6.6e4, 1.5e5, f64::INFINITY];
        let altitudes = [0.0, 10.0, 500.0, 2e3, 1e4, 2.5e4, 5e4, 9.99e4];
        let mut out = Vec::new();
        let mut n = 0usize;
        for (dir_name, d) in &directions {
            for &t in &depths {
                // Every third ray starts off the eye (a parallel projector's origin).
                let o = if n % 3 == 2 {
                    DVec3::new(5.0, 25.0, -7.0)
                } else {
                    DVec3::ZERO
                };
                // A surface point along the ray, kept above the ground (where the scenes' are).
                let reach = if t.is_finite() { t.min(1e5) } else { 5e4 };
                let p = *d * reach.min(above_ground(model, eye, *d));
                let h = altitudes[n % altitudes.len()];
                let mu = [-1.0, -0.3, -0.02, -1e-4, 0.0, 1e-4, 0.01, 0.1, 0.5, 1.0][n % 10];
                // The direction, origin, point, table altitude and cosine rounded to f32, for both
                // backends. A degenerate ray — here, looking at right angles to a sun on the
                // horizon, where the planet's shadow edge runs along the ray — may change the
                // march's steps between a direction and its f32 rounding; that is the ray's, not
                // the shader's.
                let f = |v: DVec3| v.as_vec3().as_dvec3();
                let f1 = |x: f64| f64::from(x as f32);
                out.push((
                    format!("{label}: {dir_name}, t {t}, origin {o}, table ({h}, {mu})"),
                    SkyQuery {
                        origin: f(o),
                        dir: f(*d),
                        t: if t.is_finite() { f1(t) } else { t },
                        point: f(p),
                        table: (f1(h), f1(mu)),
                    },
                ));
                n += 1;
            }
        }
        out
    }

    /// How far along `d` from `eye` a point stays at least 1 m above the planet's ground.
    fn above_ground(model: &SkyModel, eye: DVec3, d: DVec3) -> f64 {
        let r = model.observer_radius(eye.y);
        let (rg, mu) = (model.ground_radius + 1.0, d.y);
        let disc = (r * mu) * (r * mu) - (r - rg) * (r + rg);
        if mu >= 0.0 || disc < 0.0 {
            f64::INFINITY
        } else {
            0.999 * (-r * mu - disc.sqrt()).max(0.0)
        }
    }

    /// The difference measure of quantity `q`: relative to the brightest channel (radiances) or
    /// absolute (transmittances).
    fn difference(q: usize, cpu: DVec3, gpu: DVec3) -> f64 {
        if !gpu.is_finite() {
            return f64::INFINITY;
        }
        let d = (gpu - cpu).abs().max_element();
        if radiance(q) {
            d / cpu.abs().max_element().max(DARK)
        } else {
            d
        }
    }

    /// Every quantity of the GPU's sky within [`BOUNDS`] of the CPU's on every query.
    pub fn sky_matches_the_cpu() {
        let tables = SkyTables::default();
        let mut worst: [(f64, String); 6] = std::array::from_fn(|_| (0.0, String::new()));
        let mut sums = [0.0f64; 6];
        let mut count = 0usize;
        let mut bad = 0usize;
        let options = SkyOptions {
            steps: STEPS,
            sun_disc: true,
        };
        for (model_name, model) in models() {
            let first = SkySun::from_angles(0.0, 0.0, DVec3::splat(1.0));
            let mut sky = Sky::new(model, first, tables, &MemoryBudget::default()).unwrap();
            for elevation in [-2.0f64, 0.0, 2.0, 10.0, 45.0, 90.0] {
                // The sun in the south-west, E = (20, 19, 18) W/m² at the top.
                let sun =
                    SkySun::from_angles(elevation.to_radians(), 0.7, DVec3::new(20.0, 19.0, 18.0));
                sky.set_sun(sun).unwrap();
                for altitude in [2.0, 1e3, 6.6e4, 1.2e5] {
                    let eye = DVec3::new(-3.0e4, model.ground_elevation + altitude, 1.2e4);
                    let label = format!("{model_name}, sun {elevation}°, eye {altitude} m");
                    let all = queries(&label, &sky, eye);
                    let qs: Vec<SkyQuery> = all.iter().map(|(_, q)| *q).collect();
                    let view = sky.view(eye);
                    let seen = SkySeenFrom {
                        sky: &sky,
                        view: &view,
                        options,
                        eye,
                    };
                    let (cpu, got) = (Cpu.sky(seen, &qs), gpu().sky(seen, &qs));
                    for (((name, _), c), g) in all.iter().zip(&cpu).zip(&got) {
                        let (want, have) = (c.values(), g.values());
                        count += 1;
                        for q in 0..6 {
                            let e = difference(q, want[q], have[q]);
                            sums[q] += e;
                            if e > BOUNDS[q] {
                                bad += 1;
                                if bad <= 20 {
                                    eprintln!(
                                        "{}: {name}: cpu {} gpu {} ({e:.3e})",
                                        SKY_NAMES[q], want[q], have[q]
                                    );
                                }
                            }
                            if e > worst[q].0 {
                                worst[q] = (e, format!("{name}: cpu {} gpu {}", want[q], have[q]));
                            }
                        }
                    }
                }
            }
        }
        for q in 0..6 {
            let measure = if radiance(q) {
                "of the brightest channel"
            } else {
                "absolute"
            };
            eprintln!(
                "sky parity {:>22}: worst {:.3e} {measure} ({:.2} of the bound), mean {:.3e} ({})",
                SKY_NAMES[q],
                worst[q].0,
                worst[q].0 / BOUNDS[q],
                sums[q] / count.max(1) as f64,
                worst[q].1
            );
        }
        eprintln!("sky parity: {count} queries");
        assert_eq!(bad, 0, "{bad} values beyond the bounds");
    }
}
