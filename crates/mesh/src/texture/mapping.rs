//! Projected mappings for surfaces without UVs (free forms, terrain): a `(point, normal) → uv`
//! rule — planar, spherical, cylindrical, or triplanar (three planar lookups blended by the
//! normal) — each also giving its uv per world unit at the point for the footprint rule.
//!
//! Every mapping is finite on every finite input: a zero normal, the sphere's centre, a point on
//! the cylinder's axis give a stated uv and weights (never NaN); a non-finite uv component
//! reads 0.

use super::{Texture, TextureError, Wrap};
use glam::{DVec2, DVec3, Vec4};
use std::f64::consts::{PI, TAU};

/// A projected mapping (module documentation); build one with its variant's `new`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// A projection onto a plane ([`Planar`]).
    Planar(Planar),
    /// Latitude and longitude about a centre ([`Spherical`]).
    Spherical(Spherical),
    /// Angle around an axis and height along it ([`Cylindrical`]).
    Cylindrical(Cylindrical),
    /// Three axis-aligned planar projections blended by the normal ([`Triplanar`]).
    Triplanar(Triplanar),
}

/// What a mapping gives at a point: up to three `(uv, weight)` lookups (unused ones weigh 0;
/// the weights sum to 1) and the uv per world unit there, for
/// [`Footprint::uv_width`](super::Footprint::uv_width).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    /// The lookups' uvs (for triplanar: the x, y and z faces' projections, in that order).
    pub uv: [DVec2; 3],
    /// Their weights: non-negative, summing to 1.
    pub weight: [f64; 3],
    /// The largest uv length per world length at the point (conservative); finite, at most
    /// `f64::MAX` (where the map itself is singular: a sphere's poles, a cylinder's axis).
    pub uv_per_world: f64,
}

impl Projected {
    fn single(uv: DVec2, uv_per_world: f64) -> Self {
        Self {
            uv: [finite2(uv), DVec2::ZERO, DVec2::ZERO],
            weight: [1.0, 0.0, 0.0],
            uv_per_world: finite_scale(uv_per_world),
        }
    }

    /// The uv of the heaviest lookup (the only one, except for triplanar).
    pub fn main_uv(&self) -> DVec2 {
        let mut k = 0;
        for i in 1..3 {
            if self.weight[i] > self.weight[k] {
                k = i;
            }
        }
        self.uv[k]
    }

    /// The weighted sum of the lookups' anti-aliased samples ([`Texture::sample`]) at a
    /// footprint `uv_width` wide.
    pub fn sample(&self, texture: &Texture, uv_width: f64, wrap: Wrap) -> Vec4 {
        let mut sum = Vec4::ZERO;
        for (uv, &w) in self.uv.iter().zip(&self.weight) {
            if w > 0.0 {
                sum += texture.sample(*uv, uv_width, wrap) * w as f32;
            }
        }
        sum
    }
}

impl Mapping {
    /// The lookups and the scale at `point` with outward `normal` (need not be unit; only
    /// triplanar reads it).
    pub fn project(&self, point: DVec3, normal: DVec3) -> Projected {
        match self {
            Mapping::Planar(m) => Projected::single(m.uv(point), m.uv_per_world),
            Mapping::Spherical(m) => m.project(point),
            Mapping::Cylindrical(m) => m.project(point),
            Mapping::Triplanar(m) => m.project(point, normal),
        }
    }
}

fn finite(x: f64) -> f64 {
    if x.is_finite() { x } else { 0.0 }
}

fn finite2(uv: DVec2) -> DVec2 {
    DVec2::new(finite(uv.x), finite(uv.y))
}

fn finite_scale(s: f64) -> f64 {
    if s.is_nan() {
        f64::MAX
    } else {
        s.clamp(0.0, f64::MAX)
    }
}

fn param(name: &'static str, message: impl Into<String>) -> TextureError {
    TextureError::Parameter {
        name,
        message: message.into(),
    }
}

fn check_point(name: &'static str, p: DVec3) -> Result<DVec3, TextureError> {
    if p.is_finite() {
        Ok(p)
    } else {
        Err(param(name, format!("must be finite, got {p}")))
    }
}

fn check_axis(name: &'static str, a: DVec3) -> Result<DVec3, TextureError> {
    a.try_normalize()
        .ok_or_else(|| param(name, format!("must be a finite non-zero vector, got {a}")))
}

fn check_positive(name: &'static str, x: f64) -> Result<f64, TextureError> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(param(name, format!("must be finite and > 0, got {x}")))
    }
}

/// A frame of two orthonormal axes from an axis and a reference direction (Gram–Schmidt): the
/// reference must not be parallel to the axis.
fn frame(
    axis_name: &'static str,
    axis: DVec3,
    seam_name: &'static str,
    seam: DVec3,
) -> Result<(DVec3, DVec3), TextureError> {
    let axis = check_axis(axis_name, axis)?;
    let seam = check_axis(seam_name, seam)?;
    let s = seam - axis * seam.dot(axis);
    let s = s
        .try_normalize()
        .filter(|_| s.length() > 1e-9)
        .ok_or_else(|| param(seam_name, format!("must not be parallel to {axis_name}")))?;
    Ok((axis, s))
}

/// Planar: `uv = ((p − origin)·û · scale.x, (p − origin)·v̂ · scale.y)` with unit axes `û`, `v̂`
/// (not parallel; need not be orthogonal). Seen with `û` to the right and `v̂` up the image is
/// upright.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planar {
    pub(super) origin: DVec3,
    /// `û · scale.x` and `v̂ · scale.y`.
    pub(super) u: DVec3,
    pub(super) v: DVec3,
    pub(super) uv_per_world: f64,
}

impl Planar {
    /// `scale`: uv per world unit along each axis (both > 0; 1/tile size).
    pub fn new(
        origin: DVec3,
        u_axis: DVec3,
        v_axis: DVec3,
        scale: DVec2,
    ) -> Result<Self, TextureError> {
        let origin = check_point("origin", origin)?;
        let (ua, va) = (check_axis("u_axis", u_axis)?, check_axis("v_axis", v_axis)?);
        if ua.cross(va).length() < 1e-9 {
            return Err(param("v_axis", "must not be parallel to u_axis"));
        }
        let (su, sv) = (
            check_positive("scale.x", scale.x)?,
            check_positive("scale.y", scale.y)?,
        );
        let (u, v) = (ua * su, va * sv);
        // σmax of the 2 × 3 map [u; v]: the larger eigenvalue of its Gram matrix.
        let (a, b, c) = (u.dot(u), u.dot(v), v.dot(v));
        let s = (0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt()).sqrt();
        Ok(Self {
            origin,
            u,
            v,
            uv_per_world: s,
        })
    }

    /// The uv of `point`.
    pub fn uv(&self, point: DVec3) -> DVec2 {
        let d = point - self.origin;
        finite2(DVec2::new(d.dot(self.u), d.dot(self.v)))
    }

    /// The uv per world unit: the largest stretch of the projection, `max(scale)` for
    /// orthogonal axes, the same at every point.
    pub fn uv_per_world(&self) -> f64 {
        self.uv_per_world
    }
}

/// Spherical (latitude–longitude): `u = repeat.x · φ / 2π`, `φ ∈ [0, 2π)` the longitude from
/// `seam` counter-clockwise about `pole` (east, seen from outside with the pole up, is to the
/// right: the image is not mirrored); `v = repeat.y · (1 − θ/π)`, `θ` the angle from `pole`
/// (the pole is the image's top row). At the centre: `uv = (0, repeat.y/2)`; at the poles `u = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spherical {
    pub(super) centre: DVec3,
    pub(super) pole: DVec3,
    pub(super) seam: DVec3,
    pub(super) east: DVec3,
    pub(super) repeat: DVec2,
}

impl Spherical {
    /// `pole`: the direction of `v = repeat.y`; `seam`: the direction of `u = 0` (made
    /// perpendicular to the pole; not parallel to it); `repeat`: copies around (u) and pole to
    /// pole (v), both > 0.
    pub fn new(
        centre: DVec3,
        pole: DVec3,
        seam: DVec3,
        repeat: DVec2,
    ) -> Result<Self, TextureError> {
        let centre = check_point("centre", centre)?;
        let (pole, seam) = frame("pole", pole, "seam", seam)?;
        check_positive("repeat.x", repeat.x)?;
        check_positive("repeat.y", repeat.y)?;
        Ok(Self {
            centre,
            pole,
            seam,
            east: pole.cross(seam),
            repeat,
        })
    }

    /// The uv and the scale at `point`: `max(repeat.y / (π r), repeat.x / (2π r sin θ))`, the
    /// meridian's and the parallel's stretch (unbounded at the poles and the centre: capped to
    /// `f64::MAX`).
    pub fn project(&self, point: DVec3) -> Projected {
        let d = point - self.centre;
        let r = d.length();
        if !(r > 0.0 && r.is_finite()) {
            return Projected::single(DVec2::new(0.0, 0.5 * self.repeat.y), f64::MAX);
        }
        let (x, y, z) = (d.dot(self.seam), d.dot(self.east), d.dot(self.pole));
        let ring = x.hypot(y);
        let theta = ring.atan2(z);
        // On the axis through the poles every longitude meets: u = 0 there.
        let mut phi = if ring > 0.0 { y.atan2(x) } else { 0.0 };
        if phi < 0.0 {
            phi += TAU;
        }
        let uv = DVec2::new(
            self.repeat.x * phi / TAU,
            self.repeat.y * (1.0 - theta / PI),
        );
        let scale = (self.repeat.y / (PI * r)).max(self.repeat.x / (TAU * ring));
        Projected::single(uv, scale)
    }
}

/// Cylindrical: `u = repeat_u · φ / 2π`, `φ ∈ [0, 2π)` around `axis` from `seam`
/// counter-clockwise (east to the right seen from outside), `v = (p − origin)·axis · scale_v`.
/// On the axis: `u = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylindrical {
    pub(super) origin: DVec3,
    pub(super) axis: DVec3,
    pub(super) seam: DVec3,
    pub(super) east: DVec3,
    pub(super) repeat_u: f64,
    pub(super) scale_v: f64,
}

impl Cylindrical {
    /// `origin` on the axis (`v = 0` there); `axis`: `v` grows along it; `seam`: `u = 0`
    /// (not parallel to the axis); `repeat_u`: copies around; `scale_v`: uv per world unit
    /// along the axis. Both > 0.
    pub fn new(
        origin: DVec3,
        axis: DVec3,
        seam: DVec3,
        repeat_u: f64,
        scale_v: f64,
    ) -> Result<Self, TextureError> {
        let origin = check_point("origin", origin)?;
        let (axis, seam) = frame("axis", axis, "seam", seam)?;
        Ok(Self {
            origin,
            axis,
            seam,
            east: axis.cross(seam),
            repeat_u: check_positive("repeat_u", repeat_u)?,
            scale_v: check_positive("scale_v", scale_v)?,
        })
    }

    /// The uv and the scale at `point`: `max(scale_v, repeat_u / (2π ρ))`, `ρ` the distance to
    /// the axis (on the axis: `f64::MAX`).
    pub fn project(&self, point: DVec3) -> Projected {
        let d = point - self.origin;
        let (x, y, h) = (d.dot(self.seam), d.dot(self.east), d.dot(self.axis));
        let rho = x.hypot(y);
        let mut phi = if rho > 0.0 { y.atan2(x) } else { 0.0 };
        if phi < 0.0 {
            phi += TAU;
        }
        let uv = DVec2::new(self.repeat_u * phi / TAU, self.scale_v * h);
        Projected::single(uv, self.scale_v.max(self.repeat_u / (TAU * rho)))
    }
}

/// Triplanar: three planar projections along the world axes, `scale` uv per world unit, blended
/// by `wᵢ = |nᵢ|^sharpness / Σⱼ |nⱼ|^sharpness` (normalised by the largest component first, so
/// a large sharpness never underflows to 0/0; a zero or non-finite normal weighs each 1/3).
/// Each face is upright and unmirrored seen from outside: `+x`: `(−z, y)`, `−x`: `(z, y)`,
/// `+y`: `(x, −z)`, `−y`: `(x, z)`, `+z`: `(x, y)`, `−z`: `(−x, y)`, relative to `origin`,
/// times `scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triplanar {
    pub(super) origin: DVec3,
    pub(super) scale: f64,
    pub(super) sharpness: f64,
}

impl Triplanar {
    /// `scale` > 0 (uv per world unit); `sharpness` ≥ 0 (0: equal thirds; 1: `|n|`; larger:
    /// sharper transitions between faces; common: 4).
    pub fn new(origin: DVec3, scale: f64, sharpness: f64) -> Result<Self, TextureError> {
        if !(sharpness.is_finite() && sharpness >= 0.0) {
            return Err(param(
                "sharpness",
                format!("must be finite and ≥ 0, got {sharpness}"),
            ));
        }
        Ok(Self {
            origin: check_point("origin", origin)?,
            scale: check_positive("scale", scale)?,
            sharpness,
        })
    }

    /// The blend weights for `normal`, summing to 1.
    pub fn weights(&self, normal: DVec3) -> [f64; 3] {
        let a = normal.abs();
        let m = a.max_element();
        if !(m > 0.0 && m.is_finite()) {
            return [1.0 / 3.0; 3];
        }
        let w = (a / m).to_array().map(|x| x.powf(self.sharpness));
        let sum: f64 = w.iter().sum();
        w.map(|x| x / sum)
    }

    /// The three lookups at `point` and their weights for `normal`; scale: `scale`.
    pub fn project(&self, point: DVec3, normal: DVec3) -> Projected {
        let d = (point - self.origin) * self.scale;
        let side = |c: f64| if c < 0.0 { -1.0 } else { 1.0 };
        let uv = [
            DVec2::new(-side(normal.x) * d.z, d.y),
            DVec2::new(d.x, -side(normal.y) * d.z),
            DVec2::new(side(normal.z) * d.x, d.y),
        ];
        Projected {
            uv: uv.map(finite2),
            weight: self.weights(normal),
            uv_per_world: self.scale,
        }
    }
}
