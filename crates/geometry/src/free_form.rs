//! A free-form object: a base quadric plus perturbations, `F′ = F + Σ fᵢ Rᵢ`, inside a finite box.

use crate::{GeometryError, Perturbation, Quadric};
use fray_core::Aabb;
use glam::{DAffine3, DVec3};

/// `F′(p) = F(p) + Σ fᵢ Rᵢ(p)` restricted to a finite box.
///
/// The box is derived when possible: the base quadric's solid ellipsoid united with the supports
/// of the perturbations that add material (`f > 0`); outside that box `F′ < 0` is guaranteed, so a
/// derived box never changes the shape. An explicit box *clips* the shape (it acts as a CSG
/// intersection with the box), which is how planes, cylinders and cones are made finite.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeForm {
    base: Quadric,
    perturbations: Vec<Perturbation>,
    bounds: Aabb,
    clips: bool,
}

impl FreeForm {
    /// Builds the object; `bounds = None` asks for a derived box, which fails with
    /// [`GeometryError::Unbounded`] when the shape is not provably finite.
    pub fn new(
        base: Quadric,
        perturbations: Vec<Perturbation>,
        bounds: Option<Aabb>,
    ) -> Result<Self, GeometryError> {
        if !base.is_finite() {
            return Err(GeometryError::NotFinite { field: "base" });
        }
        for p in &perturbations {
            if !p.quadric.is_finite() {
                return Err(GeometryError::NotFinite {
                    field: "perturbations.quadric",
                });
            }
            if !p.form_factor.is_finite() {
                return Err(GeometryError::NotFinite {
                    field: "perturbations.form_factor",
                });
            }
        }
        let derived = Self::derived_bounds(&base, &perturbations);
        let (bounds, clips) = match (bounds, derived) {
            (Some(b), derived) => {
                if !b.is_finite() {
                    return Err(GeometryError::InvalidBounds);
                }
                match derived {
                    // The explicit box holds the whole shape: it clips nothing, so use the tighter one.
                    Some(d) if b.contains(d.min) && b.contains(d.max) => (d, false),
                    _ => (b, true),
                }
            }
            (None, Some(d)) => (d, false),
            (None, None) => return Err(GeometryError::Unbounded),
        };
        Ok(Self {
            base,
            perturbations,
            bounds,
            clips,
        })
    }

    /// The object moved by the affine map `t` (`p ↦ M p + v`): `F′_t(t(p)) = F′(p)`. The base and
    /// every perturbation's quadric are mapped exactly (`Quadric::transformed`) and a derived box is
    /// derived again; an explicit clipping box can only follow a map that keeps boxes
    /// axis-aligned (a diagonal `M`: translation and scale), since a rotated box is no box.
    pub fn moved(&self, t: &DAffine3) -> Result<Self, GeometryError> {
        let map = |q: &Quadric| q.transformed(t).ok_or(GeometryError::SingularTransform);
        let base = map(&self.base)?;
        let perturbations = self
            .perturbations
            .iter()
            .map(|p| Ok(Perturbation::new(p.form_factor, map(&p.quadric)?)))
            .collect::<Result<Vec<_>, GeometryError>>()?;
        if !self.clips {
            return Self::new(base, perturbations, None);
        }
        let m = t.matrix3;
        let diagonal = m.x_axis.y == 0.0
            && m.x_axis.z == 0.0
            && m.y_axis.x == 0.0
            && m.y_axis.z == 0.0
            && m.z_axis.x == 0.0
            && m.z_axis.y == 0.0;
        if !diagonal {
            return Err(GeometryError::ClipNotMovable { how: "rotated" });
        }
        let (a, b) = (
            t.transform_point3(self.bounds.min),
            t.transform_point3(self.bounds.max),
        );
        let bounds = Aabb::new(a.min(b), a.max(b));
        Ok(Self {
            base,
            perturbations,
            bounds,
            clips: true,
        })
    }

    /// What [`FreeForm::moved`] refuses, exactly: the object moved by any affine map `t` as the
    /// intersection (CSG `min`) of its unclipped self and the six half-spaces of its moved
    /// clipping box — the box turned with the object, which no axis-aligned box can be. Each
    /// part is clipped only by the box around the moved box's corners, which holds their
    /// intersection, so that clip cuts nothing of it. The unclipped object comes first.
    pub fn moved_as_box_intersection(&self, t: &DAffine3) -> Result<Vec<Self>, GeometryError> {
        let map = |q: &Quadric| q.transformed(t).ok_or(GeometryError::SingularTransform);
        let (lo, hi) = (self.bounds.min, self.bounds.max);
        let corners = (0..8).map(|k| {
            let pick = |bit: u32, a: f64, b: f64| if k & (1 << bit) == 0 { a } else { b };
            t.transform_point3(DVec3::new(
                pick(0, lo.x, hi.x),
                pick(1, lo.y, hi.y),
                pick(2, lo.z, hi.z),
            ))
        });
        let around = corners.fold(Aabb::EMPTY, |b, c| b.union(&Aabb::new(c, c)));
        let perturbations = self
            .perturbations
            .iter()
            .map(|p| Ok(Perturbation::new(p.form_factor, map(&p.quadric)?)))
            .collect::<Result<Vec<_>, GeometryError>>()?;
        let mut parts = vec![Self::new(map(&self.base)?, perturbations, Some(around))?];
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            // Inside the box: at or above its lower face, at or below its upper one.
            for (point, outward) in [(lo, -axis), (hi, axis)] {
                let face = map(&Quadric::half_space(point, outward))?;
                parts.push(Self::new(face, Vec::new(), Some(around))?);
            }
        }
        Ok(parts)
    }

    fn derived_bounds(base: &Quadric, perturbations: &[Perturbation]) -> Option<Aabb> {
        let mut b = base.inside_bounds()?;
        for p in perturbations.iter().filter(|p| p.form_factor > 0.0) {
            b = b.union(&p.support_bounds()?);
        }
        Some(b)
    }

    pub fn base(&self) -> &Quadric {
        &self.base
    }

    pub fn perturbations(&self) -> &[Perturbation] {
        &self.perturbations
    }

    /// The finite box that holds the object.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// [`FreeForm::bounds`] in place: the hot slab tests read the box where it lives rather
    /// than a fresh stack copy (stored and reloaded in other widths, which stalls store
    /// forwarding on every cast).
    #[inline]
    pub(crate) fn bounds_ref(&self) -> &Aabb {
        &self.bounds
    }

    /// Whether the box cuts the shape (explicit bounds), so its faces can be surface.
    pub fn clips(&self) -> bool {
        self.clips
    }

    /// `F′(p)` without the box.
    #[inline]
    pub fn eval_unclipped(&self, p: DVec3) -> f64 {
        self.base.eval(p) + self.perturbations.iter().map(|q| q.eval(p)).sum::<f64>()
    }

    /// `∇F′(p)` without the box.
    pub fn gradient_unclipped(&self, p: DVec3) -> DVec3 {
        self.perturbations
            .iter()
            .fold(self.base.gradient(p), |g, q| g + q.gradient(p))
    }

    /// `F′(p)` with the box: `−∞` outside a clipping box.
    #[inline]
    pub fn eval(&self, p: DVec3) -> f64 {
        if self.clips && !self.bounds.contains(p) {
            f64::NEG_INFINITY
        } else {
            self.eval_unclipped(p)
        }
    }

    /// A value whose sign is the sign of the clipped object and whose gradient is the surface's
    /// gradient at a surface point: `min(F′, distance to the box faces)` for a clipping box.
    pub fn eval_with_gradient(&self, p: DVec3) -> (f64, DVec3) {
        let f = self.eval_unclipped(p);
        if self.clips {
            let (d, n) = box_inner_distance(&self.bounds, p);
            if d < f {
                return (d, -n);
            }
        }
        (f, self.gradient_unclipped(p))
    }

    /// [`FreeForm::eval_with_gradient`] summing only the perturbations `subset` (increasing
    /// indices). Bit-identical to it when every perturbation left out is zero at `p` (`Q(p) ≤ 0`):
    /// the left-out terms are `+0`, whose only effect on a sum is turning a `−0` into `+0`, which
    /// one `+ 0.0` at the end reproduces.
    #[inline]
    pub fn eval_with_gradient_subset(&self, p: DVec3, subset: &[u32]) -> (f64, DVec3) {
        if subset.is_empty() {
            // A plain leaf here (the common case): value and gradient from one `p − origin`,
            // the same bits as the general path below.
            let (base, g) = self.base.eval_and_gradient(p);
            let f = base + 0.0; // the empty sum, as below
            if self.clips {
                let (d, n) = box_inner_distance(&self.bounds, p);
                if d < f {
                    return (d, -n);
                }
            }
            let g = if self.perturbations.is_empty() {
                g
            } else {
                g + DVec3::ZERO // as `gradient_subset` marks dropped terms
            };
            return (f, g);
        }
        let terms = || {
            subset
                .iter()
                .filter_map(|&k| self.perturbations.get(k as usize))
        };
        let dropped = subset.len() < self.perturbations.len();
        let sum = terms().map(|q| q.eval(p)).sum::<f64>();
        let f = self.base.eval(p) + if dropped { sum + 0.0 } else { sum };
        if self.clips {
            let (d, n) = box_inner_distance(&self.bounds, p);
            if d < f {
                return (d, -n);
            }
        }
        (f, self.gradient_subset(p, subset))
    }

    /// `∇F′(p)` (without the box) summing only the perturbations `subset`: the gradient that
    /// [`FreeForm::eval_with_gradient_subset`] returns off the box faces, bit for bit.
    #[inline]
    pub fn gradient_subset(&self, p: DVec3, subset: &[u32]) -> DVec3 {
        let mut g = subset
            .iter()
            .filter_map(|&k| self.perturbations.get(k as usize))
            .fold(self.base.gradient(p), |g, q| g + q.gradient(p));
        if subset.len() < self.perturbations.len() {
            g += DVec3::ZERO;
        }
        g
    }

    /// The closed-form first entry for an object with no perturbations, in f64 and without the
    /// caster's widening (docs/accuracy.md; a cross-check, not the accuracy tests' reference,
    /// which is double-double): the first point of the box's ray range where the quadratic is
    /// `≥ 0`, which
    /// for a clipping box is the box face when the ray enters the box inside the quadric.
    /// `None` if the object has perturbations or nothing is hit.
    pub fn closed_form_hit(&self, ray: &fray_core::Ray, range: fray_core::Interval) -> Option<f64> {
        if !self.perturbations.is_empty() {
            return None;
        }
        let range = self.bounds.clip_ray(ray, range)?;
        self.base.on_ray(ray).first_nonnegative(range)
    }
}

/// The signed distance from `p` to the nearest face of `b`, positive inside, and that face's
/// outward normal.
#[inline]
fn box_inner_distance(b: &Aabb, p: DVec3) -> (f64, DVec3) {
    // The six face distances in a fixed order, the first strictly smallest winning: selects
    // rather than branches (which face is nearest varies from pixel to pixel), and the
    // normal looked up at the end.
    const NORMALS: [DVec3; 7] = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::X,
        DVec3::NEG_Y,
        DVec3::Y,
        DVec3::NEG_Z,
        DVec3::Z,
    ];
    let (lo, hi) = (p - b.min, b.max - p);
    let mut best = (f64::INFINITY, 0usize);
    for (k, d) in [lo.x, hi.x, lo.y, hi.y, lo.z, hi.z].into_iter().enumerate() {
        best = if d < best.0 { (d, k + 1) } else { best };
    }
    (best.0, NORMALS[best.1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_are_derived_for_ellipsoids_and_grow_with_positive_perturbations() {
        let base = Quadric::sphere(DVec3::ZERO, 1.0);
        let bump = Perturbation::new(0.5, Quadric::sphere(DVec3::new(1.0, 0.0, 0.0), 0.5));
        let dent = Perturbation::new(-0.5, Quadric::sphere(DVec3::new(-1.0, 0.0, 0.0), 0.5));
        let f = FreeForm::new(base, vec![bump, dent], None).unwrap();
        assert!(!f.clips());
        assert!(f.bounds().max.x >= 1.5 && f.bounds().min.x <= -1.0 && f.bounds().min.x > -1.01);
        // Outside the derived box the function is negative: sample a shell around the box.
        for i in 0..2000 {
            let a = i as f64 * 0.7;
            let dir = DVec3::new(
                a.cos() * (a * 0.31).sin(),
                (a * 0.31).cos(),
                a.sin() * (a * 0.31).sin(),
            );
            let p = f.bounds().center() + dir * f.bounds().diagonal();
            assert!(f.eval(p) < 0.0);
        }
    }

    #[test]
    fn unbounded_shapes_need_a_box_and_the_box_clips() {
        let cyl = Quadric::cylinder(DVec3::ZERO, DVec3::Y, 1.0);
        assert_eq!(
            FreeForm::new(cyl, vec![], None).unwrap_err(),
            GeometryError::Unbounded
        );
        let positive_plane = Perturbation::new(1.0, Quadric::half_space(DVec3::ZERO, DVec3::Y));
        assert_eq!(
            FreeForm::new(
                Quadric::sphere(DVec3::ZERO, 1.0),
                vec![positive_plane],
                None
            )
            .unwrap_err(),
            GeometryError::Unbounded
        );
        let b = Aabb::new(DVec3::new(-2.0, -1.0, -2.0), DVec3::new(2.0, 1.0, 2.0));
        let f = FreeForm::new(cyl, vec![], Some(b)).unwrap();
        assert!(f.clips());
        assert_eq!(f.eval(DVec3::new(0.0, 1.5, 0.0)), f64::NEG_INFINITY);
        // On the top cap the gradient is the cap's: the outward normal is +y.
        let (v, g) = f.eval_with_gradient(DVec3::new(0.2, 1.0 - 1e-12, 0.1));
        assert!(v >= 0.0 && (-g.normalize() - DVec3::Y).length() < 1e-12);
        assert!(FreeForm::new(cyl, vec![], Some(Aabb::EMPTY)).is_err());
    }

    #[test]
    fn perturbation_gradient_matches_finite_differences() {
        let base = Quadric::sphere(DVec3::ZERO, 1.0);
        let bump = Perturbation::new(
            0.8,
            Quadric::ellipsoid(DVec3::new(0.8, 0.2, 0.0), DVec3::new(0.5, 0.3, 0.4)),
        );
        let f = FreeForm::new(base, vec![bump], None).unwrap();
        let p = DVec3::new(0.9, 0.25, 0.05);
        let g = f.gradient_unclipped(p);
        let h = 1e-6;
        for axis in 0..3 {
            let mut e = DVec3::ZERO;
            e[axis] = h;
            let fd = (f.eval(p + e) - f.eval(p - e)) / (2.0 * h);
            assert!((fd - g[axis]).abs() < 1e-6);
        }
    }
}
