//! Watertight ray–triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013), in f64. The triangle is moved into a frame where the ray runs
//! along +z from the origin (a permutation of the axes by the ray's largest component, then a
//! shear), and the 2D edge functions of the three edges decide inside. Each edge function is
//! computed from its two vertices alone, in an order that makes the edge's value in one triangle
//! exactly the negation of its value in the triangle across it: a ray through a shared edge or
//! vertex is inside at least one of the triangles that share it, so it can never leak between
//! them (Möller–Trumbore gives each triangle its own rounding and can). A ray exactly on an edge
//! hits both neighbours (at the same `t`).

use fray_core::{Interval, Ray};
use glam::DVec3;

/// The ray's frame, computed once per ray: the axis permutation and the shear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayFrame {
    origin: DVec3,
    kx: usize,
    ky: usize,
    kz: usize,
    shear: DVec3,
}

impl RayFrame {
    /// The frame of `ray` (any non-zero direction; `t` is in units of its length).
    pub fn new(ray: &Ray) -> Self {
        // Arrays, not `DVec3`'s `Index` (a `match` per access).
        let d = ray.dir.to_array();
        let a = ray.dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Keep the winding: a negative major axis mirrors the frame, so swap the others.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Self {
            origin: ray.origin,
            kx,
            ky,
            kz,
            shear: DVec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]),
        }
    }
}

impl RayFrame {
    pub(crate) fn origin(&self) -> DVec3 {
        self.origin
    }

    /// `[kx, ky, kz]`.
    pub(crate) fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    pub(crate) fn shear(&self) -> [f64; 3] {
        self.shear.to_array()
    }
}

/// A hit on a triangle: the ray parameter and the barycentric weights of its three corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f64,
    pub barycentric: [f64; 3],
}

/// The hit of the ray of `frame` on triangle `(a, b, c)` with `t` in `range` (exclusive at both
/// ends), either side facing; `None` for a miss, a degenerate triangle or a ray in its plane.
#[inline]
pub fn intersect(frame: &RayFrame, [a, b, c]: [DVec3; 3], range: Interval) -> Option<TriangleHit> {
    // Arrays, not `DVec3`'s `Index` (a `match` per access); the same subtractions.
    let relative = [
        (a - frame.origin).to_array(),
        (b - frame.origin).to_array(),
        (c - frame.origin).to_array(),
    ];
    let axes = [frame.kx, frame.ky, frame.kz];
    intersect_relative(axes, frame.shear.to_array(), relative, range).map(|h| h.resolve())
}

/// A hit before its barycentric weights are divided out: what [`intersect_relative`] finds.
/// [`UnresolvedHit::resolve`] gives [`intersect`]'s answer bit for bit; callers that keep only
/// the nearest of many hits resolve only that one (a division saved per hit passed over).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct UnresolvedHit {
    pub(crate) t: f64,
    edges: [f64; 3],
    det: f64,
}

impl UnresolvedHit {
    #[inline]
    pub(crate) fn resolve(self) -> TriangleHit {
        let inv = 1.0 / self.det;
        let [u, v, w] = self.edges;
        TriangleHit {
            t: self.t,
            barycentric: [u * inv, v * inv, w * inv],
        }
    }
}

/// [`intersect`] given the frame's axes `[kx, ky, kz]` and shear, and the corners already
/// relative to the ray's origin (the same f64 subtractions): a packet of rays from one origin
/// subtracts once per triangle, not once per ray.
#[inline(always)]
pub(crate) fn intersect_relative(
    [kx, ky, kz]: [usize; 3],
    s: [f64; 3],
    [a, b, c]: [[f64; 3]; 3],
    range: Interval,
) -> Option<UnresolvedHit> {
    // Sheared 2D positions: per vertex, the same bits in every triangle that shares it.
    let (ax, ay) = (a[kx] - s[0] * a[kz], a[ky] - s[1] * a[kz]);
    let (bx, by) = (b[kx] - s[0] * b[kz], b[ky] - s[1] * b[kz]);
    let (cx, cy) = (c[kx] - s[0] * c[kz], c[ky] - s[1] * c[kz]);
    // Edge functions, edge P → Q as Qx·Py − Qy·Px: the edge Q → P gives exactly the negation.
    let u = cx * by - cy * bx; // edge b → c: a's weight
    let v = ax * cy - ay * cx; // edge c → a: b's weight
    let w = bx * ay - by * ax; // edge a → b: c's weight
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (az, bz, cz) = (s[2] * a[kz], s[2] * b[kz], s[2] * c[kz]);
    let t_scaled = u * az + v * bz + w * cz;
    // t = t_scaled / det within the open range, tested without dividing.
    let (t_scaled, det_abs) = if det < 0.0 {
        (-t_scaled, -det)
    } else {
        (t_scaled, det)
    };
    if t_scaled <= range.lo * det_abs || t_scaled >= range.hi * det_abs {
        return None;
    }
    // The quotient can round onto an end of the range: keep the range open for the result too
    // (a caller that steps from hit to hit must always move on).
    let t = t_scaled / det_abs;
    if !(t > range.lo && t < range.hi) {
        return None;
    }
    Some(UnresolvedHit {
        t,
        edges: [u, v, w],
        det,
    })
}
