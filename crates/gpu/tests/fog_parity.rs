//! The GPU fog functions (`shaders/fog.wgsl`, through the batch `FogBatch`) vs the f64 reference
//! (`fray_atmosphere::FogLayer`) over a grid of rays: four layers (homogeneous and falling off,
//! thick and thin, one thousands of metres below the camera as in the data scenes), both models
//! (Exact, Method), every phase function, the camera below, at the bottom, inside, at the top,
//! just above and far above the layer, view elevations from straight down to straight up through
//! the horizontal (exactly 0 and ±0.001°), rays at the sun's own elevation (the exact form's
//! slope κ = 0), suns at −3° (below the horizon), 2°, 8°, 50° and 90°, ranges ending at surfaces
//! 1 m to 20 km away or at infinity. Compared: the transmittance, the ambient and sun factors of
//! the in-scatter, the optical depth, the sun's transmittance to the ray's origin and the segment
//! transmittance of the point-light path.
//!
//! Bound (f32 vs f64, camera-relative heights on the GPU): `|gpu − cpu| ≤ ABS + REL · |cpu|` per
//! quantity; see [`ABS`] and [`REL`] for the measured figures.
//!
//! Uses the libtest-mimic harness: ignored without an adapter, a failure under
//! `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_atmosphere::gpu_layout::GpuFog;
use fray_atmosphere::{FogLayer, FogLighting, FogModel, Phase, Sunlight};
use fray_core::{Interval, Ray};
use fray_gpu::testing::{FogBatch, GpuFogRay, GpuFogTerms};
use glam::DVec3;

/// Absolute allowance (the quantities are transmittances in `[0, 1]`, factors of order 1).
const ABS: f64 = 1e-6;
/// Relative allowance. Measured on lavapipe over the 64 800 rays: largest differences 3.4e-6 in
/// a transmittance, 3.4e-6 in the ambient factor, 3.0e-6 in a sun factor, 9.9e-8 in the sun's
/// transmittance, 3.1e-5 in an optical depth of 1.43 (2.2e-5 relative) — all on the thin dense
/// slab seen at −5° from 1 km above it, whose 29 m in the layer are the difference of two f32
/// distances near 11.5 km; at most 0.27 of this bound, elsewhere far less.
const REL: f64 = 5e-5;

/// The unit vector at `elevation` and `azimuth` (degrees), Y up.
fn direction(elevation: f64, azimuth: f64) -> DVec3 {
    let (e, a) = (elevation.to_radians(), azimuth.to_radians());
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

struct Case {
    layer: FogLayer,
    model: FogModel,
    camera_y: f64,
    ray: Ray,
    range: Interval,
    sun: DVec3,
}

/// The CPU's answers for `c`, in the order of [`GpuFogTerms`]'s fields.
fn cpu(c: &Case) -> [f64; 6] {
    let layer = FogLayer {
        albedo: DVec3::ONE,
        ..c.layer
    };
    let ambient = FogLighting {
        suns: Vec::new(),
        ambient: DVec3::ONE,
    };
    let sunlight = Sunlight {
        direction: c.sun,
        irradiance: DVec3::ONE,
    };
    let lit = FogLighting {
        suns: vec![sunlight],
        ambient: DVec3::ZERO,
    };
    let a = layer.terms(&c.ray, c.range, &ambient, c.model);
    let s = layer.terms(&c.ray, c.range, &lit, c.model);
    [
        a.transmittance,
        a.in_scatter.x,
        s.in_scatter.x,
        layer.optical_depth(&c.ray, c.range),
        layer.sun_transmittance(c.ray.origin, &sunlight, c.model),
        layer.transmittance(&c.ray, c.range),
    ]
}

fn gpu_values(t: &GpuFogTerms) -> [f64; 6] {
    [
        t.transmittance,
        t.ambient,
        t.sun,
        t.depth,
        t.sun_transmittance,
        t.segment_transmittance,
    ]
    .map(f64::from)
}

const NAMES: [&str; 6] = [
    "transmittance",
    "ambient factor",
    "sun factor",
    "optical depth",
    "sun transmittance",
    "segment transmittance",
];

fn layers() -> Vec<(&'static str, FogLayer)> {
    vec![
        (
            "homogeneous 400 m, HG 0.76",
            FogLayer {
                base: 0.0,
                top: 400.0,
                extinction: 1.2e-3,
                falloff: None,
                phase: Phase::HenyeyGreenstein { g: 0.76 },
                ..FogLayer::default()
            },
        ),
        (
            "falloff 30 m in 100 m, isotropic",
            FogLayer {
                base: 0.0,
                top: 100.0,
                extinction: 2e-2,
                falloff: Some(30.0),
                phase: Phase::Isotropic,
                ..FogLayer::default()
            },
        ),
        (
            "valley fog 1 km below, falloff 150 m, printed 0.5",
            FogLayer {
                base: -1100.0,
                top: -700.0,
                extinction: 1.2e-3,
                falloff: Some(150.0),
                phase: Phase::Printed { g: 0.5 },
                ..FogLayer::default()
            },
        ),
        (
            "thin dense slab, HG −0.3",
            FogLayer {
                base: 20.0,
                top: 22.5,
                extinction: 0.05,
                falloff: None,
                phase: Phase::HenyeyGreenstein { g: -0.3 },
                ..FogLayer::default()
            },
        ),
    ]
}

fn cases() -> Vec<(String, Case)> {
    let mut out = Vec::new();
    let elevations = [
        -90.0, -30.0, -5.0, -1.0, -0.05, -1e-3, 0.0, 1e-3, 0.05, 1.0, 2.0, 8.0, 30.0, 50.0, 90.0,
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
                                out.push((
                                    format!(
                                        "{name}, {model:?}, camera {camera}, elevation {e}°, azimuth {azimuth}°, sun {s}°, to {end}"
                                    ),
                                    Case {
                                        layer,
                                        model,
                                        camera_y: y,
                                        ray,
                                        range: Interval::new(0.05, end),
                                        sun: direction(s, 0.0),
                                    },
                                ));
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// The batch of `cases` that share one layer and model and camera height (one `GpuFog`).
fn gpu_terms(ctx: &fray_gpu::GpuContext, cases: &[&Case]) -> Vec<GpuFogTerms> {
    let first = cases[0];
    let fog = GpuFog::new(&first.layer, first.model, first.camera_y);
    let pass = FogBatch::new(ctx, &fog).unwrap();
    let rays: Vec<GpuFogRay> = cases
        .iter()
        .map(|c| {
            let d = c.ray.dir.as_vec3();
            let s = c.sun.as_vec3();
            let hi = if c.range.hi.is_finite() {
                c.range.hi as f32
            } else {
                1e30
            };
            // Camera-relative: the origin is the reference point.
            [
                [0.0, 0.0, 0.0, c.range.lo as f32],
                [d.x, d.y, d.z, hi],
                [s.x, s.y, s.z, 0.0],
            ]
        })
        .collect();
    pass.terms(ctx, &rays).unwrap()
}

fn fog_functions_match_the_cpu_reference() {
    let gpu = common::gpu("fog_functions_match_the_cpu_reference");
    let ctx = gpu.context();
    let all = cases();
    // Batches per (layer, model, camera height).
    let mut batches: Vec<Vec<usize>> = Vec::new();
    for (k, (_, c)) in all.iter().enumerate() {
        match batches.last_mut() {
            Some(b)
                if {
                    let f = &all[b[0]].1;
                    f.layer == c.layer && f.model == c.model && f.camera_y == c.camera_y
                } =>
            {
                b.push(k)
            }
            _ => batches.push(vec![k]),
        }
    }
    let mut worst: [(f64, f64, String); 6] = std::array::from_fn(|_| (0.0, 0.0, String::new()));
    let mut max_abs = [0.0f64; 6];
    let mut bad = 0usize;
    for batch in &batches {
        let cases: Vec<&Case> = batch.iter().map(|&k| &all[k].1).collect();
        let got = gpu_terms(ctx, &cases);
        for (&k, g) in batch.iter().zip(&got) {
            let (name, c) = &all[k];
            let want = cpu(c);
            let have = gpu_values(g);
            for q in 0..6 {
                let (w, h) = (want[q], have[q]);
                let excess = if w == f64::INFINITY {
                    // An unbounded depth: ≥ BIG on the GPU.
                    if h >= 1e30 { 0.0 } else { f64::INFINITY }
                } else if q == 3 && w > 80.0 {
                    // A depth past e^{−80}: only that it is large matters.
                    if h > 70.0 { 0.0 } else { f64::INFINITY }
                } else {
                    let d = (h - w).abs();
                    max_abs[q] = max_abs[q].max(d);
                    d / (ABS + REL * w.abs())
                };
                if excess > worst[q].0 {
                    worst[q] = (
                        excess,
                        (h - w).abs(),
                        format!("{name}: cpu {w:e} gpu {h:e}"),
                    );
                }
                if excess > 1.0 {
                    bad += 1;
                    if bad <= 20 {
                        eprintln!("{}: {name}: cpu {w:e} gpu {h:e}", NAMES[q]);
                    }
                }
            }
        }
    }
    for q in 0..6 {
        eprintln!(
            "{:>22}: max |Δ| {:.3e}; worst {:.3} of the bound ({})",
            NAMES[q], max_abs[q], worst[q].0, worst[q].2
        );
    }
    eprintln!("{} rays in {} batches", all.len(), batches.len());
    assert_eq!(bad, 0, "{bad} values beyond |Δ| ≤ {ABS} + {REL}·|cpu|");
}

fn main() {
    common::run(
        &[(
            "fog_functions_match_the_cpu_reference",
            fog_functions_match_the_cpu_reference,
        )],
        &[],
    );
}
