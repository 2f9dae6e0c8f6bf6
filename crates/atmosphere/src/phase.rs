//! Phase functions: how much of the light a fog particle scatters goes into each direction.

use std::f64::consts::PI;

/// An angular scattering function `p(cos θ)`, θ the angle between the light's direction of
/// travel and the scattered direction (θ = 0: straight on). Normalised forms integrate to 1
/// over the sphere, so single scattering is `σ_s · p · E` in radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// `1 / 4π`.
    Isotropic,
    /// The normalised Henyey–Greenstein function
    /// `(1 − g²) / (4π (1 + g² − 2 g cos θ)^{3/2})`, asymmetry `g ∈ (−1, 1)` (the mean of cos θ;
    /// `g > 0` scatters forward, so fog is bright toward the sun).
    HenyeyGreenstein { g: f64 },
    /// The function as the source prints it, eq. (16): `(1 − g)² / (1 + g² − 2 g cos θ)^{3/2}`.
    /// It is not normalised: over the sphere it integrates to `4π (1 − g) / (1 + g)` (tested), so
    /// fog rendered with it is that many times brighter than with
    /// [`Phase::HenyeyGreenstein`]. Kept for comparison with the source.
    Printed { g: f64 },
}

impl Default for Phase {
    /// Henyey–Greenstein with `g = 0.76`, a fog/haze value (Mie scattering by droplets is
    /// strongly forward).
    fn default() -> Self {
        Phase::HenyeyGreenstein { g: 0.76 }
    }
}

impl Phase {
    /// `p(cos θ)` in 1/sr (the printed form: as printed).
    #[inline]
    pub fn eval(self, cos_theta: f64) -> f64 {
        let c = cos_theta.clamp(-1.0, 1.0);
        match self {
            Phase::Isotropic => 1.0 / (4.0 * PI),
            Phase::HenyeyGreenstein { g } => (1.0 - g * g) / (4.0 * PI * hg_denominator(g, c)),
            Phase::Printed { g } => (1.0 - g) * (1.0 - g) / hg_denominator(g, c),
        }
    }

    /// The asymmetry parameter (0 for isotropic).
    pub fn g(self) -> f64 {
        match self {
            Phase::Isotropic => 0.0,
            Phase::HenyeyGreenstein { g } | Phase::Printed { g } => g,
        }
    }

    /// The integral over the sphere in closed form: 1, or `4π (1 − g)/(1 + g)` for the printed
    /// form.
    pub fn sphere_integral(self) -> f64 {
        match self {
            Phase::Isotropic | Phase::HenyeyGreenstein { .. } => 1.0,
            Phase::Printed { g } => 4.0 * PI * (1.0 - g) / (1.0 + g),
        }
    }
}

/// `(1 + g² − 2 g c)^{3/2}`; `1 + g² − 2gc ≥ (1 − |g|)² > 0` for `|g| < 1`.
#[inline]
fn hg_denominator(g: f64, c: f64) -> f64 {
    let d = (1.0 + g * g - 2.0 * g * c).max(f64::MIN_POSITIVE);
    d * d.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::integrate;

    /// `∫ p dΩ = 2π ∫₋₁¹ p(μ) dμ`, by adaptive Gauss–Kronrod (not the closed form).
    fn over_sphere(p: Phase) -> f64 {
        2.0 * PI * integrate(|mu| p.eval(mu), -1.0, 1.0, 1e-13)
    }

    #[test]
    fn henyey_greenstein_is_normalised_and_the_printed_form_is_not() {
        for g in [-0.9, -0.5, 0.0, 0.3, 0.76, 0.9, 0.99] {
            let hg = Phase::HenyeyGreenstein { g };
            assert!((over_sphere(hg) - 1.0).abs() < 1e-10, "g = {g}");
            let printed = Phase::Printed { g };
            let expected = 4.0 * PI * (1.0 - g) / (1.0 + g);
            let got = over_sphere(printed);
            assert!(
                (got / expected - 1.0).abs() < 1e-10,
                "g = {g}: {got} vs {expected}"
            );
            assert_eq!(printed.sphere_integral(), expected);
        }
        assert!((over_sphere(Phase::Isotropic) - 1.0).abs() < 1e-13);
    }

    #[test]
    fn henyey_greenstein_has_mean_cosine_g() {
        for g in [-0.6, 0.2, 0.76] {
            let p = Phase::HenyeyGreenstein { g };
            let mean = 2.0 * PI * integrate(|mu| mu * p.eval(mu), -1.0, 1.0, 1e-13);
            assert!((mean - g).abs() < 1e-10, "g = {g}: {mean}");
        }
    }

    #[test]
    fn finite_at_the_extremes() {
        for g in [-0.999_999, 0.999_999] {
            for c in [-1.0, 1.0, 2.0, -2.0] {
                assert!(Phase::HenyeyGreenstein { g }.eval(c).is_finite());
                assert!(Phase::Printed { g }.eval(c).is_finite());
            }
        }
    }
}
