//! The closed-form first hit of a CSG program whose leaves are all plain quadrics on the ray.
//!
//! Each leaf's inside (`q(t) ≥ 0` within the part of the ray its box lets through) is at most
//! two intervals of `t`, from the quadratic's roots. The program combines them as sets — max is
//! union, min intersection, negation the complement — and the hit is the first point of the
//! result in the range. Two point evaluations of `F′` certify it as the search's predictions are
//! certified (`F′(r) ≥ 0 > F′(r − ε)`), so the answer keeps the caster's contract; where rounding
//! leaves it uncertain, or a set outgrows its fixed capacity, the caller falls back to the
//! halving search.
//!
//! What is guaranteed (docs/accuracy.md): the quadratics arrive *widened* by a bound `Δ` on their
//! rounding (module `cast`), so each leaf's computed set contains the exact one — a grazing span
//! whose discriminant would round negative unwidened (its peak `|a| w²/4` below the rounding of
//! `b² − 4ac`) now has a positive one — and the roots' own rounding (at most 6 u S in value, the
//! discriminant's 3 u S) is within `Δ`. The first point of the combined set is therefore never
//! after the exact first hit; the certificate keeps it within `ε` of the first span at least `ε`
//! long, or hands the ray to the search. What may be reported: a point up to `2Δ` outside the
//! exact solid (a near-tangent ray that misses by less than the rounding hits at its vertex
//! region).
//!
//! Why: on plain quadrics the halving search spends two or three bounds and four or five point
//! evaluations to land on the same closed-form root that its `finish` certifies; a root and a
//! set operation per leaf cost a fraction of that. Everything here is exact selection between
//! the same floats (roots, box faces), so a pruned program (culling) and the full one give the
//! same bits, as the search does.

use super::on_ray::LeafOnRay;
use crate::RayQuadratic;
use crate::csg::CsgAlgebra;
use fray_core::Interval;

/// The most disjoint intervals a set holds; a program whose sets outgrow it is searched instead.
/// Four is what any two-leaf program needs (two spans per leaf; a complement adds one).
const CAPACITY: usize = 4;

/// A union of disjoint closed intervals of `t`, sorted.
#[derive(Clone, Copy, Debug)]
pub(super) struct SpanSet {
    len: usize,
    spans: [(f64, f64); CAPACITY],
}

impl SpanSet {
    pub(super) const EMPTY: SpanSet = SpanSet {
        len: 0,
        spans: [(0.0, 0.0); CAPACITY],
    };
    #[cfg(test)]
    const EVERYTHING: SpanSet = SpanSet::one(f64::NEG_INFINITY, f64::INFINITY);

    #[cfg(test)]
    const fn one(lo: f64, hi: f64) -> Self {
        let mut s = Self::EMPTY;
        s.spans[0] = (lo, hi);
        s.len = 1;
        s
    }

    #[inline]
    pub(super) fn spans(&self) -> &[(f64, f64)] {
        &self.spans[..self.len]
    }

    /// Appends a span after every span held (merging one that touches the last); `false` when
    /// full.
    #[inline]
    fn push(&mut self, lo: f64, hi: f64) -> bool {
        if let Some(last) = self.len.checked_sub(1).map(|k| &mut self.spans[k])
            && lo <= last.1
        {
            if hi > last.1 {
                last.1 = hi;
            }
            return true;
        }
        if self.len == CAPACITY {
            return false;
        }
        self.spans[self.len] = (lo, hi);
        self.len += 1;
        true
    }

    /// Where `q ≥ 0` within `present` (the leaf's part of the ray): at most two spans. `None` if
    /// the roots are not finite numbers (overflow), so the caller searches instead.
    #[inline]
    pub(super) fn of_leaf(q: &RayQuadratic, present: Interval) -> Option<Self> {
        let mut s = Self::EMPTY;
        for (lo, hi) in nonnegative_spans(q)?.into_iter().flatten() {
            let (lo, hi) = (lo.max(present.lo), hi.min(present.hi));
            // Two spans that touch (a double root) merge into one.
            if lo <= hi {
                s.push(lo, hi);
            }
        }
        Some(s)
    }

    /// `Self::of_leaf(q, present)?.first_in(range)` without building the set, for a program
    /// that is one leaf: the same selection among the same floats, so the same bits (tested).
    /// `present` must lie within `range`, as a leaf's part of the ray does.
    #[inline]
    pub(super) fn first_of_leaf(
        q: &RayQuadratic,
        present: Interval,
        range: Interval,
    ) -> Option<Option<f64>> {
        // A span's first point once the box cuts it. Where the box keeps both spans and they
        // touch (a double root), the set merges them, and its first point is still the earlier
        // span's.
        let first = |(lo, hi): (f64, f64)| {
            let (lo, hi) = (lo.max(present.lo), hi.min(present.hi));
            (lo <= hi && hi >= range.lo)
                .then(|| lo.max(range.lo))
                .filter(|&t| t <= range.hi)
        };
        let [s0, s1] = nonnegative_spans(q)?;
        Some(s0.and_then(first).or_else(|| s1.and_then(first)))
    }

    /// `self ∪ other`; `None` if it does not fit.
    #[inline]
    fn union(&self, other: &Self) -> Option<Self> {
        let (mut i, mut j) = (0, 0);
        let (a, b) = (self.spans(), other.spans());
        let mut out = Self::EMPTY;
        while i < a.len() || j < b.len() {
            let next = if j == b.len() || (i < a.len() && a[i].0 <= b[j].0) {
                i += 1;
                a[i - 1]
            } else {
                j += 1;
                b[j - 1]
            };
            if !out.push(next.0, next.1) {
                return None;
            }
        }
        Some(out)
    }

    /// `self ∩ other` (never larger than the two together, so it always fits).
    #[inline]
    fn intersection(&self, other: &Self) -> Self {
        let (mut i, mut j) = (0, 0);
        let (a, b) = (self.spans(), other.spans());
        let mut out = Self::EMPTY;
        while i < a.len() && j < b.len() {
            let lo = a[i].0.max(b[j].0);
            let hi = a[i].1.min(b[j].1);
            if lo <= hi {
                out.push(lo, hi);
            }
            if a[i].1 < b[j].1 {
                i += 1;
            } else {
                j += 1;
            }
        }
        out
    }

    /// The closure of the complement (boundaries belong to both: the certification decides
    /// which side a boundary point is on); `None` if it does not fit.
    #[inline]
    fn complement(&self) -> Option<Self> {
        let mut out = Self::EMPTY;
        let mut from = f64::NEG_INFINITY;
        for &(lo, hi) in self.spans() {
            if lo > from && !out.push(from, lo) {
                return None;
            }
            from = hi;
        }
        if from < f64::INFINITY && !out.push(from, f64::INFINITY) {
            return None;
        }
        Some(out)
    }

    /// The first point of the set in `range`.
    #[inline]
    pub(super) fn first_in(&self, range: Interval) -> Option<f64> {
        self.spans()
            .iter()
            .find(|s| s.1 >= range.lo)
            .map(|s| s.0.max(range.lo))
            .filter(|&t| t <= range.hi)
    }
}

/// Where `q(t) ≥ 0` on the whole line: at most two spans, in order (endpoints may be infinite;
/// `None` entries unused). `None` when the roots are not finite numbers (overflow), so the
/// caller searches instead. The roots are the cancellation-free ones of
/// `RayQuadratic::first_nonnegative`.
#[inline(always)]
fn nonnegative_spans(q: &RayQuadratic) -> Option<[Option<(f64, f64)>; 2]> {
    const ALL: Option<(f64, f64)> = Some((f64::NEG_INFINITY, f64::INFINITY));
    let (a, b, c) = (q.a, q.b, q.c);
    if a == 0.0 {
        let span = if b > 0.0 {
            Some((-c / b, f64::INFINITY))
        } else if b < 0.0 {
            Some((f64::NEG_INFINITY, -c / b))
        } else if c >= 0.0 {
            ALL
        } else {
            None
        };
        return Some([span, None]);
    }
    let disc = b * b - 4.0 * a * c;
    if disc.is_nan() || disc.is_infinite() {
        return None;
    }
    if disc < 0.0 {
        // No root: q has a's sign everywhere.
        return Some([if a > 0.0 { ALL } else { None }, None]);
    }
    let half = -0.5 * (b + b.signum() * disc.sqrt());
    let (r0, r1) = if half == 0.0 {
        (0.0, 0.0)
    } else {
        (half / a, c / half)
    };
    let (r0, r1) = if r0 <= r1 { (r0, r1) } else { (r1, r0) };
    if r0.is_nan() || r1.is_nan() {
        return None;
    }
    Some(if a < 0.0 {
        [Some((r0, r1)), None]
    } else {
        // Outside the roots.
        [Some((f64::NEG_INFINITY, r0)), Some((r1, f64::INFINITY))]
    })
}

/// Where the program is non-negative, as sets of `t`: the span-set algebra of the one CSG
/// evaluator. A leaf's set comes from its roots within its part of the ray (empty where it is
/// absent); max is union, min intersection, negation the complement. `None` when a set outgrows
/// [`CAPACITY`] or a leaf's roots overflow.
pub(super) struct SpanSets<'a> {
    pub(super) leaves: &'a [LeafOnRay],
}

impl CsgAlgebra for SpanSets<'_> {
    type Value = SpanSet;
    #[inline(always)]
    fn leaf(&mut self, i: u32) -> Option<SpanSet> {
        match self.leaves.get(i as usize) {
            Some(LeafOnRay {
                present: Some(present),
                base,
                ..
            }) => SpanSet::of_leaf(base, *present),
            _ => Some(SpanSet::EMPTY),
        }
    }
    #[inline(always)]
    fn max(&mut self, a: SpanSet, b: SpanSet) -> Option<SpanSet> {
        a.union(&b)
    }
    #[inline(always)]
    fn min(&mut self, a: SpanSet, b: SpanSet) -> Option<SpanSet> {
        Some(a.intersection(&b))
    }
    #[inline(always)]
    fn neg(&mut self, a: SpanSet) -> Option<SpanSet> {
        a.complement()
    }
}

/// The outcome of certifying a closed-form hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Certified {
    /// The first point of the range where `F′ ≥ 0`, within ε (or no hit at all).
    Hit(Option<f64>),
    /// Rounding put the prediction where the point evaluations disagree: search instead.
    Unsure,
}

/// Certifies `first` (the set's first point in `range`) with point values of `F′`: at the start
/// of the range `F′ ≥ 0` suffices; past it, `F′(r) ≥ 0 > F′(max(r − ε, range.lo))` puts the root
/// in the last ε. A root that rounding put just before the surface (`F′(r) < 0`) is nudged past
/// the rounding (or, failing that, to `r + ε/2`) when `F′` is non-negative there. A miss needs
/// no evaluation.
#[inline]
pub(super) fn certify(
    first: Option<f64>,
    range: Interval,
    eps: f64,
    mut value: impl FnMut(f64) -> f64,
) -> Certified {
    let Some(r) = first else {
        return Certified::Hit(None);
    };
    let fr = value(r);
    if r <= range.lo {
        return if fr >= 0.0 {
            Certified::Hit(Some(r))
        } else {
            Certified::Unsure
        };
    }
    if fr >= 0.0 {
        let before = (r - eps).max(range.lo);
        return if value(before) < 0.0 {
            Certified::Hit(Some(r))
        } else {
            Certified::Unsure
        };
    }
    // F′(r) < 0: the crossing is after r, by the rounding of the root if the prediction is
    // right. Step past that rounding (a few dozen ulps), and only then by ε/2.
    for step in [(r.abs() * ROOT_ROUNDING).min(0.5 * eps), 0.5 * eps] {
        let nudged = r + step;
        if nudged > r && nudged <= range.hi && value(nudged) >= 0.0 {
            return Certified::Hit(Some(nudged));
        }
    }
    Certified::Unsure
}

/// How far past a computed root (relative to it) the surface may still lie from the rounding
/// of the root and of the point evaluation: about fifty ulps.
const ROOT_ROUNDING: f64 = 1e-14;

#[cfg(test)]
mod tests {
    use super::*;

    fn set(spans: &[(f64, f64)]) -> SpanSet {
        let mut s = SpanSet::EMPTY;
        for &(lo, hi) in spans {
            assert!(s.push(lo, hi));
        }
        s
    }

    #[test]
    fn set_operations_match_pointwise_membership() {
        let a = set(&[(0.0, 1.0), (2.0, 3.0), (5.0, 8.0)]);
        let b = set(&[(0.5, 2.5), (7.0, 9.0)]);
        let u = a.union(&b).unwrap();
        let i = a.intersection(&b);
        let ca = a.complement().unwrap();
        let member = |s: &SpanSet, t: f64| s.spans().iter().any(|&(lo, hi)| lo <= t && t <= hi);
        // Sample off the boundaries, where membership is unambiguous.
        for k in 0..200 {
            let t = -1.05 + 0.0537 * f64::from(k);
            assert_eq!(
                member(&u, t),
                member(&a, t) || member(&b, t),
                "union at {t}"
            );
            assert_eq!(member(&i, t), member(&a, t) && member(&b, t), "∩ at {t}");
            assert_eq!(member(&ca, t), !member(&a, t), "complement at {t}");
        }
        assert_eq!(u.spans(), &[(0.0, 3.0), (5.0, 9.0)]);
        assert_eq!(i.spans(), &[(0.5, 1.0), (2.0, 2.5), (7.0, 8.0)]);
        assert_eq!(
            ca.spans(),
            &[
                (f64::NEG_INFINITY, 0.0),
                (1.0, 2.0),
                (3.0, 5.0),
                (8.0, f64::INFINITY)
            ]
        );
        assert_eq!(
            SpanSet::EMPTY.complement().unwrap().spans(),
            SpanSet::EVERYTHING.spans()
        );
        assert_eq!(SpanSet::EVERYTHING.complement().unwrap().len, 0);
    }

    #[test]
    fn a_set_that_outgrows_its_capacity_gives_up() {
        let comb = |offset: f64| {
            let mut s = SpanSet::EMPTY;
            for k in 0..CAPACITY {
                assert!(s.push(offset + 4.0 * k as f64, offset + 4.0 * k as f64 + 1.0));
            }
            s
        };
        assert!(comb(0.0).union(&comb(2.0)).is_none());
        assert!(comb(0.0).complement().is_none());
    }

    #[test]
    fn leaf_sets_follow_the_roots_and_the_box() {
        let all = Interval::new(f64::NEG_INFINITY, f64::INFINITY);
        // −(t − 1)(t − 3): inside between the roots.
        let cap = RayQuadratic {
            a: -1.0,
            b: 4.0,
            c: -3.0,
        };
        assert_eq!(SpanSet::of_leaf(&cap, all).unwrap().spans(), &[(1.0, 3.0)]);
        assert_eq!(
            SpanSet::of_leaf(&cap, Interval::new(2.0, 2.5))
                .unwrap()
                .spans(),
            &[(2.0, 2.5)]
        );
        // (t − 1)(t − 3): outside the roots; a box over the first root keeps one span.
        let cup = RayQuadratic {
            a: 1.0,
            b: -4.0,
            c: 3.0,
        };
        let s = SpanSet::of_leaf(&cup, all).unwrap();
        assert_eq!(s.spans(), &[(f64::NEG_INFINITY, 1.0), (3.0, f64::INFINITY)]);
        let s = SpanSet::of_leaf(&cup, Interval::new(0.0, 2.0)).unwrap();
        assert_eq!(s.spans(), &[(0.0, 1.0)]);
        // Linear, constant, and rootless cases.
        let line = RayQuadratic {
            a: 0.0,
            b: -2.0,
            c: 4.0,
        };
        assert_eq!(
            SpanSet::of_leaf(&line, all).unwrap().spans(),
            &[(f64::NEG_INFINITY, 2.0)]
        );
        let negative = RayQuadratic {
            a: -1.0,
            b: 0.0,
            c: -1.0,
        };
        assert_eq!(SpanSet::of_leaf(&negative, all).unwrap().len, 0);
        let positive = RayQuadratic {
            a: 0.0,
            b: 0.0,
            c: 1.0,
        };
        assert_eq!(SpanSet::of_leaf(&positive, all).unwrap().len, 1);
        // Overflowing coefficients give up rather than invent roots.
        let huge = RayQuadratic {
            a: 1e300,
            b: 1e300,
            c: -1e300,
        };
        assert!(SpanSet::of_leaf(&huge, all).is_none());
    }

    /// The one-leaf shortcut picks the same bits as building the leaf's set, on random, edge
    /// and degenerate quadratics and boxes.
    #[test]
    fn the_one_leaf_shortcut_equals_the_set() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            // Small integers and their halves make roots, faces and ties coincide often.
            ((state % 17) as f64 - 8.0) * if state & 1 == 0 { 1.0 } else { 0.5 }
        };
        for _ in 0..20_000 {
            let q = RayQuadratic {
                a: next(),
                b: next(),
                c: next(),
            };
            let (r0, r1) = (next(), next());
            let range = Interval::new(r0.min(r1), r0.max(r1));
            let (p0, p1) = (next(), next());
            let present = Interval::new(
                p0.min(p1).clamp(range.lo, range.hi),
                p0.max(p1).clamp(range.lo, range.hi),
            );
            let set = SpanSet::of_leaf(&q, present).map(|s| s.first_in(range));
            let direct = SpanSet::first_of_leaf(&q, present, range);
            let bits = |x: Option<Option<f64>>| x.map(|o| o.map(f64::to_bits));
            assert_eq!(bits(set), bits(direct), "{q:?} {present:?} {range:?}");
        }
    }

    #[test]
    fn certification_accepts_nudges_and_refuses() {
        let range = Interval::new(0.0, 10.0);
        let root = 2.0;
        let f = |t: f64| t - root;
        assert_eq!(
            certify(Some(2.0), range, 1e-6, f),
            Certified::Hit(Some(2.0))
        );
        // Just before the root: nudged into the last ε.
        let just_before = 2.0 - 1e-9;
        match certify(Some(just_before), range, 1e-6, f) {
            Certified::Hit(Some(t)) => assert!(t >= root && t - root <= 1e-6),
            other => panic!("{other:?}"),
        }
        // Far past the root, or far before it: refused.
        assert_eq!(certify(Some(3.0), range, 1e-6, f), Certified::Unsure);
        assert_eq!(certify(Some(1.0), range, 1e-6, f), Certified::Unsure);
        // At the range's start only the value there counts.
        assert_eq!(
            certify(Some(0.0), range, 1e-6, |_| 1.0),
            Certified::Hit(Some(0.0))
        );
        assert_eq!(certify(None, range, 1e-6, f), Certified::Hit(None));
    }
}
