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
use crate::fog::{FOG_NAMES, FogAnswer, FogRay};
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

/// One batch: a layer by a model seen from one camera height, and its rays with their names.
struct Batch {
    layer: FogLayer,
    model: FogModel,
    camera_y: f64,
    rays: Vec<(String, FogRay)>,
}

fn batches() -> Vec<Batch> {
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
        let cpu: Vec<FogAnswer> = Cpu.fog(&b.layer, b.model, b.camera_y, &fog_rays);
        let got: Vec<FogAnswer> = gpu().fog(&b.layer, b.model, b.camera_y, &fog_rays);
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
