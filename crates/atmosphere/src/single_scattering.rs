//! Exact single scattering in the fog layer: along the view ray each point sees the sun
//! through the fog between it and the layer's top, `τ_sun(y) = ∫_y^top B(y') dy' / sin β`, not
//! the method's whole layer.
//!
//! The closed form, for the homogeneous slab and the exponential falloff alike: with `τ` the
//! view ray's optical depth from the span's start, the in-scatter integral is
//! `∫ σ e^{−τ} e^{−τ_sun} ds = ∫₀^{τ₁} e^{−E(τ)} dτ`, and the total depth `E = τ + τ_sun` is
//! *affine* in `τ` with slope `κ = 1 − d_y / sin β` — for the slab because both depths are linear
//! in `s`; for the falloff because both are linear in the density `B(y(s))` (`dτ = −h/d_y dB`,
//! `dτ_sun = h/sin β dB`). So the integral is `e^{−E_min} (1 − e^{−|κ| τ₁}) / |κ|`, taken from
//! the end where `E` is smallest so no factor exceeds 1, with `(1 − e^{−x})/x` written stably:
//! its `κ → 0` limit is `τ₁`.

use crate::fog::{FogLayer, FogLighting, FogTerms, Sunlight, mean_decay};
use fray_core::{Interval, Ray};

/// Exact single scattering over `span` (inside the layer, `extinction > 0`).
pub(crate) fn exact(fog: &FogLayer, ray: &Ray, span: Interval, light: &FogLighting) -> FogTerms {
    let depth = fog.span_depth(ray, span);
    // 1 − T, exact for small depths.
    let scattered = -(-depth).exp_m1();
    let mut in_scatter = fog.albedo * light.ambient * scattered;
    for sun in &light.suns {
        let phase = fog.phase.eval(sun.direction.dot(ray.dir));
        let through = sun_integral(fog, ray, span, depth, sun);
        in_scatter += fog.albedo * sun.irradiance * (phase * through);
    }
    FogTerms {
        transmittance: (-depth).exp(),
        in_scatter,
    }
}

/// `∫ σ_t e^{−τ_view} e^{−τ_sun} ds` over `span`, whose view depth is `depth`: the closed form
/// of the module comment.
fn sun_integral(fog: &FogLayer, ray: &Ray, span: Interval, depth: f64, sun: &Sunlight) -> f64 {
    let sin_b = sun.direction.y;
    if sin_b.is_nan() || sin_b <= 0.0 {
        // A sun at or below the horizon lights no point under the top through the slab.
        return 0.0;
    }
    let slope = 1.0 - ray.dir.y / sin_b;
    let smallest = if slope >= 0.0 {
        fog.sun_depth(ray.at(span.lo).y, sin_b)
    } else {
        // The far end (finite: a ray climbing faster than the sun leaves the layer).
        depth + fog.sun_depth(ray.at(span.hi).y, sin_b)
    };
    let spread = if depth == f64::INFINITY {
        // A horizontal ray in the layer for ever: slope 1, ∫₀^∞ e^{−τ} dτ.
        1.0 / slope.abs()
    } else {
        depth * mean_decay(slope.abs() * depth)
    };
    (-smallest).exp() * spread
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn the_slope_to_zero_limit_is_continuous() {
        // A ray climbing at exactly the sun's elevation: κ = 0; and just either side of it.
        for falloff in [None, Some(40.0)] {
            let fog = FogLayer {
                extinction: 0.01,
                falloff,
                ..FogLayer::default()
            };
            let sun = Sunlight {
                direction: DVec3::new(0.8, 0.6, 0.0),
                irradiance: DVec3::ONE,
            };
            let at = |dy: f64| {
                let d = DVec3::new((1.0 - dy * dy).sqrt(), dy, 0.0);
                let r = Ray::new(DVec3::new(0.0, 10.0, 0.0), d).unwrap();
                let span = fog.span(&r, Interval::new(0.0, f64::INFINITY)).unwrap();
                sun_integral(&fog, &r, span, fog.span_depth(&r, span), &sun)
            };
            let centre = at(0.6);
            assert!(centre.is_finite() && centre > 0.0);
            for delta in [1e-12, 1e-9, 1e-6] {
                for v in [at(0.6 - delta), at(0.6 + delta)] {
                    assert!((v / centre - 1.0).abs() < 1e-5, "{v} vs {centre}");
                }
            }
        }
    }
}
