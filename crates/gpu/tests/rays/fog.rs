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

/// The layer the rays of a call see, by its model, from the camera's height.
#[derive(Clone, Copy, Debug)]
pub struct FogSeen<'a> {
    pub layer: &'a FogLayer,
    pub model: FogModel,
    /// Every ray starts at the camera, at this height (a backend that works relative to it
    /// takes heights from there).
    pub camera_y: f64,
}

/// What a backend of the suite answers for the fog layer.
pub trait FogBackend {
    /// What `seen.layer` (by `seen.model`) does to each ray.
    fn fog(&self, seen: FogSeen<'_>, rays: &[FogRay]) -> Vec<FogAnswer>;
    /// How far its fog answers may be from the reference: `abs + rel · |reference|`.
    fn medium_bounds(&self) -> (f64, f64);
}

impl FogBackend for Cpu {
    fn fog(&self, seen: FogSeen<'_>, rays: &[FogRay]) -> Vec<FogAnswer> {
        let FogSeen { layer, model, .. } = seen;
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
    fn fog(&self, seen: FogSeen<'_>, rays: &[FogRay]) -> Vec<FogAnswer> {
        let FogSeen {
            layer,
            model,
            camera_y,
        } = seen;
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
        // The parity bound (`parity` below: f32, camera-relative heights).
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
            let answers = backend.fog(
                FogSeen {
                    layer,
                    model: fog.model,
                    camera_y: eye_y,
                },
                &fog_rays,
            );
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

pub mod parity {
    //! Fog parity: the GPU's fog (`shaders/fog.wgsl`) against the f64 CPU (`FogLayer`) on the same
    //! rays — a GPU-vs-CPU bound, the f32 arithmetic's, tighter than any independent reference
    //! allows. Four layers (homogeneous and falling off, thick and thin, one thousands of metres
    //! below the camera as in the data scenes), both models (Exact, Method), every phase function,
    //! the camera below, at the bottom, inside, at the top, just above and far above the layer, view
    //! elevations from straight down to straight up through the horizontal (exactly 0 and
    //! ±0.001°), rays at the sun's own elevation (the exact form's slope κ = 0), suns at −3° (below
    //! the horizon), 2°, 8°, 50° and 90°, ranges ending at surfaces 1 m to 20 km away or at
    //! infinity. Compared: every field of [`FogAnswer`] — the transmittance, the ambient and sun
    //! factors of the in-scatter, the optical depth, the sun's transmittance to the ray's origin
    //! and the segment transmittance of the point-light path — within `ABS + REL · |cpu|`.

    use crate::backend::CaseRay;
    use crate::cases::direction;
    use crate::cpu::Cpu;
    use crate::fog::FogBackend;
    use crate::fog::{FOG_NAMES, FogAnswer, FogRay, FogSeen};
    use crate::gpu::gpu;
    use fray_atmosphere::{FogLayer, FogModel, Phase};
    use fray_core::{Interval, Ray};
    use glam::DVec3;

    /// Absolute allowance (the quantities are transmittances in `[0, 1]`, factors of order 1).
    const ABS: f64 = 1e-6;
    /// Relative allowance. Measured on lavapipe over the 64 800 rays: largest differences 3.4e-6 in
    /// a transmittance, 3.4e-6 in the ambient factor, 3.0e-6 in a sun factor, 9.9e-8 in the sun's
    /// transmittance, 3.1e-5 in an optical depth of 1.43 (2.2e-5 relative) — all on the thin dense
    /// slab seen at −5° from 1 km above it, whose 29 m in the layer are the difference of two f32
    /// distances near 11.5 km; at most 0.27 of this bound, elsewhere far less.
    const REL: f64 = 5e-5;

    /// A layer from `base` to `top` with the default albedo.
    fn layer(base: f64, top: f64, extinction: f64, falloff: Option<f64>, phase: Phase) -> FogLayer {
        FogLayer {
            base,
            top,
            extinction,
            falloff,
            phase,
            ..FogLayer::default()
        }
    }

    fn layers() -> Vec<(&'static str, FogLayer)> {
        vec![
            (
                "homogeneous 400 m, HG 0.76",
                layer(
                    0.0,
                    400.0,
                    1.2e-3,
                    None,
                    Phase::HenyeyGreenstein { g: 0.76 },
                ),
            ),
            (
                "falloff 30 m in 100 m, isotropic",
                layer(0.0, 100.0, 2e-2, Some(30.0), Phase::Isotropic),
            ),
            (
                "valley fog 1 km below, falloff 150 m, printed 0.5",
                layer(
                    -1100.0,
                    -700.0,
                    1.2e-3,
                    Some(150.0),
                    Phase::Printed { g: 0.5 },
                ),
            ),
            (
                "thin dense slab, HG −0.3",
                layer(20.0, 22.5, 0.05, None, Phase::HenyeyGreenstein { g: -0.3 }),
            ),
        ]
    }

    /// One batch: a layer by a model seen from one camera height, and its rays with their names.
    struct Batch {
        layer: FogLayer,
        model: FogModel,
        camera_y: f64,
        rays: Vec<(String, FogRay)>,
    }

    impl Batch {
        fn seen(&self) -> FogSeen<'_> {
            FogSeen {
                layer: &self.layer,
                model: self.model,
                camera_y: self.camera_y,
            }
        }
    }

    fn batches() -> Vec<Batch> {
        let mut out = Vec::new();
        let elevations = [
            -90.0, -30.0, -5.0, -1.0, -0.05, -1e-3, 0.0, 1e-3, 0.05, 1.0, 2.0, 8.0, 30.0, 50.0,
            90.0,
        ];
        let suns = [-3.0, 2.0, 8.0, 50.0, 90.0];
        let ends = [1.0, 50.0, 300.0, 2000.0, 20000.0, f64::INFINITY];
        for (name, layer) in layers() {
            let h = layer.thickness();
            let cameras = [
                ("below", layer.base - 0.3 * h),
                ("at the bottom", layer.base),
                ("inside", layer.base + 0.37 * h),
                ("at the top", layer.top),
                ("just above", layer.top + 0.5),
                ("far above", layer.top + 1000.0),
            ];
            for model in [FogModel::Exact, FogModel::Method] {
                for (camera, y) in cameras {
                    let mut rays = Vec::new();
                    for &e in &elevations {
                        // Azimuth 0 is the sun's: the rays at the sun's elevation point at it.
                        for azimuth in [0.0, 100.0, 180.0] {
                            for &s in &suns {
                                for &end in &ends {
                                    let Some(ray) =
                                        Ray::new(DVec3::new(0.0, y, 0.0), direction(e, azimuth))
                                    else {
                                        continue;
                                    };
                                    rays.push((
                                    format!(
                                        "{name}, {model:?}, camera {camera}, elevation {e}°, azimuth {azimuth}°, sun {s}°, to {end}"
                                    ),
                                    FogRay {
                                        ray: CaseRay {
                                            ray,
                                            range: Interval::new(0.05, end),
                                        },
                                        sun: direction(s, 0.0),
                                    },
                                ));
                                }
                            }
                        }
                    }
                    out.push(Batch {
                        layer,
                        model,
                        camera_y: y,
                        rays,
                    });
                }
            }
        }
        out
    }

    /// How far `gpu` is from `cpu` for field `q` of [`FogAnswer::values`], as a share of the bound
    /// (`∞`: wrong), and `|Δ|` where it is measured.
    fn excess(q: usize, cpu: f64, gpu: f64) -> (f64, Option<f64>) {
        if cpu == f64::INFINITY {
            // An unbounded depth: ≥ BIG on the GPU.
            (if gpu >= 1e30 { 0.0 } else { f64::INFINITY }, None)
        } else if q == 3 && cpu > 80.0 {
            // A depth past e^{−80}: only that it is large matters.
            (if gpu > 70.0 { 0.0 } else { f64::INFINITY }, None)
        } else {
            let d = (gpu - cpu).abs();
            (d / (ABS + REL * cpu.abs()), Some(d))
        }
    }

    /// Every field of the GPU's fog within `ABS + REL · |cpu|` of the CPU's on every ray.
    pub fn fog_matches_the_cpu() {
        let batches = batches();
        let mut worst: [(f64, String); 6] = std::array::from_fn(|_| (0.0, String::new()));
        let mut max_abs = [0.0f64; 6];
        let (mut bad, mut rays) = (0usize, 0usize);
        for b in &batches {
            let fog_rays: Vec<FogRay> = b.rays.iter().map(|(_, r)| *r).collect();
            let cpu: Vec<FogAnswer> = Cpu.fog(b.seen(), &fog_rays);
            let got: Vec<FogAnswer> = gpu().fog(b.seen(), &fog_rays);
            rays += fog_rays.len();
            for (((name, _), c), g) in b.rays.iter().zip(&cpu).zip(&got) {
                let (want, have) = (c.values(), g.values());
                for q in 0..6 {
                    let (w, h) = (want[q], have[q]);
                    let (e, d) = excess(q, w, h);
                    if let Some(d) = d {
                        max_abs[q] = max_abs[q].max(d);
                    }
                    if e > worst[q].0 {
                        worst[q] = (e, format!("{name}: cpu {w:e} gpu {h:e}"));
                    }
                    if e > 1.0 {
                        bad += 1;
                        if bad <= 20 {
                            eprintln!("{}: {name}: cpu {w:e} gpu {h:e}", FOG_NAMES[q]);
                        }
                    }
                }
            }
        }
        for q in 0..6 {
            eprintln!(
                "fog parity {:>22}: max |Δ| {:.3e}; worst {:.3} of the bound ({})",
                FOG_NAMES[q], max_abs[q], worst[q].0, worst[q].1
            );
        }
        eprintln!("fog parity: {rays} rays in {} batches", batches.len());
        assert_eq!(bad, 0, "{bad} values beyond |Δ| ≤ {ABS} + {REL}·|cpu|");
    }
}
