//! Ray casting of a [`Solid`] by binary search on the ray segment.
//!
//! Along a ray every quadric is a quadratic in `t` and every perturbation a clamped cube of one,
//! so the value *and* the derivative of each leaf have cheap, exact-per-term ranges over a segment.
//! The search splits the segment in halves, nearer half first, and drops a half whose value range
//! proves `F′ < 0`. When the derivative range of a segment excludes zero, `F′` is monotone there
//! (for CSG and clipping boxes: its *sign* changes at most once, which is all the search needs;
//! see `sign_slope`): one or two point evaluations decide it, and the root is finished without
//! further halving. The leaf that decides `F′` at the bracket's end predicts the root — its
//! quadratic's closed-form root, or the clipping-box face the ray enters through — and two point
//! evaluations certify the prediction (`F′(r) ≥ 0 > F′(r − ε)`); otherwise, or for perturbed
//! leaves, the Illinois variant of regula falsi finishes the bracket.
//!
//! One generic search runs over a `RayFunction`: a CSG program over prepared leaves, or —
//! the common case after culling — a single leaf without perturbations, monomorphised so that it
//! needs no scratch space and no program interpretation (and gives the same answer bit for bit).
//!
//! Where no perturbation reaches the ray, every leaf on it is a plain quadric, and by default
//! ([`CastMethod::ClosedForm`]) the caster answers in closed form instead (module
//! `closed_form`), certified the same way; the search stays the method for perturbed rays and
//! the fallback wherever rounding leaves the closed form unsure. [`CastPlan`] decides a solid's
//! fast path once for many rays.
//!
//! Rounding: every leaf on the ray is *widened* by `Δ`, a bound on the rounding of any f64 value
//! of it over the range (`K u Φ(‖o − origin‖₁ + T)`: `Φ` bounds the size of the quadric's terms
//! at that distance from its origin, `K = 24` counts the roundings, perturbations add theirs;
//! docs/accuracy.md) — raised, or lowered under an odd number of negations — so the computed `F′`
//! is never below the exact `F′`. Then nothing rounding hides is lost: a grazing span whose
//! values all round negative (`√(u·S/|a|)` wide: `4·10⁻⁷` for a unit sphere 10 m away) is still
//! inside for the search's bounds and points and for the closed form's roots alike.
//!
//! Contract (docs/accuracy.md; "exact": the f64 inputs taken as exact reals):
//! - `t` is a number in the range: never behind its start;
//! - if the exact solid has a span at least `ε` long in the range, starting at `t₁`, there is a
//!   hit and `t ≤ t₁ + ε`; spans shorter than `ε` may be skipped;
//! - the hit lies in the solid with every leaf grown by `2Δ`: `t ≥ t* − ρ`, `ρ ≈ 2Δ / |dF′/dt|` at
//!   a simple root. A ray that misses the exact solid by less than that may hit, within
//!   `~2Δ/|∇F|` of the surface.

use crate::closed_form::{Certified, SpanSet, certify, program_set};
use crate::quadric::{Magnitude, ROUNDING_UNITS, UNIT_ROUNDOFF};
use crate::{ActiveSet, CsgOp, FreeForm, OriginTerms, Perturbation, RayQuadratic, Solid};
use fray_core::root::illinois;
use fray_core::{Interval, Ray};
use glam::DVec3;

/// Work counters of the ray caster.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CastStats {
    /// Interval (segment) evaluations: the halving steps.
    pub bound_evaluations: u64,
    /// Point evaluations: sign checks and root refinement.
    pub point_evaluations: u64,
    /// Casts answered in closed form (every leaf on the ray a plain quadric; see
    /// [`CastMethod::ClosedForm`]) rather than by the halving search.
    pub closed_form_casts: u64,
}

impl std::ops::AddAssign for CastStats {
    fn add_assign(&mut self, o: Self) {
        self.bound_evaluations += o.bound_evaluations;
        self.point_evaluations += o.point_evaluations;
        self.closed_form_casts += o.closed_form_casts;
    }
}

/// One leaf restricted to the current ray.
#[derive(Clone, Copy, Debug)]
struct LeafOnRay {
    /// Where the leaf can be non-negative; `None` if never on this ray. Outside it the leaf's
    /// value is taken as `−∞`: exact for a clipping box, and for a derived box *sign-equivalent*
    /// (there `F′ < 0`, and replacing a negative operand by `−∞` keeps the sign of every
    /// max/min/neg composition), which is all the search decides on. This lets a segment skip
    /// every leaf whose box it misses.
    present: Option<Interval>,
    /// Whether the box cuts the shape, so a segment straddling it has no slope information.
    clips: bool,
    base: RayQuadratic,
    perturbations: (u32, u32),
}

/// The value range and derivative range of a function over a segment.
#[derive(Clone, Copy, Debug)]
struct Bound {
    value: Interval,
    slope: Interval,
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

const ABSENT: Bound = Bound {
    value: Interval::NEG_INFINITY,
    slope: Interval::point(0.0),
};

/// The exact value and derivative ranges of a quadratic over `t`: the hot path of every bound.
/// The vertex lies strictly inside exactly when the derivative changes sign over `t`, which the
/// derivative range (needed anyway) tells without a division; plain comparisons stand in for
/// `f64::min`/`max` because nothing here is NaN.
#[inline]
fn quadratic_bound(q: &RayQuadratic, t: Interval) -> Bound {
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

/// Programs of fewer than twice this many ops (so at most this many leaves deep) evaluate on a
/// stack array instead of the heap.
const INLINE_STACK: usize = 4;

/// How a [`RayCaster`] answers rays on which every leaf it meets is a plain quadric (no
/// perturbation reaches the ray). Rays that meet a perturbation are always searched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CastMethod {
    /// Each leaf's inside from its quadratic's roots, combined by the CSG program as sets of
    /// `t`, and the first point certified by two point evaluations (the module `closed_form`);
    /// the halving search where rounding leaves it uncertain. The same contract as the search,
    /// at a fraction of its cost.
    #[default]
    ClosedForm,
    /// The halving search everywhere: the method the closed form is checked against, and what
    /// the GPU runs.
    Halving,
}

/// Reusable per-thread scratch space for casting rays; holds no scene data between calls.
#[derive(Debug, Default)]
pub struct RayCaster {
    method: CastMethod,
    leaves: Vec<LeafOnRay>,
    perturbations: Vec<(f64, RayQuadratic)>,
    bounds: Vec<Bound>,
    values: Vec<(f64, u32)>,
    segments: Vec<(f64, f64)>,
    sets: Vec<SpanSet>,
    /// The last ray direction and its reciprocal: a pixel's ray is cast against each of its
    /// candidates in turn, and the three divisions sit at the head of every cast's chain.
    inverse: (DVec3, DVec3),
}

impl RayCaster {
    /// A caster with the default [`CastMethod::ClosedForm`].
    pub fn new() -> Self {
        Self::default()
    }

    /// A caster that answers plain rays by `method`.
    pub fn with_method(method: CastMethod) -> Self {
        Self {
            method,
            ..Self::default()
        }
    }

    /// How this caster answers rays that meet only plain quadrics.
    pub fn method(&self) -> CastMethod {
        self.method
    }

    /// The first `t` in `range` where `solid` is non-negative, to within `eps` (world units), up
    /// to the rounding of the inputs (module docs): never past a span at least `eps` long by more
    /// than `eps`, never behind `range.lo`.
    pub fn cast(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        eps: f64,
        stats: &mut CastStats,
    ) -> Option<f64> {
        self.cast_program(solid, ray, range, eps, None, stats)
    }

    /// [`RayCaster::cast`] restricted to the leaves and perturbations of `active` (and its pruned
    /// program): the same answer whenever `active` is conservative for this ray (see
    /// [`ActiveSet`]), at the cost of only what is active.
    pub fn cast_with(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        eps: f64,
        active: &ActiveSet,
        stats: &mut CastStats,
    ) -> Option<f64> {
        self.cast_program(solid, ray, range, eps, Some(active), stats)
    }

    fn cast_program(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        eps: f64,
        active: Option<&ActiveSet>,
        stats: &mut CastStats,
    ) -> Option<f64> {
        let inv_dir = self.inverse_of(ray.dir);
        let range = solid
            .bounds_ref()
            .clip_ray_with_inverse(ray, inv_dir, range)?;
        let program = active.map_or(solid.program(), ActiveSet::program);
        // The common case — one leaf and no perturbation — needs no scratch space and no program:
        // the same search over the same leaf, monomorphised (bit-identical to the general path).
        if let Some((leaf, covers, magnitude)) = plain_leaf(solid, program, active) {
            let terms = leaf.base().at_origin(ray.origin);
            return self.cast_plain_leaf(
                leaf, covers, magnitude, &terms, ray, inv_dir, range, eps, stats,
            );
        }
        if !self.prepare(solid, ray, inv_dir, range, active) {
            return None;
        }
        let mut f = ProgramOnRay {
            leaves: &self.leaves,
            perturbations: &self.perturbations,
            program,
            bounds: &mut self.bounds,
            values: &mut self.values,
            stats,
            decided: [(f64::NAN, u32::MAX); 2],
        };
        if self.method == CastMethod::ClosedForm && self.perturbations.is_empty() {
            // Every leaf on this ray is a plain quadric. Leaves absent from the ray have empty
            // sets, exactly as a pruned program folds them out, so culling keeps the bits.
            let leaves = &self.leaves;
            let leaf_set = |i: u32| match leaves.get(i as usize) {
                Some(LeafOnRay {
                    present: Some(present),
                    base,
                    ..
                }) => SpanSet::of_leaf(base, *present),
                _ => Some(SpanSet::EMPTY),
            };
            if let Some(set) = program_set(program, leaf_set, &mut self.sets)
                && let Certified::Hit(hit) =
                    certify(set.first_in(range), range, eps, |t| f.value(t))
            {
                f.stats.closed_form_casts += 1;
                return hit;
            }
        }
        search(f, &mut self.segments, range, eps)
    }

    /// `1 / dir`, componentwise (the same bits as dividing afresh).
    #[inline]
    fn inverse_of(&mut self, dir: DVec3) -> DVec3 {
        if self.inverse.0 != dir {
            self.inverse = (dir, DVec3::ONE / dir);
        }
        self.inverse.1
    }

    /// Casts one leaf without perturbations over `range` (already clipped to the solid's box);
    /// `covers`: the leaf's box contains the solid's; `magnitude`: its quadric's term bounds;
    /// `terms`: its quadric at the ray's origin.
    /// Shared by [`RayCaster::cast_with`] and [`RayCaster::cast_planned`], so both give the same
    /// bits.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn cast_plain_leaf(
        &mut self,
        leaf: &FreeForm,
        covers: bool,
        magnitude: Magnitude,
        terms: &OriginTerms,
        ray: &Ray,
        inv_dir: DVec3,
        range: Interval,
        eps: f64,
        stats: &mut CastStats,
    ) -> Option<f64> {
        let present = if covers {
            range
        } else {
            leaf.bounds_ref()
                .clip_ray_with_inverse(ray, inv_dir, range)?
        };
        let mut base = leaf.base().on_ray_from(terms, ray.dir);
        base.c += magnitude.rounding(terms.distance + reach(range));
        let mut f = PlainLeaf {
            leaf: LeafOnRay {
                present: Some(present),
                clips: leaf.clips(),
                base,
                perturbations: (0, 0),
            },
            stats,
        };
        if self.method == CastMethod::ClosedForm {
            let first = SpanSet::first_of_leaf(&f.leaf.base, present, range);
            if let Some(first) = first
                && let Certified::Hit(hit) = certify(first, range, eps, |t| f.value(t))
            {
                f.stats.closed_form_casts += 1;
                return hit;
            }
        }
        search(f, &mut self.segments, range, eps)
    }

    /// [`RayCaster::cast_with`] (`active: Some`) or [`RayCaster::cast`] (`None`) with what
    /// depends on the solid alone decided once, in `plan` ([`CastPlan::new`]), and what depends
    /// on the ray's origin kept while rays share it: for casting one solid along many rays (a
    /// tile's pixels). The same answer, bit for bit; inlined, so that a plain leaf's cast runs in
    /// the caller's loop without a call.
    #[inline]
    pub fn cast_planned(
        &mut self,
        plan: &mut CastPlan<'_>,
        ray: &Ray,
        range: Interval,
        eps: f64,
        stats: &mut CastStats,
    ) -> Option<f64> {
        let Some((leaf, covers, magnitude)) = plan.plain else {
            return self.cast_program(plan.solid, ray, range, eps, plan.active, stats);
        };
        let inv_dir = self.inverse_of(ray.dir);
        let range = plan
            .solid
            .bounds_ref()
            .clip_ray_with_inverse(ray, inv_dir, range)?;
        // The leaf's quadric at the ray's origin, kept while rays share it (a pinhole camera's
        // do): the same terms `cast_with` computes afresh, so the same bits.
        let terms = match plan.origin {
            Some((origin, terms)) if origin == ray.origin => terms,
            _ => {
                let terms = leaf.base().at_origin(ray.origin);
                plan.origin = Some((ray.origin, terms));
                terms
            }
        };
        self.cast_plain_leaf(
            leaf, covers, magnitude, &terms, ray, inv_dir, range, eps, stats,
        )
    }

    /// Restricts `solid` to `ray` for [`RayCaster::segment_bound`]: clips `range` to the solid's
    /// box and prepares every leaf (the first step of [`RayCaster::cast`]). Returns the clipped
    /// range, or `None` if the ray cannot reach the solid there. For benchmarks and diagnostics.
    pub fn prepare_ray(&mut self, solid: &Solid, ray: &Ray, range: Interval) -> Option<Interval> {
        let inv_dir = DVec3::ONE / ray.dir;
        let range = solid
            .bounds_ref()
            .clip_ray_with_inverse(ray, inv_dir, range)?;
        self.prepare(solid, ray, inv_dir, range, None)
            .then_some(range)
    }

    /// The conservative range of the solid's value and of its derivative along the ray over the
    /// parameter segment `seg` of the ray last given to [`RayCaster::prepare_ray`] (with the same
    /// `solid`): the test that [`RayCaster::cast`] applies to each segment it halves. For a CSG
    /// solid the second range is a derivative range of a function with the *same sign* as the
    /// solid's along the segment (all the search needs; see `sign_slope`). Without a
    /// matching `prepare_ray` it answers the uninformative `(ℝ, ℝ)`.
    pub fn segment_bound(&mut self, solid: &Solid, seg: Interval) -> (Interval, Interval) {
        if self.leaves.len() != solid.leaves().len() {
            return (Interval::EVERYTHING, Interval::EVERYTHING);
        }
        let mut stats = CastStats::default();
        let mut f = ProgramOnRay {
            leaves: &self.leaves,
            perturbations: &self.perturbations,
            program: solid.program(),
            bounds: &mut self.bounds,
            values: &mut self.values,
            stats: &mut stats,
            decided: [(f64::NAN, u32::MAX); 2],
        };
        let b = f.bound(seg);
        (b.value, b.slope)
    }

    /// Restricts every leaf (every active one, given a subset) to the ray; false if no leaf can
    /// be reached. Inlined so that `inv_dir` stays in registers: passed by pointer, it is
    /// spilled and reloaded in different widths, which stalls store forwarding on every cast.
    #[inline(always)]
    fn prepare(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        inv_dir: DVec3,
        range: Interval,
        active: Option<&ActiveSet>,
    ) -> bool {
        self.leaves.clear();
        self.perturbations.clear();
        let mut any = false;
        let reach = reach(range);
        for (i, leaf) in solid.leaves().iter().enumerate() {
            // The slab test as two bare floats (an `Option` here is spilled and reloaded).
            let slab = match active {
                Some(a) if !a.leaf_is_active(i) => Interval::EMPTY,
                _ if solid.leaf_covers_solid(i) => range,
                _ => leaf.bounds_ref().slab_interval(ray, inv_dir, range),
            };
            let present = (slab.lo <= slab.hi).then_some(slab);
            let start = self.perturbations.len() as u32;
            // An absent leaf's quadric is never read: skip restricting it.
            let mut base = RayQuadratic {
                a: 0.0,
                b: 0.0,
                c: 0.0,
            };
            if let Some(present) = present {
                any = true;
                let terms = leaf.base().at_origin(ray.origin);
                base = leaf.base().on_ray_from(&terms, ray.dir);
                // The leaf widened by the rounding of its value (module docs), away from the
                // solid's outside: up, or down under an odd number of negations.
                let widening = solid
                    .leaf_widening(i)
                    .map_or(0.0, |w| w.rounding(terms.distance + reach));
                let all = leaf.perturbations();
                let subset = active.map(|a| a.leaf_perturbations(i));
                let count = subset.map_or(all.len(), <[u32]>::len);
                if count > 0 {
                    let more = push_perturbations(
                        &mut self.perturbations,
                        all,
                        solid.perturbation_magnitudes(i),
                        subset,
                        ray,
                        present,
                        reach,
                        widening.abs(),
                    );
                    base.c += if solid.leaf_is_negated(i) {
                        -more
                    } else {
                        more
                    };
                }
                base.c += widening;
            }
            self.leaves.push(LeafOnRay {
                present,
                clips: leaf.clips(),
                base,
                perturbations: (start, self.perturbations.len() as u32),
            });
        }
        any
    }
}

/// Restricts a leaf's perturbations (all, or `subset`) to the ray and pushes those whose support
/// the ray enters within `present` onto `out`; returns what they add to the leaf's widening
/// (`base`: the base quadric's): for each, `f·Q³` with `Q ≤ q̄` known to `δ_Q`, and the rounding of
/// the sum. Kept out of line: most leaves have none on the ray.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn push_perturbations(
    out: &mut Vec<(f64, RayQuadratic)>,
    all: &[Perturbation],
    magnitudes: &[Magnitude],
    subset: Option<&[u32]>,
    ray: &Ray,
    present: Interval,
    reach: f64,
    base: f64,
) -> f64 {
    let count = subset.map_or(all.len(), <[u32]>::len);
    let (mut terms_rounding, mut terms_size, mut n) = (0.0, 0.0, 0u32);
    for k in 0..count {
        let index = match subset {
            Some(s) => s[k] as usize,
            None => k,
        };
        let (Some(p), Some(magnitude)) = (all.get(index), magnitudes.get(index)) else {
            continue;
        };
        let origin_terms = p.quadric.at_origin(ray.origin);
        let q = p.quadric.on_ray_from(&origin_terms, ray.dir);
        let hi = q.range(present).hi;
        // Per-ray pruning: a support the ray never enters inside the leaf's box contributes 0
        // there. (Outside a derived box the pruned F′ stays < 0: F < 0 there and the supports of
        // bumps lie inside the box.)
        if p.form_factor != 0.0 && hi > 0.0 {
            out.push((p.form_factor, q));
            let dq = magnitude.rounding(origin_terms.distance + reach);
            let qb = hi + 2.0 * dq;
            let f = p.form_factor.abs();
            terms_rounding += f
                * (dq * (3.0 * qb * qb + dq * (3.0 * qb + dq))
                    + 4.0 * UNIT_ROUNDOFF * qb * qb * qb);
            terms_size += f * qb * qb * qb;
            n += 1;
        }
    }
    if n == 0 {
        return 0.0;
    }
    // The rounding of the sum: `n` additions of terms up to the base's and the perturbations'.
    terms_rounding + f64::from(n) * (base / ROUNDING_UNITS + UNIT_ROUNDOFF * terms_size)
}

/// The largest `|t|` of `range` (`lo ≤ hi`, not NaN): how far along the ray the rounding bounds
/// must hold. A comparison rather than `f64::max`, whose NaN handling costs four instructions.
#[inline]
fn reach(range: Interval) -> f64 {
    if range.hi >= -range.lo {
        range.hi
    } else {
        -range.lo
    }
}

/// What [`RayCaster::cast_planned`] needs to know about a solid (and its active subset) before
/// any ray: whether the (pruned) program is a single leaf without perturbations, the caster's
/// fast path.
#[derive(Clone, Copy, Debug)]
pub struct CastPlan<'a> {
    solid: &'a Solid,
    active: Option<&'a ActiveSet>,
    /// The single plain leaf, whether its box contains the solid's, and its term bounds.
    plain: Option<(&'a FreeForm, bool, Magnitude)>,
    /// That leaf's quadric at the last ray origin.
    origin: Option<(DVec3, OriginTerms)>,
}

impl<'a> CastPlan<'a> {
    /// The plan for casting `solid` restricted to `active` (or whole, `None`).
    pub fn new(solid: &'a Solid, active: Option<&'a ActiveSet>) -> Self {
        let program = active.map_or(solid.program(), ActiveSet::program);
        Self {
            solid,
            active,
            plain: plain_leaf(solid, program, active),
            origin: None,
        }
    }
}

/// The leaf of a one-leaf `program` that has no perturbation (none active, or none at all when
/// casting the whole solid), with whether its box contains the solid's and its quadric's term
/// bounds.
#[inline]
fn plain_leaf<'a>(
    solid: &'a Solid,
    program: &[CsgOp],
    active: Option<&ActiveSet>,
) -> Option<(&'a FreeForm, bool, Magnitude)> {
    if let [CsgOp::Leaf(i)] = *program
        && let Some(leaf) = solid.leaves().get(i as usize)
        && let Some(&widening) = solid.leaf_widening(i as usize)
        && active.is_none_or(|a| a.leaf_perturbations(i as usize).is_empty())
        && (active.is_some() || leaf.perturbations().is_empty())
    {
        return Some((leaf, solid.leaf_covers_solid(i as usize), widening));
    }
    None
}

/// `F′` along the current ray, as the search sees it: bounds over segments, values at points.
trait RayFunction {
    fn bound(&mut self, seg: Interval) -> Bound;
    fn value(&mut self, t: f64) -> f64;
    /// Where `F′` is one plain quadratic over `[a, b]`, its closed-form first root there: a
    /// prediction for [`finish`] to certify.
    fn predict(&self, a: f64, b: f64) -> Option<f64>;
}

/// A single leaf with no perturbation on this ray.
struct PlainLeaf<'a> {
    leaf: LeafOnRay,
    stats: &'a mut CastStats,
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
const NEGATED: u32 = 1 << 31;

/// A CSG program over prepared leaves.
struct ProgramOnRay<'a> {
    leaves: &'a [LeafOnRay],
    perturbations: &'a [(f64, RayQuadratic)],
    program: &'a [CsgOp],
    bounds: &'a mut Vec<Bound>,
    values: &'a mut Vec<(f64, u32)>,
    stats: &'a mut CastStats,
    /// The last two points evaluated and the leaf whose value decided each (with [`NEGATED`]
    /// set if the program negated it on the way).
    decided: [(f64, u32); 2],
}

impl ProgramOnRay<'_> {
    #[inline]
    fn leaf(&self, i: u32) -> &LeafOnRay {
        &self.leaves[i as usize]
    }

    #[inline]
    fn leaf_perturbations(&self, leaf: &LeafOnRay) -> &[(f64, RayQuadratic)] {
        &self.perturbations[leaf.perturbations.0 as usize..leaf.perturbations.1 as usize]
    }
}

impl RayFunction for ProgramOnRay<'_> {
    fn bound(&mut self, seg: Interval) -> Bound {
        self.stats.bound_evaluations += 1;
        if let [CsgOp::Leaf(i)] = *self.program {
            let leaf = self.leaf(i);
            return leaf_bound(leaf, self.leaf_perturbations(leaf), seg);
        }
        // The two-leaf programs of a union, intersection or difference, without a stack.
        let leaf_bound_at = |i: u32| {
            let leaf = &self.leaves[i as usize];
            leaf_bound(leaf, self.leaf_perturbations(leaf), seg)
        };
        match *self.program {
            [
                CsgOp::Leaf(i),
                CsgOp::Leaf(j),
                op @ (CsgOp::Max | CsgOp::Min),
            ] => {
                return combine_bounds(op == CsgOp::Max, leaf_bound_at(i), leaf_bound_at(j));
            }
            [
                CsgOp::Leaf(i),
                CsgOp::Leaf(j),
                CsgOp::Neg,
                op @ (CsgOp::Max | CsgOp::Min),
            ] => {
                let b = leaf_bound_at(j);
                let b = Bound {
                    value: -b.value,
                    slope: -b.slope,
                };
                return combine_bounds(op == CsgOp::Max, leaf_bound_at(i), b);
            }
            _ => {}
        }
        // The stack never holds more than the program's leaves: short programs use an array.
        let mut inline = [ABSENT; INLINE_STACK];
        let heap = &mut *self.bounds;
        let stack: &mut [Bound] = if self.program.len() < 2 * INLINE_STACK {
            &mut inline
        } else {
            heap.clear();
            heap.resize(self.program.len(), ABSENT);
            heap
        };
        let mut len = 0usize;
        for op in self.program {
            match *op {
                CsgOp::Leaf(i) => {
                    let leaf = &self.leaves[i as usize];
                    let perturbations = &self.perturbations
                        [leaf.perturbations.0 as usize..leaf.perturbations.1 as usize];
                    stack[len] = leaf_bound(leaf, perturbations, seg);
                    len += 1;
                }
                CsgOp::Max | CsgOp::Min => {
                    if len < 2 {
                        continue; // never compiled; keep the operand
                    }
                    let (a, b) = (stack[len - 2], stack[len - 1]);
                    len -= 1;
                    stack[len - 1] = combine_bounds(*op == CsgOp::Max, a, b);
                }
                CsgOp::Neg => {
                    if len > 0 {
                        let top = &mut stack[len - 1];
                        top.value = -top.value;
                        top.slope = -top.slope;
                    }
                }
            }
        }
        if len > 0 { stack[len - 1] } else { ABSENT }
    }

    fn value(&mut self, t: f64) -> f64 {
        self.stats.point_evaluations += 1;
        if let [CsgOp::Leaf(i)] = *self.program {
            let leaf = self.leaf(i);
            return leaf_value(leaf, self.leaf_perturbations(leaf), t);
        }
        // Values with the leaf that decides each (max/min pick an operand, negation keeps it).
        let value_at = |i: u32| {
            let leaf = &self.leaves[i as usize];
            (leaf_value(leaf, self.leaf_perturbations(leaf), t), i)
        };
        let two_leaves = match *self.program {
            [
                CsgOp::Leaf(i),
                CsgOp::Leaf(j),
                op @ (CsgOp::Max | CsgOp::Min),
            ] => Some(combine_values(op == CsgOp::Max, value_at(i), value_at(j))),
            [
                CsgOp::Leaf(i),
                CsgOp::Leaf(j),
                CsgOp::Neg,
                op @ (CsgOp::Max | CsgOp::Min),
            ] => {
                let (v, leaf) = value_at(j);
                Some(combine_values(
                    op == CsgOp::Max,
                    value_at(i),
                    (-v, leaf ^ NEGATED),
                ))
            }
            _ => None,
        };
        if let Some((v, leaf)) = two_leaves {
            self.decided = [self.decided[1], (t, leaf)];
            return v;
        }
        let mut inline = [(f64::NEG_INFINITY, u32::MAX); INLINE_STACK];
        let heap = &mut *self.values;
        let stack: &mut [(f64, u32)] = if self.program.len() < 2 * INLINE_STACK {
            &mut inline
        } else {
            heap.clear();
            heap.resize(self.program.len(), (f64::NEG_INFINITY, u32::MAX));
            heap
        };
        let mut len = 0usize;
        for op in self.program {
            match *op {
                CsgOp::Leaf(i) => {
                    let leaf = &self.leaves[i as usize];
                    let perturbations = &self.perturbations
                        [leaf.perturbations.0 as usize..leaf.perturbations.1 as usize];
                    stack[len] = (leaf_value(leaf, perturbations, t), i);
                    len += 1;
                }
                CsgOp::Max | CsgOp::Min => {
                    if len < 2 {
                        continue;
                    }
                    let (a, b) = (stack[len - 2], stack[len - 1]);
                    len -= 1;
                    stack[len - 1] = combine_values(*op == CsgOp::Max, a, b);
                }
                CsgOp::Neg => {
                    if len > 0 {
                        let top = &mut stack[len - 1];
                        *top = (-top.0, top.1 ^ NEGATED);
                    }
                }
            }
        }
        let (v, leaf) = if len > 0 {
            stack[len - 1]
        } else {
            (f64::NEG_INFINITY, u32::MAX)
        };
        self.decided = [self.decided[1], (t, leaf)];
        v
    }

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

/// `max` or `min` of two (value, deciding leaf) pairs; `a` wins ties.
#[inline]
fn combine_values(is_max: bool, a: (f64, u32), b: (f64, u32)) -> (f64, u32) {
    let take_a = if is_max { a.0 >= b.0 } else { a.0 <= b.0 };
    if take_a { a } else { b }
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

/// A prediction of the root in `(a, b)` when the leaf decides `F′` there: the clipping-box face
/// where the ray enters the box with the leaf already `≥ 0` (`F′` jumps from `−∞`), or else, for
/// a plain leaf (`plain`: no perturbation), the closed-form root of its quadratic past the face.
#[inline]
fn predict_leaf(leaf: &LeafOnRay, plain: bool, a: f64, b: f64) -> Option<f64> {
    let present = leaf.present?;
    let mut lo = a;
    if present.lo > a {
        if present.lo >= b {
            return None;
        }
        if leaf.clips && (!plain || leaf.base.eval(present.lo) >= 0.0) {
            return Some(present.lo);
        }
        lo = present.lo;
    }
    if !plain || b > present.hi {
        return None;
    }
    leaf.base
        .first_nonnegative(Interval { lo, hi: b })
        .filter(|&r| r > a && r < b)
}

#[inline]
fn leaf_bound(leaf: &LeafOnRay, perturbations: &[(f64, RayQuadratic)], seg: Interval) -> Bound {
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

#[inline]
fn leaf_value(leaf: &LeafOnRay, perturbations: &[(f64, RayQuadratic)], t: f64) -> f64 {
    let Some(present) = leaf.present else {
        return f64::NEG_INFINITY;
    };
    if t < present.lo || t > present.hi {
        return f64::NEG_INFINITY;
    }
    let mut v = leaf.base.eval(t);
    for &(f, q) in perturbations {
        let qt = q.eval(t);
        if qt > 0.0 {
            v += f * qt * qt * qt;
        }
    }
    v
}

/// The halving search (module docs) over `range`; `segments` is scratch space.
fn search<F: RayFunction>(
    mut f: F,
    segments: &mut Vec<(f64, f64)>,
    range: Interval,
    eps: f64,
) -> Option<f64> {
    segments.clear();
    segments.push((range.lo, range.hi));
    // The last point evaluated: a halved segment's right half starts where the left half's
    // test ended, so its start value is often known already.
    let mut known = (f64::NAN, f64::NAN);
    let mut first = true;
    let mut hit = None;
    while let Some((a, b)) = segments.pop() {
        let bound = f.bound(Interval { lo: a, hi: b });
        if bound.value.hi < 0.0 {
            continue; // proven empty (most misses end here, after one bound)
        }
        if first {
            // The range may start inside the solid (the picture surface cuts it): then the
            // answer is its start, exactly.
            first = false;
            let fa = f.value(a);
            if fa >= 0.0 {
                hit = Some(a);
                break;
            }
            known = (a, fa);
        }
        if bound.value.lo >= 0.0 {
            hit = Some(a); // everything before `a` was proven or tested negative
            break;
        }
        if bound.slope.lo > 0.0 {
            // Increasing: a root exists iff F′(b) ≥ 0, and it is unique.
            let fb = f.value(b);
            if fb < 0.0 {
                known = (b, fb);
                continue;
            }
            let fa = value_at(&mut f, a, known);
            if fa >= 0.0 {
                hit = Some(a);
            } else {
                hit = Some(finish(&mut f, (a, fa), (b, fb), eps));
            }
            break;
        }
        if bound.slope.hi < 0.0 {
            // Decreasing: the maximum is at `a`.
            if value_at(&mut f, a, known) >= 0.0 {
                hit = Some(a);
                break;
            }
            continue;
        }
        let m = a + 0.5 * (b - a);
        if b - a <= eps || m <= a || m >= b {
            // Shorter than ε (or than the float spacing): test it directly.
            if f.value(m) >= 0.0 {
                hit = Some(m);
                break;
            }
            let fb = f.value(b);
            if fb >= 0.0 {
                hit = Some(b);
                break;
            }
            known = (b, fb);
            continue;
        }
        segments.push((m, b));
        segments.push((a, m));
    }
    hit
}

/// `F′(t)`, reusing `known = (t, F′(t))` when it is that point.
#[inline]
fn value_at<F: RayFunction>(f: &mut F, t: f64, known: (f64, f64)) -> f64 {
    if known.0 == t { known.1 } else { f.value(t) }
}

/// The root of a monotone bracket `f(a) < 0 ≤ f(b)`, to within `eps` (the contract of
/// [`illinois`]). When the program is one leaf that is a plain quadric over the
/// bracket, its closed-form root is the prediction, and two point evaluations certify it:
/// `f(r) ≥ 0` and `f(r − ε) < 0` put the root in `(r − ε, r]`. A prediction that rounding
/// put on the wrong side only narrows the bracket for the Illinois iteration.
fn finish<F: RayFunction>(f: &mut F, (a, fa): (f64, f64), (b, fb): (f64, f64), eps: f64) -> f64 {
    if let Some(r) = f.predict(a, b) {
        let fr = f.value(r);
        if fr < 0.0 {
            return illinois(|t| f.value(t), (r, fr), (b, fb), eps);
        }
        let before = r - eps;
        if before <= a {
            return r;
        }
        let f_before = f.value(before);
        if f_before < 0.0 {
            return r;
        }
        return illinois(|t| f.value(t), (a, fa), (before, f_before), eps);
    }
    illinois(|t| f.value(t), (a, fa), (b, fb), eps)
}

impl Solid {
    /// Convenience: [`RayCaster::cast`] with a fresh scratch space.
    pub fn cast(&self, ray: &Ray, range: Interval, eps: f64) -> Option<f64> {
        RayCaster::new().cast(self, ray, range, eps, &mut CastStats::default())
    }
}
