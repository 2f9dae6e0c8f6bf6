//! The atmosphere's constituents: a spherical planet, a Rayleigh and a Mie layer falling off
//! exponentially with altitude, and an ozone layer with a tent profile (Bruneton 2017).

use crate::AtmosphereError;
use glam::DVec3;

/// A planet and its atmosphere, in metres and per metre (RGB where it varies with wavelength).
///
/// Altitude `h` is measured from the planet's surface (radius [`SkyModel::ground_radius`]); the
/// atmosphere is the shell up to [`SkyModel::top_radius`]. The densities are relative (1 at their
/// peak) and scale the coefficients:
///
/// - Rayleigh: `ρ_R(h) = exp(−h / H_R)`, scattering `σ_R ρ_R` (no absorption);
/// - Mie: `ρ_M(h) = exp(−h / H_M)`, scattering `σ_M ρ_M`, absorption `σ_Ma ρ_M` (grey);
/// - ozone: `ρ_O(h) = max(0, 1 − |h − c| / (w / 2))` (a tent of full width `w` centred at `c`),
///   absorption `σ_O ρ_O`, no scattering.
///
/// Extinction is `σ_t(h) = σ_R ρ_R + (σ_M + σ_Ma) ρ_M + σ_O ρ_O`. Altitudes below the ground
/// count as the ground.
///
/// [`SkyModel::earth`] is Earth's atmosphere as in Bruneton, "A Qualitative and Quantitative
/// Evaluation of 8 Clear Sky Models" (IEEE TVCG 2017, the `precomputed_atmospheric_scattering`
/// demo's constants) and Hillaire, "A Scalable and Production Ready Sky and Atmosphere Rendering
/// Technique" (EGSR 2020), which uses the same values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyModel {
    /// Radius of the planet's surface (m).
    pub ground_radius: f64,
    /// Radius of the top of the atmosphere (m); nothing scatters or absorbs above it.
    pub top_radius: f64,
    /// The scene `y` of the planet's surface under the observer (m).
    pub ground_elevation: f64,
    /// Rayleigh scattering coefficient at the ground (1/m, RGB).
    pub rayleigh_scattering: DVec3,
    /// Rayleigh scale height `H_R` (m).
    pub rayleigh_scale_height: f64,
    /// Mie scattering coefficient at the ground (1/m, grey).
    pub mie_scattering: f64,
    /// Mie absorption coefficient at the ground (1/m, grey).
    pub mie_absorption: f64,
    /// Mie scale height `H_M` (m).
    pub mie_scale_height: f64,
    /// Mie asymmetry `g` of the Cornette–Shanks phase function, `|g| < 1`.
    pub mie_g: f64,
    /// Ozone absorption coefficient at the layer's peak (1/m, RGB).
    pub ozone_absorption: DVec3,
    /// Altitude of the ozone layer's peak (m).
    pub ozone_centre: f64,
    /// Full width of the ozone tent (m): the density is zero outside `centre ± width / 2`.
    pub ozone_width: f64,
}

impl Default for SkyModel {
    fn default() -> Self {
        Self::earth()
    }
}

/// The highest altitude an observer is placed at (m); higher eyes are clamped to it so that the
/// planet-centred arithmetic stays finite (from there the atmosphere subtends under 1°).
pub const MAX_OBSERVER_ALTITUDE: f64 = 1e9;

impl SkyModel {
    /// Earth (Bruneton 2017; Hillaire 2020): R = 6360 km, top at 100 km altitude, Rayleigh
    /// `(5.802, 13.558, 33.1)·10⁻⁶ /m` with H_R = 8 km, Mie scattering `3.996·10⁻⁶ /m` and
    /// absorption `0.444·10⁻⁶ /m` with H_M = 1.2 km and g = 0.8, ozone
    /// `(0.650, 1.881, 0.085)·10⁻⁶ /m` in a tent from 10 to 40 km peaking at 25 km.
    pub const fn earth() -> Self {
        Self {
            ground_radius: 6_360_000.0,
            top_radius: 6_460_000.0,
            ground_elevation: 0.0,
            rayleigh_scattering: DVec3::new(5.802e-6, 13.558e-6, 33.1e-6),
            rayleigh_scale_height: 8_000.0,
            mie_scattering: 3.996e-6,
            mie_absorption: 0.444e-6,
            mie_scale_height: 1_200.0,
            mie_g: 0.8,
            ozone_absorption: DVec3::new(0.650e-6, 1.881e-6, 0.085e-6),
            ozone_centre: 25_000.0,
            ozone_width: 30_000.0,
        }
    }

    /// Checks every field: finite, radii and scale heights and the ozone width positive,
    /// `top_radius > ground_radius`, coefficients non-negative, `|mie_g| < 1`. The error names
    /// the field, e.g. `sky.mie_g`.
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        let positive = "must be positive";
        let non_negative = "must not be negative";
        AtmosphereError::check(
            "sky.ground_radius",
            self.ground_radius,
            self.ground_radius > 0.0,
            positive,
        )?;
        AtmosphereError::check(
            "sky.top_radius",
            self.top_radius,
            self.top_radius > self.ground_radius,
            "must exceed sky.ground_radius",
        )?;
        AtmosphereError::check(
            "sky.ground_elevation",
            self.ground_elevation,
            true,
            "must be finite",
        )?;
        check_rgb(
            [
                "sky.rayleigh_scattering.r",
                "sky.rayleigh_scattering.g",
                "sky.rayleigh_scattering.b",
            ],
            self.rayleigh_scattering,
        )?;
        AtmosphereError::check(
            "sky.rayleigh_scale_height",
            self.rayleigh_scale_height,
            self.rayleigh_scale_height > 0.0,
            positive,
        )?;
        AtmosphereError::check(
            "sky.mie_scattering",
            self.mie_scattering,
            self.mie_scattering >= 0.0,
            non_negative,
        )?;
        AtmosphereError::check(
            "sky.mie_absorption",
            self.mie_absorption,
            self.mie_absorption >= 0.0,
            non_negative,
        )?;
        AtmosphereError::check(
            "sky.mie_scale_height",
            self.mie_scale_height,
            self.mie_scale_height > 0.0,
            positive,
        )?;
        AtmosphereError::check(
            "sky.mie_g",
            self.mie_g,
            self.mie_g.abs() < 1.0,
            "must lie strictly between -1 and 1",
        )?;
        check_rgb(
            [
                "sky.ozone_absorption.r",
                "sky.ozone_absorption.g",
                "sky.ozone_absorption.b",
            ],
            self.ozone_absorption,
        )?;
        AtmosphereError::check(
            "sky.ozone_centre",
            self.ozone_centre,
            true,
            "must be finite",
        )?;
        AtmosphereError::check(
            "sky.ozone_width",
            self.ozone_width,
            self.ozone_width > 0.0,
            positive,
        )?;
        Ok(())
    }

    /// Altitude above the ground of a point at planet-centred radius `r`.
    pub fn altitude(&self, r: f64) -> f64 {
        r - self.ground_radius
    }

    /// The observer's planet-centred radius for a scene height `eye_y`: the ground radius plus
    /// the altitude `eye_y − ground_elevation`, clamped to `[0, MAX_OBSERVER_ALTITUDE]` (an eye
    /// below the ground — or a NaN height — is put on the ground).
    pub fn observer_radius(&self, eye_y: f64) -> f64 {
        let altitude = eye_y - self.ground_elevation;
        // `!(a > 0)` also catches NaN.
        let altitude = if altitude > 0.0 {
            altitude.min(MAX_OBSERVER_ALTITUDE)
        } else {
            0.0
        };
        self.ground_radius + altitude
    }

    /// Relative Rayleigh density `exp(−h / H_R)`.
    pub fn rayleigh_density(&self, h: f64) -> f64 {
        (-h.max(0.0) / self.rayleigh_scale_height).exp()
    }

    /// Relative Mie density `exp(−h / H_M)`.
    pub fn mie_density(&self, h: f64) -> f64 {
        (-h.max(0.0) / self.mie_scale_height).exp()
    }

    /// Relative ozone density `max(0, 1 − |h − centre| / (width / 2))`.
    pub fn ozone_density(&self, h: f64) -> f64 {
        (1.0 - (h.max(0.0) - self.ozone_centre).abs() / (0.5 * self.ozone_width)).max(0.0)
    }

    /// Mie extinction at the ground, `σ_M + σ_Ma`.
    pub fn mie_extinction(&self) -> f64 {
        self.mie_scattering + self.mie_absorption
    }

    /// Optical depth (RGB) of the column densities `c = (∫ρ_R, ∫ρ_M, ∫ρ_O)` (metres each).
    pub fn optical_depth_of_columns(&self, c: DVec3) -> DVec3 {
        self.rayleigh_scattering * c.x
            + DVec3::splat(self.mie_extinction() * c.y)
            + self.ozone_absorption * c.z
    }

    /// The three relative densities `(ρ_R, ρ_M, ρ_O)` at altitude `h`.
    pub fn densities(&self, h: f64) -> DVec3 {
        DVec3::new(
            self.rayleigh_density(h),
            self.mie_density(h),
            self.ozone_density(h),
        )
    }

    /// Extinction `σ_t(h)` (1/m, RGB).
    pub fn extinction(&self, h: f64) -> DVec3 {
        self.optical_depth_of_columns(self.densities(h))
    }

    /// Rayleigh scattering `σ_R ρ_R(h)` (1/m, RGB).
    pub fn rayleigh_scattering_at(&self, h: f64) -> DVec3 {
        self.rayleigh_scattering * self.rayleigh_density(h)
    }

    /// Mie scattering `σ_M ρ_M(h)` (1/m, grey).
    pub fn mie_scattering_at(&self, h: f64) -> f64 {
        self.mie_scattering * self.mie_density(h)
    }

    /// The radii where a density has a kink (the ozone tent's feet and peak): quadratures
    /// split there (those outside a segment are ignored).
    pub(crate) fn kink_radii(&self) -> [f64; 3] {
        let half = 0.5 * self.ozone_width;
        [
            self.ground_radius + self.ozone_centre - half,
            self.ground_radius + self.ozone_centre,
            self.ground_radius + self.ozone_centre + half,
        ]
    }
}

/// Checks an RGB coefficient: finite and non-negative, naming the channel.
fn check_rgb(fields: [&'static str; 3], v: DVec3) -> Result<(), AtmosphereError> {
    for (field, value) in fields.into_iter().zip(v.to_array()) {
        AtmosphereError::check(field, value, value >= 0.0, "must not be negative")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn earth_is_valid_and_profiles_peak_where_stated() {
        let m = SkyModel::earth();
        assert_eq!(m.validate(), Ok(()));
        assert_eq!(m.rayleigh_density(0.0), 1.0);
        assert_eq!(m.ozone_density(25_000.0), 1.0);
        assert_eq!(m.ozone_density(10_000.0), 0.0);
        assert_eq!(m.ozone_density(40_000.0), 0.0);
        assert!((m.ozone_density(17_500.0) - 0.5).abs() < 1e-15);
        assert!((m.mie_density(1_200.0) - (-1f64).exp()).abs() < 1e-15);
        // Below the ground counts as the ground.
        assert_eq!(m.rayleigh_density(-5.0), 1.0);
    }

    #[test]
    fn validate_names_the_field() {
        let bad = |f: fn(&mut SkyModel)| {
            let mut m = SkyModel::earth();
            f(&mut m);
            match m.validate() {
                Err(AtmosphereError::Invalid { field, .. }) => field,
                other => panic!("expected an error, got {other:?}"),
            }
        };
        assert_eq!(bad(|m| m.mie_g = 1.0), "sky.mie_g");
        assert_eq!(bad(|m| m.mie_g = f64::NAN), "sky.mie_g");
        assert_eq!(bad(|m| m.top_radius = m.ground_radius), "sky.top_radius");
        assert_eq!(bad(|m| m.ground_radius = -1.0), "sky.ground_radius");
        assert_eq!(
            bad(|m| m.ground_elevation = f64::INFINITY),
            "sky.ground_elevation"
        );
        assert_eq!(
            bad(|m| m.rayleigh_scattering.y = -1e-6),
            "sky.rayleigh_scattering.g"
        );
        assert_eq!(
            bad(|m| m.rayleigh_scale_height = 0.0),
            "sky.rayleigh_scale_height"
        );
        assert_eq!(bad(|m| m.mie_scattering = f64::NAN), "sky.mie_scattering");
        assert_eq!(bad(|m| m.mie_absorption = -1.0), "sky.mie_absorption");
        assert_eq!(bad(|m| m.mie_scale_height = -1.0), "sky.mie_scale_height");
        assert_eq!(
            bad(|m| m.ozone_absorption.z = f64::INFINITY),
            "sky.ozone_absorption.b"
        );
        assert_eq!(bad(|m| m.ozone_centre = f64::NAN), "sky.ozone_centre");
        assert_eq!(bad(|m| m.ozone_width = 0.0), "sky.ozone_width");
    }

    #[test]
    fn observer_radius_clamps() {
        let m = SkyModel {
            ground_elevation: 100.0,
            ..SkyModel::earth()
        };
        assert_eq!(m.observer_radius(50.0), m.ground_radius);
        assert_eq!(m.observer_radius(f64::NAN), m.ground_radius);
        assert_eq!(m.observer_radius(1100.0), m.ground_radius + 1000.0);
        assert_eq!(
            m.observer_radius(f64::INFINITY),
            m.ground_radius + MAX_OBSERVER_ALTITUDE
        );
    }
}
