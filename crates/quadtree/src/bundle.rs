//! The ray bundle of an image cell: a conservative description of the rays through all of its
//! pixel centres, for every projector kind, and the conservative box-versus-bundle test.
//!
//! A bundle says: every ray of the cell starts within `origin_radius` of `origin` and its unit
//! direction makes an angle of at most `half_angle` with `axis`. For a pinhole the directions of
//! the pixel centres are an affine image of the rectangle, so the cone around the four corner
//! rays holds them all; for a parallel projection the origins are affine in the pixel and the
//! direction is fixed; for the sphere picture surface, whose directions are not linear in the
//! pixel, the picture points of the cell are bounded by interval arithmetic over its azimuth and
//! elevation ranges (ripple included) and the cone is the one from the eye around that ball. Side
//! planes (through the eye or the edge origins) cut the cone down to the cell's pyramid: for the
//! sphere surface, two wedges over the corners of that box of picture points.

use crate::trig::{cos_range, sin_range};
use fray_core::{Aabb, Interval, Projector, Ray};
use glam::DVec3;
use std::f64::consts::PI;

/// Angular slack added to every cone (radians): covers the rounding of normalised directions
/// (`acos` of a dot product one ulp below 1 is already ≈ 1.5e-8).
const ANGLE_SLACK: f64 = 1e-7;
/// Relative slack on distances: covers rounding in the projector and in the callers' evaluations.
const RELATIVE_SLACK: f64 = 1e-7;

/// Which points of a cell's pixels its rays pass through.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PixelCoverage {
    /// The pixel centres: one ray per pixel.
    #[default]
    Centres,
    /// Any point of the pixels (several samples per pixel, anywhere in it).
    Area,
}

/// A conservative description of all rays through the pixel centres of the cell
/// `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayBundle {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    /// Every ray's origin lies within `origin_radius` of this point.
    pub origin: DVec3,
    pub origin_radius: f64,
    /// Every ray's unit direction is within `half_angle` of this unit vector.
    pub axis: DVec3,
    /// In radians; `≥ π` means "any direction" (no culling possible).
    pub half_angle: f64,
    /// Side planes `(n, p)` of the bundle (pinhole, parallel and sphere surface): every point of
    /// every ray has `n · (x − p) ≥ 0`. Unused planes have `n = 0`.
    pub planes: [(DVec3, DVec3); 4],
}

impl RayBundle {
    /// The bundle of the rays through the pixel centres of the cell `[x0, x1) × [y0, y1)`
    /// (non-empty) of a `width × height` image.
    pub fn of_cell(projector: &Projector, size: (u32, u32), cell: (u32, u32, u32, u32)) -> Self {
        Self::covering(projector, size, cell, PixelCoverage::Centres)
    }

    /// The bundle of the cell's rays through the points `coverage` names: the pixel centres,
    /// or every point of its pixels (the rays of anti-aliasing samples anywhere in a pixel).
    pub fn covering(
        projector: &Projector,
        (width, height): (u32, u32),
        (x0, y0, x1, y1): (u32, u32, u32, u32),
        coverage: PixelCoverage,
    ) -> Self {
        let inset = match coverage {
            PixelCoverage::Centres => 0.5,
            PixelCoverage::Area => 0.0,
        };
        let (xa, xb) = (f64::from(x0) + inset, f64::from(x1.max(x0 + 1)) - inset);
        let (ya, yb) = (f64::from(y0) + inset, f64::from(y1.max(y0 + 1)) - inset);
        let mut bundle = Self {
            x0,
            y0,
            x1,
            y1,
            origin: DVec3::ZERO,
            origin_radius: 0.0,
            axis: DVec3::Z,
            half_angle: 2.0 * PI,
            planes: [(DVec3::ZERO, DVec3::ZERO); 4],
        };
        let corners = [(xa, ya), (xb, ya), (xa, yb), (xb, yb)];
        match projector {
            Projector::Pinhole(p) => {
                bundle.origin = p.eye;
                bundle.origin_radius = 1e-12 * p.eye.length();
                let dirs = corners.map(|(x, y)| {
                    projector
                        .ray(x, y, width, height)
                        .map_or(DVec3::ZERO, |r| r.ray.dir)
                });
                bundle.set_cone_around(&dirs);
                // The pixel-centre directions are an affine image of the rectangle: the cone
                // spanned by the corner rays holds them, bounded by the planes through the eye
                // and two adjacent corner rays.
                let ring = [dirs[0], dirs[1], dirs[3], dirs[2]];
                let inside: DVec3 = dirs.iter().sum();
                for k in 0..4 {
                    let n = ring[k].cross(ring[(k + 1) % 4]);
                    bundle.planes[k] = (orient(n, inside), p.eye);
                }
            }
            Projector::Parallel(p) => {
                let origins = corners.map(|(x, y)| projector.pair(x, y, width, height).0);
                let centre = origins.iter().sum::<DVec3>() * 0.25;
                let spread = origins
                    .iter()
                    .map(|o| (*o - centre).length())
                    .fold(0.0, f64::max);
                bundle.origin = centre;
                bundle.origin_radius =
                    spread * (1.0 + RELATIVE_SLACK) + 1e-12 * (centre.length() + p.height);
                bundle.axis = p.basis.forward;
                bundle.half_angle = ANGLE_SLACK;
                // Origins fill the rectangle of the corner origins; rays run along `forward`:
                // the side planes contain `forward` and an edge of the rectangle.
                let ring = [origins[0], origins[1], origins[3], origins[2]];
                for k in 0..4 {
                    let (a, b) = (ring[k], ring[(k + 1) % 4]);
                    let n = (b - a).cross(p.basis.forward);
                    bundle.planes[k] = (orient(n, centre - a), a);
                }
            }
            Projector::Sphere(s) => {
                let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
                let theta = |x: f64| 0.5 * s.fov_x * (2.0 * x / w - 1.0);
                let phi = |y: f64| 0.5 * s.fov_y * (1.0 - 2.0 * y / h);
                let widen = |i: Interval| {
                    let m = 1e-12 * (1.0 + i.lo.abs().max(i.hi.abs()));
                    Interval::new(i.lo - m, i.hi + m)
                };
                let th = widen(Interval::new(theta(xa), theta(xb)));
                let ph = widen(Interval::new(phi(yb), phi(ya)));
                let (ct, st, cp, sp) = (cos_range(th), sin_range(th), cos_range(ph), sin_range(ph));
                let ripple = cos_range(th.scale(s.frequency)) * cos_range(ph.scale(s.frequency));
                let r = (Interval::point(1.0) + ripple.scale(s.amplitude)).scale(s.radius);
                let local = [cp * ct * r, cp * st * r, sp * r];
                let b = &s.basis;
                let mid = s.centre
                    + b.forward * local[0].mid()
                    + b.right * local[1].mid()
                    + b.up * local[2].mid();
                let half = DVec3::new(local[0].width(), local[1].width(), local[2].width()) * 0.5;
                let rho = half.length() * (1.0 + RELATIVE_SLACK)
                    + 1e-12 * (s.radius + s.centre.length() + s.eye.length());
                bundle.origin = s.eye;
                bundle.origin_radius = 1e-12 * s.eye.length();
                let v = mid - s.eye;
                let l = v.length();
                if l > rho * (1.0 + RELATIVE_SLACK) && l.is_finite() {
                    bundle.axis = v / l;
                    bundle.half_angle = (rho / l).asin() + ANGLE_SLACK;
                }
                // Side planes through the eye: every ray passes through the box of picture points
                // (inflated by the same slack as `rho`), so its direction lies in the cone over
                // the box's corners. Bound that cone by a wedge about `up` (its projection on the
                // forward/right plane) and one about `right` (on the forward/up plane).
                let slack = rho - half.length();
                let mut corners = [DVec3::ZERO; 8];
                for (k, c) in corners.iter_mut().enumerate() {
                    // Corner k of the box: the low or high end of each local interval.
                    let end = |axis: usize| {
                        let i = local[axis];
                        if k & (1 << axis) == 0 {
                            i.lo - slack
                        } else {
                            i.hi + slack
                        }
                    };
                    *c = s.centre + b.forward * end(0) + b.right * end(1) + b.up * end(2) - s.eye;
                }
                for (k, (a, c)) in [(b.forward, b.right), (b.forward, b.up)]
                    .into_iter()
                    .enumerate()
                {
                    if let Some([n0, n1]) = wedge(&corners, a, c) {
                        bundle.planes[2 * k] = (n0, s.eye);
                        bundle.planes[2 * k + 1] = (n1, s.eye);
                    }
                }
            }
        }
        bundle
    }

    /// Sets the cone to the smallest-ish cap around the unit vectors `dirs` (their geodesic hull
    /// included: a cap narrower than a hemisphere is convex); "any direction" when that is wide.
    fn set_cone_around(&mut self, dirs: &[DVec3]) {
        let sum: DVec3 = dirs.iter().sum();
        let len = sum.length();
        if !(len > 0.0 && len.is_finite()) || dirs.contains(&DVec3::ZERO) {
            return;
        }
        let axis = sum / len;
        let angle = dirs
            .iter()
            .map(|d| d.dot(axis).clamp(-1.0, 1.0).acos())
            .fold(0.0, f64::max)
            + ANGLE_SLACK;
        if angle < 0.5 * PI - 1e-6 {
            self.axis = axis;
            self.half_angle = angle;
        }
    }

    /// Whether the whole box lies strictly outside one of the side planes (by a margin).
    fn outside_a_plane(&self, b: &Aabb) -> bool {
        let c = b.center();
        let h = 0.5 * (b.max - b.min);
        self.planes.iter().any(|&(n, p)| {
            if n == DVec3::ZERO {
                return false;
            }
            // The largest n · (x − p) over the box, against a margin for rounding.
            let best = n.dot(c - p) + n.abs().dot(h);
            let margin = RELATIVE_SLACK * (h.length() + (c - p).length() + p.length()) + 1e-12;
            best < -margin
        })
    }

    /// Whether the bundle can hold no constraint on directions.
    pub fn is_unbounded(&self) -> bool {
        self.half_angle >= PI
    }

    /// Whether `ray` is one of the rays the bundle describes (origin in the ball, direction in
    /// the cone): what the bundle promises for every pixel-centre ray of its cell.
    pub fn contains(&self, ray: &Ray) -> bool {
        if (ray.origin - self.origin).length() > self.origin_radius {
            return false;
        }
        // Every point of the ray on the inner side of every side plane (within the slack).
        let in_planes = self.planes.iter().all(|&(n, p)| {
            n == DVec3::ZERO
                || (n.dot(ray.dir) >= -ANGLE_SLACK
                    && n.dot(ray.origin - p)
                        >= -(RELATIVE_SLACK * (ray.origin.length() + p.length()) + 1e-12))
        });
        in_planes
            && (self.is_unbounded()
                || ray.dir.dot(self.axis).clamp(-1.0, 1.0).acos() <= self.half_angle)
    }

    /// A conservative range of the ray parameter `t ≥ 0` where rays of the bundle can be inside
    /// `b`; `None` when no ray of the bundle meets the box. Empty or non-finite boxes are not
    /// culled (`Some([0, ∞])`). The box is slightly inflated, so a box the bundle misses is
    /// missed by a margin well above the rounding of the callers' per-ray tests.
    pub fn box_range(&self, b: &Aabb) -> Option<Interval> {
        let all = Interval::new(0.0, f64::INFINITY);
        if !b.is_finite() {
            return Some(all);
        }
        let c = b.center();
        let v = c - self.origin;
        let l = v.length();
        let radius = (0.5 * (b.max - b.min).length() + self.origin_radius) * (1.0 + RELATIVE_SLACK)
            + 1e-9 * (l + c.length());
        if self.outside_a_plane(b) {
            return None;
        }
        let near = Interval::new(0.0, l + radius);
        if l <= radius || self.is_unbounded() {
            return Some(near);
        }
        let beta = (v.dot(self.axis) / l).clamp(-1.0, 1.0).acos();
        let gap = beta - self.half_angle;
        let range = Interval::new((l - radius).max(0.0), l + radius);
        if gap <= 0.0 {
            return Some(range);
        }
        // The nearest point of the cone to the centre is on its surface (or the apex).
        if gap >= 0.5 * PI || l * gap.sin() > radius {
            return None;
        }
        Some(range)
    }
}

/// The two planes through the origin, each containing the axis `a × c`, that bound the projections
/// of `dirs` on the (orthonormal) `a`/`c` plane: unit normals `n` with `n · d ≥ 0` for every `d`
/// (with [`ANGLE_SLACK`] to spare). `None` when the projected wedge is not well inside a
/// half-plane (or a direction projects onto the axis).
fn wedge(dirs: &[DVec3], a: DVec3, c: DVec3) -> Option<[DVec3; 2]> {
    let flat: Vec<(f64, f64)> = dirs.iter().map(|d| (d.dot(a), d.dot(c))).collect();
    let mut m = (0.0, 0.0);
    for &(x, y) in &flat {
        let len = x.hypot(y);
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        m = (m.0 + x / len, m.1 + y / len);
    }
    let len = m.0.hypot(m.1);
    if len.is_nan() || len <= 1e-6 {
        return None;
    }
    let m = (m.0 / len, m.1 / len);
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for &(x, y) in &flat {
        let angle = (m.0 * y - m.1 * x).atan2(m.0 * x + m.1 * y);
        lo = lo.min(angle);
        hi = hi.max(angle);
    }
    let (lo, hi) = (lo - ANGLE_SLACK, hi + ANGLE_SLACK);
    if lo <= -0.5 * PI + 1e-6 || hi >= 0.5 * PI - 1e-6 {
        return None;
    }
    let rotate = |t: f64| (m.0 * t.cos() - m.1 * t.sin(), m.0 * t.sin() + m.1 * t.cos());
    let (w0, w1) = (rotate(lo), rotate(hi));
    // Inside is counter-clockwise of w0 and clockwise of w1.
    Some([a * -w0.1 + c * w0.0, a * w1.1 - c * w1.0])
}

/// `n` normalised and flipped so that `n · inside ≥ 0`; zero if degenerate (plane unused).
fn orient(n: DVec3, inside: DVec3) -> DVec3 {
    let len = n.length();
    if !(len > 0.0 && len.is_finite()) {
        return DVec3::ZERO;
    }
    let n = n / len;
    if n.dot(inside) < 0.0 { -n } else { n }
}
