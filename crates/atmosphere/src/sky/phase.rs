//! The sky's phase functions, each normalised to 1 over the sphere (per steradian):
//! Rayleigh for molecules, Cornette–Shanks for aerosols (and Henyey–Greenstein for comparison).
//!
//! `mu` is the cosine of the angle between the view direction (from the eye outward) and the
//! direction toward the sun, so `mu = 1` looks straight at the sun: with `g > 0` the aerosols
//! scatter forward and that direction is bright.

use std::f64::consts::PI;

/// Rayleigh: `3 / (16π) · (1 + μ²)`.
pub fn rayleigh(mu: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

/// Cornette–Shanks (1992), the sky's Mie phase function (as in Bruneton 2017):
/// `3 / (8π) · (1 − g²) (1 + μ²) / ((2 + g²) (1 + g² − 2gμ)^{3/2})`. It tends to Rayleigh
/// as `g → 0` and, unlike Henyey–Greenstein, has Rayleigh's `1 + μ²` polarisation factor.
pub fn cornette_shanks(mu: f64, g: f64) -> f64 {
    let g2 = g * g;
    let denom = (1.0 + g2 - 2.0 * g * mu).max(0.0);
    3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + mu * mu) / ((2.0 + g2) * denom * denom.sqrt())
}

/// Henyey–Greenstein: `(1 − g²) / (4π (1 + g² − 2gμ)^{3/2})` (not used by the sky; for
/// comparison with the fog layer's phase function).
pub fn henyey_greenstein(mu: f64, g: f64) -> f64 {
    let g2 = g * g;
    let denom = (1.0 + g2 - 2.0 * g * mu).max(0.0);
    (1.0 - g2) / (4.0 * PI * denom * denom.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::integrate_rgb as integrate;
    use glam::DVec3;

    /// `∫ p dΩ = 2π ∫₋₁¹ p(μ) dμ` by adaptive Gauss–Kronrod.
    fn sphere_integral(p: impl Fn(f64) -> f64) -> f64 {
        let mut f = |mu: f64| DVec3::splat(p(mu));
        2.0 * PI * integrate(&mut f, &[-1.0, 0.0, 0.9, 1.0], 1e-14, DVec3::ZERO, 8, 4000).x
    }

    #[test]
    fn normalised_over_the_sphere() {
        assert!((sphere_integral(rayleigh) - 1.0).abs() < 1e-12);
        for g in [-0.9, -0.5, 0.0, 0.3, 0.76, 0.8, 0.95] {
            let cs = sphere_integral(|mu| cornette_shanks(mu, g));
            let hg = sphere_integral(|mu| henyey_greenstein(mu, g));
            assert!((cs - 1.0).abs() < 1e-9, "Cornette–Shanks g = {g}: {cs}");
            assert!((hg - 1.0).abs() < 1e-9, "Henyey–Greenstein g = {g}: {hg}");
        }
    }

    #[test]
    fn forward_is_bright_for_positive_g() {
        assert!(cornette_shanks(1.0, 0.8) > 100.0 * cornette_shanks(-1.0, 0.8));
        assert!((cornette_shanks(0.3, 0.0) - rayleigh(0.3)).abs() < 1e-15);
    }
}
