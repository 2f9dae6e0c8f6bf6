//! A solid restricted to one ray: each leaf's quadric as a quadratic in `t`, widened by a bound
//! on its rounding (module docs of `cast`, docs/accuracy.md), its box as the range of `t` where it
//! is present, the perturbations whose support the ray enters; and a leaf's value at a point.

use super::RayCaster;
use crate::quadric::{Magnitude, ROUNDING_UNITS, UNIT_ROUNDOFF};
use crate::{ActiveSet, Perturbation, RayQuadratic, Solid};
use fray_core::{Interval, Ray};
use glam::DVec3;

/// One leaf restricted to the current ray.
#[derive(Clone, Copy, Debug)]
pub(super) struct LeafOnRay {
    /// Where the leaf can be non-negative; `None` if never on this ray. Outside it the leaf's
    /// value is taken as `−∞`: exact for a clipping box, and for a derived box *sign-equivalent*
    /// (there `F′ < 0`, and replacing a negative operand by `−∞` keeps the sign of every
    /// max/min/neg composition), which is all the search decides on. This lets a segment skip
    /// every leaf whose box it misses.
    pub(super) present: Option<Interval>,
    /// Whether the box cuts the shape, so a segment straddling it has no slope information.
    pub(super) clips: bool,
    pub(super) base: RayQuadratic,
    pub(super) perturbations: (u32, u32),
}

impl RayCaster {
    /// Restricts every leaf (every active one, given a subset) to the ray; false if no leaf can
    /// be reached. Inlined so that `inv_dir` stays in registers: passed by pointer, it is
    /// spilled and reloaded in different widths, which stalls store forwarding on every cast.
    #[inline(always)]
    pub(super) fn prepare(
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
pub(super) fn reach(range: Interval) -> f64 {
    if range.hi >= -range.lo {
        range.hi
    } else {
        -range.lo
    }
}

/// A leaf's `F′` at `t` on the ray: `−∞` where it is absent.
#[inline(always)]
pub(super) fn leaf_value(leaf: &LeafOnRay, perturbations: &[(f64, RayQuadratic)], t: f64) -> f64 {
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
