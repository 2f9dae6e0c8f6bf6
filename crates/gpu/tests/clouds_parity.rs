//! The GPU clouds (`shaders/clouds.wgsl`) vs the f64 reference (`fray_clouds::march`):
//!
//! - ray by ray through the batch `CloudsBatch`: two baked volumes (a thin one and a dense one
//!   whose march exits early), with and without empty-space skipping, near the world origin and
//!   10⁵ m from it (camera-relative on the GPU), rays from inside the box, from its faces and
//!   corners, from outside, grazing a face, through empty stretches and dense ones, over
//!   unbounded ranges and ranges ending inside the box, with several jitters — the march's
//!   transmittance and in-scatter, the optical depth, the density at the origin and the pixel
//!   jitter, all finite;
//! - frames (`fray_trace::render` vs the GPU's) on synthetic cloud scenes (camera outside and
//!   inside the box, fog, the sky with misses, jitter, a point light, anti-aliasing) and the data
//!   scenes with clouds (`clouds_*.ron`, `ct_*.ron`) at a small width;
//! - a scene without clouds allocates, uploads and compiles none of them.
//!
//! Uses the libtest-mimic harness: ignored without an adapter, a failure under
//! `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_clouds::DensityGrid;
use fray_clouds::bake::Region;
use fray_clouds::gpu_layout::GpuClouds;
use fray_clouds::march::{self, CloudLight, DualLobe, GridVolume, MarchSettings};
use fray_core::{Frame, MemoryBudget};
use fray_gpu::testing::{CloudsBatch, GpuCloudRay};
use fray_gpu::{GpuRenderer, GpuSettings};
use fray_scene::Scene;
use fray_trace::TraceSettings;
use glam::DVec3;

/// The batch bound: `|gpu − cpu| ≤ BATCH_ABS + BATCH_REL · |cpu|` for the transmittance, each
/// channel of the in-scatter (the light is of order 1), the optical depth and the density.
/// Measured on lavapipe over the 2 × 2 × 2 × 3924 rays: see
/// `batch_march_matches_the_cpu_reference` for the worst figures (at most 0.01 of this bound;
/// the margin is for drivers whose f32 clip makes `ceil(length / step)` one step more or less
/// than the f64's on a ray whose length is a whole number of steps, which moves every sample).
const BATCH_ABS: f64 = 5e-5;
const BATCH_REL: f64 = 5e-4;

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

/// The unit vector at `elevation` and `azimuth` (degrees), Y up.
fn direction(elevation: f64, azimuth: f64) -> DVec3 {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

/// A ray of the batch: world origin and unit direction, range, jitter.
struct Case {
    o: DVec3,
    d: DVec3,
    range: (f64, f64),
    jitter: f64,
    pixel: (u32, u32),
}

/// Rays through `region` (see the module's list).
fn cases(region: &Region) -> Vec<(String, Case)> {
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
                    out.push((
                        format!("from {where_}, {what}, range {range:?}, jitter {jitter}"),
                        Case {
                            o,
                            d,
                            range,
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
/// products of pixel coordinates up to 1920; bound 2e-3), samples within ±1 of the CPU's with
/// skipping and equal without (skipping leaves out 2–3 % of them here). Every value finite.
fn batch_march_matches_the_cpu_reference() {
    let gpu = common::gpu("batch_march_matches_the_cpu_reference");
    let ctx = gpu.context();
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
                let block = GpuClouds::new(&volume, &light, &settings, true, reference.to_array());
                let pass = CloudsBatch::new(ctx, &volume, &block).unwrap();
                let cases = cases(&region);
                let rays: Vec<GpuCloudRay> = cases
                    .iter()
                    .map(|(_, c)| {
                        let o = (c.o - reference).as_vec3();
                        let t1 = if c.range.1.is_finite() {
                            c.range.1 as f32
                        } else {
                            1e30
                        };
                        [
                            [o.x, o.y, o.z, c.range.0 as f32],
                            [c.d.x as f32, c.d.y as f32, c.d.z as f32, t1],
                            [c.jitter as f32, c.pixel.0 as f32, c.pixel.1 as f32, 0.0],
                        ]
                    })
                    .collect();
                let got = pass.terms(ctx, &rays).unwrap();
                assert_eq!(got.len(), cases.len());
                let mut w = Worst::default();
                let mut sampled = 0u64;
                for ((name, c), g) in cases.iter().zip(&got) {
                    let (o, d) = (c.o.to_array(), c.d.to_array());
                    let s = MarchSettings {
                        jitter: c.jitter,
                        ..settings
                    };
                    let m = march::march(&volume, o, d, c.range, &s, &light);
                    let depth = march::optical_depth(&volume, o, d, c.range, settings.step);
                    let density = march::Density::density(&volume, o);
                    let jitter = march::pixel_jitter(c.pixel.0, c.pixel.1);
                    let values = [
                        ("transmittance", m.transmittance, g.transmittance),
                        ("in-scatter r", m.in_scatter[0], g.in_scatter[0]),
                        ("in-scatter g", m.in_scatter[1], g.in_scatter[1]),
                        ("in-scatter b", m.in_scatter[2], g.in_scatter[2]),
                        ("optical depth", depth, g.optical_depth),
                        ("density", density, g.density),
                    ];
                    for (what, cpu, gpu) in values {
                        let gpu = f64::from(gpu);
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
                    let dj = (f64::from(g.pixel_jitter) - jitter).abs();
                    assert!((0.0..1.0).contains(&g.pixel_jitter), "{name}");
                    w.jitter = w.jitter.max(dj.min(1.0 - dj));
                    let ds = i64::from(g.samples) - i64::from(m.samples);
                    if ds.abs() > w.samples.abs() {
                        w.samples = ds;
                    }
                    sampled += u64::from(m.samples);
                }
                eprintln!(
                    "{label}, skip {skip:?}, offset {offset}: {} rays, {sampled} CPU samples: {w:?}",
                    cases.len()
                );
                assert!(w.ratio <= 1.0, "{label}, skip {skip:?}: {w:?}");
                assert!(w.jitter <= 2e-3, "{w:?}");
                assert!(sampled > 0);
                total += cases.len();
            }
        }
    }
    assert!(total > 10_000);
}

/// Per-pixel frame bound: `|Δ| ≤ FRAME_ABS + FRAME_REL · max channel of the CPU's colour` on
/// every pixel away from silhouettes and shadow boundaries. Measured on lavapipe at 64 px
/// (largest difference, its share of the bound): camera outside 8.3e-7 (0.0013), inside with
/// fog 3.1e-6 (0.0056), the sky 1.6e-5 (0.086: a ground pixel 860 m away through the cloud's
/// shadow and the air), dense 2.8e-7 (0.0009); the data scenes clouds_aircraft_above 6.9e-6
/// (0.011), clouds_aircraft_inside 3.8e-6 (0.013), clouds_ct_skull 1.8e-6 (0.0096); means
/// 4e-8–5e-7. The cloud samples the frames count agree with the CPU's to 1 in 178 798.
const FRAME_ABS: f32 = 1e-4;
const FRAME_REL: f32 = 1e-3;

/// What a frame comparison found.
#[derive(Debug, Default)]
struct FrameReport {
    checked: usize,
    /// Pixels past the bound.
    bad: usize,
    /// The largest `|Δ| / (FRAME_ABS + FRAME_REL · |c|)` and where.
    worst_ratio: f32,
    worst: String,
    max_abs: f32,
    mean_abs: f64,
    /// The camera rays' cloud samples, CPU and GPU.
    cloud_samples: (u64, u64),
}

/// The GPU frame of `scene` against the CPU's: hit/miss the same off silhouettes, colour within
/// the frame bound off silhouettes and (solid) shadow boundaries; the GPU frame's passes name the
/// clouds, culling on and off give the same bits, and no value is NaN.
fn compare(name: &str, scene: &Scene, gpu: &GpuRenderer) -> FrameReport {
    let cpu_settings = TraceSettings::for_scene(scene);
    let cpu: Frame = fray_trace::render(scene, &cpu_settings, None).unwrap();
    let settings = GpuSettings::for_scene(scene);
    let g = gpu.render(scene, &settings).unwrap();
    assert!(
        g.stats.passes[0].contains("clouds]") && g.stats.passes.iter().any(|p| p == "clouds"),
        "{name}: {:?}",
        g.stats.passes
    );
    let off = gpu
        .render(
            scene,
            &GpuSettings {
                culling: false,
                ..settings
            },
        )
        .unwrap();
    assert_eq!(g.colour.pixels(), off.colour.pixels(), "{name}: culling");
    let (w, h) = (scene.width, scene.height);
    // Silhouettes: the hit/miss state changes, or the depth jumps by 5 %, between neighbours.
    let depth = cpu.depth.pixels();
    let mut edges = vec![false; depth.len()];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let k = (y * i64::from(w) + x) as usize;
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= i64::from(w) || ny >= i64::from(h) {
                    continue;
                }
                let n = depth[(ny * i64::from(w) + nx) as usize];
                let (a, b) = (depth[k], n);
                if a.is_finite() != b.is_finite() || (a.is_finite() && (a / b).ln().abs() > 0.05) {
                    edges[k] = true;
                }
            }
        }
    }
    let shadow_edges = common::shadow_edges(scene, &cpu_settings, &cpu);
    let mut r = FrameReport {
        cloud_samples: (cpu.stats.cloud_samples, g.stats.cloud_samples),
        ..FrameReport::default()
    };
    for k in 0..(w * h) as usize {
        let (cc, cg) = (cpu.colour.pixels()[k], g.colour.pixels()[k]);
        assert!(cg.is_finite(), "{name}: pixel {k} is {cg}");
        if edges[k] || shadow_edges[k] {
            continue;
        }
        let (tc, tg) = (cpu.depth.pixels()[k], g.depth.pixels()[k]);
        assert_eq!(tc.is_finite(), tg.is_finite(), "{name}: hit/miss at {k}");
        r.checked += 1;
        let d = (cg - cc).abs().max_element();
        let ratio = d / (FRAME_ABS + FRAME_REL * cc.abs().max_element());
        r.max_abs = r.max_abs.max(d);
        r.mean_abs += f64::from(d);
        if ratio > 1.0 {
            r.bad += 1;
        }
        if ratio > r.worst_ratio {
            r.worst_ratio = ratio;
            r.worst = format!(
                "({}, {}) depth {tc:.3}: cpu {cc} gpu {cg}",
                k as u32 % w,
                k as u32 / w
            );
        }
    }
    r.mean_abs /= r.checked.max(1) as f64;
    eprintln!("{name}: {w}×{h}: {r:?} | gpu {:?}", g.stats.passes);
    assert!(
        r.checked * 2 > (w * h) as usize,
        "{name}: too few pixels checked"
    );
    // The GPU counts the camera rays' cloud samples as the CPU does (f32 clips may move a
    // sample in or out of a ray's range).
    let (sc, sg) = r.cloud_samples;
    assert!(
        sc > 0 && sc.abs_diff(sg) * 1000 <= sc,
        "{name}: samples {sc} vs {sg}"
    );
    r
}

/// Synthetic cloud scenes: a layer of cumulus 40 m wide over a ground plane with a sphere half in
/// it, seen from outside with the sun low and its shadows on the ground; the camera inside the
/// box, in fog, with a point light; the sky behind the clouds (misses peel the air in front of
/// them) with aerial perspective and 4 samples per pixel; a CT-like dense volume without
/// skipping or jitter.
const SCENES: [(&str, &str); 4] = [
    (
        "clouds: camera outside, low sun, shadows on the ground",
        r#"Scene(
            image: (width: 64, height: 40),
            camera: Pinhole(eye: (0, 7, -48), look_at: (0, 4, 0), fov_y: 50, near: 0.1),
            background: (0.4, 0.55, 0.8),
            ambient: (0.15, 0.17, 0.2),
            lights: [Sun(direction: (0.5, 0.45, 0.3), irradiance: (3, 2.9, 2.7))],
            materials: { "ground": (diffuse: (0.4, 0.38, 0.3)), "red": (diffuse: (0.8, 0.2, 0.1), specular: (0.3, 0.3, 0.3), shininess: 30) },
            clouds: (
                region: (min: (-20, 2, -20), max: (20, 12, 20)),
                density: Layer((resolution: (32, 10, 32), feature_size: 14, octaves: 3, seed: 5, coverage: 0.6)),
                scattering: 0.4,
                step: 0.6,
                phase: (g: 0.7, back_g: -0.2, back_weight: 0.25),
            ),
            objects: [
                (material: "ground", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-80, -1, -80), max: (80, 0, 80)))),
                (material: "red", shape: Sphere(center: (4, 3, 2), radius: 3)),
            ],
        )"#,
    ),
    (
        "clouds and fog: camera inside the box, a point light, no jitter",
        r#"Scene(
            image: (width: 64, height: 40),
            camera: Pinhole(eye: (-6, 5, -9), look_at: (2, 4, 6), fov_y: 60, near: 0.1),
            background: (0.4, 0.55, 0.8),
            ambient: (0.15, 0.17, 0.2),
            lights: [
                Sun(direction: (0.2, 1.0, 0.4), irradiance: (3, 2.9, 2.7)),
                Point(position: (3, 9, 0), intensity: (60, 60, 60)),
            ],
            atmosphere: (fog: (base: -1, top: 6, extinction: 0.02, phase: HenyeyGreenstein(g: 0.5))),
            clouds: (
                region: (min: (-20, 2, -20), max: (20, 12, 20)),
                density: Layer((resolution: (32, 10, 32), feature_size: 14, octaves: 3, seed: 2, coverage: 0.5)),
                scattering: 0.15,
                step: 0.5,
                jitter: false,
            ),
            objects: [
                (shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-80, -1, -80), max: (80, 0, 80)))),
                (shape: Sphere(center: (2, 4, 6), radius: 2)),
            ],
        )"#,
    ),
    (
        "clouds and sky: a layer 1 km up over the horizon, misses, 4 samples",
        r#"Scene(
            image: (width: 64, height: 40),
            camera: Pinhole(eye: (0, 2, 0), look_at: (1000, 250, 200), fov_y: 50, near: 0.1),
            ambient: (0.05, 0.06, 0.08),
            lights: [Sun(direction: (0.5, 0.35, -0.6), irradiance: (20, 20, 20))],
            materials: { "ground": (diffuse: (0.3, 0.3, 0.25)) },
            atmosphere: (sky: (haze: 2)),
            clouds: (
                region: (min: (-3000, 600, -3000), max: (3000, 1400, 3000)),
                density: Layer((resolution: (48, 10, 48), feature_size: 1500, octaves: 3, seed: 9, coverage: 0.55)),
                scattering: 0.01,
                step: 40,
                ambient: 2,
            ),
            objects: [
                (material: "ground", shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-20000, -1, -20000), max: (20000, 0, 20000)))),
                (shape: Sphere(center: (900, 80, 200), radius: 80)),
            ],
            settings: (samples: 4),
        )"#,
    ),
    (
        "clouds: a dense volume, no skipping, camera on its face",
        r#"Scene(
            image: (width: 64, height: 40),
            camera: Pinhole(eye: (0, 5, -10), look_at: (0, 5, 0), fov_y: 60, near: 0.1),
            background: (0.1, 0.1, 0.1),
            ambient: (0.2, 0.2, 0.2),
            lights: [Sun(direction: (-0.3, 0.9, -0.3), irradiance: (2, 2, 2))],
            clouds: (
                region: (min: (-6, 0, -10), max: (6, 10, 2)),
                density: Layer((resolution: (16, 16, 16), feature_size: 5, octaves: 2, seed: 1, coverage: 0.7, threshold: 0.0)),
                scattering: 1.5,
                absorption: 0.2,
                step: 0.25,
                skip_block: 0,
            ),
            objects: [
                (shape: Sphere(center: (1, 4, -3), radius: 1.5)),
                (shape: FreeForm(base: HalfSpace(point: (0, 0, 0), normal: (0, 1, 0)),
                    bounds: (min: (-30, -1, -30), max: (30, 0, 30)))),
            ],
        )"#,
    ),
];

/// The synthetic scenes ([`SCENES`]) match the CPU within the frame bound on every checked
/// pixel; the clouds really show (colours differ from the scene without them); a second frame
/// of the resident scene from a moved camera builds no pipeline and uploads no scene.
fn synthetic_cloud_scenes_match_the_cpu_reference() {
    let gpu = common::gpu("synthetic_cloud_scenes_match_the_cpu_reference");
    for (name, text) in SCENES {
        let scene = fray_scene::parse(text, name).unwrap();
        assert!(scene.features.clouds, "{name}");
        let r = compare(name, &scene, &gpu);
        assert_eq!(r.bad, 0, "{name}: {r:?}");
        // The clouds show.
        let mut clear = scene.clone();
        clear.clouds = None;
        clear.features.clouds = false;
        let settings = GpuSettings::for_scene(&scene);
        let without = gpu.render(&clear, &settings).unwrap();
        let with = gpu.render(&scene, &settings).unwrap();
        let changed = with
            .colour
            .pixels()
            .iter()
            .zip(without.colour.pixels())
            .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-3)
            .count();
        assert!(
            changed * 10 > with.colour.pixels().len(),
            "{name}: {changed}"
        );
        // Resident: a moved camera uploads the block and the work list only.
        let mut resident = gpu.upload(&scene, &settings).unwrap();
        let view = fray_gpu::View::of_scene(&scene, settings.samples);
        let first = resident.render(&view).unwrap();
        assert!(resident.specialisation().clouds);
        let mut moved = view;
        if let fray_core::Projector::Pinhole(p) = &mut moved.camera {
            p.eye += glam::DVec3::new(0.5, 0.2, -0.3);
        }
        let second = resident.render(&moved).unwrap();
        assert!(first.stats.scene_uploaded_bytes > 0);
        assert_eq!(
            (
                second.stats.scene_uploaded_bytes,
                second.stats.pipelines_built
            ),
            (0, 0),
            "{name}"
        );
        assert!(second.stats.cloud_samples > 0, "{name}");
    }
}

/// The cloud data scenes (`data/scenes/clouds_*.ron` and `ct_*.ron`) at 64 pixels wide match
/// the CPU within the frame bound on all but 0.5 % of the checked pixels (terrain scenes: the
/// terrain's own allowance, grazing shadow rays on a DEM), and within 4× of it everywhere.
fn cloud_data_scenes_match_the_cpu_reference() {
    let gpu = common::gpu("cloud_data_scenes_match_the_cpu_reference");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            name.ends_with(".ron") && (name.starts_with("clouds_") || name.starts_with("ct_"))
        })
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "no cloud data scene");
    for path in paths {
        let mut scene = fray_scene::load(&path).unwrap();
        if !scene.features.clouds {
            continue;
        }
        let width = 64;
        scene.height =
            ((u64::from(width) * u64::from(scene.height)) / u64::from(scene.width)).max(1) as u32;
        scene.width = width;
        let name = path.display().to_string();
        let r = compare(&name, &scene, &gpu);
        assert!(r.bad * 200 <= r.checked, "{name}: {r:?}");
        assert!(r.worst_ratio <= 4.0, "{name}: {r:?}");
    }
}

/// A scene without clouds allocates, uploads and compiles none of them: the same scene with a
/// cloud volume uploads exactly its grids' bytes more (the density grid and the max grid of its
/// blocks, 4 bytes a texel), and only the cloudy one is specialised for clouds and names them.
fn a_scene_without_clouds_builds_none_of_them() {
    let gpu = common::gpu("a_scene_without_clouds_builds_none_of_them");
    let (_, text) = SCENES[0];
    let scene = fray_scene::parse(text, "clouds").unwrap();
    let mut clear = scene.clone();
    clear.clouds = None;
    clear.features.clouds = false;
    let settings = GpuSettings::for_scene(&scene);
    let cloudy = gpu.upload(&scene, &settings).unwrap();
    let plain = gpu.upload(&clear, &settings).unwrap();
    assert!(cloudy.specialisation().clouds && !plain.specialisation().clouds);
    drop((cloudy, plain));
    let a = gpu.render(&scene, &settings).unwrap();
    let b = gpu.render(&clear, &settings).unwrap();
    let c = scene.clouds.as_ref().unwrap();
    let grid = c.volume.grid.size().iter().product::<usize>() as u64;
    let blocks = c
        .volume
        .skip
        .as_ref()
        .map_or(1, |m| m.blocks().iter().product::<usize>() as u64);
    assert_eq!(
        a.stats.scene_uploaded_bytes - b.stats.scene_uploaded_bytes,
        4 * (grid + blocks)
    );
    assert!(!b.stats.passes[0].contains("clouds") && !b.stats.passes.iter().any(|p| p == "clouds"));
    assert_eq!(b.stats.cloud_samples, 0);
    assert!(a.stats.cloud_samples > 0);
}

/// A grid wider than the device's 3D textures is refused with `TooLarge` (the facade then
/// renders on the CPU), naming the grid; one at the limit is not.
fn grids_past_the_device_limit_are_refused() {
    let gpu = common::gpu("grids_past_the_device_limit_are_refused");
    let ctx = gpu.context();
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
    let block =
        |v: &GridVolume| GpuClouds::new(v, &light(), &MarchSettings::default(), false, [0.0; 3]);
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

fn main() {
    common::run(
        &[
            (
                "batch_march_matches_the_cpu_reference",
                batch_march_matches_the_cpu_reference,
            ),
            (
                "synthetic_cloud_scenes_match_the_cpu_reference",
                synthetic_cloud_scenes_match_the_cpu_reference,
            ),
            (
                "cloud_data_scenes_match_the_cpu_reference",
                cloud_data_scenes_match_the_cpu_reference,
            ),
            (
                "a_scene_without_clouds_builds_none_of_them",
                a_scene_without_clouds_builds_none_of_them,
            ),
            (
                "grids_past_the_device_limit_are_refused",
                grids_past_the_device_limit_are_refused,
            ),
        ],
        &[],
    )
}
