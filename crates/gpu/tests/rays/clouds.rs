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

/// The clouds the queries of a call see: `volume` lit by `light`, marched at `settings`;
/// `reference` as for [`crate::free_forms::FreeFormsSeen`].
#[derive(Clone, Copy, Debug)]
pub struct CloudsSeen<'a> {
    pub volume: &'a GridVolume,
    pub light: &'a CloudLight,
    pub settings: &'a MarchSettings,
    pub reference: DVec3,
}

/// What a backend of the suite answers for the clouds.
pub trait CloudBackend {
    /// The cloud march (at `seen.settings`, each query's jitter), its optical depth at the
    /// march's step, the density at the origin and the pixel's jitter.
    fn clouds(&self, seen: CloudsSeen<'_>, queries: &[CloudQuery]) -> Vec<CloudAnswer>;
}

impl CloudBackend for Cpu {
    fn clouds(&self, seen: CloudsSeen<'_>, queries: &[CloudQuery]) -> Vec<CloudAnswer> {
        let CloudsSeen {
            volume,
            light,
            settings,
            ..
        } = seen;
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
    fn clouds(&self, seen: CloudsSeen<'_>, queries: &[CloudQuery]) -> Vec<CloudAnswer> {
        let CloudsSeen {
            volume,
            light,
            settings,
            reference,
        } = seen;
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
/// march's step error, both backends alike; the GPU's f32 adds ≤ 1.6e-6, [`crate::clouds::parity`]).
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
        let answers = backend.clouds(
            CloudsSeen {
                volume: &clouds.volume,
                light: &light,
                settings: &clouds.march,
                reference: eye,
            },
            &queries,
        );
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

pub mod parity {
    //! Cloud parity: the GPU's clouds (`shaders/clouds.wgsl`) against the f64 CPU
    //! (`fray_clouds::march`) on the same rays — a GPU-vs-CPU bound, the f32 arithmetic's. Two
    //! baked volumes (a thin one and a dense one whose march exits early), with and without
    //! empty-space skipping, near the world origin and 10⁵ m from it (camera-relative on the GPU),
    //! rays from inside the box, from its faces and corners, from outside, grazing a face, through
    //! empty stretches and dense ones, over unbounded ranges and ranges ending inside the box, with
    //! several jitters: the march's transmittance and in-scatter, the optical depth, the density at
    //! the origin and the pixel jitter, all finite. And a grid past the device's 3D texture limit is
    //! refused.

    use crate::backend::CaseRay;
    use crate::cases::direction;
    use crate::clouds::CloudBackend;
    use crate::clouds::{CloudQuery, CloudsSeen};
    use crate::cpu::Cpu;
    use crate::gpu::gpu;
    use fray_clouds::DensityGrid;
    use fray_clouds::bake::Region;
    use fray_clouds::gpu_layout::GpuClouds;
    use fray_clouds::march::{CloudLight, DualLobe, GridVolume, MarchSettings};
    use fray_core::{Interval, MemoryBudget, Ray};
    use fray_gpu::testing::CloudsBatch;
    use glam::DVec3;

    /// The batch bound: `|gpu − cpu| ≤ BATCH_ABS + BATCH_REL · |cpu|` for the transmittance, each
    /// channel of the in-scatter (the light is of order 1), the optical depth and the density.
    /// Measured on lavapipe over the 2 × 2 × 2 × 3924 rays: see [`clouds_match_the_cpu`] for the
    /// worst figures (at most 0.01 of this bound; the margin is for drivers whose f32 clip makes
    /// `ceil(length / step)` one step more or less than the f64's on a ray whose length is a whole
    /// number of steps, which moves every sample).
    const BATCH_ABS: f64 = 5e-5;
    const BATCH_REL: f64 = 5e-4;
    /// The pixel jitter's bound (on the circle: the f32 products of pixel coordinates up to 1920).
    const JITTER_BOUND: f64 = 2e-3;

    /// A smooth density with empty stretches: lumps where a product of sines is positive, zero
    /// elsewhere (about half the grid), every value finite and ≥ 0.
    fn grid(size: [usize; 3]) -> DensityGrid {
        DensityGrid::from_fn(size, &MemoryBudget::default(), |i, j, k| {
            let u = [i, j, k].map(|v| v as f64);
            let v = (u[0] * 0.45).sin() * (u[1] * 0.6 + 0.3).sin() * (u[2] * 0.35 + 1.0).sin();
            (v.max(0.0) * 1.6 + if i == 3 && j == 2 { 2.0 } else { 0.0 }) as f32
        })
        .unwrap()
    }

    fn light() -> CloudLight {
        CloudLight {
            sun_direction: DVec3::new(0.3, 0.8, -0.5).normalize().to_array(),
            sun_irradiance: [3.0, 2.9, 2.7],
            ambient: [0.2, 0.25, 0.3],
            albedo: 0.95,
            phase: DualLobe {
                g1: 0.8,
                g2: -0.3,
                weight: 0.2,
            },
        }
    }

    /// Rays through `region` (see the module's list), with their names.
    fn queries(region: &Region) -> Vec<(String, CloudQuery)> {
        let lo = DVec3::from_array(region.min);
        let hi = DVec3::from_array(region.max);
        let c = 0.5 * (lo + hi);
        let e = hi - lo;
        let origins = [
            ("centre", c),
            ("inside, off centre", lo + e * DVec3::new(0.2, 0.7, 0.35)),
            ("on the -x face", DVec3::new(lo.x, c.y, c.z + 0.1 * e.z)),
            ("on the top face", DVec3::new(c.x - 0.13 * e.x, hi.y, c.z)),
            ("at a corner", lo),
            ("outside, near", c - DVec3::new(0.8 * e.x, 0.1 * e.y, 0.0)),
            (
                "outside, far",
                c + DVec3::new(0.3 * e.x, 3.0 * e.y, -4.0 * e.z),
            ),
            (
                "outside, below",
                DVec3::new(c.x, lo.y - 20.0, c.z - 0.2 * e.z),
            ),
        ];
        let mut out = Vec::new();
        let mut n = 0u32;
        for (where_, o) in origins {
            // Toward the box's centre and quarter points from outside, then a sphere of directions.
            let mut dirs: Vec<(String, DVec3)> = [
                c,
                lo + 0.25 * e,
                hi - 0.25 * e,
                lo + e * DVec3::new(0.9, 0.1, 0.5),
            ]
            .iter()
            .filter_map(|t| {
                (*t - o)
                    .try_normalize()
                    .map(|d| ("toward the box".into(), d))
            })
            .collect();
            for elevation in [-90.0, -40.0, -5.0, 0.0, 5.0, 40.0, 90.0] {
                for azimuth in [0.0, 37.0, 90.0, 180.0, 243.0] {
                    dirs.push((
                        format!("elevation {elevation}°, azimuth {azimuth}°"),
                        direction(elevation, azimuth),
                    ));
                }
            }
            // Along the box's faces: grazing.
            dirs.push(("along x".into(), DVec3::X));
            dirs.push(("along -z".into(), DVec3::NEG_Z));
            for (what, d) in dirs {
                for range in [
                    (0.0, f64::INFINITY),
                    (0.5, 0.3 * e.length()),
                    (0.0, 1.5 * e.length()),
                ] {
                    for jitter in [0.5, 0.0, 0.37, 0.999] {
                        n += 1;
                        // The unit direction as it is (`Ray::new` would renormalise it).
                        let ray = Ray { origin: o, dir: d };
                        out.push((
                            format!("from {where_}, {what}, range {range:?}, jitter {jitter}"),
                            CloudQuery {
                                ray: CaseRay {
                                    ray,
                                    range: Interval::new(range.0, range.1),
                                },
                                jitter,
                                pixel: (n * 7 % 1920, n * 13 % 1080),
                            },
                        ));
                    }
                }
            }
        }
        out
    }

    /// The largest difference over a batch and where.
    #[derive(Debug, Default)]
    struct Worst {
        /// Of `|Δ| / (BATCH_ABS + BATCH_REL·|cpu|)`, with the quantity.
        ratio: f64,
        at: String,
        transmittance: f64,
        in_scatter: f64,
        depth: f64,
        density: f64,
        jitter: f64,
        samples: i64,
    }

    /// The march, optical depth, density and jitter on the GPU agree with the CPU's ray by ray.
    /// Measured on lavapipe (the figures printed): transmittance within 1.6e-6 (0.124 on the
    /// dense volume seen from far outside, jitter 0.999), in-scatter 5.7e-7, optical depth 1.0e-5,
    /// densities 1.1e-9, at most 0.0095 of the bound; the pixel jitter within 6.7e-4 (the f32
    /// products of pixel coordinates up to 1920; bound [`JITTER_BOUND`]), samples within ±1 of the
    /// CPU's with skipping and equal without (skipping leaves out 2–3 % of them here). Every value
    /// finite.
    pub fn clouds_match_the_cpu() {
        let settings = MarchSettings {
            step: 2.0,
            sun_steps: 6,
            jitter: 0.5,
            min_transmittance: 1e-3,
        };
        let mut total = 0;
        for (label, scale, size) in [
            ("thin", 0.05, [24usize, 12, 20]),
            ("dense", 0.6, [17usize, 9, 13]),
        ] {
            let g = grid(size);
            for skip in [None, Some(4usize)] {
                for offset in [DVec3::ZERO, DVec3::new(1e5, 300.0, -7e4)] {
                    let region = Region {
                        min: (DVec3::new(-50.0, 10.0, -40.0) + offset).to_array(),
                        max: (DVec3::new(50.0, 40.0, 40.0) + offset).to_array(),
                    };
                    let volume = GridVolume {
                        grid: g.clone(),
                        region,
                        scale,
                        skip: skip.map(|b| g.max_grid(b)),
                    };
                    let light = light();
                    // The reference point: the "camera", near the box.
                    let reference = offset + DVec3::new(-70.0, 25.0, -3.0);
                    let all = queries(&region);
                    let qs: Vec<CloudQuery> = all.iter().map(|(_, q)| *q).collect();
                    let seen = CloudsSeen {
                        volume: &volume,
                        light: &light,
                        settings: &settings,
                        reference,
                    };
                    let (cpu, got) = (Cpu.clouds(seen, &qs), gpu().clouds(seen, &qs));
                    assert_eq!(got.len(), qs.len());
                    let mut w = Worst::default();
                    let mut sampled = 0u64;
                    for (((name, _), c), g) in all.iter().zip(&cpu).zip(&got) {
                        let values = [
                            ("transmittance", c.transmittance, g.transmittance),
                            ("in-scatter r", c.in_scatter.x, g.in_scatter.x),
                            ("in-scatter g", c.in_scatter.y, g.in_scatter.y),
                            ("in-scatter b", c.in_scatter.z, g.in_scatter.z),
                            ("optical depth", c.optical_depth, g.optical_depth),
                            ("density", c.density, g.density),
                        ];
                        for (what, cpu, gpu) in values {
                            assert!(gpu.is_finite(), "{name}: {what} {gpu}");
                            let diff = (gpu - cpu).abs();
                            let ratio = diff / (BATCH_ABS + BATCH_REL * cpu.abs());
                            if ratio > w.ratio {
                                w.ratio = ratio;
                                w.at = format!("{name}: {what} cpu {cpu} gpu {gpu}");
                            }
                            let slot = match what {
                                "transmittance" => &mut w.transmittance,
                                "optical depth" => &mut w.depth,
                                "density" => &mut w.density,
                                _ => &mut w.in_scatter,
                            };
                            *slot = slot.max(diff);
                        }
                        // On the circle: a value just under 1 in f64 may round to just over 0.
                        let dj = (g.pixel_jitter - c.pixel_jitter).abs();
                        assert!((0.0..1.0).contains(&g.pixel_jitter), "{name}");
                        w.jitter = w.jitter.max(dj.min(1.0 - dj));
                        let ds = i64::from(g.samples) - i64::from(c.samples);
                        if ds.abs() > w.samples.abs() {
                            w.samples = ds;
                        }
                        sampled += u64::from(c.samples);
                    }
                    eprintln!(
                        "cloud parity, {label}, skip {skip:?}, offset {offset}: {} rays, {sampled} \
                     CPU samples: {w:?}",
                        qs.len()
                    );
                    assert!(w.ratio <= 1.0, "{label}, skip {skip:?}: {w:?}");
                    assert!(w.jitter <= JITTER_BOUND, "{w:?}");
                    assert!(sampled > 0);
                    total += qs.len();
                }
            }
        }
        assert!(total > 10_000);
    }

    /// A grid wider than the device's 3D textures is refused with `TooLarge` (the facade then
    /// renders on the CPU), naming the grid; one at the limit is not.
    pub fn grids_past_the_device_limit_are_refused() {
        let ctx = gpu().context();
        let limit = ctx.limits.max_texture_dimension_3d as usize;
        let volume = |side: usize| GridVolume {
            grid: DensityGrid::from_data([side, 1, 1], vec![0.5; side]).unwrap(),
            region: Region {
                min: [0.0; 3],
                max: [1.0; 3],
            },
            scale: 1.0,
            skip: None,
        };
        let block = |v: &GridVolume| {
            GpuClouds::new(v, &light(), &MarchSettings::default(), false, [0.0; 3])
        };
        let wide = volume(limit + 1);
        match CloudsBatch::new(ctx, &wide, &block(&wide)) {
            Err(fray_gpu::GpuError::TooLarge {
                what,
                needed,
                limit: l,
            }) => {
                assert!(what.contains("cloud density grid"), "{what}");
                assert_eq!((needed, l), ((limit + 1) as u64, limit as u64));
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        let fits = volume(limit);
        assert!(CloudsBatch::new(ctx, &fits, &block(&fits)).is_ok());
    }
}
