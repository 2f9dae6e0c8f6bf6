//! Resolving a CSG shape tree of free forms into a [`Solid`]: quadrics placed by the
//! accumulated transforms, perturbations, bounds, a material per leaf, the `csg` and
//! `perturbations` features. Shared by the free-form objects and the clouds' envelopes.

use crate::FeatureSet;
use crate::checks::{
    Invalid, Result, angle, bounds, direction, finite, invalid, point, positive, show, transform,
};
use crate::description;
use crate::path::FieldPath;
use fray_core::Aabb;
use fray_geometry::{FreeForm, GeometryError, Perturbation, Quadric, Shape, Sheets, Solid};
use glam::{DAffine3, DVec3};
use std::collections::BTreeMap;

/// Per-object state while a shape tree is resolved.
struct ShapeContext<'a> {
    materials: &'a BTreeMap<&'a str, u32>,
    /// One material per leaf, in leaf order (depth first, left to right).
    leaf_materials: Vec<u32>,
    features: &'a mut FeatureSet,
}

impl ShapeContext<'_> {
    fn material(&self, path: &FieldPath, name: &str) -> Result<u32> {
        crate::checks::material(self.materials, path, name)
    }

    /// Resolves `s`, with `outer` the transform of the enclosing `Transformed` shapes and
    /// `material` the material its leaves inherit.
    fn shape(
        &mut self,
        path: &FieldPath,
        s: &description::Shape,
        outer: DAffine3,
        material: u32,
    ) -> Result<Shape> {
        use description::Shape as S;
        match s {
            S::Quadric(q) => self.free_form(path, path, q, &[], None, outer, material),
            S::FreeForm(f) => {
                let material = match &f.material {
                    Some(name) => self.material(&path.field("material"), name)?,
                    None => material,
                };
                let t = match &f.transform {
                    Some(t) => outer * transform(&path.field("transform"), t)?,
                    None => outer,
                };
                let bounds = match &f.bounds {
                    Some(b) => Some(bounds(&path.field("bounds"), b)?),
                    None => None,
                };
                self.free_form(
                    path,
                    &path.field("base"),
                    &f.base,
                    &f.perturbations,
                    bounds,
                    t,
                    material,
                )
            }
            S::Union(children) | S::Intersection(children) => {
                let op = if matches!(s, S::Union(_)) {
                    "Union"
                } else {
                    "Intersection"
                };
                if children.len() < 2 {
                    return invalid(
                        path,
                        format!("a {op} needs at least 2 shapes, got {}", children.len()),
                    );
                }
                self.features.csg = true;
                let mut out = Vec::with_capacity(children.len());
                for (i, c) in children.iter().enumerate() {
                    out.push(self.shape(&path.index(i), c, outer, material)?);
                }
                Ok(if op == "Union" {
                    Shape::Union(out)
                } else {
                    Shape::Intersection(out)
                })
            }
            S::Difference(a, b) => {
                self.features.csg = true;
                let a = self.shape(&path.index(0), a, outer, material)?;
                let b = self.shape(&path.index(1), b, outer, material)?;
                Ok(Shape::Difference(Box::new(a), Box::new(b)))
            }
            S::Transformed {
                shape,
                transform: t,
            } => {
                let inner = outer * transform(&path.field("transform"), t)?;
                self.shape(&path.field("shape"), shape, inner, material)
            }
            // The other kinds: only ever an object's whole shape.
            other => invalid(path, other.whole_shape_only()),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn free_form(
        &mut self,
        path: &FieldPath,
        base_path: &FieldPath,
        base: &description::Quadric,
        perturbations: &[description::Perturbation],
        bounds: Option<Aabb>,
        t: DAffine3,
        material: u32,
    ) -> Result<Shape> {
        let base = placed(path, quadric(base_path, base)?, t)?;
        let perts_path = path.field("perturbations");
        let mut perts = Vec::with_capacity(perturbations.len());
        for (i, p) in perturbations.iter().enumerate() {
            let pp = perts_path.index(i);
            let form_factor = finite(&pp.field("form_factor"), p.form_factor)?;
            if form_factor != 0.0 {
                self.features.perturbations = true;
            }
            let own = match &p.transform {
                Some(own) => transform(&pp.field("transform"), own)?,
                None => DAffine3::IDENTITY,
            };
            let q = placed(&pp, quadric(&pp.field("quadric"), &p.quadric)?, t * own)?;
            perts.push(Perturbation::new(form_factor, q));
        }
        let f = FreeForm::new(base, perts, bounds).map_err(|e| {
            let at = match e {
                GeometryError::InvalidBounds => path.field("bounds"),
                _ => path.clone(),
            };
            Invalid {
                path: at,
                message: e.to_string(),
            }
        })?;
        self.leaf_materials.push(material);
        Ok(Shape::FreeForm(f))
    }
}

/// An object's CSG solid from its `shape` (at `path`) and the material of each of its leaves,
/// which inherit `material` unless they name their own; `materials` are the scene's by name.
pub(crate) fn object_solid(
    path: &FieldPath,
    shape: &description::Shape,
    material: u32,
    materials: &BTreeMap<&str, u32>,
    features: &mut FeatureSet,
) -> Result<(Solid, Vec<u32>)> {
    let mut ctx = ShapeContext {
        materials,
        leaf_materials: Vec::new(),
        features,
    };
    let shape = ctx.shape(path, shape, DAffine3::IDENTITY, material)?;
    let solid = Solid::new(shape).or_else(|e| invalid(path, e.to_string()))?;
    Ok((solid, ctx.leaf_materials))
}

/// A shape that is not drawn but bounds something (a cloud's envelope): its CSG solid, with no
/// materials and no effect on the scene's features.
pub(crate) fn bounding_solid(path: &FieldPath, shape: &description::Shape) -> Result<Solid> {
    let materials = BTreeMap::new();
    let mut features = FeatureSet::default();
    let mut ctx = ShapeContext {
        materials: &materials,
        leaf_materials: Vec::new(),
        features: &mut features,
    };
    let shape = ctx.shape(path, shape, DAffine3::IDENTITY, 0)?;
    Solid::new(shape).or_else(|e| invalid(path, e.to_string()))
}

/// `q` moved by `t` (skipped for the identity, so plain quadrics keep their exact coefficients).
fn placed(path: &FieldPath, q: Quadric, t: DAffine3) -> Result<Quadric> {
    if t == DAffine3::IDENTITY {
        return Ok(q);
    }
    match q.transformed(&t) {
        Some(q) if q.is_finite() => Ok(q),
        _ => invalid(
            path,
            "the accumulated transform is singular or too large for this shape",
        ),
    }
}

fn quadric(path: &FieldPath, q: &description::Quadric) -> Result<Quadric> {
    use description::Quadric as Q;
    Ok(match *q {
        Q::Sphere { center, radius } => Quadric::sphere(
            point(&path.field("center"), center)?,
            positive(&path.field("radius"), radius)?,
        ),
        Q::Ellipsoid { center, radii } => {
            let center = point(&path.field("center"), center)?;
            if !radii.iter().all(|r| r.is_finite() && *r > 0.0) {
                return invalid(
                    &path.field("radii"),
                    format!("must be > 0 on every axis, got {}", show(radii)),
                );
            }
            Quadric::ellipsoid(center, DVec3::from_array(radii))
        }
        Q::HalfSpace { point: p, normal } => Quadric::half_space(
            point(&path.field("point"), p)?,
            direction(&path.field("normal"), normal)?,
        ),
        Q::Cylinder {
            point: p,
            axis,
            radius,
        } => Quadric::cylinder(
            point(&path.field("point"), p)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("radius"), radius)?,
        ),
        Q::Cone {
            apex,
            axis,
            half_angle,
        } => Quadric::cone(
            point(&path.field("apex"), apex)?,
            direction(&path.field("axis"), axis)?,
            angle(&path.field("half_angle"), half_angle, 0.0, 90.0, false)?,
        ),
        Q::Paraboloid {
            vertex,
            axis,
            focal_length,
        } => Quadric::paraboloid(
            point(&path.field("vertex"), vertex)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("focal_length"), focal_length)?,
        ),
        Q::Hyperboloid {
            center,
            axis,
            radius,
            height,
            sheets,
        } => Quadric::hyperboloid(
            point(&path.field("center"), center)?,
            direction(&path.field("axis"), axis)?,
            positive(&path.field("radius"), radius)?,
            positive(&path.field("height"), height)?,
            match sheets {
                description::Sheets::One => Sheets::One,
                description::Sheets::Two => Sheets::Two,
            },
        ),
        Q::General {
            origin,
            coefficients,
        } => {
            let origin = point(&path.field("origin"), origin)?;
            let cpath = path.field("coefficients");
            if let Some(i) = coefficients.iter().position(|c| !c.is_finite()) {
                return invalid(
                    &cpath.index(i),
                    format!("must be a finite number, got {}", coefficients[i]),
                );
            }
            if coefficients.iter().all(|c| *c == 0.0) {
                return invalid(&cpath, "must not all be zero");
            }
            Quadric::new(origin, coefficients)
        }
    })
}
