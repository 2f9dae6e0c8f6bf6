//! The scene's atmosphere: what a file's `atmosphere:` means once checked — a fog layer (with its
//! model) and how the media's terms are evaluated — and its resolution with located errors.

use crate::description;
use crate::path::FieldPath;
use crate::resolve::{Result, finite, invalid};
use fray_atmosphere::{FogLayer, FogModel, Phase};
use glam::DVec3;

/// The grid spacings accepted for the "per vertex" evaluation, in pixels.
pub const GRID_SPACINGS: std::ops::RangeInclusive<u32> = 2..=64;

/// The media between the camera and what it sees. `Default`: none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Atmosphere {
    pub fog: Option<Fog>,
    /// `Some(n)`: the media's terms on a grid of pixels `n` apart, interpolated where the
    /// depths agree (the method's per-vertex evaluation); `None`: every pixel.
    pub grid: Option<u32>,
}

impl Atmosphere {
    /// Whether any medium is present.
    pub fn is_empty(&self) -> bool {
        self.fog.is_none()
    }
}

/// A fog layer and the formula its light is evaluated with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    pub layer: FogLayer,
    pub model: FogModel,
}

/// Checks `d` (at `path`, the file's `atmosphere`).
pub(crate) fn resolve(path: &FieldPath, d: &description::Atmosphere) -> Result<Atmosphere> {
    let fog = match &d.fog {
        None => None,
        Some(f) => Some(fog(&path.field("fog"), f)?),
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
    Ok(Atmosphere { fog, grid })
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
