//! CSG trees of free-form objects and their flat postfix form, [`Solid`].
//!
//! Union is `max`, intersection `min`, difference `min(a, −b)`. The tree is compiled once into a
//! postfix program over the leaves — the form that the ray caster and the GPU both evaluate. The
//! program has one interpreter, [`run`], generic over what a value is ([`CsgAlgebra`]; module
//! `program`): point values and normals (module `point`), the caster's bounds, values and span
//! sets (module `cast`), the fold over absent leaves (module `active`), and the compile-time
//! facts below (stack depth, negated leaves).

mod point;
mod program;

#[cfg(test)]
pub(crate) use point::Surface;
pub use program::{CsgAlgebra, INLINE_DEPTH, run, run_in};

use crate::quadric::Magnitude;
use crate::{FreeForm, GeometryError};
use fray_core::Aabb;

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
        Ok(Self::from_program(leaves, program, bounds))
    }

    /// The solid of a compiled program over `leaves` whose result lies in `bounds`: the facts
    /// the caster reads (stack depth, covering and negated leaves, term bounds) derived once.
    fn from_program(leaves: Vec<FreeForm>, program: Vec<CsgOp>, bounds: Aabb) -> Self {
        let max_stack = run(&program, &mut Depth).unwrap_or(0);
        let leaf_covers_solid = covers(&leaves, &bounds);
        let leaf_negated = negated(&program, leaves.len());
        let (widenings, perturbation_magnitudes) = magnitudes(&leaves, &leaf_negated);
        Self {
            widenings,
            perturbation_magnitudes,
            leaves,
            program,
            bounds,
            max_stack,
            leaf_covers_solid,
            leaf_negated,
        }
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

    /// The complement within the same box: the value `−F` (the program followed by a negation),
    /// so `−F ≥ 0` is "inside" it. Cast from a point inside the solid, its first hit is where the
    /// ray leaves the solid — the exit a refracted ray needs. The box stays the solid's: a ray
    /// that leaves through a clipping box face finds no hit in it (the caller takes the box's
    /// exit).
    pub fn complement(&self) -> Self {
        let mut program = self.program.clone();
        program.push(CsgOp::Neg);
        let leaf_negated = negated(&program, self.leaves.len());
        let (widenings, perturbation_magnitudes) = magnitudes(&self.leaves, &leaf_negated);
        Self {
            widenings,
            perturbation_magnitudes,
            leaves: self.leaves.clone(),
            program,
            bounds: self.bounds,
            max_stack: self.max_stack,
            leaf_covers_solid: self.leaf_covers_solid.clone(),
            leaf_negated,
        }
    }

    /// The solid moved by the affine map `t`, exactly, with the leaf of `self` each of its
    /// leaves comes from (for per-leaf materials): every leaf moved (`FreeForm::moved`), except
    /// that a leaf whose clipping box the map turns becomes the intersection of its unclipped
    /// self and its box's six moved half-spaces (`FreeForm::moved_as_box_intersection`: seven
    /// leaves from one); the same program otherwise, the box recomputed from the leaves' new
    /// boxes as compiling does (a union's is the union of its operands', an intersection's their
    /// intersection, a difference's its first operand's).
    pub fn moved(&self, t: &glam::DAffine3) -> Result<(Self, Vec<u32>), GeometryError> {
        let mut leaves = Vec::with_capacity(self.leaves.len());
        let mut origins = Vec::with_capacity(self.leaves.len());
        let mut fragments: Vec<Vec<CsgOp>> = Vec::with_capacity(self.leaves.len());
        for (i, leaf) in self.leaves.iter().enumerate() {
            let parts = match leaf.moved(t) {
                Ok(moved) => vec![moved],
                Err(GeometryError::ClipNotMovable { .. }) => leaf.moved_as_box_intersection(t)?,
                Err(e) => return Err(e),
            };
            let mut fragment = Vec::with_capacity(2 * parts.len());
            for (k, part) in parts.into_iter().enumerate() {
                fragment.push(CsgOp::Leaf(leaves.len() as u32));
                if k > 0 {
                    fragment.push(CsgOp::Min);
                }
                leaves.push(part);
                origins.push(i as u32);
            }
            fragments.push(fragment);
        }
        // A leaf's fragment stands where the leaf stood: leaves keep their postfix order.
        let program: Vec<CsgOp> = self
            .program
            .iter()
            .flat_map(|op| match op {
                CsgOp::Leaf(i) => fragments[*i as usize].clone(),
                other => vec![*other],
            })
            .collect();
        let boxes: Vec<Aabb> = leaves.iter().map(FreeForm::bounds).collect();
        let bounds = run(&program, &mut Boxes(&boxes))
            .flatten()
            .unwrap_or(Aabb::EMPTY);
        Ok((Self::from_program(leaves, program, bounds), origins))
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

/// The box of a program's value from its leaves' boxes, as [`compile`] makes it: `None` is a
/// negated operand (unbounded: everything outside a box), which an intersection ignores.
struct Boxes<'a>(&'a [Aabb]);

impl CsgAlgebra for Boxes<'_> {
    type Value = Option<Aabb>;
    fn leaf(&mut self, i: u32) -> Option<Option<Aabb>> {
        self.0.get(i as usize).map(|b| Some(*b))
    }
    fn max(&mut self, a: Option<Aabb>, b: Option<Aabb>) -> Option<Option<Aabb>> {
        Some(a.zip(b).map(|(a, b)| a.union(&b)))
    }
    fn min(&mut self, a: Option<Aabb>, b: Option<Aabb>) -> Option<Option<Aabb>> {
        Some(match (a, b) {
            (Some(a), Some(b)) => Some(a.intersection(&b)),
            (a, b) => a.or(b),
        })
    }
    fn neg(&mut self, _: Option<Aabb>) -> Option<Option<Aabb>> {
        Some(None)
    }
}

/// The stack depth of the program: an operand's is its own, or one more than its second
/// operand's while the first waits beneath it.
struct Depth;

impl CsgAlgebra for Depth {
    type Value = usize;
    fn leaf(&mut self, _: u32) -> Option<usize> {
        Some(1)
    }
    fn max(&mut self, a: usize, b: usize) -> Option<usize> {
        Some(a.max(b + 1))
    }
    fn min(&mut self, a: usize, b: usize) -> Option<usize> {
        Some(a.max(b + 1))
    }
    fn neg(&mut self, a: usize) -> Option<usize> {
        Some(a)
    }
}

/// Which leaves an odd number of negations lies above. An operand's leaves are consecutive
/// among the program's leaves (postfix keeps a subtree's ops together), so a value is the range
/// of them, by position in `order`; a negation flips each.
struct Negations {
    order: Vec<u32>,
    negated: Vec<bool>,
}

impl CsgAlgebra for Negations {
    type Value = (usize, usize);
    fn leaf(&mut self, i: u32) -> Option<(usize, usize)> {
        self.order.push(i);
        Some((self.order.len() - 1, self.order.len()))
    }
    fn max(&mut self, a: (usize, usize), b: (usize, usize)) -> Option<(usize, usize)> {
        Some((a.0, b.1))
    }
    fn min(&mut self, a: (usize, usize), b: (usize, usize)) -> Option<(usize, usize)> {
        Some((a.0, b.1))
    }
    fn neg(&mut self, a: (usize, usize)) -> Option<(usize, usize)> {
        for &i in self.order.get(a.0..a.1)? {
            if let Some(n) = self.negated.get_mut(i as usize) {
                *n = !*n;
            }
        }
        Some(a)
    }
}

/// Per leaf, whether an odd number of `Neg`s lies above it in `program` (`leaves` leaves).
fn negated(program: &[CsgOp], leaves: usize) -> Vec<bool> {
    let mut negations = Negations {
        order: Vec::with_capacity(leaves),
        negated: vec![false; leaves],
    };
    // A malformed program (never compiled) leaves the rest unflipped.
    let _ = run(program, &mut negations);
    negations.negated
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
    use glam::DVec3;

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
