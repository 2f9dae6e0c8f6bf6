//! The fog's numerical reference, independent of the closed forms: single scattering as a
//! nested adaptive Gauss–Kronrod integral in f64 — the view ray's optical depth, the sun ray's
//! optical depth from each point to where it leaves the layer, and the in-scatter integral
//! itself, each by quadrature of [`FogLayer::density`] — for any layer, the falloff included.

use crate::fog::{FogLayer, FogLighting, FogTerms};
use crate::quadrature::integrate;
use fray_core::{Interval, Ray};
use glam::DVec3;

/// Relative tolerance of every integral of the reference.
pub const REFERENCE_TOLERANCE: f64 = 1e-11;

/// Exact single scattering of `light` by `fog` over `range` of `ray`, and its transmittance,
/// by quadrature. Slow (thousands of density evaluations): for tests and benchmarks.
pub fn single_scattering(
    fog: &FogLayer,
    ray: &Ray,
    range: Interval,
    light: &FogLighting,
) -> FogTerms {
    let pieces = in_layer_pieces(fog, ray, range);
    if pieces.is_empty() || fog.extinction == 0.0 {
        return FogTerms::CLEAR;
    }
    let tol = REFERENCE_TOLERANCE;
    // The optical depth from the range's start to `s` (pieces in order; 0 outside the layer).
    let depth_to = |s: f64| -> f64 {
        pieces
            .iter()
            .filter(|p| p.0 < s)
            .map(|&(a, b)| integrate(|u| fog.density(ray.at(u).y), a, b.min(s), tol))
            .sum()
    };
    let total_depth = depth_to(f64::INFINITY);
    let mut in_scatter = DVec3::ZERO;
    // Ambient: ∫ σ T ds (should be 1 − T; integrated anyway).
    let ambient: f64 = pieces
        .iter()
        .map(|&(a, b)| {
            integrate(
                |s| fog.density(ray.at(s).y) * (-depth_to(s)).exp(),
                a,
                b,
                tol,
            )
        })
        .sum();
    in_scatter += fog.albedo * light.ambient * ambient;
    for sun in &light.suns {
        let sin_b = sun.direction.y;
        let through: f64 = pieces
            .iter()
            .map(|&(a, b)| {
                integrate(
                    |s| {
                        let p = ray.at(s);
                        fog.density(p.y)
                            * (-depth_to(s)).exp()
                            * (-sun_depth(fog, p.y, sin_b)).exp()
                    },
                    a,
                    b,
                    tol,
                )
            })
            .sum();
        let phase = fog.phase.eval(sun.direction.dot(ray.dir));
        in_scatter += fog.albedo * sun.irradiance * (phase * through);
    }
    FogTerms {
        transmittance: (-total_depth).exp(),
        in_scatter,
    }
}

/// The sun ray's optical depth from height `y` until it leaves the layer, by quadrature along
/// it (∞ if it never leaves: a sun at or below the horizon).
fn sun_depth(fog: &FogLayer, y: f64, sin_b: f64) -> f64 {
    if y >= fog.top {
        return 0.0;
    }
    if sin_b.is_nan() || sin_b <= 0.0 {
        return f64::INFINITY;
    }
    let length = (fog.top - y) / sin_b;
    integrate(
        |v| fog.density(y + v * sin_b),
        0.0,
        length,
        REFERENCE_TOLERANCE,
    )
}

/// The parts of `range` inside the layer as finite `(a, b)` pieces: the range split where the
/// ray crosses `y = base` and `y = top`, keeping the pieces whose midpoint is inside; an
/// unbounded piece (a horizontal ray in the layer) is cut where its transmittance falls below
/// `e^{−800}`.
fn in_layer_pieces(fog: &FogLayer, ray: &Ray, range: Interval) -> Vec<(f64, f64)> {
    let mut cuts = vec![range.lo];
    if ray.dir.y != 0.0 {
        for plane in [fog.base, fog.top] {
            let t = (plane - ray.origin.y) / ray.dir.y;
            if t > range.lo && t < range.hi {
                cuts.push(t);
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.push(range.hi);
    let mut pieces = Vec::new();
    for w in cuts.windows(2) {
        let (a, mut b) = (w[0], w[1]);
        if a >= b {
            continue;
        }
        if b == f64::INFINITY {
            if ray.dir.y != 0.0 || fog.extinction == 0.0 {
                // Past the last crossing a sloped ray is outside the layer.
                let inside = (fog.base..=fog.top).contains(&ray.at(a + 1.0).y);
                if !inside {
                    continue;
                }
            }
            // Horizontal: the density is the same all along.
            let density = fog.density(ray.at(a).y);
            if density == 0.0 {
                continue;
            }
            b = a + 800.0 / density;
        }
        let mid = ray.at(0.5 * (a + b)).y;
        if (fog.base..=fog.top).contains(&mid) {
            pieces.push((a, b));
        }
    }
    pieces
}
