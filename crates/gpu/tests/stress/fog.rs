//! Fog under stress on the GPU (`FogBatch`): layers `10^[−1, 4]` m thick, homogeneous or
//! falling off, extinction `10^[−6, 1]` per thickness; rays from inside, above, below, from `10⁴`
//! away, horizontal and nearly so, over bounded and unbounded ranges. Per ray: `T ∈ [0, 1]`,
//! `τ ≥ 0` and a number; against `FogLayer`'s f64 closed form, `T` within `10⁻⁶ + 5·10⁻⁵ T` (the
//! rays suite's) and `τ` within `10⁻⁶ + 5·10⁻⁵ τ`, each plus the f32 rounding of the crossing's
//! length (`c = B · 4 · 2⁻²³ |Δy| / |d_y|` of `τ`, `T c` of `T`; `Δy` the layer's bounds relative
//! to the camera — what a camera far above or a nearly horizontal ray costs in f32 —, and with a
//! falloff `τ · 4 · 2⁻²³ |Δy| / H`; and `B 2⁻²³ (|lo| + |hi|)` for the range's ends).

use crate::{cases, seed};
use fray_atmosphere::gpu_layout::GpuFog;
use fray_atmosphere::{FogLayer, FogModel, Phase};
use fray_core::{Interval, Ray};
use fray_gpu::GpuContext;
use fray_gpu::testing::{FogBatch, GpuFogRay};
use fray_test_support::Rng;
use glam::DVec3;

pub const FOG_RAYS: usize = 16384;

pub fn fogs(ctx: &GpuContext) -> (u64, f64) {
    let mut total = 0u64;
    let mut worst = 0.0f64;
    for case in 0..cases(40) {
        let mut rng = Rng(seed(0xf0, case));
        let thickness = rng.log_uniform(-1.0, 4.0);
        let base = rng.range(-1.0, 1.0) * thickness;
        let layer = FogLayer {
            base,
            top: base + thickness,
            extinction: rng.log_uniform(-6.0, 1.0) / thickness,
            albedo: DVec3::splat(0.9),
            falloff: (rng.unit() < 0.5).then(|| thickness * rng.log_uniform(-1.0, 1.0)),
            phase: Phase::Isotropic,
        };
        // The camera: inside, above, below the layer, or 10⁴ thicknesses away.
        let eye_y = match case % 4 {
            0 => base + thickness * rng.unit(),
            1 => base + thickness * rng.range(1.0, 3.0),
            2 => base - thickness * rng.range(0.0, 2.0),
            _ => base + thickness * rng.range(-1.0, 2.0) * 1e4,
        };
        let eye = DVec3::new(0.0, eye_y, 0.0);
        let block = GpuFog::new(&layer, FogModel::Exact, eye_y);
        let batch = FogBatch::new(ctx, &block).unwrap_or_else(|e| panic!("{e}"));
        let rays: Vec<(DVec3, Interval)> = (0..FOG_RAYS)
            .map(|i| {
                let d = match i % 4 {
                    0 => {
                        let a = rng.range(0.0, std::f64::consts::TAU);
                        DVec3::new(a.cos(), 0.0, a.sin())
                    }
                    1 => {
                        let a = rng.range(0.0, std::f64::consts::TAU);
                        let e =
                            rng.log_uniform(-7.0, -1.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                        DVec3::new(a.cos(), e, a.sin()).normalize()
                    }
                    2 => DVec3::Y * if rng.unit() < 0.5 { -1.0 } else { 1.0 },
                    _ => rng.direction(),
                };
                let lo = if rng.unit() < 0.5 {
                    0.0
                } else {
                    thickness * rng.log_uniform(-3.0, 1.0)
                };
                let hi = if rng.unit() < 0.3 {
                    f64::INFINITY
                } else {
                    lo + thickness * rng.log_uniform(-3.0, 3.0)
                };
                (d, Interval::new(lo, hi))
            })
            .collect();
        let queries: Vec<GpuFogRay> = rays
            .iter()
            .map(|(d, r)| {
                let d = d.as_vec3();
                [
                    [0.0, 0.0, 0.0, r.lo as f32],
                    [d.x, d.y, d.z, r.hi.min(1e30) as f32],
                    [0.0, 1.0, 0.0, 0.0],
                ]
            })
            .collect();
        let terms = batch.terms(ctx, &queries).unwrap_or_else(|e| panic!("{e}"));
        for ((d, range), g) in rays.iter().zip(&terms) {
            total += 1;
            let ray = Ray::new(eye, *d).expect("a unit direction");
            let fail = |what: String| {
                panic!(
                    "fog case {case} ({layer:?}, eye y {eye_y}): {what} for dir {d:?} over {range:?}"
                )
            };
            let (t, tau) = (f64::from(g.transmittance), f64::from(g.depth));
            if !((0.0..=1.0).contains(&t) && tau >= 0.0 && !tau.is_nan()) {
                fail(format!("T = {t}, τ = {tau}"));
            }
            let depth = layer.optical_depth(&ray, *range);
            // The crossing's ends: heights relative to the camera rounded to f32 (`2⁻²³` of the
            // larger of the layer's bounds' and the eye's), over the sine.
            let heights = (layer.base - eye_y).abs().max((layer.top - eye_y).abs());
            let e = 4.0 * f64::from(f32::EPSILON) * heights;
            // (A level ray crosses nothing; with a falloff, the rounded height also moves the
            // density by `e / H` relative.)
            let crossing = if d.y == 0.0 {
                0.0
            } else {
                (layer.extinction * e / d.y.abs()).min(1e300)
            } + layer.falloff.map_or(0.0, |h| depth.min(1e300) * e / h)
                // The range's ends rounded to f32.
                + layer.extinction
                    * f64::from(f32::EPSILON)
                    * (range.lo.abs() + if range.hi.is_finite() { range.hi } else { 0.0 });
            let want_t = (-depth).exp();
            let off_t = (t - want_t).abs();
            let bound_t = 1e-6 + 5e-5 * want_t + want_t * crossing;
            worst = worst.max(off_t / bound_t);
            if off_t > bound_t {
                fail(format!(
                    "T = {t} against the f64 {want_t} (bound {bound_t:e})"
                ));
            }
            if depth.is_finite() && tau < 1e29 {
                let bound = 1e-6 + 5e-5 * depth + crossing;
                if (tau - depth).abs() > bound {
                    fail(format!(
                        "τ = {tau} against the f64 {depth} (bound {bound:e})"
                    ));
                }
            } else if depth.is_infinite() != (tau >= 1e29 || tau.is_infinite()) {
                fail(format!("τ = {tau} against the f64 {depth}"));
            }
        }
    }
    (total, worst)
}
