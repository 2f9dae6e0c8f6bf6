//! CSG trees of free-form objects and their flat postfix form, [`Solid`].
//!
//! Union is `max`, intersection `min`, difference `min(a, −b)`. The tree is compiled once into a
//! postfix program over the leaves — the form that the ray caster and the GPU both evaluate.

use crate::quadric::Magnitude;
use crate::{FreeForm, GeometryError};
use fray_core::Aabb;
use glam::DVec3;

/// A CSG tree whose leaves are free-form objects.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    FreeForm(FreeForm),
    /// `max` of two or more operands.
    Union(Vec<Shape>),
    /// `min` of two or more operands.
    Intersection(Vec<Shape>),
    /// `min(a, −b)`.
    Difference(Box<Shape>, Box<Shape>),
}

/// One instruction of the postfix CSG program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOp {
    /// Push leaf `i`'s value.
    Leaf(u32),
    /// Pop two, push the larger (union).
    Max,
    /// Pop two, push the smaller (intersection).
    Min,
    /// Negate the top (complement, for difference).
    Neg,
}

/// A compiled CSG tree: leaves, a postfix program over them, and the finite box of the result.
#[derive(Clone, Debug, PartialEq)]
pub struct Solid {
    leaves: Vec<FreeForm>,
    program: Vec<CsgOp>,
    bounds: Aabb,
    max_stack: usize,
    /// Per leaf: its box contains the solid's box, so a ray's range clipped to the solid is
    /// already clipped to the leaf (the caster skips that slab test).
    leaf_covers_solid: Vec<bool>,
    /// Per leaf: an odd number of negations lies between it and the result, so the solid's
    /// value *decreases* with the leaf's (the caster widens such a leaf downwards).
    leaf_negated: Vec<bool>,
    /// Per leaf, the term bounds of its base quadric for the caster's widening (module
    /// `cast`), negated for a negated leaf so that they widen it downwards; and of each of its
    /// perturbations' quadrics.
    widenings: Vec<Magnitude>,
    perturbation_magnitudes: Vec<Vec<Magnitude>>,
}

/// The leaves' signed base term bounds and their perturbations' (see [`Solid`]'s fields).
fn magnitudes(leaves: &[FreeForm], negated: &[bool]) -> (Vec<Magnitude>, Vec<Vec<Magnitude>>) {
    let widenings = leaves
        .iter()
        .zip(negated)
        .map(|(l, &n)| {
            let m = l.base().magnitude();
            if n { m.negated() } else { m }
        })
        .collect();
    let perturbations = leaves
        .iter()
        .map(|l| {
            l.perturbations()
                .iter()
                .map(|p| p.quadric.magnitude())
                .collect()
        })
        .collect();
    (widenings, perturbations)
}

impl Solid {
    /// Compiles a tree; fails on a union or intersection with fewer than two operands.
    pub fn new(shape: Shape) -> Result<Self, GeometryError> {
        let mut leaves = Vec::new();
        let mut program = Vec::new();
        let bounds = compile(shape, &mut leaves, &mut program)?;
        let mut depth = 0usize;
        let mut max_stack = 0usize;
        for op in &program {
            match op {
                CsgOp::Leaf(_) => depth += 1,
                CsgOp::Max | CsgOp::Min => depth -= 1,
                CsgOp::Neg => {}
            }
            max_stack = max_stack.max(depth);
        }
        let leaf_covers_solid = covers(&leaves, &bounds);
        let leaf_negated = negated(&program, leaves.len());
        let (widenings, perturbation_magnitudes) = magnitudes(&leaves, &leaf_negated);
        Ok(Self {
            widenings,
            perturbation_magnitudes,
            leaves,
            program,
            bounds,
            max_stack,
            leaf_covers_solid,
            leaf_negated,
        })
    }

    /// A solid of one free-form object.
    pub fn from_free_form(f: FreeForm) -> Self {
        let bounds = f.bounds();
        let leaves = vec![f];
        let leaf_covers_solid = covers(&leaves, &bounds);
        let (widenings, perturbation_magnitudes) = magnitudes(&leaves, &[false]);
        Self {
            widenings,
            perturbation_magnitudes,
            leaves,
            program: vec![CsgOp::Leaf(0)],
            bounds,
            max_stack: 1,
            leaf_covers_solid,
            leaf_negated: vec![false],
        }
    }

    pub fn leaves(&self) -> &[FreeForm] {
        &self.leaves
    }

    pub fn program(&self) -> &[CsgOp] {
        &self.program
    }

    /// The finite box that holds the solid (may be empty, e.g. for disjoint intersections).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// [`Solid::bounds`] in place (see `FreeForm::bounds_ref`).
    #[inline]
    pub(crate) fn bounds_ref(&self) -> &Aabb {
        &self.bounds
    }

    /// Whether leaf `i`'s box contains the solid's box (so clipping a ray to the solid's box
    /// clips it to the leaf's as well).
    #[inline]
    pub fn leaf_covers_solid(&self, i: usize) -> bool {
        self.leaf_covers_solid.get(i).copied().unwrap_or(false)
    }

    /// Whether leaf `i` reaches the solid's value through an odd number of negations (the
    /// subtrahend of a difference): the solid's value decreases as the leaf's increases.
    #[inline]
    pub fn leaf_is_negated(&self, i: usize) -> bool {
        self.leaf_negated.get(i).copied().unwrap_or(false)
    }

    /// Leaf `i`'s base term bounds, negated if the leaf is (the direction the caster widens it).
    #[inline]
    pub(crate) fn leaf_widening(&self, i: usize) -> Option<&Magnitude> {
        self.widenings.get(i)
    }

    /// The term bounds of leaf `i`'s perturbations' quadrics.
    #[inline]
    pub(crate) fn perturbation_magnitudes(&self, i: usize) -> &[Magnitude] {
        self.perturbation_magnitudes
            .get(i)
            .map_or(&[], Vec::as_slice)
    }

    /// The deepest the evaluation stack gets.
    pub fn max_stack(&self) -> usize {
        self.max_stack
    }

    /// Total perturbations over all leaves.
    pub fn perturbation_count(&self) -> usize {
        self.leaves.iter().map(|l| l.perturbations().len()).sum()
    }

    /// The CSG value at `p` (`≥ 0` inside).
    pub fn eval(&self, p: DVec3) -> f64 {
        let mut stack: Vec<f64> = Vec::with_capacity(self.max_stack);
        for op in &self.program {
            match *op {
                CsgOp::Leaf(i) => stack.push(self.leaves[i as usize].eval(p)),
                CsgOp::Max | CsgOp::Min => {
                    let b = stack.pop().unwrap_or(f64::NEG_INFINITY);
                    let a = stack.pop().unwrap_or(f64::NEG_INFINITY);
                    stack.push(if *op == CsgOp::Max {
                        a.max(b)
                    } else {
                        a.min(b)
                    });
                }
                CsgOp::Neg => {
                    if let Some(v) = stack.last_mut() {
                        *v = -*v;
                    }
                }
            }
        }
        stack.pop().unwrap_or(f64::NEG_INFINITY)
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
    pub fn surface_at_with(
        &self,
        p: DVec3,
        fallback: DVec3,
        active: &crate::ActiveSet,
    ) -> (DVec3, u32) {
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

    fn surface_by(
        &self,
        fallback: DVec3,
        eval: impl Fn(usize, &FreeForm) -> (f64, DVec3),
    ) -> (DVec3, u32) {
        // A fixed stack for the usual shallow programs: no allocation per surface point.
        const INLINE: usize = 8;
        if self.max_stack <= INLINE {
            let mut stack = [(0.0, DVec3::ZERO, 0u32); INLINE];
            let mut len = 0usize;
            for op in &self.program {
                match *op {
                    CsgOp::Leaf(i) => {
                        let (v, g) = eval(i as usize, &self.leaves[i as usize]);
                        stack[len] = (v, g, i);
                        len += 1;
                    }
                    CsgOp::Max | CsgOp::Min => {
                        let b = stack[len - 1];
                        let a = stack[len - 2];
                        len -= 1;
                        let take_a = if *op == CsgOp::Max {
                            a.0 >= b.0
                        } else {
                            a.0 <= b.0
                        };
                        stack[len - 1] = if take_a { a } else { b };
                    }
                    CsgOp::Neg => {
                        let v = &mut stack[len - 1];
                        v.0 = -v.0;
                        v.1 = -v.1;
                    }
                }
            }
            let (_, g, leaf) = if len > 0 {
                stack[len - 1]
            } else {
                (0.0, DVec3::ZERO, 0)
            };
            return Self::outward(g, leaf, fallback);
        }
        let mut stack: Vec<(f64, DVec3, u32)> = Vec::with_capacity(self.max_stack);
        for op in &self.program {
            match *op {
                CsgOp::Leaf(i) => {
                    let (v, g) = eval(i as usize, &self.leaves[i as usize]);
                    stack.push((v, g, i));
                }
                CsgOp::Max | CsgOp::Min => {
                    let b = stack.pop().unwrap_or((f64::NEG_INFINITY, DVec3::ZERO, 0));
                    let a = stack.pop().unwrap_or((f64::NEG_INFINITY, DVec3::ZERO, 0));
                    let take_a = if *op == CsgOp::Max {
                        a.0 >= b.0
                    } else {
                        a.0 <= b.0
                    };
                    stack.push(if take_a { a } else { b });
                }
                CsgOp::Neg => {
                    if let Some(v) = stack.last_mut() {
                        v.0 = -v.0;
                        v.1 = -v.1;
                    }
                }
            }
        }
        let (_, g, leaf) = stack.pop().unwrap_or((0.0, DVec3::ZERO, 0));
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

/// Per leaf, whether its box contains `bounds` (never for an empty `bounds`: its slab test is not
/// a clip).
fn covers(leaves: &[FreeForm], bounds: &Aabb) -> Vec<bool> {
    leaves
        .iter()
        .map(|l| {
            let b = l.bounds();
            !bounds.is_empty() && b.min.cmple(bounds.min).all() && b.max.cmpge(bounds.max).all()
        })
        .collect()
}

/// Per leaf, whether an odd number of `Neg`s lies above it in `program` (`leaves` leaves).
fn negated(program: &[CsgOp], leaves: usize) -> Vec<bool> {
    let mut negated = vec![false; leaves];
    // Each stack entry: the leaves of one operand.
    let mut stack: Vec<Vec<u32>> = Vec::new();
    for op in program {
        match *op {
            CsgOp::Leaf(i) => stack.push(vec![i]),
            CsgOp::Neg => {
                for &i in stack.last().into_iter().flatten() {
                    if let Some(n) = negated.get_mut(i as usize) {
                        *n = !*n;
                    }
                }
            }
            CsgOp::Max | CsgOp::Min => {
                if stack.len() >= 2 {
                    let b = stack.pop().unwrap_or_default();
                    if let Some(a) = stack.last_mut() {
                        a.extend(b);
                    }
                }
            }
        }
    }
    negated
}

fn compile(
    shape: Shape,
    leaves: &mut Vec<FreeForm>,
    program: &mut Vec<CsgOp>,
) -> Result<Aabb, GeometryError> {
    match shape {
        Shape::FreeForm(f) => {
            let b = f.bounds();
            program.push(CsgOp::Leaf(leaves.len() as u32));
            leaves.push(f);
            Ok(b)
        }
        Shape::Union(children) | Shape::Intersection(children) if children.len() < 2 => {
            Err(GeometryError::TooFewOperands {
                op: "union or intersection",
                min: 2,
                got: children.len(),
            })
        }
        Shape::Union(children) => {
            let mut b = Aabb::EMPTY;
            for (i, c) in children.into_iter().enumerate() {
                b = b.union(&compile(c, leaves, program)?);
                if i > 0 {
                    program.push(CsgOp::Max);
                }
            }
            Ok(b)
        }
        Shape::Intersection(children) => {
            let mut b: Option<Aabb> = None;
            for (i, c) in children.into_iter().enumerate() {
                let cb = compile(c, leaves, program)?;
                b = Some(b.map_or(cb, |b| b.intersection(&cb)));
                if i > 0 {
                    program.push(CsgOp::Min);
                }
            }
            Ok(b.unwrap_or(Aabb::EMPTY))
        }
        Shape::Difference(a, b) => {
            let ab = compile(*a, leaves, program)?;
            compile(*b, leaves, program)?;
            program.push(CsgOp::Neg);
            program.push(CsgOp::Min);
            Ok(ab)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Quadric;

    fn ball(c: DVec3, r: f64) -> Shape {
        Shape::FreeForm(FreeForm::new(Quadric::sphere(c, r), vec![], None).unwrap())
    }

    #[test]
    fn csg_semantics_and_bounds() {
        let a = ball(DVec3::ZERO, 1.0);
        let b = ball(DVec3::new(1.0, 0.0, 0.0), 1.0);
        let u = Solid::new(Shape::Union(vec![a.clone(), b.clone()])).unwrap();
        let i = Solid::new(Shape::Intersection(vec![a.clone(), b.clone()])).unwrap();
        let d = Solid::new(Shape::Difference(Box::new(a.clone()), Box::new(b.clone()))).unwrap();
        let p_a_only = DVec3::new(-0.5, 0.0, 0.0);
        let p_both = DVec3::new(0.5, 0.0, 0.0);
        let p_b_only = DVec3::new(1.5, 0.0, 0.0);
        assert!(u.eval(p_a_only) >= 0.0 && u.eval(p_both) >= 0.0 && u.eval(p_b_only) >= 0.0);
        assert!(i.eval(p_a_only) < 0.0 && i.eval(p_both) >= 0.0 && i.eval(p_b_only) < 0.0);
        assert!(d.eval(p_a_only) >= 0.0 && d.eval(p_both) < 0.0 && d.eval(p_b_only) < 0.0);
        assert!((i.bounds().min.x - 0.0).abs() < 1e-6 && (i.bounds().max.x - 1.0).abs() < 1e-6);
        assert!((u.bounds().max.x - 2.0).abs() < 1e-6);
        assert_eq!(
            d.program(),
            &[CsgOp::Leaf(0), CsgOp::Leaf(1), CsgOp::Neg, CsgOp::Min]
        );
        assert!(!d.leaf_is_negated(0) && d.leaf_is_negated(1));
        // a − (b − c): c is negated twice.
        let c = ball(DVec3::new(2.0, 0.0, 0.0), 1.0);
        let nested = Shape::Difference(
            Box::new(a.clone()),
            Box::new(Shape::Difference(Box::new(b.clone()), Box::new(c))),
        );
        let nested = Solid::new(Shape::Union(vec![nested, b.clone()])).unwrap();
        let flags: Vec<bool> = (0..4).map(|i| nested.leaf_is_negated(i)).collect();
        assert_eq!(flags, [false, true, false, false]);
        assert_eq!(
            Solid::new(Shape::Union(vec![a])).unwrap_err(),
            GeometryError::TooFewOperands {
                op: "union or intersection",
                min: 2,
                got: 1
            }
        );
    }

    #[test]
    fn difference_normal_points_into_the_carved_hole() {
        let a = ball(DVec3::ZERO, 1.0);
        let b = ball(DVec3::new(1.0, 0.0, 0.0), 0.5);
        let d = Solid::new(Shape::Difference(Box::new(a), Box::new(b))).unwrap();
        // On the carved face at x = 0.5 the outward normal of the result points to −x... into the
        // hole, i.e. toward b's centre (+x).
        let (n, leaf) = d.surface_at(DVec3::new(0.5, 0.0, 0.0), DVec3::Z);
        assert_eq!(leaf, 1);
        assert!((n - DVec3::X).length() < 1e-12);
    }
}
