//! Where a height map sits in the world: the origin (world position of sample `(0, 0)` at raw
//! height 0, the base plane), an orientation, the horizontal spacing of samples and the
//! vertical scale, and the affine map between world space and height-map space `(u, v, r)`.
//!
//! Height-map space: `u` counts columns and `v` rows (in samples, so cell `(i, j)` is
//! `[i, i+1] × [j, j+1]`), `r` is in raw height units. With the identity orientation
//! `(u, v, h) → (x, z, y)`: world `x = origin.x + u · spacing.x`, `z = origin.z + v ·
//! spacing.y`, `y = origin.y + r · vertical_scale` (Y up). The map is affine in `t`, so a ray
//! stays a straight line `(u, v, r)(t) = o + t · d` with `t` still the world distance.

use crate::TerrainError;
use fray_core::Ray;
use glam::{DMat3, DVec2, DVec3};

/// The placement of a height map in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    origin: DVec3,
    /// Columns: the world directions of the map's `u` axis, up axis and `v` axis.
    rotation: DMat3,
    spacing: DVec2,
    vertical_scale: f64,
}

/// A ray in height-map space: `(u, v, r)(t) = origin + t · dir` (components x = u, y = v,
/// z = r), `t` the world distance along the original ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapRay {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl MapRay {
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

impl Placement {
    /// An axis-aligned placement: sample `(0, 0)` at raw height 0 lies at `origin`; samples
    /// are `spacing = (along x, along z)` apart; a raw unit of height is `vertical_scale` world
    /// units. All must be finite, spacing and scale `> 0`.
    pub fn new(origin: DVec3, spacing: DVec2, vertical_scale: f64) -> Result<Self, TerrainError> {
        let bad = |name, message: String| Err(TerrainError::Parameter { name, message });
        if !origin.is_finite() {
            return bad("origin", format!("must be finite, got {origin}"));
        }
        if !(spacing.is_finite() && spacing.x > 0.0 && spacing.y > 0.0) {
            return bad("spacing", format!("must be finite and > 0, got {spacing}"));
        }
        if !(vertical_scale.is_finite() && vertical_scale > 0.0) {
            return bad(
                "vertical_scale",
                format!("must be finite and > 0, got {vertical_scale}"),
            );
        }
        Ok(Self {
            origin,
            rotation: DMat3::IDENTITY,
            spacing,
            vertical_scale,
        })
    }

    /// The same placement turned by `rotation` about its origin (an orthonormal, right-handed
    /// matrix; checked to 1e-9).
    pub fn with_rotation(mut self, rotation: DMat3) -> Result<Self, TerrainError> {
        let orthonormal = (rotation.transpose() * rotation - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|e| e.abs() < 1e-9)
            && (rotation.determinant() - 1.0).abs() < 1e-9;
        if !orthonormal {
            return Err(TerrainError::Parameter {
                name: "rotation",
                message: "must be a rotation (orthonormal, determinant 1)".into(),
            });
        }
        self.rotation = rotation;
        Ok(self)
    }

    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    pub fn rotation(&self) -> DMat3 {
        self.rotation
    }

    pub fn spacing(&self) -> DVec2 {
        self.spacing
    }

    pub fn vertical_scale(&self) -> f64 {
        self.vertical_scale
    }

    /// Map space `(u, v, r)` → world.
    pub fn to_world(&self, p: DVec3) -> DVec3 {
        let local = DVec3::new(
            p.x * self.spacing.x,
            p.z * self.vertical_scale,
            p.y * self.spacing.y,
        );
        self.origin + self.rotation * local
    }

    /// World → map space `(u, v, r)` (the inverse of [`Placement::to_world`]).
    pub fn to_map(&self, w: DVec3) -> DVec3 {
        self.vector_to_map(w - self.origin)
    }

    /// A world vector → map space (no origin).
    fn vector_to_map(&self, w: DVec3) -> DVec3 {
        let l = self.rotation.transpose() * w;
        DVec3::new(
            l.x / self.spacing.x,
            l.z / self.spacing.y,
            l.y / self.vertical_scale,
        )
    }

    /// The ray in map space. Computed relative to the origin, so a map far from the world
    /// origin keeps full precision near itself.
    pub fn map_ray(&self, ray: &Ray) -> MapRay {
        MapRay {
            origin: self.vector_to_map(ray.origin - self.origin),
            dir: self.vector_to_map(ray.dir),
        }
    }

    /// The world unit normal of the surface `r = S(u, v)` with slopes `(∂S/∂u, ∂S/∂v)` (raw
    /// units per sample): `(−σ S_u / Δu, 1, −σ S_v / Δv)` in the map's frame.
    pub fn surface_normal(&self, slope: DVec2) -> DVec3 {
        let s = self.vertical_scale;
        let local = DVec3::new(
            -s * slope.x / self.spacing.x,
            1.0,
            -s * slope.y / self.spacing.y,
        );
        (self.rotation * local).normalize()
    }

    /// The world unit normal of a map-space axis direction (`axis` 0 = u, 1 = v, 2 = r;
    /// `sign` ±1).
    pub fn axis_normal(&self, axis: usize, sign: f64) -> DVec3 {
        let local = match axis {
            0 => DVec3::X,
            1 => DVec3::Z,
            _ => DVec3::Y,
        };
        self.rotation * (local * sign)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_space_round_trips_and_keeps_t_a_world_distance() {
        let rot = DMat3::from_rotation_y(0.3) * DMat3::from_rotation_x(0.1);
        let p = Placement::new(DVec3::new(1e6, -20.0, 3e5), DVec2::new(74.0, 93.0), 2.0)
            .unwrap()
            .with_rotation(rot)
            .unwrap();
        let ray = Ray::new(
            DVec3::new(1e6 + 500.0, 900.0, 3e5 + 700.0),
            DVec3::new(0.3, -1.0, 0.2),
        )
        .unwrap();
        let m = p.map_ray(&ray);
        for t in [0.0, 10.0, 1234.5] {
            let w = p.to_world(m.at(t));
            assert!((w - ray.at(t)).length() < 1e-6, "{w} vs {}", ray.at(t));
        }
        assert!(Placement::new(DVec3::ZERO, DVec2::new(0.0, 1.0), 1.0).is_err());
        assert!(Placement::new(DVec3::ZERO, DVec2::ONE, f64::NAN).is_err());
        let shear = DMat3::from_cols(DVec3::X, DVec3::new(0.1, 1.0, 0.0), DVec3::Z);
        assert!(p.with_rotation(shear).is_err());
    }
}
