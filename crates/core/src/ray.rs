//! A ray `p(t) = origin + t · dir` in f64, with a unit direction so that `t` is a distance.

use glam::DVec3;

/// A ray with a unit direction: the parameter `t` is the distance from the origin in world units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    /// A ray from `origin` along `dir`; `dir` is normalised here. Returns `None` for a zero or
    /// non-finite direction, so a degenerate camera can never produce NaN points. Inlined: an
    /// `Option<Ray>` returned through memory and reloaded stalls store forwarding.
    #[inline]
    pub fn new(origin: DVec3, dir: DVec3) -> Option<Self> {
        Self::with_length(origin, dir, dir.length())
    }

    /// [`Ray::new`] given `len = dir.length()`, for callers that need the length too.
    #[inline]
    pub(crate) fn with_length(origin: DVec3, dir: DVec3, len: f64) -> Option<Self> {
        // One division for the three components.
        (len.is_finite() && len > 0.0 && origin.is_finite()).then(|| Self {
            origin,
            dir: dir * (1.0 / len),
        })
    }

    /// The point at distance `t` along the ray.
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }

    /// The same ray with its origin moved by `-offset`: used to work relative to the camera.
    #[inline]
    pub fn translated(&self, offset: DVec3) -> Self {
        Self {
            origin: self.origin - offset,
            dir: self.dir,
        }
    }
}
