//! `F′` along the current ray as the search sees it ([`RayFunction`]): one plain leaf,
//! monomorphised so that it needs no program and no scratch space, or a CSG program over the
//! prepared leaves, run by the one evaluator (`csg::run_in`) in the interval algebra over
//! segments ([`Bounds`]) and, at points, in the algebra of values with the leaf that decides them
//! ([`Deciding`], for the prediction of [`super::finish`]).

use super::CastStats;
use super::bound::{ABSENT, Bound, Bounds, leaf_bound};
use super::finish::predict_leaf;
use super::on_ray::{LeafOnRay, leaf_value};
use crate::csg::{CsgAlgebra, run_in};
use crate::{CsgOp, RayQuadratic};
use fray_core::Interval;

/// `F′` along the current ray, as the search sees it: bounds over segments, values at points.
pub(super) trait RayFunction {
    fn bound(&mut self, seg: Interval) -> Bound;
    fn value(&mut self, t: f64) -> f64;
    /// Where `F′` is one plain quadratic over `[a, b]`, its closed-form first root there: a
    /// prediction for [`finish`] to certify.
    fn predict(&self, a: f64, b: f64) -> Option<f64>;
}

/// A single leaf with no perturbation on this ray.
pub(super) struct PlainLeaf<'a> {
    pub(super) leaf: LeafOnRay,
    pub(super) stats: &'a mut CastStats,
}

impl RayFunction for PlainLeaf<'_> {
    #[inline]
    fn bound(&mut self, seg: Interval) -> Bound {
        self.stats.bound_evaluations += 1;
        leaf_bound(&self.leaf, &[], seg)
    }

    #[inline]
    fn value(&mut self, t: f64) -> f64 {
        self.stats.point_evaluations += 1;
        leaf_value(&self.leaf, &[], t)
    }

    #[inline]
    fn predict(&self, a: f64, b: f64) -> Option<f64> {
        predict_leaf(&self.leaf, true, a, b)
    }
}

/// Marks a deciding leaf index whose value reached the result negated.
pub(super) const NEGATED: u32 = 1 << 31;

/// A CSG program over prepared leaves.
pub(super) struct ProgramOnRay<'a> {
    pub(super) leaves: &'a [LeafOnRay],
    pub(super) perturbations: &'a [(f64, RayQuadratic)],
    pub(super) program: &'a [CsgOp],
    /// The evaluator's stacks for bounds and for values, reused from call to call.
    pub(super) bounds: &'a mut Vec<Bound>,
    pub(super) values: &'a mut Vec<(f64, u32)>,
    pub(super) stats: &'a mut CastStats,
    /// The last two points evaluated and the leaf whose value decided each (with [`NEGATED`]
    /// set if the program negated it on the way).
    pub(super) decided: [(f64, u32); 2],
}

/// Values at `t` with the leaf that decides each: `max`/`min` pick an operand (the first on a
/// tie), negation keeps it and marks it [`NEGATED`] (or clears the mark).
pub(super) struct Deciding<'a> {
    pub(super) leaves: &'a [LeafOnRay],
    pub(super) perturbations: &'a [(f64, RayQuadratic)],
    pub(super) t: f64,
}

impl CsgAlgebra for Deciding<'_> {
    type Value = (f64, u32);
    #[inline(always)]
    fn leaf(&mut self, i: u32) -> Option<(f64, u32)> {
        let leaf = self.leaves.get(i as usize)?;
        let perturbations =
            &self.perturbations[leaf.perturbations.0 as usize..leaf.perturbations.1 as usize];
        Some((leaf_value(leaf, perturbations, self.t), i))
    }
    #[inline(always)]
    fn max(&mut self, a: (f64, u32), b: (f64, u32)) -> Option<(f64, u32)> {
        Some(combine_values(true, a, b))
    }
    #[inline(always)]
    fn min(&mut self, a: (f64, u32), b: (f64, u32)) -> Option<(f64, u32)> {
        Some(combine_values(false, a, b))
    }
    #[inline(always)]
    fn neg(&mut self, (v, leaf): (f64, u32)) -> Option<(f64, u32)> {
        Some((-v, leaf ^ NEGATED))
    }
}

/// `max` or `min` of two (value, deciding leaf) pairs; `a` wins ties.
#[inline]
fn combine_values(is_max: bool, a: (f64, u32), b: (f64, u32)) -> (f64, u32) {
    let take_a = if is_max { a.0 >= b.0 } else { a.0 <= b.0 };
    if take_a { a } else { b }
}

impl RayFunction for ProgramOnRay<'_> {
    fn bound(&mut self, seg: Interval) -> Bound {
        self.stats.bound_evaluations += 1;
        let mut bounds = Bounds {
            leaves: self.leaves,
            perturbations: self.perturbations,
            seg,
        };
        run_in(self.program, &mut bounds, self.bounds).unwrap_or(ABSENT)
    }

    fn value(&mut self, t: f64) -> f64 {
        self.stats.point_evaluations += 1;
        let mut values = Deciding {
            leaves: self.leaves,
            perturbations: self.perturbations,
            t,
        };
        let (v, leaf) =
            run_in(self.program, &mut values, self.values).unwrap_or((f64::NEG_INFINITY, u32::MAX));
        self.decided = [self.decided[1], (t, leaf)];
        v
    }

    #[inline]
    fn predict(&self, a: f64, b: f64) -> Option<f64> {
        // One leaf, or the leaf that decided F′(b) last time it was evaluated: near the root
        // the CSG value is that leaf's (or its negation), so its root is the prediction.
        let decided = match *self.program {
            [CsgOp::Leaf(i)] => i,
            _ => self.decided.iter().find(|d| d.0 == b)?.1,
        };
        let leaf = self.leaves.get((decided & !NEGATED) as usize)?;
        let plain = leaf.perturbations.0 == leaf.perturbations.1;
        if decided & NEGATED == 0 {
            predict_leaf(leaf, plain, a, b)
        } else if !plain {
            None
        } else {
            let q = leaf.base;
            let negated = LeafOnRay {
                base: RayQuadratic {
                    a: -q.a,
                    b: -q.b,
                    c: -q.c,
                },
                ..*leaf
            };
            // Only the quadratic's root: a negated leaf is +∞ outside its box.
            predict_leaf(
                &LeafOnRay {
                    clips: false,
                    ..negated
                },
                true,
                a,
                b,
            )
        }
    }
}
