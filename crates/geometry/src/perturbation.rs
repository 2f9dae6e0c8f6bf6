//! Perturbation functions `f · R(p)` with `R = Q³` where the perturbing quadric `Q > 0`, else 0.

use crate::Quadric;
use fray_core::Aabb;
use glam::DVec3;

/// A perturbation `f · R(p)`, `R(p) = Q(p)³` where `Q(p) > 0` and `0` elsewhere. `R` is C² across
/// the support boundary `Q = 0`, so a perturbed surface stays smooth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perturbation {
    /// The form factor `f`: positive adds material (a bump), negative removes it (a dent).
    pub form_factor: f64,
    pub quadric: Quadric,
}

impl Perturbation {
    pub fn new(form_factor: f64, quadric: Quadric) -> Self {
        Self {
            form_factor,
            quadric,
        }
    }

    /// `f · R(p)`.
    #[inline]
    pub fn eval(&self, p: DVec3) -> f64 {
        let q = self.quadric.eval(p);
        if q > 0.0 {
            self.form_factor * q * q * q
        } else {
            0.0
        }
    }

    /// `∇(f · R) = 3 f Q² ∇Q` inside the support, 0 outside.
    #[inline]
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let q = self.quadric.eval(p);
        if q > 0.0 {
            self.quadric.gradient(p) * (3.0 * self.form_factor * q * q)
        } else {
            DVec3::ZERO
        }
    }

    /// The box of the support `{Q > 0}` if it is bounded.
    pub fn support_bounds(&self) -> Option<Aabb> {
        self.quadric.inside_bounds()
    }
}
