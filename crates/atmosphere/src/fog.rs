//! Klassen's fog layer: a horizontal slab `base ≤ y ≤ top` of extinction `B` (1/m), optionally
//! falling off exponentially with height, and what it does to light along a ray segment.

use crate::{AtmosphereError, Phase};
use fray_core::{Interval, Ray};
use glam::DVec3;

/// A horizontal fog layer (world space, Y up, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FogLayer {
    /// Height of the layer's bottom (the ground under the fog).
    pub base: f64,
    /// Height of the layer's top; the layer's thickness `H = top − base > 0`.
    pub top: f64,
    /// Extinction coefficient `B` in 1/m (at `base` when it falls off), `≥ 0`.
    pub extinction: f64,
    /// Single-scattering albedo per channel in `[0, 1]`: the scattering coefficient is
    /// `albedo · B` (fog droplets barely absorb: close to 1).
    pub albedo: DVec3,
    /// Scale height in metres of an exponential falloff, `B(y) = B e^{−(y − base)/falloff}`;
    /// `None`: homogeneous (the method's layer).
    pub falloff: Option<f64>,
    pub phase: Phase,
}

impl Default for FogLayer {
    fn default() -> Self {
        Self {
            base: 0.0,
            top: 100.0,
            extinction: 1e-3,
            albedo: DVec3::splat(0.95),
            falloff: None,
            phase: Phase::default(),
        }
    }
}

/// How the in-scattered light is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FogModel {
    /// Exact single scattering: the sun's path in the fog from each point of the ray to the
    /// layer's top (in closed form, the falloff included).
    #[default]
    Exact,
    /// The method's formulas (eq. 14, 15): every point of the ray sees the sun through the
    /// whole layer, `e^{−B H cosec β}`.
    Method,
}

/// A distant light as the fog sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sunlight {
    /// Unit vector toward the sun; its `y` is `sin β`, β the sun's elevation.
    pub direction: DVec3,
    /// Irradiance (W/m²) at the layer's top on a surface facing the sun.
    pub irradiance: DVec3,
}

/// The light that fog scatters toward the viewer.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FogLighting {
    pub suns: Vec<Sunlight>,
    /// Uniform ambient radiance (isotropic: the fog scatters `albedo · ambient` of it).
    pub ambient: DVec3,
}

/// What the fog does to a ray segment: `L_eye = transmittance · L_behind + in_scatter`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FogTerms {
    pub transmittance: f64,
    /// Radiance (W/(m² sr)) scattered toward the ray's origin.
    pub in_scatter: DVec3,
}

impl FogTerms {
    /// No fog on the segment.
    pub const CLEAR: Self = Self {
        transmittance: 1.0,
        in_scatter: DVec3::ZERO,
    };

    /// The radiance reaching the ray's origin when `behind` leaves the segment's far end.
    #[inline]
    pub fn apply(&self, behind: DVec3) -> DVec3 {
        behind * self.transmittance + self.in_scatter
    }
}

impl FogLayer {
    /// Checks every field; errors name it (`fog.top`, …).
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        AtmosphereError::check("fog.base", self.base, true, "must be finite")?;
        AtmosphereError::check(
            "fog.top",
            self.top,
            self.top > self.base,
            "must be above base",
        )?;
        AtmosphereError::check(
            "fog.extinction",
            self.extinction,
            self.extinction >= 0.0,
            "must be ≥ 0 (1/m)",
        )?;
        for a in self.albedo.to_array() {
            AtmosphereError::check(
                "fog.albedo",
                a,
                (0.0..=1.0).contains(&a),
                "must be in [0, 1]",
            )?;
        }
        if let Some(h) = self.falloff {
            AtmosphereError::check("fog.falloff", h, h > 0.0, "must be > 0 (metres)")?;
        }
        let g = self.phase.g();
        AtmosphereError::check("fog.phase.g", g, g.abs() < 1.0, "must be in (−1, 1)")?;
        Ok(())
    }

    /// The layer's thickness `H`.
    #[inline]
    pub fn thickness(&self) -> f64 {
        self.top - self.base
    }

    /// The extinction coefficient at height `y` (0 outside the layer).
    #[inline]
    pub fn density(&self, y: f64) -> f64 {
        if !(self.base..=self.top).contains(&y) {
            return 0.0;
        }
        match self.falloff {
            None => self.extinction,
            Some(h) => self.extinction * (-(y - self.base) / h).exp(),
        }
    }

    /// The part of `range` where `ray` is inside the layer (`None` if it never is, or for an
    /// empty range). Horizontal rays are inside for all of `range` or none of it.
    pub fn span(&self, ray: &Ray, range: Interval) -> Option<Interval> {
        if range.lo.is_nan() || range.hi.is_nan() || range.lo > range.hi {
            return None;
        }
        let (y, dy) = (ray.origin.y, ray.dir.y);
        let (lo, hi) = if dy == 0.0 {
            if !(self.base..=self.top).contains(&y) {
                return None;
            }
            (range.lo, range.hi)
        } else {
            let a = (self.base - y) / dy;
            let b = (self.top - y) / dy;
            (range.lo.max(a.min(b)), range.hi.min(a.max(b)))
        };
        (lo <= hi).then_some(Interval { lo, hi })
    }

    /// The optical depth `∫ B(y) ds` of `ray` over `range` (∞ for an unbounded stretch of
    /// fog), in closed form.
    pub fn optical_depth(&self, ray: &Ray, range: Interval) -> f64 {
        match self.span(ray, range) {
            Some(span) if self.extinction > 0.0 => self.span_depth(ray, span),
            _ => 0.0,
        }
    }

    /// The transmittance `e^{−τ}` of `ray` over `range`.
    #[inline]
    pub fn transmittance(&self, ray: &Ray, range: Interval) -> f64 {
        (-self.optical_depth(ray, range)).exp()
    }

    /// The optical depth over `span` (inside the layer).
    pub(crate) fn span_depth(&self, ray: &Ray, span: Interval) -> f64 {
        let length = span.width();
        match self.falloff {
            None => self.extinction * length,
            Some(h) => {
                if length == f64::INFINITY {
                    // Only a horizontal ray stays in the layer for ever.
                    return if self.density(ray.origin.y) > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    };
                }
                // The densest end times the length times the mean of the exponential.
                let (y0, y1) = (ray.at(span.lo).y, ray.at(span.hi).y);
                let low = y0.min(y1).clamp(self.base, self.top);
                let rise = (y1 - y0).abs() / h;
                self.extinction * (-(low - self.base) / h).exp() * length * mean_decay(rise)
            }
        }
    }

    /// The optical depth from height `y` in the layer to the layer's top, toward a sun at
    /// `sin β = sin_elevation` (∞ for a sun at or below the horizon, below the top).
    pub fn sun_depth(&self, y: f64, sin_elevation: f64) -> f64 {
        let y = y.clamp(self.base, self.top);
        let rise = self.top - y;
        if rise <= 0.0 || self.extinction == 0.0 {
            return 0.0;
        }
        if sin_elevation.is_nan() || sin_elevation <= 0.0 {
            return f64::INFINITY;
        }
        let path = rise / sin_elevation;
        match self.falloff {
            None => self.extinction * path,
            Some(h) => self.extinction * (-(y - self.base) / h).exp() * path * mean_decay(rise / h),
        }
    }

    /// What the fog does to `ray` over `range` (the camera's `[t_near, t_hit]`, or to infinity
    /// for a ray that hits nothing): transmittance and the single-scattered light of `light`,
    /// evaluated by `model`.
    pub fn terms(
        &self,
        ray: &Ray,
        range: Interval,
        light: &FogLighting,
        model: FogModel,
    ) -> FogTerms {
        let Some(span) = self.span(ray, range) else {
            return FogTerms::CLEAR;
        };
        if self.extinction == 0.0 {
            return FogTerms::CLEAR;
        }
        match model {
            FogModel::Exact => crate::single_scattering::exact(self, ray, span, light),
            FogModel::Method => crate::method::terms(self, ray, span, light),
        }
    }

    /// The transmittance toward `sun` from the surface point `p` as `model` sees it: exact, the
    /// path from `p` to the top; the method, the whole layer `e^{−B H cosec β}` for every
    /// point in the layer.
    pub fn sun_transmittance(&self, p: DVec3, sun: &Sunlight, model: FogModel) -> f64 {
        if p.y > self.top {
            return 1.0;
        }
        let y = match model {
            FogModel::Exact => p.y,
            FogModel::Method => self.base,
        };
        (-self.sun_depth(y, sun.direction.y)).exp()
    }
}

/// `(1 − e^{−x}) / x` for `x ≥ 0`, the mean of `e^{−s}` over `[0, x]`: 1 at 0, stable near it.
#[inline]
pub(crate) fn mean_decay(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else if x == f64::INFINITY {
        0.0
    } else {
        -(-x).exp_m1() / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f64; 3], d: [f64; 3]) -> Ray {
        Ray::new(DVec3::from(o), DVec3::from(d)).unwrap()
    }

    #[test]
    fn spans_clip_to_the_layer() {
        let fog = FogLayer::default(); // 0 ≤ y ≤ 100
        let all = Interval::new(0.0, f64::INFINITY);
        // Straight down from above: enters at the top, leaves at the base.
        let s = fog
            .span(&ray([0.0, 150.0, 0.0], [0.0, -1.0, 0.0]), all)
            .unwrap();
        assert_eq!((s.lo, s.hi), (50.0, 150.0));
        // Up from inside: from the origin to the top.
        let s = fog
            .span(&ray([0.0, 40.0, 0.0], [0.0, 1.0, 0.0]), all)
            .unwrap();
        assert_eq!((s.lo, s.hi), (0.0, 60.0));
        // Horizontal inside: everything; outside: nothing.
        let s = fog
            .span(&ray([0.0, 40.0, 0.0], [1.0, 0.0, 0.0]), all)
            .unwrap();
        assert_eq!(s.hi, f64::INFINITY);
        assert!(
            fog.span(&ray([0.0, 140.0, 0.0], [1.0, 0.0, 0.0]), all)
                .is_none()
        );
        // Exactly at the top, horizontal: in (the boundary belongs to the layer).
        assert!(
            fog.span(&ray([0.0, 100.0, 0.0], [1.0, 0.0, 0.0]), all)
                .is_some()
        );
        // Up from above: never.
        assert!(
            fog.span(&ray([0.0, 140.0, 0.0], [0.0, 1.0, 0.0]), all)
                .is_none()
        );
    }

    #[test]
    fn falloff_optical_depth_matches_quadrature() {
        let fog = FogLayer {
            falloff: Some(30.0),
            extinction: 2e-2,
            ..FogLayer::default()
        };
        for d in [
            [1.0, -0.3, 0.0],
            [1.0, 0.2, 0.5],
            [0.0, -1.0, 0.0],
            [1.0, 1e-9, 0.0],
        ] {
            let r = ray([0.0, 80.0, 0.0], d);
            let range = Interval::new(2.0, 300.0);
            let span = fog.span(&r, range).unwrap();
            let q =
                crate::quadrature::integrate(|s| fog.density(r.at(s).y), span.lo, span.hi, 1e-14);
            let closed = fog.optical_depth(&r, range);
            assert!((closed / q - 1.0).abs() < 1e-12, "{d:?}: {closed} vs {}", q);
        }
    }

    #[test]
    fn validation_names_the_field() {
        let bad = FogLayer {
            top: -1.0,
            ..FogLayer::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("fog.top")
        );
        let bad = FogLayer {
            phase: Phase::HenyeyGreenstein { g: 1.0 },
            ..FogLayer::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("fog.phase.g")
        );
        let bad = FogLayer {
            extinction: f64::NAN,
            ..FogLayer::default()
        };
        assert!(bad.validate().is_err());
        FogLayer::default().validate().unwrap();
    }
}
