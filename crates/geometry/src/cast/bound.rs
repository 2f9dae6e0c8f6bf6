//! Bounds over a ray segment: the value range and slope range of a leaf, exact per term, and
//! of a program — the interval algebra of the one CSG evaluator, whose `max`/`min` keep the
//! *sign* pattern of the slope (`sign_slope`), which is all the search needs.

use super::on_ray::LeafOnRay;
use crate::RayQuadratic;
use crate::csg::CsgAlgebra;
use fray_core::Interval;

/// The value range and derivative range of a function over a segment.
#[derive(Clone, Copy, Debug)]
pub(super) struct Bound {
    pub(super) value: Interval,
    pub(super) slope: Interval,
}

/// The slope of a segment whose sign changes at most once, from − to + (clipped leaves).
const SIGN_INCREASING: Interval = Interval {
    lo: f64::MIN_POSITIVE,
    hi: f64::INFINITY,
};
/// The slope of a segment whose sign changes at most once, from + to −.
const SIGN_DECREASING: Interval = Interval {
    lo: f64::NEG_INFINITY,
    hi: -f64::MIN_POSITIVE,
};

pub(super) const ABSENT: Bound = Bound {
    value: Interval::NEG_INFINITY,
    slope: Interval::point(0.0),
};

/// The exact value and derivative ranges of a quadratic over `t`: the hot path of every bound.
/// The vertex lies strictly inside exactly when the derivative changes sign over `t`, which the
/// derivative range (needed anyway) tells without a division; plain comparisons stand in for
/// `f64::min`/`max` because nothing here is NaN.
#[inline]
pub(super) fn quadratic_bound(q: &RayQuadratic, t: Interval) -> Bound {
    let (f0, f1) = (q.eval(t.lo), q.eval(t.hi));
    let (d0, d1) = (q.derivative(t.lo), q.derivative(t.hi));
    let (mut lo, mut hi) = if f0 <= f1 { (f0, f1) } else { (f1, f0) };
    if (d0 < 0.0 && d1 > 0.0) || (d0 > 0.0 && d1 < 0.0) {
        let fv = q.eval(-q.b / (2.0 * q.a));
        if fv < lo {
            lo = fv;
        }
        if fv > hi {
            hi = fv;
        }
    }
    let slope = if d0 <= d1 {
        Interval { lo: d0, hi: d1 }
    } else {
        Interval { lo: d1, hi: d0 }
    };
    Bound {
        value: Interval { lo, hi },
        slope,
    }
}

#[inline]
pub(super) fn leaf_bound(
    leaf: &LeafOnRay,
    perturbations: &[(f64, RayQuadratic)],
    seg: Interval,
) -> Bound {
    let Some(present) = leaf.present else {
        return ABSENT;
    };
    if seg.hi < present.lo || seg.lo > present.hi {
        return ABSENT;
    }
    let mut inner = seg;
    if leaf.clips {
        if present.lo > inner.lo {
            inner.lo = present.lo;
        }
        if present.hi < inner.hi {
            inner.hi = present.hi;
        }
    }
    let Bound {
        mut value,
        mut slope,
    } = quadratic_bound(&leaf.base, inner);
    for &(f, q) in perturbations {
        let qr = q.range(inner).positive_part();
        value = value + qr.cube().scale(f);
        slope = slope + (qr.square() * q.derivative_range(inner)).scale(3.0 * f);
    }
    if inner != seg {
        // Part of the segment is outside the clipping box, where the value is −∞: negative, a
        // sign pattern the search can still use (see `sign_slope`). Entering the box with the
        // leaf increasing, or ≥ 0, inside, the sign changes at most once, from − to +; leaving
        // it decreasing or ≥ 0, at most once from + to −.
        let before = seg.lo < inner.lo;
        let after = seg.hi > inner.hi;
        let nonnegative = value.lo >= 0.0;
        slope = match (before, after) {
            (true, false) if slope.lo > 0.0 || nonnegative => SIGN_INCREASING,
            (false, true) if slope.hi < 0.0 || nonnegative => SIGN_DECREASING,
            _ => Interval::EVERYTHING,
        };
        value = Interval {
            lo: f64::NEG_INFINITY,
            hi: value.hi,
        };
    }
    Bound { value, slope }
}

/// The leaves on the ray bounded over `seg`: the interval algebra ([`Bound`]s under
/// [`combine_bounds`] and negation).
pub(super) struct Bounds<'a> {
    pub(super) leaves: &'a [LeafOnRay],
    pub(super) perturbations: &'a [(f64, RayQuadratic)],
    pub(super) seg: Interval,
}

impl CsgAlgebra for Bounds<'_> {
    type Value = Bound;
    #[inline(always)]
    fn leaf(&mut self, i: u32) -> Option<Bound> {
        let leaf = self.leaves.get(i as usize)?;
        let perturbations =
            &self.perturbations[leaf.perturbations.0 as usize..leaf.perturbations.1 as usize];
        Some(leaf_bound(leaf, perturbations, self.seg))
    }
    #[inline(always)]
    fn max(&mut self, a: Bound, b: Bound) -> Option<Bound> {
        Some(combine_bounds(true, a, b))
    }
    #[inline(always)]
    fn min(&mut self, a: Bound, b: Bound) -> Option<Bound> {
        Some(combine_bounds(false, a, b))
    }
    #[inline(always)]
    fn neg(&mut self, a: Bound) -> Option<Bound> {
        Some(Bound {
            value: -a.value,
            slope: -a.slope,
        })
    }
}

/// `max(a, b)` (`is_max`) or `min(a, b)` of two bounds. If one operand dominates over the whole
/// segment, the result *is* that operand; otherwise the value is the exact max/min range and
/// the slope comes from [`sign_slope`].
#[inline]
fn combine_bounds(is_max: bool, a: Bound, b: Bound) -> Bound {
    let a_wins = if is_max {
        a.value.lo >= b.value.hi
    } else {
        a.value.hi <= b.value.lo
    };
    let b_wins = if is_max {
        b.value.lo >= a.value.hi
    } else {
        b.value.hi <= a.value.lo
    };
    if a_wins {
        a
    } else if b_wins {
        b
    } else if is_max {
        Bound {
            value: a.value.max(b.value),
            slope: sign_slope(a, b, b.value.hi < 0.0, a.value.hi < 0.0),
        }
    } else {
        Bound {
            value: a.value.min(b.value),
            slope: sign_slope(a, b, b.value.lo >= 0.0, a.value.lo >= 0.0),
        }
    }
}

/// The slope range of `max(a, b)` or `min(a, b)` when neither operand dominates in value.
///
/// The search needs the slope only for its *sign pattern*: a slope range above 0 must mean
/// that the sign of `F′` changes at most once on the segment, from − to + (below 0: from + to
/// −). Where `b`'s sign is fixed so that it cannot decide (`b < 0` under `max`, `b ≥ 0` under
/// `min`: `b_idle`), the result has exactly `a`'s sign and `a`'s slope stands in; likewise for
/// `a`. Otherwise the hull of both: the union (`max`) or intersection (`min`) of two up-sets is
/// an up-set. This keeps CSG segments "monotone" where a hole or a clip plane stays off to one
/// side, so they finish by root solving instead of halving.
#[inline]
fn sign_slope(a: Bound, b: Bound, b_idle: bool, a_idle: bool) -> Interval {
    if b_idle {
        a.slope
    } else if a_idle {
        b.slope
    } else {
        a.slope.hull(b.slope)
    }
}
