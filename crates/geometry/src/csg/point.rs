//! A solid's program at a point: its value ([`Solid::eval`]) and, for normals, the value with
//! its gradient and the leaf that decides it ([`Solid::surface_at`]) — two algebras of the one
//! evaluator.

use super::{CsgAlgebra, CsgOp, Solid, run};
use crate::{ActiveSet, FreeForm};
use glam::DVec3;

/// `F′(p)`: each leaf's value, `max`, `min` and negation of numbers.
struct PointValue<'a> {
    leaves: &'a [FreeForm],
    p: DVec3,
}

impl CsgAlgebra for PointValue<'_> {
    type Value = f64;
    #[inline(always)]
    fn leaf(&mut self, i: u32) -> Option<f64> {
        Some(self.leaves.get(i as usize)?.eval(self.p))
    }
    #[inline(always)]
    fn max(&mut self, a: f64, b: f64) -> Option<f64> {
        Some(a.max(b))
    }
    #[inline(always)]
    fn min(&mut self, a: f64, b: f64) -> Option<f64> {
        Some(a.min(b))
    }
    #[inline(always)]
    fn neg(&mut self, a: f64) -> Option<f64> {
        Some(-a)
    }
}

/// Value, gradient and leaf of the operand that wins every `max`/`min` (the first on a tie); a
/// negation negates value and gradient and keeps the leaf. `eval(i, leaf)` gives a leaf's value
/// and gradient.
pub(crate) struct Surface<'a, F> {
    pub(crate) leaves: &'a [FreeForm],
    pub(crate) eval: F,
}

impl<F: Fn(usize, &FreeForm) -> (f64, DVec3)> CsgAlgebra for Surface<'_, F> {
    type Value = (f64, DVec3, u32);
    #[inline(always)]
    fn leaf(&mut self, i: u32) -> Option<Self::Value> {
        let (v, g) = (self.eval)(i as usize, self.leaves.get(i as usize)?);
        Some((v, g, i))
    }
    #[inline(always)]
    fn max(&mut self, a: Self::Value, b: Self::Value) -> Option<Self::Value> {
        Some(if a.0 >= b.0 { a } else { b })
    }
    #[inline(always)]
    fn min(&mut self, a: Self::Value, b: Self::Value) -> Option<Self::Value> {
        Some(if a.0 <= b.0 { a } else { b })
    }
    #[inline(always)]
    fn neg(&mut self, (v, g, leaf): Self::Value) -> Option<Self::Value> {
        Some((-v, -g, leaf))
    }
}

impl Solid {
    /// The CSG value at `p` (`≥ 0` inside).
    pub fn eval(&self, p: DVec3) -> f64 {
        let mut value = PointValue {
            leaves: &self.leaves,
            p,
        };
        run(&self.program, &mut value).unwrap_or(f64::NEG_INFINITY)
    }

    /// The CSG value at `p` with the gradient of the operand that decides it (the one that wins
    /// every `max`/`min`): `F / |∇F|` is a first-order distance to the surface, which is how
    /// cloud envelopes measure "how deep" a point is.
    pub fn eval_with_gradient(&self, p: DVec3) -> (f64, DVec3) {
        let mut surface = Surface {
            leaves: &self.leaves,
            eval: |_: usize, leaf: &FreeForm| leaf.eval_with_gradient(p),
        };
        run(&self.program, &mut surface)
            .map_or((f64::NEG_INFINITY, DVec3::ZERO), |(v, g, _)| (v, g))
    }

    /// The outward unit normal at a surface point `p` and the leaf whose surface it is: the
    /// gradient of the operand that is active in every `max`/`min`. Falls back to `fallback`
    /// where the gradient vanishes (a cone's apex).
    pub fn surface_at(&self, p: DVec3, fallback: DVec3) -> (DVec3, u32) {
        if let [CsgOp::Leaf(i)] = self.program[..]
            && let Some(leaf) = self.leaves.get(i as usize)
        {
            return Self::outward(leaf.eval_with_gradient(p).1, i, fallback);
        }
        self.surface_by(fallback, |_, leaf| leaf.eval_with_gradient(p))
    }

    /// [`Solid::surface_at`] evaluating each leaf with only the perturbations `active` lists for
    /// it: bit-identical when every perturbation left out is zero at `p` (as for a point on a ray
    /// that misses its support) — and as cheap as the active perturbations. Always inlined: a
    /// frame loop calls it per hit, and a returned normal reloaded from memory stalls.
    #[inline(always)]
    pub fn surface_at_with(&self, p: DVec3, fallback: DVec3, active: &ActiveSet) -> (DVec3, u32) {
        // One leaf: no program to run, and without a clipping box its value decides nothing.
        if let [CsgOp::Leaf(i)] = self.program[..]
            && let Some(leaf) = self.leaves.get(i as usize)
        {
            let subset = active.leaf_perturbations(i as usize);
            let g = if leaf.clips() {
                leaf.eval_with_gradient_subset(p, subset).1
            } else {
                leaf.gradient_subset(p, subset)
            };
            return Self::outward(g, i, fallback);
        }
        self.surface_by(fallback, |i, leaf| {
            leaf.eval_with_gradient_subset(p, active.leaf_perturbations(i))
        })
    }

    /// The normal and leaf of the [`Surface`] algebra over the whole program.
    fn surface_by(
        &self,
        fallback: DVec3,
        eval: impl Fn(usize, &FreeForm) -> (f64, DVec3),
    ) -> (DVec3, u32) {
        let mut surface = Surface {
            leaves: &self.leaves,
            eval,
        };
        let (_, g, leaf) = run(&self.program, &mut surface).unwrap_or((0.0, DVec3::ZERO, 0));
        Self::outward(g, leaf, fallback)
    }

    /// The outward unit normal from an F-rep gradient (`−∇F`), or `fallback` where it vanishes.
    #[inline]
    fn outward(g: DVec3, leaf: u32, fallback: DVec3) -> (DVec3, u32) {
        let len = g.length();
        let n = if len > 0.0 && len.is_finite() {
            g * (-1.0 / len) // one division for the three components
        } else {
            fallback
        };
        (n, leaf)
    }
}
