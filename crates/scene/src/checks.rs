//! The checks every resolver shares: a resolution failure at a field path, and the checked
//! numbers, points, directions, angles, boxes, transforms and material names of a description.

use crate::description::{self, Vec3};
use crate::path::FieldPath;
use fray_core::Aabb;
use glam::{DAffine3, DMat3, DVec3};
use std::collections::BTreeMap;

/// A resolution failure: the offending field and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Invalid {
    pub(crate) path: FieldPath,
    pub(crate) message: String,
}

pub(crate) type Result<T> = std::result::Result<T, Invalid>;

pub(crate) fn invalid<T>(path: &FieldPath, message: impl Into<String>) -> Result<T> {
    Err(Invalid {
        path: path.clone(),
        message: message.into(),
    })
}

pub(crate) fn show(v: Vec3) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

pub(crate) fn finite(path: &FieldPath, x: f64) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        invalid(path, format!("must be a finite number, got {x}"))
    }
}

pub(crate) fn point(path: &FieldPath, v: Vec3) -> Result<DVec3> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        invalid(path, format!("must be finite, got {}", show(v)))
    }
}

pub(crate) fn direction(path: &FieldPath, v: Vec3) -> Result<DVec3> {
    let d = point(path, v)?;
    let len = d.length();
    if len > 0.0 && len.is_finite() {
        Ok(d)
    } else {
        invalid(path, format!("must be a non-zero vector, got {}", show(v)))
    }
}

pub(crate) fn positive(path: &FieldPath, x: f64) -> Result<f64> {
    if !x.is_finite() {
        invalid(path, format!("must be a finite number > 0, got {x}"))
    } else if x > 0.0 {
        Ok(x)
    } else {
        invalid(path, format!("must be > 0, got {x}"))
    }
}

pub(crate) fn non_negative(path: &FieldPath, x: f64) -> Result<f64> {
    if x >= 0.0 && x.is_finite() {
        Ok(x)
    } else {
        invalid(path, format!("must be ≥ 0, got {x}"))
    }
}

/// An angle in degrees, checked against `(lo, hi)` (or `(lo, hi]` when `hi_closed`), in radians.
pub(crate) fn angle(
    path: &FieldPath,
    degrees: f64,
    lo: f64,
    hi: f64,
    hi_closed: bool,
) -> Result<f64> {
    let ok = degrees > lo && (degrees < hi || (hi_closed && degrees == hi));
    if ok {
        Ok(degrees.to_radians())
    } else {
        let close = if hi_closed { ']' } else { ')' };
        invalid(
            path,
            format!("must be in ({lo}, {hi}{close} degrees, got {degrees}"),
        )
    }
}

/// An affine map from its description: scale, then rotate about x, y, z (degrees), then translate.
pub(crate) fn transform(path: &FieldPath, t: &description::Transform) -> Result<DAffine3> {
    let translate = point(&path.field("translate"), t.translate)?;
    let rotate = point(&path.field("rotate"), t.rotate)?;
    let scale = point(&path.field("scale"), t.scale)?;
    if scale.abs().min_element() == 0.0 {
        return invalid(
            &path.field("scale"),
            format!("must be non-zero on every axis, got {}", show(t.scale)),
        );
    }
    let r = DMat3::from_rotation_z(rotate.z.to_radians())
        * DMat3::from_rotation_y(rotate.y.to_radians())
        * DMat3::from_rotation_x(rotate.x.to_radians());
    Ok(DAffine3::from_mat3_translation(
        r * DMat3::from_diagonal(scale),
        translate,
    ))
}

pub(crate) fn bounds(path: &FieldPath, b: &description::Bounds) -> Result<Aabb> {
    let min = point(&path.field("min"), b.min)?;
    let max = point(&path.field("max"), b.max)?;
    if min.cmple(max).all() {
        Ok(Aabb::new(min, max))
    } else {
        invalid(
            path,
            format!(
                "`min` must be ≤ `max` on every axis, got min {} and max {}",
                show(b.min),
                show(b.max)
            ),
        )
    }
}

/// The index of the material `name` (`default`: the built-in one, 0) among the scene's,
/// `materials` the defined ones by name.
pub(crate) fn material(
    materials: &BTreeMap<&str, u32>,
    path: &FieldPath,
    name: &str,
) -> Result<u32> {
    if name == "default" {
        return Ok(0);
    }
    match materials.get(name) {
        Some(&i) => Ok(i),
        None => {
            let known: Vec<String> = materials.keys().map(|k| format!("`{k}`")).collect();
            let known = if known.is_empty() {
                "none are defined".to_owned()
            } else {
                known.join(", ")
            };
            invalid(
                path,
                format!("unknown material `{name}` (defined: {known})"),
            )
        }
    }
}
