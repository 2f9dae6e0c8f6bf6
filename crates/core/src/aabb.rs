//! Axis-aligned bounding boxes in f64 and the robust slab test against a ray.

use crate::{Interval, Ray};
use glam::DVec3;

/// An axis-aligned box `[min, max]`. An empty box has some `min > max`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    /// The box that contains nothing; the identity of [`Aabb::union`].
    pub const EMPTY: Self = Self {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// The box of the given centre and half extents.
    pub fn from_center_half(center: DVec3, half: DVec3) -> Self {
        Self {
            min: center - half,
            max: center + half,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// All six bounds finite and the box not empty.
    pub fn is_finite(&self) -> bool {
        !self.is_empty() && self.min.is_finite() && self.max.is_finite()
    }

    pub fn union(&self, o: &Self) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn intersection(&self, o: &Self) -> Self {
        Self {
            min: self.min.max(o.min),
            max: self.max.min(o.max),
        }
    }

    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Length of the diagonal; 0 for an empty box.
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The box grown by `margin` on every side.
    pub fn expanded(&self, margin: f64) -> Self {
        Self {
            min: self.min - DVec3::splat(margin),
            max: self.max + DVec3::splat(margin),
        }
    }

    /// The box moved by `-offset` (camera-relative coordinates).
    pub fn translated(&self, offset: DVec3) -> Self {
        Self {
            min: self.min - offset,
            max: self.max - offset,
        }
    }

    /// The parameter range `[t_in, t_out]` where the ray is inside the box, clipped to `range`;
    /// `None` if the ray misses. Rays parallel to a slab are handled without dividing by zero.
    pub fn clip_ray(&self, ray: &Ray, range: Interval) -> Option<Interval> {
        let mut lo = range.lo;
        let mut hi = range.hi;
        for axis in 0..3 {
            let o = ray.origin[axis];
            let d = ray.dir[axis];
            let (bmin, bmax) = (self.min[axis], self.max[axis]);
            if d == 0.0 {
                if o < bmin || o > bmax {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut t0, mut t1) = ((bmin - o) * inv, (bmax - o) * inv);
            if t0 > t1 {
                std::mem::swap(&mut t0, &mut t1);
            }
            lo = lo.max(t0);
            hi = hi.min(t1);
            if lo > hi {
                return None;
            }
        }
        Some(Interval { lo, hi })
    }

    /// [`Aabb::clip_ray`] with the ray's componentwise inverse direction `inv_dir = 1 / ray.dir`
    /// precomputed (once per ray, for many boxes): the same result, bit for bit, without the
    /// divisions and the per-axis branches. A ray parallel to a slab (infinite `inv_dir`) takes
    /// the general path.
    #[inline]
    pub fn clip_ray_with_inverse(
        &self,
        ray: &Ray,
        inv_dir: DVec3,
        range: Interval,
    ) -> Option<Interval> {
        let t = self.slab_interval(ray, inv_dir, range);
        (t.lo <= t.hi).then_some(t)
    }

    /// [`Aabb::clip_ray_with_inverse`] as a bare interval, empty (`lo > hi`, or NaN) where the
    /// ray misses: two floats that travel in registers, for hot loops where the `Option`
    /// would be spilled to the stack and reloaded in other widths (a store-forwarding stall).
    #[inline]
    pub fn slab_interval(&self, ray: &Ray, inv_dir: DVec3, range: Interval) -> Interval {
        if !inv_dir.is_finite() {
            return self.clip_ray(ray, range).unwrap_or(Interval::EMPTY);
        }
        let t0 = (self.min - ray.origin) * inv_dir;
        let t1 = (self.max - ray.origin) * inv_dir;
        let near = t0.min(t1);
        let far = t0.max(t1);
        let lo = range.lo.max(near.max_element());
        let hi = range.hi.min(far.min_element());
        Interval { lo, hi }
    }

    /// The outward unit normal of the face nearest to `p` (for hits on a clipping box).
    pub fn face_normal(&self, p: DVec3) -> DVec3 {
        let mut best = (f64::INFINITY, DVec3::X);
        for axis in 0..3 {
            let mut n = DVec3::ZERO;
            let dmin = (p[axis] - self.min[axis]).abs();
            let dmax = (p[axis] - self.max[axis]).abs();
            if dmin < best.0 {
                n[axis] = -1.0;
                best = (dmin, n);
            }
            let mut n = DVec3::ZERO;
            if dmax < best.0 {
                n[axis] = 1.0;
                best = (dmax, n);
            }
        }
        best.1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_test_hits_misses_and_parallel_rays() {
        let b = Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0));
        let r = Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z).unwrap();
        let i = b.clip_ray(&r, Interval::new(0.0, f64::INFINITY)).unwrap();
        assert_eq!((i.lo, i.hi), (4.0, 6.0));
        // Parallel to the x slabs, outside them: miss without NaN.
        let r = Ray::new(DVec3::new(2.0, 0.0, -5.0), DVec3::Z).unwrap();
        assert!(b.clip_ray(&r, Interval::new(0.0, f64::INFINITY)).is_none());
        // Ray along an edge of the box: inside (closed box).
        let r = Ray::new(DVec3::new(1.0, 1.0, -5.0), DVec3::Z).unwrap();
        assert!(b.clip_ray(&r, Interval::new(0.0, f64::INFINITY)).is_some());
        // Box behind the origin.
        let r = Ray::new(DVec3::new(0.0, 0.0, 5.0), DVec3::Z).unwrap();
        assert!(b.clip_ray(&r, Interval::new(0.0, f64::INFINITY)).is_none());
    }

    proptest::proptest! {
        /// The precomputed-inverse slab test answers exactly what the general one does: random
        /// boxes (some empty), rays with components snapped to 0 (parallel slabs) and origins
        /// snapped onto slab planes.
        #[test]
        fn clip_with_inverse_is_bit_identical(
            min in proptest::array::uniform3(-4i32..4),
            ext in proptest::array::uniform3(-1i32..4),
            o in proptest::array::uniform3(-8i32..8),
            d in proptest::array::uniform3(-3i32..4),
            frac in proptest::array::uniform3(0.0f64..1.0),
            lo in -2.0f64..3.0,
        ) {
            let min = DVec3::new(min[0] as f64, min[1] as f64, min[2] as f64);
            let b = Aabb::new(min, min + DVec3::new(ext[0] as f64, ext[1] as f64, ext[2] as f64));
            // Integer origins land on slab planes often; fractions move some off them.
            let origin = DVec3::new(
                o[0] as f64 + if frac[0] < 0.5 { 0.0 } else { frac[0] },
                o[1] as f64,
                o[2] as f64 + frac[2] * 0.25,
            );
            let dir = DVec3::new(d[0] as f64 + frac[1] * 0.1, d[1] as f64, d[2] as f64);
            if let Some(ray) = Ray::new(origin, dir) {
                let range = Interval::new(lo, f64::INFINITY);
                let inv = DVec3::ONE / ray.dir;
                proptest::prop_assert_eq!(
                    b.clip_ray_with_inverse(&ray, inv, range),
                    b.clip_ray(&ray, range)
                );
            }
        }
    }

    #[test]
    fn face_normal_points_out_of_the_nearest_face() {
        let b = Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0));
        assert_eq!(b.face_normal(DVec3::new(0.2, 0.99, 0.0)), DVec3::Y);
        assert_eq!(b.face_normal(DVec3::new(-0.999, 0.1, 0.0)), -DVec3::X);
    }
}
