//! The world size of a camera pixel along its ray: what a level-of-detail rule needs.

use crate::Projector;

/// The width of one pixel at distance `t` along its camera ray, `size + angle · t` (world
/// units): a pinhole or a sphere picture surface has an angle and no size, a parallel projection
/// a size and no angle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelFootprint {
    /// World width of a pixel at distance 0 (parallel projection: the picture height / pixels).
    pub size: f64,
    /// Growth per unit distance (radians per pixel for the angular projectors).
    pub angle: f64,
}

impl PixelFootprint {
    /// No footprint: every pixel is a point (exact rendering).
    pub const ZERO: Self = Self {
        size: 0.0,
        angle: 0.0,
    };

    /// The pixel's width at distance `t` (`t < 0` counts as 0).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        self.size + self.angle * t.max(0.0)
    }

    /// Whether the footprint is zero everywhere (or not a usable number).
    pub fn is_zero(&self) -> bool {
        !(self.size > 0.0 || self.angle > 0.0)
    }

    /// The footprint `2^levels` times wider (whole pyramid levels coarser).
    pub fn coarser(self, levels: u32) -> Self {
        let k = 2f64.powi(levels.min(1023) as i32);
        Self {
            size: self.size * k,
            angle: self.angle * k,
        }
    }
}

impl Projector {
    /// The footprint of a pixel of a `width × height` image: pinhole `2 tan(fov_y/2) / height`
    /// per unit distance (the pixel's angle on the axis; off-axis pixels are slightly narrower in
    /// angle, so this errs coarse by at most `1/cos²` of the half field), parallel the constant
    /// `height_world / height`, sphere picture surface the larger angular step
    /// `max(fov_x / width, fov_y / height)` (exact seen from the sphere's centre).
    pub fn pixel_footprint(&self, width: u32, height: u32) -> PixelFootprint {
        let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
        match self {
            Projector::Pinhole(p) => PixelFootprint {
                size: 0.0,
                angle: 2.0 * p.tan_half_fov_y / h,
            },
            Projector::Parallel(p) => PixelFootprint {
                size: p.height / h,
                angle: 0.0,
            },
            Projector::Sphere(s) => PixelFootprint {
                size: 0.0,
                angle: (s.fov_x / w).max(s.fov_y / h),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Parallel, Pinhole};
    use glam::DVec3;

    /// The footprint matches the distance between neighbouring pixel rays at distance `t`.
    #[test]
    fn footprint_is_the_spacing_of_neighbouring_rays() {
        let (w, h) = (200, 100);
        let pin = Projector::Pinhole(
            Pinhole::new(DVec3::ZERO, DVec3::Z, DVec3::Y, 40f64.to_radians(), 1.0).unwrap(),
        );
        let par =
            Projector::Parallel(Parallel::new(DVec3::ZERO, DVec3::Z, DVec3::Y, 8.0, 0.5).unwrap());
        for p in [pin, par] {
            let fp = p.pixel_footprint(w, h);
            let a = p.pixel_ray(100, 50, w, h).unwrap().ray;
            let b = p.pixel_ray(100, 51, w, h).unwrap().ray;
            for t in [10.0, 1000.0] {
                let gap = (a.at(t) - b.at(t)).length();
                assert!(
                    (gap - fp.at(t)).abs() <= 1e-3 * fp.at(t),
                    "{gap} vs {}",
                    fp.at(t)
                );
            }
        }
        assert!(PixelFootprint::ZERO.is_zero());
        assert_eq!(
            PixelFootprint {
                size: 1.0,
                angle: 0.5
            }
            .coarser(2),
            PixelFootprint {
                size: 4.0,
                angle: 2.0
            }
        );
    }
}
