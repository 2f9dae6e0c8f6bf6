//! Whitted's optics: mirror reflection `R = 2(L·N)N − L`, refraction by Snell's law with total
//! internal reflection past the critical angle, and the dielectric Fresnel reflectance — plain
//! functions of unit vectors, shared by the integrator and its tests.

use glam::DVec3;

/// The mirror image of the unit direction `d` (travelling toward the surface) about the unit
/// normal `n`: `d − 2(d·n)n` — Whitted's `R = 2(L·N)N − L` with `L = −d`.
#[inline]
pub fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - n * (2.0 * d.dot(n))
}

/// The refracted direction of the unit direction `d` at a surface with unit normal `n` on the
/// side `d` arrives from (`d · n ≤ 0`), `eta = n_from / n_to`; `None` past the critical angle
/// (total internal reflection: `η² (1 − cos²θᵢ) > 1`). Snell: `sin θₜ = η sin θᵢ`, the result
/// unit length and in the plane of `d` and `n`.
#[inline]
pub fn refract(d: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let t = d * eta + n * (eta * cos_i - cos_t);
    // Renormalised: rounding in `d` and `n` would otherwise build up over many interfaces.
    t.try_normalize()
}

/// The unpolarised Fresnel reflectance of a dielectric interface for light arriving at
/// `cos_i = |cos θᵢ|` from the medium of index `n_from` into `n_to`: the mean of the squared
/// s- and p-amplitude ratios; 1 past the critical angle. At normal incidence
/// `((n_from − n_to)/(n_from + n_to))²`.
#[inline]
pub fn fresnel_dielectric(cos_i: f64, n_from: f64, n_to: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = n_from / n_to;
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (n_from * cos_i - n_to * cos_t) / (n_from * cos_i + n_to * cos_t);
    let rp = (n_to * cos_i - n_from * cos_t) / (n_to * cos_i + n_from * cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z).normalize()
    }

    #[test]
    fn reflection_mirrors_about_the_normal() {
        let d = unit(1.0, -1.0, 0.0);
        let r = reflect(d, DVec3::Y);
        assert!((r - unit(1.0, 1.0, 0.0)).length() < 1e-15);
        // Whitted's form: R = 2(L·N)N − L with L = −d.
        let l = -d;
        assert!((r - (DVec3::Y * (2.0 * l.dot(DVec3::Y)) - l)).length() < 1e-15);
    }

    /// Snell's law against the angles themselves: `sin θₜ = η sin θᵢ` to 1e-14 over incidence
    /// angles 0…89°, and the refracted ray on the far side of the surface.
    #[test]
    fn refraction_obeys_snell() {
        for eta in [1.0 / 1.5, 1.0 / 1.33, 1.0, 1.2] {
            for deg in 0..90 {
                let theta = f64::from(deg).to_radians();
                let d = DVec3::new(theta.sin(), -theta.cos(), 0.0);
                let Some(t) = refract(d, DVec3::Y, eta) else {
                    assert!(eta * theta.sin() > 1.0, "TIR only past the critical angle");
                    continue;
                };
                assert!((t.length() - 1.0).abs() < 1e-15);
                assert!(t.y < 0.0 || eta * theta.sin() >= 1.0 - 1e-12);
                let sin_t = t.x;
                assert!((sin_t - eta * theta.sin()).abs() < 1e-14, "{eta} {deg}");
                assert!(t.z.abs() < 1e-15);
            }
        }
    }

    /// Total internal reflection occurs exactly past the critical angle `asin(1/n)`: a hair
    /// below it refracts (grazing), a hair above it does not.
    #[test]
    fn total_internal_reflection_starts_at_the_critical_angle() {
        for n in [1.33f64, 1.5, 2.42] {
            let critical = (1.0 / n).asin();
            for (theta, refracts) in [(critical - 1e-9, true), (critical + 1e-9, false)] {
                let d = DVec3::new(theta.sin(), theta.cos(), 0.0);
                // From inside (index n) to outside (1): the normal faces the incoming ray.
                let out = refract(d, -DVec3::Y, n);
                assert_eq!(out.is_some(), refracts, "n = {n}, θ = {theta}");
                assert_eq!(fresnel_dielectric(theta.cos(), n, 1.0) == 1.0, !refracts);
            }
        }
    }

    /// `((n − 1)/(n + 1))²` at normal incidence, both ways through the interface.
    #[test]
    fn fresnel_at_normal_incidence() {
        for n in [1.0f64, 1.33, 1.5, 2.42] {
            let expected = ((n - 1.0) / (n + 1.0)).powi(2);
            assert!((fresnel_dielectric(1.0, 1.0, n) - expected).abs() < 1e-15);
            assert!((fresnel_dielectric(1.0, n, 1.0) - expected).abs() < 1e-15);
        }
    }

    /// Against Fresnel's equations written with the angles (an independent form):
    /// `rs = −sin(θᵢ−θₜ)/sin(θᵢ+θₜ)`, `rp = tan(θᵢ−θₜ)/tan(θᵢ+θₜ)`, to 1e-12; 1 at grazing.
    #[test]
    fn fresnel_matches_the_angle_form() {
        let n = 1.5;
        for deg in 1..90 {
            let ti = f64::from(deg).to_radians();
            let tt = (ti.sin() / n).asin();
            let rs = -(ti - tt).sin() / (ti + tt).sin();
            let rp = (ti - tt).tan() / (ti + tt).tan();
            let expected = 0.5 * (rs * rs + rp * rp);
            let got = fresnel_dielectric(ti.cos(), 1.0, n);
            assert!(
                (got - expected).abs() < 1e-12,
                "{deg}°: {got} vs {expected}"
            );
        }
        assert!((fresnel_dielectric(0.0, 1.0, n) - 1.0).abs() < 1e-15);
    }
}
