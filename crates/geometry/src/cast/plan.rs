//! Casting one solid along many rays (a tile's pixels): what depends on the solid alone — is the
//! (pruned) program one plain leaf, the caster's fast path? — decided once in a [`CastPlan`],
//! and the leaf's quadric at the ray origin kept while rays share it.

use super::{CastStats, RayCaster};
use crate::quadric::Magnitude;
use crate::{ActiveSet, CsgOp, FreeForm, OriginTerms, Solid};
use fray_core::{Interval, Ray};
use glam::DVec3;

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
pub(super) fn plain_leaf<'a>(
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

impl RayCaster {
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
            return self.cast_program::<false>(plan.solid, ray, range, eps, plan.active, stats);
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
        self.cast_plain_leaf::<false>(
            leaf, covers, magnitude, &terms, ray, inv_dir, range, eps, stats,
        )
    }
}
