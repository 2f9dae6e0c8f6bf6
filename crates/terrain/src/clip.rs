//! The slab test in height-map space, reporting which face the ray enters through (for the
//! normals of walls: threshold outlines, the map's border and the base).

use crate::MapRay;
use glam::DVec3;

/// The part `[t0, t1]` of a ray inside a box, and the face it enters through: `Some((axis,
/// sign))` with `axis` 0 = u, 1 = v, 2 = r and `sign` the outward direction of that face, or
/// `None` when `t0` is the start of the given range (the ray starts inside).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Clip {
    pub(crate) t0: f64,
    pub(crate) t1: f64,
    pub(crate) entry: Option<(usize, f64)>,
}

/// Clips `ray` to the box `[min, max]` within `[lo, hi]`; rays parallel to a slab never divide
/// by zero (closed slabs: a ray along a face is inside).
#[inline]
pub(crate) fn clip_box(ray: &MapRay, min: DVec3, max: DVec3, lo: f64, hi: f64) -> Option<Clip> {
    clip_within(
        ray,
        min,
        max,
        &Clip {
            t0: lo,
            t1: hi,
            entry: None,
        },
    )
}

/// [`clip_box`] within an earlier clip, whose entry face stands when this box adds none.
#[inline]
pub(crate) fn clip_within(ray: &MapRay, min: DVec3, max: DVec3, outer: &Clip) -> Option<Clip> {
    let (mut t0, mut t1, mut entry) = (outer.t0, outer.t1, outer.entry);
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        if d == 0.0 {
            if o < min[axis] || o > max[axis] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d;
        let (a, b) = ((min[axis] - o) * inv, (max[axis] - o) * inv);
        let (near, far, sign) = if a <= b { (a, b, -1.0) } else { (b, a, 1.0) };
        if near > t0 {
            t0 = near;
            entry = Some((axis, sign));
        }
        t1 = t1.min(far);
        if t0 > t1 {
            return None;
        }
    }
    Some(Clip { t0, t1, entry })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_faces_and_parallel_rays() {
        let b = (DVec3::ZERO, DVec3::ONE);
        let r = MapRay {
            origin: DVec3::new(-1.0, 0.5, 0.5),
            dir: DVec3::X,
        };
        let c = clip_box(&r, b.0, b.1, 0.0, 10.0).unwrap();
        assert_eq!((c.t0, c.t1, c.entry), (1.0, 2.0, Some((0, -1.0))));
        let inside = MapRay {
            origin: DVec3::splat(0.5),
            dir: -DVec3::Z,
        };
        let c = clip_box(&inside, b.0, b.1, 0.0, 10.0).unwrap();
        assert_eq!((c.t0, c.t1, c.entry), (0.0, 0.5, None));
        let along_face = MapRay {
            origin: DVec3::new(1.0, 0.5, 5.0),
            dir: -DVec3::Z,
        };
        assert_eq!(
            clip_box(&along_face, b.0, b.1, 0.0, 10.0).unwrap().entry,
            Some((2, 1.0))
        );
        let outside = MapRay {
            origin: DVec3::new(1.5, 0.5, 5.0),
            dir: -DVec3::Z,
        };
        assert!(clip_box(&outside, b.0, b.1, 0.0, 10.0).is_none());
    }
}
