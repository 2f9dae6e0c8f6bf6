//! Quadrics `F(x) = A11 x² + A22 y² + A33 z² + A12 xy + A13 xz + A23 yz + A14 x + A24 y + A34 z + A44`
//! in coordinates relative to a stored origin, with named constructors, affine transforms and
//! bounds. Convention: `F ≥ 0` is inside.
//!
//! Keeping an origin per quadric (instead of expanding everything about the world origin) keeps
//! the coefficients small and well-conditioned for objects far from the world origin.

use fray_core::{Aabb, Interval, Ray};
use glam::{DAffine3, DMat3, DMat4, DVec3, DVec4};

use crate::RayQuadratic;

/// A quadric polynomial about `origin`: `F(p) = q(p − origin)` with `q` the ten-coefficient form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    /// The point the coefficients are expressed about (world coordinates).
    pub origin: DVec3,
    /// `[A11, A22, A33, A12, A13, A23, A14, A24, A34, A44]`.
    pub coefficients: [f64; 10],
}

/// Which hyperboloid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sheets {
    One,
    Two,
}

/// A quadric's value and gradient at a ray origin ([`Quadric::at_origin`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OriginTerms {
    pub value: f64,
    pub gradient: DVec3,
    /// `‖o − origin‖₁`, a bound on the distance from the quadric's origin: the scale of the
    /// rounding of `value` and `gradient` (docs/accuracy.md).
    pub distance: f64,
}

/// The unit roundoff of f64, `2⁻⁵³`.
pub(crate) const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// Rounding units per unit of term magnitude in one f64 value of a quadric on a ray: the
/// subtraction `o − origin` (1), `F(o)`, `∇F(o)·d`, `dᵀAd` (≤ 9 more), Horner in `t` (≤ 4),
/// and, where the caster stands a computed root, vertex or bound for the value, the rounding of
/// that root or vertex in value terms (≤ 10 more). Derived in docs/accuracy.md.
pub(crate) const ROUNDING_UNITS: f64 = 24.0;

/// Bounds on the size of a quadric's terms, scaled to a rounding bound: `Φ(r) = K u (α r² + λ r +
/// κ)` bounds `K u` times the sum of the absolute values of the terms of `F(p)` at every point
/// `p` within distance `r` of its origin (`α`: the largest row sum of `|M|`, which bounds
/// `|v|ᵀ|M||v| ≤ α ‖v‖²`; `λ = ‖b‖₂`; `κ = |k|`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Magnitude {
    alpha: f64,
    lambda: f64,
    kappa: f64,
}

impl Magnitude {
    /// `Φ(r)`: the rounding bound of one f64 value of the quadric on a unit-direction ray, at
    /// every parameter `t` with `‖o − origin‖₁ + |t| ≤ r`.
    #[inline]
    pub(crate) fn rounding(&self, r: f64) -> f64 {
        (self.alpha * r + self.lambda) * r + self.kappa
    }

    /// The same bounds negated: [`Magnitude::rounding`] gives `−Φ(r)`.
    pub(crate) fn negated(self) -> Self {
        Self {
            alpha: -self.alpha,
            lambda: -self.lambda,
            kappa: -self.kappa,
        }
    }
}

impl Quadric {
    /// A quadric from its ten coefficients about `origin`.
    pub const fn new(origin: DVec3, coefficients: [f64; 10]) -> Self {
        Self {
            origin,
            coefficients,
        }
    }

    /// `F(x) = xᵀ M x + b·x + k` about `origin`, `M` symmetric.
    pub fn from_parts(origin: DVec3, m: DMat3, b: DVec3, k: f64) -> Self {
        let c = [
            m.x_axis.x,
            m.y_axis.y,
            m.z_axis.z,
            m.y_axis.x + m.x_axis.y,
            m.z_axis.x + m.x_axis.z,
            m.z_axis.y + m.y_axis.z,
            b.x,
            b.y,
            b.z,
            k,
        ];
        Self::new(origin, c)
    }

    /// The symmetric matrix `M`, linear part `b` and constant `k` of the local polynomial.
    pub fn parts(&self) -> (DMat3, DVec3, f64) {
        let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = self.coefficients;
        let m = DMat3::from_cols(
            DVec3::new(a11, 0.5 * a12, 0.5 * a13),
            DVec3::new(0.5 * a12, a22, 0.5 * a23),
            DVec3::new(0.5 * a13, 0.5 * a23, a33),
        );
        (m, DVec3::new(a14, a24, a34), a44)
    }

    /// Solid ball: `1 − |x − c|² / r²` (dimensionless, 1 at the centre).
    pub fn sphere(center: DVec3, radius: f64) -> Self {
        Self::ellipsoid(center, DVec3::splat(radius))
    }

    /// Solid axis-aligned ellipsoid `1 − Σ (xᵢ / rᵢ)²`.
    pub fn ellipsoid(center: DVec3, radii: DVec3) -> Self {
        let inv = (radii * radii).recip();
        Self::new(
            center,
            [-inv.x, -inv.y, -inv.z, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        )
    }

    /// Half-space through `point` whose outward normal is `normal`: `F = −n̂·(x − point)` (metres).
    pub fn half_space(point: DVec3, normal: DVec3) -> Self {
        let n = normal.normalize();
        Self::from_parts(point, DMat3::ZERO, -n, 0.0)
    }

    /// Infinite solid cylinder of `radius` around the line through `point` along `axis`:
    /// `1 − ρ² / r²`, `ρ` the distance to the axis.
    pub fn cylinder(point: DVec3, axis: DVec3, radius: f64) -> Self {
        let a = axis.normalize();
        // ρ² = |x|² − (a·x)²  →  M = −(I − a aᵀ) / r².
        let m = (DMat3::IDENTITY - outer(a, a)) * (-1.0 / (radius * radius));
        Self::from_parts(point, m, DVec3::ZERO, 1.0)
    }

    /// Infinite solid double cone with `apex`, `axis` and `half_angle` (radians):
    /// `(a·x)² tan²α − ρ²` (m²).
    pub fn cone(apex: DVec3, axis: DVec3, half_angle: f64) -> Self {
        let a = axis.normalize();
        let t2 = half_angle.tan().powi(2);
        let m = outer(a, a) * (t2 + 1.0) - DMat3::IDENTITY;
        Self::from_parts(apex, m, DVec3::ZERO, 0.0)
    }

    /// Solid paraboloid opening along `axis` from `vertex`: `(a·x) − ρ² / (4 f)` (metres), with
    /// focal length `f`.
    pub fn paraboloid(vertex: DVec3, axis: DVec3, focal_length: f64) -> Self {
        let a = axis.normalize();
        let m = (DMat3::IDENTITY - outer(a, a)) * (-1.0 / (4.0 * focal_length));
        Self::from_parts(vertex, m, a, 0.0)
    }

    /// Solid hyperboloid about `center` along `axis`, waist (or vertex) radius `radius`, axial
    /// scale `height`: one sheet `1 − ρ²/r² + (a·x)²/h²`, two sheets `(a·x)²/h² − ρ²/r² − 1`.
    pub fn hyperboloid(
        center: DVec3,
        axis: DVec3,
        radius: f64,
        height: f64,
        sheets: Sheets,
    ) -> Self {
        let a = axis.normalize();
        let radial = (DMat3::IDENTITY - outer(a, a)) * (-1.0 / (radius * radius));
        let axial = outer(a, a) * (1.0 / (height * height));
        let k = match sheets {
            Sheets::One => 1.0,
            Sheets::Two => -1.0,
        };
        Self::from_parts(center, radial + axial, DVec3::ZERO, k)
    }

    /// The value at world point `p`.
    #[inline]
    pub fn eval(&self, p: DVec3) -> f64 {
        self.eval_local(p - self.origin)
    }

    /// The value at local point `x = p − origin`.
    #[inline]
    pub fn eval_local(&self, x: DVec3) -> f64 {
        let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = self.coefficients;
        x.x * (a11 * x.x + a12 * x.y + a13 * x.z + a14)
            + x.y * (a22 * x.y + a23 * x.z + a24)
            + x.z * (a33 * x.z + a34)
            + a44
    }

    /// `∇F` at world point `p`.
    #[inline]
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        self.gradient_local(p - self.origin)
    }

    /// `(F, ∇F)` at world point `p`: the same bits as [`Quadric::eval`] and
    /// [`Quadric::gradient`], with `p − origin` formed once.
    #[inline]
    pub fn eval_and_gradient(&self, p: DVec3) -> (f64, DVec3) {
        let x = p - self.origin;
        (self.eval_local(x), self.gradient_local(x))
    }

    /// `∇F` at local point `x = p − origin`.
    #[inline]
    fn gradient_local(&self, x: DVec3) -> DVec3 {
        let [a11, a22, a33, a12, a13, a23, a14, a24, a34, _] = self.coefficients;
        DVec3::new(
            2.0 * a11 * x.x + a12 * x.y + a13 * x.z + a14,
            2.0 * a22 * x.y + a12 * x.x + a23 * x.z + a24,
            2.0 * a33 * x.z + a13 * x.x + a23 * x.y + a34,
        )
    }

    /// `F` restricted to `ray`: the quadratic `a t² + b t + c` in the ray parameter
    /// (`a = dᵀAd`, `b = ∇F(o)·d`, `c = F(o)`).
    #[inline]
    pub fn on_ray(&self, ray: &Ray) -> RayQuadratic {
        self.on_ray_from(&self.at_origin(ray.origin), ray.dir)
    }

    /// What [`Quadric::on_ray`] needs of a ray's origin alone: rays that share an origin (a
    /// pinhole camera's) can share it.
    #[inline]
    pub fn at_origin(&self, origin: DVec3) -> OriginTerms {
        let x = origin - self.origin;
        OriginTerms {
            value: self.eval_local(x),
            gradient: self.gradient_local(x),
            distance: x.abs().element_sum(),
        }
    }

    /// The term bounds of `F` for rounding bounds (kept by a free form for its quadrics).
    pub(crate) fn magnitude(&self) -> Magnitude {
        let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = self.coefficients.map(f64::abs);
        let rows = [
            a11 + 0.5 * (a12 + a13),
            a22 + 0.5 * (a12 + a23),
            a33 + 0.5 * (a13 + a23),
        ];
        let k = ROUNDING_UNITS * UNIT_ROUNDOFF;
        Magnitude {
            alpha: k * rows[0].max(rows[1]).max(rows[2]),
            lambda: k * DVec3::new(a14, a24, a34).length(),
            kappa: k * a44,
        }
    }

    /// [`Quadric::on_ray`] of the ray along `dir` from the origin of `terms`: the same bits.
    #[inline]
    pub fn on_ray_from(&self, terms: &OriginTerms, dir: DVec3) -> RayQuadratic {
        let d = dir;
        let [a11, a22, a33, a12, a13, a23, ..] = self.coefficients;
        let a = d.x * (a11 * d.x + a12 * d.y + a13 * d.z)
            + d.y * (a22 * d.y + a23 * d.z)
            + a33 * d.z * d.z;
        RayQuadratic {
            a,
            b: terms.gradient.dot(d),
            c: terms.value,
        }
    }

    /// A conservative range of `F` over a world-space box (natural interval extension).
    pub fn range_on_box(&self, aabb: &Aabb) -> Interval {
        let x = Interval::new(aabb.min.x - self.origin.x, aabb.max.x - self.origin.x);
        let y = Interval::new(aabb.min.y - self.origin.y, aabb.max.y - self.origin.y);
        let z = Interval::new(aabb.min.z - self.origin.z, aabb.max.z - self.origin.z);
        let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = self.coefficients;
        x.square().scale(a11)
            + y.square().scale(a22)
            + z.square().scale(a33)
            + (x * y).scale(a12)
            + (x * z).scale(a13)
            + (y * z).scale(a23)
            + x.scale(a14)
            + y.scale(a24)
            + z.scale(a34)
            + Interval::point(a44)
    }

    /// The same polynomial multiplied by `k` (same surface; inside and outside swap if `k < 0`).
    pub fn scaled(&self, k: f64) -> Self {
        Self::new(self.origin, self.coefficients.map(|c| c * k))
    }

    /// The complement: `−F`.
    pub fn negated(&self) -> Self {
        self.scaled(-1.0)
    }

    /// The quadric of the shape moved by `offset`.
    pub fn translated(&self, offset: DVec3) -> Self {
        Self::new(self.origin + offset, self.coefficients)
    }

    /// The quadric of the shape mapped by the affine map `t` (`p ↦ M p + v`): `F'(p') = F(t⁻¹ p')`.
    /// Returns `None` if `t` is singular or not finite. The origin moves with the shape, so the new
    /// local polynomial is a pure linear substitution and stays well-conditioned.
    pub fn transformed(&self, t: &DAffine3) -> Option<Self> {
        let det = t.matrix3.determinant();
        if !det.is_finite() || det.abs() < 1e-300 || !t.translation.is_finite() {
            return None;
        }
        let l = t.matrix3.inverse();
        let h = DMat4::from_cols(
            l.x_axis.extend(0.0),
            l.y_axis.extend(0.0),
            l.z_axis.extend(0.0),
            DVec4::W,
        );
        let q = h.transpose() * self.homogeneous() * h;
        let origin = t.transform_point3(self.origin);
        Some(Self::from_homogeneous(origin, &q))
    }

    /// The symmetric 4×4 matrix `Q` with `F = [x 1] Q [x 1]ᵀ`.
    pub fn homogeneous(&self) -> DMat4 {
        let (m, b, k) = self.parts();
        DMat4::from_cols(
            m.x_axis.extend(0.5 * b.x),
            m.y_axis.extend(0.5 * b.y),
            m.z_axis.extend(0.5 * b.z),
            DVec4::new(0.5 * b.x, 0.5 * b.y, 0.5 * b.z, k),
        )
    }

    fn from_homogeneous(origin: DVec3, q: &DMat4) -> Self {
        let m = DMat3::from_cols(
            q.x_axis.truncate(),
            q.y_axis.truncate(),
            q.z_axis.truncate(),
        );
        let m = (m + m.transpose()) * 0.5;
        let b = DVec3::new(
            q.x_axis.w + q.w_axis.x,
            q.y_axis.w + q.w_axis.y,
            q.z_axis.w + q.w_axis.z,
        );
        Self::from_parts(origin, m, b, q.w_axis.w)
    }

    /// Whether all coefficients are finite.
    pub fn is_finite(&self) -> bool {
        self.origin.is_finite() && self.coefficients.iter().all(|c| c.is_finite())
    }

    /// The bounding box of `{F ≥ 0}` when that set is a bounded ellipsoid (negative-definite
    /// quadratic part); `Some(Aabb::EMPTY)` if the set is empty; `None` if it is unbounded.
    pub fn inside_bounds(&self) -> Option<Aabb> {
        let (m, b, k) = self.parts();
        let neg = -m;
        // Sylvester's criterion on −M: all leading principal minors positive.
        let m1 = neg.x_axis.x;
        let m2 = neg.x_axis.x * neg.y_axis.y - neg.x_axis.y * neg.y_axis.x;
        let m3 = neg.determinant();
        let scale = neg
            .x_axis
            .x
            .abs()
            .max(neg.y_axis.y.abs())
            .max(neg.z_axis.z.abs());
        if !(m1 > 0.0 && m2 > 1e-14 * scale * scale && m3 > 1e-14 * scale * scale * scale) {
            return None;
        }
        let inv = neg.inverse(); // (−M)⁻¹, positive definite
        // Centre c solves 2 M c + b = 0 → c = ½ (−M)⁻¹ b.
        let c = inv * b * 0.5;
        let level = k + 0.5 * b.dot(c); // F(c), the maximum
        if level < 0.0 {
            return Some(Aabb::EMPTY);
        }
        let half = DVec3::new(
            (level * inv.x_axis.x).sqrt(),
            (level * inv.y_axis.y).sqrt(),
            (level * inv.z_axis.z).sqrt(),
        );
        let centre = self.origin + c;
        let size = half.max_element().max(1e-300);
        // A small margin so a derived box never clips the surface it bounds.
        Some(
            Aabb::from_center_half(centre, half)
                .expanded(1e-9 * size + 4.0 * f64::EPSILON * centre.abs().max_element()),
        )
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructors_are_inside_where_expected() {
        let s = Quadric::sphere(DVec3::new(1.0, 2.0, 3.0), 2.0);
        assert_eq!(s.eval(DVec3::new(1.0, 2.0, 3.0)), 1.0);
        assert!(s.eval(DVec3::new(3.0, 2.0, 3.0)).abs() < 1e-15);
        assert!(s.eval(DVec3::new(3.1, 2.0, 3.0)) < 0.0);

        let c = Quadric::cylinder(DVec3::ZERO, DVec3::Y, 1.0);
        assert!(c.eval(DVec3::new(0.5, 1e6, 0.0)) > 0.0);
        assert!(c.eval(DVec3::new(1.5, 0.0, 0.0)) < 0.0);

        let cone = Quadric::cone(DVec3::ZERO, DVec3::Y, 45f64.to_radians());
        assert!(cone.eval(DVec3::new(0.5, 1.0, 0.0)) > 0.0);
        assert!(cone.eval(DVec3::new(1.5, 1.0, 0.0)) < 0.0);
        assert!(cone.eval(DVec3::new(0.5, -1.0, 0.0)) > 0.0);

        let h = Quadric::half_space(DVec3::ZERO, DVec3::Y);
        assert!(h.eval(DVec3::new(0.0, -1.0, 0.0)) > 0.0);

        let p = Quadric::paraboloid(DVec3::ZERO, DVec3::Y, 0.25);
        assert!(p.eval(DVec3::new(0.5, 1.0, 0.0)) > 0.0); // ρ² = 0.25 < 4 f y = 1
        assert!(p.eval(DVec3::new(0.0, -0.1, 0.0)) < 0.0);

        let one = Quadric::hyperboloid(DVec3::ZERO, DVec3::Y, 1.0, 1.0, Sheets::One);
        assert!(one.eval(DVec3::new(1.2, 1.0, 0.0)) > 0.0); // radius grows to √2 at y = 1
        let two = Quadric::hyperboloid(DVec3::ZERO, DVec3::Y, 1.0, 1.0, Sheets::Two);
        assert!(two.eval(DVec3::ZERO) < 0.0 && two.eval(DVec3::new(0.0, 2.0, 0.0)) > 0.0);
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let q = Quadric::new(
            DVec3::new(0.3, -1.0, 2.0),
            [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -3.0],
        );
        let p = DVec3::new(0.7, 0.2, -0.4);
        let g = q.gradient(p);
        let h = 1e-6;
        for axis in 0..3 {
            let mut e = DVec3::ZERO;
            e[axis] = h;
            let fd = (q.eval(p + e) - q.eval(p - e)) / (2.0 * h);
            assert!(
                (fd - g[axis]).abs() < 1e-7,
                "axis {axis}: {fd} vs {}",
                g[axis]
            );
        }
    }

    #[test]
    fn on_ray_agrees_with_point_evaluation() {
        let q = Quadric::new(
            DVec3::new(5.0, 0.0, 1.0),
            [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -3.0],
        );
        let ray = Ray::new(DVec3::new(-1.0, 2.0, 0.5), DVec3::new(0.3, -0.2, 1.0)).unwrap();
        let rq = q.on_ray(&ray);
        for t in [-2.0, 0.0, 0.5, 3.7] {
            assert!((rq.eval(t) - q.eval(ray.at(t))).abs() < 1e-12);
        }
    }

    #[test]
    fn transforms_move_the_surface_with_the_points() {
        let q = Quadric::ellipsoid(DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 3.0));
        let t = DAffine3::from_scale_rotation_translation(
            DVec3::new(2.0, 1.0, 0.5),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.8, 1.2),
            DVec3::new(-4.0, 7.0, 2.0),
        );
        let qt = q.transformed(&t).unwrap();
        for p in [
            DVec3::new(1.5, 0.3, -1.0),
            DVec3::new(0.0, 1.9, 0.0),
            DVec3::new(3.0, 3.0, 3.0),
        ] {
            assert!((qt.eval(t.transform_point3(p)) - q.eval(p)).abs() < 1e-12);
        }
        assert!(
            q.transformed(&DAffine3::from_scale(DVec3::new(1.0, 0.0, 1.0)))
                .is_none()
        );
    }

    #[test]
    fn ellipsoid_bounds_are_tight_and_unbounded_sets_have_none() {
        let q = Quadric::ellipsoid(DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 2.0, 3.0));
        let b = q.inside_bounds().unwrap();
        assert!((b.min - DVec3::new(0.0, 0.0, 0.0)).abs().max_element() < 1e-8);
        assert!((b.max - DVec3::new(2.0, 4.0, 6.0)).abs().max_element() < 1e-8);
        // A rotated ellipsoid: the box must contain sampled surface points.
        let t = DAffine3::from_rotation_z(0.6);
        let qr = q.transformed(&t).unwrap();
        let br = qr.inside_bounds().unwrap();
        for i in 0..1000 {
            let a = i as f64 * 0.1;
            let p = DVec3::new(
                1.0 + a.cos() * (a * 0.37).sin(),
                2.0 + 2.0 * a.sin() * (a * 0.37).sin(),
                3.0 + 3.0 * (a * 0.37).cos(),
            );
            assert!(br.contains(t.transform_point3(p)));
        }
        assert!(
            Quadric::cylinder(DVec3::ZERO, DVec3::Y, 1.0)
                .inside_bounds()
                .is_none()
        );
        assert!(
            Quadric::half_space(DVec3::ZERO, DVec3::Y)
                .inside_bounds()
                .is_none()
        );
        assert!(
            Quadric::sphere(DVec3::ZERO, 1.0)
                .negated()
                .inside_bounds()
                .is_none()
        );
        // 1 + |x|²... negated sphere of negative level: empty.
        let empty = Quadric::new(
            DVec3::ZERO,
            [-1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        );
        assert!(empty.inside_bounds().unwrap().is_empty());
    }

    #[test]
    fn box_range_contains_sampled_values() {
        let q = Quadric::new(
            DVec3::new(0.3, -1.0, 2.0),
            [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -3.0],
        );
        let b = Aabb::new(DVec3::new(-1.0, 0.0, 1.0), DVec3::new(0.5, 2.0, 1.5));
        let r = q.range_on_box(&b);
        for i in 0..=10 {
            for j in 0..=10 {
                for k in 0..=10 {
                    let p =
                        b.min + (b.max - b.min) * DVec3::new(i as f64, j as f64, k as f64) / 10.0;
                    assert!(r.contains(q.eval(p)));
                }
            }
        }
    }
}
