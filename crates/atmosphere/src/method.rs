//! The method's fog terms (Klassen; docs/methods.md §5), written radiometrically. For an object at the
//! layer's bottom seen from height `h` at elevation `α`, the sun at elevation `β`:
//! object light (14) `I = A e^{−B h cosec α} + Ic e^{−B h cosec α − B H cosec β} R`, fog light
//! (15) `It = Ic e^{−B H cosec β} S (1 − e^{−B h cosec α}) / B`. Read radiometrically:
//! `h cosec α` is the view ray's path in the fog (here its optical depth, so that the falloff
//! layer has a method form too), (15) is multiplied by the scattering coefficient `σ_s = ω B`
//! (as printed it has units of length), `S` is the phase function, and every point of the ray
//! sees the sun through the whole layer, `e^{−B H cosec β}`. The object term (14) is the
//! integrator's: the surface lit by the sun through [`crate::FogLayer::sun_transmittance`] with
//! [`crate::FogModel::Method`], attenuated by the view transmittance.

use crate::fog::{FogLayer, FogLighting, FogTerms};
use fray_core::{Interval, Ray};

/// (15) and the view transmittance over `span` (inside the layer).
pub(crate) fn terms(fog: &FogLayer, ray: &Ray, span: Interval, light: &FogLighting) -> FogTerms {
    let depth = fog.span_depth(ray, span);
    let scattered = -(-depth).exp_m1();
    let mut in_scatter = fog.albedo * light.ambient * scattered;
    for sun in &light.suns {
        // The whole layer, from its bottom: e^{−B H cosec β}.
        let through = (-fog.sun_depth(fog.base, sun.direction.y)).exp();
        let phase = fog.phase.eval(sun.direction.dot(ray.dir));
        in_scatter += fog.albedo * sun.irradiance * (phase * through * scattered);
    }
    FogTerms {
        transmittance: (-depth).exp(),
        in_scatter,
    }
}
