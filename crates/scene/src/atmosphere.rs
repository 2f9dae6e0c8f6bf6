//! The scene's atmosphere: what a file's `atmosphere:` means once checked — a fog layer (with its
//! model), a physically based sky (its transmittance table built once), and how the media's
//! terms are evaluated — and its resolution with located errors.

use crate::Light;
use crate::checks::{Result, finite, invalid};
use crate::description;
use crate::path::FieldPath;
use fray_atmosphere::sky::{SkyModel, SkySun, SkyTables};
use fray_atmosphere::{FogLayer, FogModel, Phase};
use fray_core::MemoryBudget;
use glam::DVec3;
use std::sync::Arc;

/// The grid spacings accepted for the "per vertex" evaluation, in pixels.
pub const GRID_SPACINGS: std::ops::RangeInclusive<u32> = 2..=64;

/// The grid spacing the per-vertex mode takes when asked for without one (`--media-grid`), and
/// the one its figures are measured at (`cargo xtask bench atmosphere`).
pub const DEFAULT_GRID_SPACING: u32 = 8;
/// [`DEFAULT_GRID_SPACING`] as text, for command-line parsers.
pub const DEFAULT_GRID_SPACING_TEXT: &str = "8";

/// The media between the camera and what it sees. `Default`: none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Atmosphere {
    pub fog: Option<Fog>,
    pub sky: Option<Sky>,
    /// `Some(n)`: the media's terms on a grid of pixels `n` apart, interpolated where the
    /// depths agree (the method's per-vertex evaluation); `None`: every pixel.
    pub grid: Option<u32>,
}

impl Atmosphere {
    /// Whether any medium is present.
    pub fn is_empty(&self) -> bool {
        self.fog.is_none() && self.sky.is_none()
    }
}

/// A fog layer and the formula its light is evaluated with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    pub layer: FogLayer,
    pub model: FogModel,
}

/// The physically based sky of a scene.
#[derive(Clone, Debug)]
pub struct Sky {
    /// The model, its sun and its transmittance table (built once, shared by the backends).
    pub sky: Arc<fray_atmosphere::sky::Sky>,
    /// Which of the scene's lights is the sky's sun (its first `Sun`); `None`: no sun.
    pub sun_light: Option<usize>,
    pub sun_disc: bool,
    pub aerial_perspective: bool,
    /// Steps of the aerial-perspective march.
    pub steps: u32,
}

impl PartialEq for Sky {
    fn eq(&self, other: &Self) -> bool {
        self.sky.model() == other.sky.model()
            && self.sky.sun() == other.sky.sun()
            && (
                self.sun_light,
                self.sun_disc,
                self.aerial_perspective,
                self.steps,
            ) == (
                other.sun_light,
                other.sun_disc,
                other.aerial_perspective,
                other.steps,
            )
    }
}

/// The most steps an aerial-perspective march may take.
pub const MAX_SKY_STEPS: u32 = 256;

/// Checks `d` (at `path`, the file's `atmosphere`); `lights` are the scene's, resolved.
pub(crate) fn resolve(
    path: &FieldPath,
    d: &description::Atmosphere,
    lights: &[Light],
    budget: &MemoryBudget,
) -> Result<Atmosphere> {
    let fog = match &d.fog {
        None => None,
        Some(f) => Some(fog(&path.field("fog"), f)?),
    };
    let sky = match &d.sky {
        None => None,
        Some(s) => Some(sky(&path.field("sky"), s, lights, budget)?),
    };
    let grid = match d.grid {
        None => None,
        Some(n) => {
            let (lo, hi) = (*GRID_SPACINGS.start(), *GRID_SPACINGS.end());
            if n.fract() == 0.0 && n >= f64::from(lo) && n <= f64::from(hi) {
                Some(n as u32)
            } else {
                return invalid(
                    &path.field("grid"),
                    format!("must be a whole number of pixels in {lo}..={hi}, got {n}"),
                );
            }
        }
    };
    Ok(Atmosphere { fog, sky, grid })
}

fn sky(
    path: &FieldPath,
    d: &description::Sky,
    lights: &[Light],
    budget: &MemoryBudget,
) -> Result<Sky> {
    let ground = finite(&path.field("ground_elevation"), d.ground_elevation)?;
    if !(d.haze.is_finite() && d.haze >= 0.0) {
        return invalid(&path.field("haze"), format!("must be ≥ 0, got {}", d.haze));
    }
    let steps = d.steps;
    if !(steps.fract() == 0.0 && steps >= 1.0 && steps <= f64::from(MAX_SKY_STEPS)) {
        return invalid(
            &path.field("steps"),
            format!("must be a whole number in 1..={MAX_SKY_STEPS}, got {steps}"),
        );
    }
    let earth = SkyModel::earth();
    let model = SkyModel {
        ground_elevation: ground,
        mie_scattering: earth.mie_scattering * d.haze,
        mie_absorption: earth.mie_absorption * d.haze,
        ozone_absorption: if d.ozone {
            earth.ozone_absorption
        } else {
            DVec3::ZERO
        },
        ..earth
    };
    let sun_light = lights.iter().position(|l| matches!(l, Light::Sun { .. }));
    let sun = match sun_light.map(|i| lights[i]) {
        Some(Light::Sun {
            direction,
            irradiance,
        }) => SkySun::new(direction, irradiance.as_dvec3()),
        // No sun: a dark sky (the tables still describe the air's transmittance).
        _ => SkySun::new(DVec3::Y, DVec3::ZERO),
    };
    let built =
        fray_atmosphere::sky::Sky::new(model, sun, SkyTables::default(), budget).map_err(|e| {
            crate::checks::Invalid {
                path: path.clone(),
                message: e.to_string(),
            }
        })?;
    Ok(Sky {
        sky: Arc::new(built),
        sun_light,
        sun_disc: d.sun_disc,
        aerial_perspective: d.aerial_perspective,
        steps: steps as u32,
    })
}

fn fog(path: &FieldPath, f: &description::Fog) -> Result<Fog> {
    let base = finite(&path.field("base"), f.base)?;
    let top = finite(&path.field("top"), f.top)?;
    if top <= base {
        return invalid(
            &path.field("top"),
            format!("must be above base ({base}), got {top}"),
        );
    }
    let extinction = f.extinction;
    if !(extinction.is_finite() && extinction >= 0.0) {
        return invalid(
            &path.field("extinction"),
            format!("must be ≥ 0 (1/m), got {extinction}"),
        );
    }
    if !f.albedo.iter().all(|a| (0.0..=1.0).contains(a)) {
        return invalid(
            &path.field("albedo"),
            format!(
                "must be in [0, 1] on every channel, got ({}, {}, {})",
                f.albedo[0], f.albedo[1], f.albedo[2]
            ),
        );
    }
    let falloff = match f.falloff {
        None => None,
        Some(h) if h.is_finite() && h > 0.0 => Some(h),
        Some(h) => {
            return invalid(
                &path.field("falloff"),
                format!("must be a scale height > 0 (metres), got {h}"),
            );
        }
    };
    let g_ok = |g: f64| g.is_finite() && g.abs() < 1.0;
    let phase = match f.phase {
        description::Phase::Isotropic => Phase::Isotropic,
        description::Phase::HenyeyGreenstein { g } if g_ok(g) => Phase::HenyeyGreenstein { g },
        description::Phase::Printed { g } if g_ok(g) => Phase::Printed { g },
        description::Phase::HenyeyGreenstein { g } | description::Phase::Printed { g } => {
            return invalid(
                &path.field("phase").field("g"),
                format!("must be in (−1, 1), got {g}"),
            );
        }
    };
    let layer = FogLayer {
        base,
        top,
        extinction,
        albedo: DVec3::from_array(f.albedo),
        falloff,
        phase,
    };
    let model = match f.model {
        description::FogModel::Exact => FogModel::Exact,
        description::FogModel::Method => FogModel::Method,
    };
    Ok(Fog { layer, model })
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_default_grid_spacing_and_its_text_agree() {
        assert_eq!(
            super::DEFAULT_GRID_SPACING_TEXT.parse::<u32>(),
            Ok(super::DEFAULT_GRID_SPACING)
        );
        assert!(super::GRID_SPACINGS.contains(&super::DEFAULT_GRID_SPACING));
    }
}
