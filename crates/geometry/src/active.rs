//! A subset of a solid's leaves and perturbations that may matter for a set of rays (one image
//! tile), with the CSG program pruned to it: the input of [`crate::RayCaster::cast_with`].
//!
//! A leaf left out is taken as absent (`−∞`) and folded out of the postfix program
//! (`max(a, −∞) = a`, `min(a, −∞) = −∞`, `−(−∞) = +∞`, …). Casting with the subset gives the
//! same answer as casting with everything exactly when the subset is *conservative* for the
//! ray: every leaf left out has a box the ray misses, and every perturbation left out has a
//! support the ray does not enter within its leaf's box — the same things the per-ray pruning
//! drops, so the arithmetic that remains is the same, term for term. The fold is an algebra of
//! the one program evaluator (`csg::run`).

use crate::csg::{CsgAlgebra, run_in};
use crate::{CsgOp, Solid};
use fray_core::Aabb;

/// Which leaves and perturbations of one [`Solid`] are active, and the pruned program.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ActiveSet {
    leaf_active: Vec<bool>,
    /// Per leaf, the range of its active perturbations in `perturbations`.
    leaf_perturbations: Vec<(u32, u32)>,
    /// Leaf-local perturbation indices, increasing within each leaf.
    perturbations: Vec<u32>,
    program: Vec<CsgOp>,
    stack: Vec<Term>,
}

/// A folded operand: a known constant or a run of code at the end of the output program.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Term {
    NegInf,
    PosInf,
    Code(usize),
}

impl ActiveSet {
    pub fn new() -> Self {
        Self::default()
    }

    /// Every leaf and perturbation of `solid` active: casting with it equals [`crate::RayCaster::cast`].
    pub fn all(solid: &Solid) -> Self {
        let leaves: Vec<u32> = (0..solid.leaves().len() as u32).collect();
        let perturbations: Vec<u32> = (0..solid.perturbation_count() as u32).collect();
        let mut set = Self::new();
        set.set(solid, &leaves, &perturbations);
        set
    }

    /// Makes `leaves` (indices into `solid.leaves()`) and `perturbations` (object-wide indices:
    /// leaf 0's perturbations first, then leaf 1's, …; increasing) the active subset, and prunes
    /// the program. Perturbations of inactive leaves are kept for [`Solid::surface_at_with`]
    /// (casting never reads them). Returns `false` when the pruned
    /// solid is `−∞` everywhere, i.e. no ray for which the subset is conservative can hit it.
    pub fn set(&mut self, solid: &Solid, leaves: &[u32], perturbations: &[u32]) -> bool {
        let n = solid.leaves().len();
        self.leaf_active.clear();
        self.leaf_active.resize(n, false);
        for &l in leaves {
            if let Some(a) = self.leaf_active.get_mut(l as usize) {
                *a = true;
            }
        }
        self.leaf_perturbations.clear();
        self.perturbations.clear();
        let mut global = perturbations.iter().copied().peekable();
        let mut first = 0u32;
        for leaf in solid.leaves() {
            let count = leaf.perturbations().len() as u32;
            let start = self.perturbations.len() as u32;
            while let Some(&g) = global.peek() {
                if g >= first + count {
                    break;
                }
                if g >= first {
                    self.perturbations.push(g - first);
                }
                global.next();
            }
            self.leaf_perturbations
                .push((start, self.perturbations.len() as u32));
            first += count;
        }
        self.fold(solid)
    }

    /// Whether leaf `i` is active.
    #[inline]
    pub fn leaf_is_active(&self, i: usize) -> bool {
        self.leaf_active.get(i).copied().unwrap_or(false)
    }

    /// The active perturbations of leaf `i`, as indices into that leaf's perturbations.
    #[inline]
    pub fn leaf_perturbations(&self, i: usize) -> &[u32] {
        self.leaf_perturbations
            .get(i)
            .and_then(|&(s, e)| self.perturbations.get(s as usize..e as usize))
            .unwrap_or(&[])
    }

    /// The pruned postfix program.
    pub fn program(&self) -> &[CsgOp] {
        &self.program
    }

    fn fold(&mut self, solid: &Solid) -> bool {
        self.program.clear();
        let mut fold = Fold {
            active: &self.leaf_active,
            out: &mut self.program,
        };
        match run_in(solid.program(), &mut fold, &mut self.stack) {
            Some(Term::Code(_)) => true,
            Some(Term::NegInf) | None => false,
            Some(Term::PosInf) => {
                // Non-negative wherever every active leaf is absent: keep the whole program
                // (inactive leaves still read as absent), which casts exactly like the original.
                self.program.clear();
                self.program.extend_from_slice(solid.program());
                true
            }
        }
    }
}

/// The program folded over absent leaves, as an algebra of the one evaluator: an operand is a
/// constant (`±∞`) or code it has emitted at the end of `out`, which an absorbing constant drops
/// again.
struct Fold<'a> {
    active: &'a [bool],
    out: &'a mut Vec<CsgOp>,
}

impl Fold<'_> {
    /// `max` (`absorbing = +∞`, identity `−∞`) or `min` (the other way round) of two terms.
    fn combine(&mut self, op: CsgOp, a: Term, b: Term, absorbing: Term, identity: Term) -> Term {
        match (a, b) {
            (Term::Code(s), Term::Code(_)) => {
                self.out.push(op);
                Term::Code(s)
            }
            (x, y) if x == absorbing || y == absorbing => {
                // Drop whatever code the operands left.
                if let Term::Code(s) = a {
                    self.out.truncate(s);
                } else if let Term::Code(s) = b {
                    self.out.truncate(s);
                }
                absorbing
            }
            (x, y) if x == identity => y,
            (x, _) => x, // y is the identity
        }
    }
}

impl CsgAlgebra for Fold<'_> {
    type Value = Term;
    fn leaf(&mut self, i: u32) -> Option<Term> {
        Some(if self.active.get(i as usize).copied().unwrap_or(false) {
            self.out.push(CsgOp::Leaf(i));
            Term::Code(self.out.len() - 1)
        } else {
            Term::NegInf
        })
    }
    fn max(&mut self, a: Term, b: Term) -> Option<Term> {
        Some(self.combine(CsgOp::Max, a, b, Term::PosInf, Term::NegInf))
    }
    fn min(&mut self, a: Term, b: Term) -> Option<Term> {
        Some(self.combine(CsgOp::Min, a, b, Term::NegInf, Term::PosInf))
    }
    fn neg(&mut self, a: Term) -> Option<Term> {
        Some(match a {
            Term::NegInf => Term::PosInf,
            Term::PosInf => Term::NegInf,
            Term::Code(s) => {
                self.out.push(CsgOp::Neg);
                Term::Code(s)
            }
        })
    }
}

impl Solid {
    /// The leaves and perturbations that a set of rays may need, given a conservative test
    /// `may_meet(box)` ("some ray of the set may pass through the box"): a leaf is kept when its
    /// box may be met, a perturbation when its support box may be met (always, for an unbounded
    /// support) — whatever its leaf, and with zero form factors too, so that
    /// [`Solid::surface_at_with`] sums exactly the terms that can be non-zero on the rays. Writes
    /// object-wide indices (see [`ActiveSet::set`]) into the two lists (cleared).
    pub fn active_parts(
        &self,
        mut may_meet: impl FnMut(&Aabb) -> bool,
        leaves: &mut Vec<u32>,
        perturbations: &mut Vec<u32>,
    ) {
        leaves.clear();
        perturbations.clear();
        let mut k = 0u32;
        for (i, leaf) in self.leaves().iter().enumerate() {
            if may_meet(&leaf.bounds()) {
                leaves.push(i as u32);
            }
            for p in leaf.perturbations() {
                if p.support_bounds().is_none_or(|s| may_meet(&s)) {
                    perturbations.push(k);
                }
                k += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CastStats, FreeForm, Perturbation, Quadric, RayCaster, Shape};
    use fray_core::{Interval, Ray};
    use glam::DVec3;

    fn ball(x: f64) -> Shape {
        Shape::FreeForm(
            FreeForm::new(Quadric::sphere(DVec3::new(x, 0.0, 0.0), 1.0), vec![], None).unwrap(),
        )
    }

    #[test]
    fn folding_drops_absent_operands() {
        // (a ∪ b) − c
        let s = Solid::new(Shape::Difference(
            Box::new(Shape::Union(vec![ball(0.0), ball(3.0)])),
            Box::new(ball(1.0)),
        ))
        .unwrap();
        let mut set = ActiveSet::new();
        assert!(set.set(&s, &[0, 1, 2], &[]));
        assert_eq!(set.program(), s.program());
        assert!(set.set(&s, &[1], &[]));
        assert_eq!(set.program(), &[CsgOp::Leaf(1)]);
        assert!(set.set(&s, &[0, 2], &[]));
        assert_eq!(
            set.program(),
            &[CsgOp::Leaf(0), CsgOp::Leaf(2), CsgOp::Neg, CsgOp::Min]
        );
        assert!(!set.set(&s, &[2], &[]));
        // a ∩ b with b absent is empty.
        let s = Solid::new(Shape::Intersection(vec![ball(0.0), ball(1.0)])).unwrap();
        assert!(!set.set(&s, &[0], &[]));
    }

    #[test]
    fn casting_with_everything_or_a_conservative_subset_matches_cast_bit_for_bit() {
        let bumpy = |x: f64| {
            let bumps = (0..6)
                .map(|k| {
                    let a = f64::from(k);
                    let c = DVec3::new(x + a.cos(), 0.3 * a.sin(), a.sin());
                    Perturbation::new(0.5 - 0.2 * a, Quadric::sphere(c, 0.4))
                })
                .collect();
            Shape::FreeForm(
                FreeForm::new(Quadric::sphere(DVec3::new(x, 0.0, 0.0), 1.0), bumps, None).unwrap(),
            )
        };
        let s = Solid::new(Shape::Difference(
            Box::new(Shape::Union(vec![bumpy(0.0), bumpy(2.5)])),
            Box::new(ball(1.2)),
        ))
        .unwrap();
        let all = ActiveSet::all(&s);
        let mut caster = RayCaster::new();
        let mut stats = CastStats::default();
        for i in 0..400 {
            let a = f64::from(i) * 0.37;
            let origin = DVec3::new(1.2 + 6.0 * a.cos(), 2.0 * (a * 0.7).sin(), 6.0 * a.sin());
            let target = DVec3::new(1.2 + (a * 1.3).sin(), 0.5 * a.cos(), 0.3 * (a * 2.1).cos());
            let ray = Ray::new(origin, target - origin).unwrap();
            let range = Interval::new(0.0, f64::INFINITY);
            let full = caster.cast(&s, &ray, range, 1e-9, &mut stats);
            let with = caster.cast_with(&s, &ray, range, 1e-9, &all, &mut stats);
            assert_eq!(full.map(f64::to_bits), with.map(f64::to_bits), "ray {i}");
            // The subset this ray needs: leaves and perturbations whose boxes it meets.
            let (mut leaves, mut perts) = (Vec::new(), Vec::new());
            s.active_parts(
                |b| b.clip_ray(&ray, range).is_some(),
                &mut leaves,
                &mut perts,
            );
            let mut subset = ActiveSet::new();
            let may_hit = subset.set(&s, &leaves, &perts);
            let with = caster.cast_with(&s, &ray, range, 1e-9, &subset, &mut stats);
            assert_eq!(
                full.map(f64::to_bits),
                with.map(f64::to_bits),
                "ray {i} (subset)"
            );
            // Planned casts, whole and with the subset, give the same bits too.
            for active in [None, Some(&subset)] {
                let mut plan = crate::CastPlan::new(&s, active);
                let planned = caster.cast_planned(&mut plan, &ray, range, 1e-9, &mut stats);
                assert_eq!(
                    full.map(f64::to_bits),
                    planned.map(f64::to_bits),
                    "ray {i} (planned)"
                );
            }
            assert!(may_hit || full.is_none());
            if let Some(t) = full {
                let p = ray.at(t);
                assert_eq!(
                    s.surface_at(p, -ray.dir),
                    s.surface_at_with(p, -ray.dir, &subset)
                );
            }
        }
    }

    /// A plain leaf, clipped by a box that cuts it and not: the planned fast path and the
    /// general cast agree bit for bit, with either cast method.
    #[test]
    fn planned_plain_leaves_match_cast_bit_for_bit() {
        let cut = fray_core::Aabb::from_center_half(DVec3::new(0.2, 0.1, 0.0), DVec3::splat(0.8));
        let leaves = [
            FreeForm::new(Quadric::sphere(DVec3::ZERO, 1.0), vec![], None).unwrap(),
            FreeForm::new(Quadric::sphere(DVec3::ZERO, 1.0), vec![], Some(cut)).unwrap(),
            FreeForm::new(
                Quadric::cylinder(DVec3::ZERO, DVec3::Y, 0.6),
                vec![],
                Some(cut),
            )
            .unwrap(),
        ];
        for leaf in leaves {
            let s = Solid::from_free_form(leaf);
            let all = ActiveSet::all(&s);
            for method in [crate::CastMethod::ClosedForm, crate::CastMethod::Halving] {
                let mut caster = RayCaster::with_method(method);
                let mut stats = CastStats::default();
                for i in 0..500 {
                    let a = f64::from(i) * 0.61;
                    let origin = DVec3::new(3.0 * a.cos(), 1.5 * (a * 0.3).sin(), 3.0 * a.sin());
                    let target = DVec3::new(0.7 * (a * 1.7).sin(), 0.6 * a.cos(), 0.2);
                    let ray = Ray::new(origin, target - origin).unwrap();
                    let range = Interval::new(0.0, f64::INFINITY);
                    let cast = caster.cast(&s, &ray, range, 1e-9, &mut stats);
                    for active in [None, Some(&all)] {
                        let mut plan = crate::CastPlan::new(&s, active);
                        let planned = caster.cast_planned(&mut plan, &ray, range, 1e-9, &mut stats);
                        assert_eq!(cast.map(f64::to_bits), planned.map(f64::to_bits), "ray {i}");
                    }
                }
            }
        }
    }
}
