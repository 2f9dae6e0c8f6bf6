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
//! One generic search runs over a `RayFunction`: a CSG program over prepared leaves — run by the
//! one CSG evaluator (`csg::run`) in the interval algebra over segments and the algebra of values
//! with their deciding leaf at points — or, the common case after culling, a single leaf without
//! perturbations, monomorphised so that it needs no scratch space and no program interpretation
//! (and gives the same answer bit for bit).
//!
//! The concepts, one file each: `on_ray` (leaves restricted to the ray, widened), `bound` (value
//! and slope ranges over a segment, the sign-slope rule), `program` (what the search evaluates),
//! `search` (the halving), `finish` (prediction, certification, Illinois), `closed_form` (span
//! sets and the certificate), `plan` ([`CastPlan`]).
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

#[cfg(test)]
mod agreement;
mod bound;
mod closed_form;
mod finish;
mod on_ray;
mod plan;
mod program;
mod search;

pub use plan::CastPlan;

use crate::csg::run_in;
use crate::quadric::Magnitude;
use crate::{ActiveSet, FreeForm, OriginTerms, RayQuadratic, Solid};
use bound::Bound;
use closed_form::{Certified, SpanSet, SpanSets, certify};
use fray_core::{Interval, Ray};
use glam::DVec3;
use on_ray::{LeafOnRay, reach};
use plan::plain_leaf;
use program::{PlainLeaf, ProgramOnRay, RayFunction};
use search::search;

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
        self.cast_program::<false>(solid, ray, range, eps, None, stats)
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
        self.cast_program::<false>(solid, ray, range, eps, Some(active), stats)
    }

    /// Whether `solid` (restricted to `active`, when given — see [`RayCaster::cast_with`]) is
    /// non-negative somewhere on `range`: the any-hit query of shadow rays. True wherever
    /// [`RayCaster::cast`] finds a hit, and also where it steps over a span shorter than `eps`
    /// that a midpoint test meets; cheaper, as it stops at the first point it proves inside.
    pub fn occludes(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        eps: f64,
        active: Option<&ActiveSet>,
        stats: &mut CastStats,
    ) -> bool {
        self.cast_program::<true>(solid, ray, range, eps, active, stats)
            .is_some()
    }

    /// The first hit (`ANY` false) or any hit (`ANY`: see [`RayCaster::occludes`]).
    fn cast_program<const ANY: bool>(
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
            return self.cast_plain_leaf::<ANY>(
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
            let mut sets = SpanSets {
                leaves: &self.leaves,
            };
            if let Some(set) = run_in(program, &mut sets, &mut self.sets)
                && let Certified::Hit(hit) =
                    certify(set.first_in(range), range, eps, |t| f.value(t))
            {
                f.stats.closed_form_casts += 1;
                return hit;
            }
        }
        search::<_, ANY>(f, &mut self.segments, range, eps)
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
    fn cast_plain_leaf<const ANY: bool>(
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
        search_plain_leaf::<ANY>(f, &mut self.segments, range, eps)
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
}

/// [`search`] over one plain leaf, kept out of line: [`RayCaster::cast_plain_leaf`] is inlined
/// into the callers' pixel loops, where the search runs only when the closed form is unsure (or
/// with [`CastMethod::Halving`]) and, inlined, would crowd the loop (measured: a 12 % slower
/// frame).
#[inline(never)]
fn search_plain_leaf<const ANY: bool>(
    f: PlainLeaf<'_>,
    segments: &mut Vec<(f64, f64)>,
    range: Interval,
    eps: f64,
) -> Option<f64> {
    search::<_, ANY>(f, segments, range, eps)
}

impl Solid {
    /// Convenience: [`RayCaster::cast`] with a fresh scratch space.
    pub fn cast(&self, ray: &Ray, range: Interval, eps: f64) -> Option<f64> {
        RayCaster::new().cast(self, ray, range, eps, &mut CastStats::default())
    }
}
