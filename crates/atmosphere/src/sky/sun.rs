//! The sun: a direction, its irradiance above the atmosphere and its disc.

use crate::AtmosphereError;
use glam::DVec3;
use std::f64::consts::PI;

/// The sun as the sky sees it.
///
/// The disc is uniform (no limb darkening) with radiance `L = E / Ω`, `Ω = 2π(1 − cos α)` its
/// solid angle, so that `∫_disc L dΩ = E` (the cosine-weighted integral over a surface facing
/// the sun is `E (1 + cos α) / 2`, `1 − 5.5·10⁻⁶ E` for the real sun). At the eye the disc is
/// seen through the view ray's transmittance, and below the planet's horizon it is hidden.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkySun {
    /// Unit vector toward the sun (world space, Y up); normalised by [`SkySun::validate`]'s
    /// callers ([`super::Sky::new`]), so any non-zero length is accepted.
    pub direction: DVec3,
    /// Irradiance at the top of the atmosphere on a surface facing the sun (W/m², RGB).
    pub irradiance: DVec3,
    /// Angular radius α of the disc (radians).
    pub angular_radius: f64,
}

impl SkySun {
    /// The sun's mean angular radius seen from Earth (0.2679°).
    pub const ANGULAR_RADIUS: f64 = 0.004_675;

    /// A sun toward `direction` of `irradiance`, with the default angular radius.
    pub const fn new(direction: DVec3, irradiance: DVec3) -> Self {
        Self {
            direction,
            irradiance,
            angular_radius: Self::ANGULAR_RADIUS,
        }
    }

    /// A sun at `elevation` above the horizontal plane and `azimuth` (radians) measured from
    /// `+X` toward `+Z`: `direction = (cos e cos a, sin e, cos e sin a)`.
    pub fn from_angles(elevation: f64, azimuth: f64, irradiance: DVec3) -> Self {
        let (se, ce) = elevation.sin_cos();
        let (sa, ca) = azimuth.sin_cos();
        Self::new(DVec3::new(ce * ca, se, ce * sa), irradiance)
    }

    /// Checks the fields: a finite non-zero direction, finite non-negative irradiance, an
    /// angular radius in `(0, π/2)`. The error names the field, e.g. `sky.sun.irradiance.g`.
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        for (field, value) in [
            ("sky.sun.direction.x", self.direction.x),
            ("sky.sun.direction.y", self.direction.y),
            ("sky.sun.direction.z", self.direction.z),
        ] {
            AtmosphereError::check(field, value, true, "must be finite")?;
        }
        let length = self.direction.length();
        AtmosphereError::check(
            "sky.sun.direction",
            length,
            length > 1e-150,
            "must not be zero",
        )?;
        for (field, value) in [
            ("sky.sun.irradiance.r", self.irradiance.x),
            ("sky.sun.irradiance.g", self.irradiance.y),
            ("sky.sun.irradiance.b", self.irradiance.z),
        ] {
            AtmosphereError::check(field, value, value >= 0.0, "must not be negative")?;
        }
        AtmosphereError::check(
            "sky.sun.angular_radius",
            self.angular_radius,
            self.angular_radius > 0.0 && self.angular_radius < 0.5 * PI,
            "must lie in (0, π/2)",
        )
    }

    /// The disc's solid angle `2π(1 − cos α) = 4π sin²(α/2)` (the second form keeps its digits
    /// for small α).
    pub fn solid_angle(&self) -> f64 {
        let s = (0.5 * self.angular_radius).sin();
        4.0 * PI * s * s
    }

    /// The disc's radiance above the atmosphere, `E / Ω` (W/(m² sr)).
    pub fn disc_radiance(&self) -> DVec3 {
        self.irradiance / self.solid_angle()
    }

    /// The unit direction toward the sun (`+Y` for a zero or non-finite direction, which
    /// [`SkySun::validate`] refuses).
    pub fn unit_direction(&self) -> DVec3 {
        self.direction.try_normalize().unwrap_or(DVec3::Y)
    }

    /// Whether the unit direction `dir` points into the disc.
    pub fn in_disc(&self, dir: DVec3) -> bool {
        dir.dot(self.unit_direction()) >= self.angular_radius.cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angle_and_validation() {
        let sun = SkySun::new(DVec3::new(0.0, 2.0, 0.0), DVec3::ONE);
        let omega = 2.0 * PI * (1.0 - sun.angular_radius.cos());
        // The naive form loses ~5 digits to cancellation.
        assert!((sun.solid_angle() - omega).abs() < 1e-9 * omega);
        assert_eq!(sun.validate(), Ok(()));
        assert_eq!(sun.unit_direction(), DVec3::Y);
        let bad = SkySun::new(DVec3::ZERO, DVec3::ONE);
        assert!(matches!(
            bad.validate(),
            Err(AtmosphereError::Invalid {
                field: "sky.sun.direction",
                ..
            })
        ));
        let bad = SkySun {
            angular_radius: 0.0,
            ..sun
        };
        assert!(bad.validate().is_err());
        let bad = SkySun::new(DVec3::Y, DVec3::new(1.0, -1.0, 1.0));
        assert!(matches!(
            bad.validate(),
            Err(AtmosphereError::Invalid {
                field: "sky.sun.irradiance.g",
                ..
            })
        ));
    }
}
