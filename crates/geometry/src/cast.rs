//! Ray casting of a [`Solid`] by binary search on the ray segment.
//!
//! Along a ray every quadric is a quadratic in `t` and every perturbation a clamped cube of one,
//! so the value *and* the derivative of each leaf have cheap, exact-per-term ranges over a segment.
//! The search splits the segment in halves, nearer half first, and drops a half whose value range
//! proves `F′ < 0`. When the derivative range of a segment excludes zero, `F′` is monotone there:
//! one or two point evaluations decide it, and a root is finished by the Illinois variant of
//! regula falsi instead of further halving (≈ 2× fewer evaluations at the same ε).
//!
//! Contract: the returned `t` is the first point of the range (up to `ε`) where `F′ ≥ 0`; it is
//! never behind the range's start. Features thinner than `ε` along the ray may be missed.

use crate::{ActiveSet, CsgOp, RayQuadratic, Solid};
use fray_core::{Interval, Ray};

/// Work counters of the ray caster.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CastStats {
    /// Interval (segment) evaluations: the halving steps.
    pub bound_evaluations: u64,
    /// Point evaluations: sign checks and root refinement.
    pub point_evaluations: u64,
}

impl std::ops::AddAssign for CastStats {
    fn add_assign(&mut self, o: Self) {
        self.bound_evaluations += o.bound_evaluations;
        self.point_evaluations += o.point_evaluations;
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

const ABSENT: Bound = Bound {
    value: Interval::NEG_INFINITY,
    slope: Interval::point(0.0),
};

/// Reusable per-thread scratch space for casting rays; holds no scene data between calls.
#[derive(Debug, Default)]
pub struct RayCaster {
    leaves: Vec<LeafOnRay>,
    perturbations: Vec<(f64, RayQuadratic)>,
    bounds: Vec<Bound>,
    values: Vec<f64>,
    segments: Vec<(f64, f64)>,
}

impl RayCaster {
    pub fn new() -> Self {
        Self::default()
    }

    /// The first `t` in `range` where `solid` is non-negative, to within `eps` (world units).
    pub fn cast(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        eps: f64,
        stats: &mut CastStats,
    ) -> Option<f64> {
        let range = solid.bounds().clip_ray(ray, range)?;
        if !self.prepare(solid, ray, range, None) {
            return None;
        }
        self.search(solid.program(), range, eps, stats)
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
        let range = solid.bounds().clip_ray(ray, range)?;
        if !self.prepare(solid, ray, range, Some(active)) {
            return None;
        }
        self.search(active.program(), range, eps, stats)
    }

    /// Restricts `solid` to `ray` for [`RayCaster::segment_bound`]: clips `range` to the solid's
    /// box and prepares every leaf (the first step of [`RayCaster::cast`]). Returns the clipped
    /// range, or `None` if the ray cannot reach the solid there. For benchmarks and diagnostics.
    pub fn prepare_ray(&mut self, solid: &Solid, ray: &Ray, range: Interval) -> Option<Interval> {
        let range = solid.bounds().clip_ray(ray, range)?;
        self.prepare(solid, ray, range, None).then_some(range)
    }

    /// The conservative range of the solid's value and of its derivative along the ray over the
    /// parameter segment `seg` of the ray last given to [`RayCaster::prepare_ray`] (with the same
    /// `solid`): the test that [`RayCaster::cast`] applies to each segment it halves. Without a
    /// matching `prepare_ray` it answers the uninformative `(ℝ, ℝ)`.
    pub fn segment_bound(&mut self, solid: &Solid, seg: Interval) -> (Interval, Interval) {
        if self.leaves.len() != solid.leaves().len() {
            return (Interval::EVERYTHING, Interval::EVERYTHING);
        }
        let b = self.bound(solid.program(), seg, &mut CastStats::default());
        (b.value, b.slope)
    }

    /// Restricts every leaf (every active one, given a subset) to the ray; false if no leaf can
    /// be reached.
    fn prepare(
        &mut self,
        solid: &Solid,
        ray: &Ray,
        range: Interval,
        active: Option<&ActiveSet>,
    ) -> bool {
        self.leaves.clear();
        self.perturbations.clear();
        let mut any = false;
        for (i, leaf) in solid.leaves().iter().enumerate() {
            let present = match active {
                Some(a) if !a.leaf_is_active(i) => None,
                _ => leaf.bounds().clip_ray(ray, range),
            };
            let start = self.perturbations.len() as u32;
            if let Some(present) = present {
                any = true;
                let all = leaf.perturbations();
                let subset = active.map(|a| a.leaf_perturbations(i));
                let count = subset.map_or(all.len(), <[u32]>::len);
                for k in 0..count {
                    let p = match subset {
                        Some(s) => match all.get(s[k] as usize) {
                            Some(p) => p,
                            None => continue,
                        },
                        None => &all[k],
                    };
                    let q = p.quadric.on_ray(ray);
                    // Per-ray pruning: a support the ray never enters inside the leaf's box
                    // contributes 0 there. (Outside a derived box the pruned F′ stays < 0:
                    // F < 0 there and the supports of bumps lie inside the box.)
                    if p.form_factor != 0.0 && q.range(present).hi > 0.0 {
                        self.perturbations.push((p.form_factor, q));
                    }
                }
            }
            self.leaves.push(LeafOnRay {
                present,
                clips: leaf.clips(),
                // An absent leaf's quadric is never read: skip restricting it.
                base: if present.is_some() {
                    leaf.base().on_ray(ray)
                } else {
                    RayQuadratic {
                        a: 0.0,
                        b: 0.0,
                        c: 0.0,
                    }
                },
                perturbations: (start, self.perturbations.len() as u32),
            });
        }
        any
    }

    fn leaf_bound(&self, leaf: &LeafOnRay, seg: Interval) -> Bound {
        let Some(present) = leaf.present else {
            return ABSENT;
        };
        if seg.hi < present.lo || seg.lo > present.hi {
            return ABSENT;
        }
        let mut inner = seg;
        if leaf.clips {
            inner = Interval {
                lo: seg.lo.max(present.lo),
                hi: seg.hi.min(present.hi),
            };
        }
        let mut value = leaf.base.range(inner);
        let mut slope = leaf.base.derivative_range(inner);
        for &(f, q) in
            &self.perturbations[leaf.perturbations.0 as usize..leaf.perturbations.1 as usize]
        {
            let qr = q.range(inner).positive_part();
            value = value + qr.cube().scale(f);
            slope = slope + (qr.square() * q.derivative_range(inner)).scale(3.0 * f);
        }
        if inner != seg {
            // Part of the segment is outside the clipping box, where the value is −∞.
            value = Interval {
                lo: f64::NEG_INFINITY,
                hi: value.hi,
            };
            slope = Interval::EVERYTHING;
        }
        Bound { value, slope }
    }

    fn leaf_value(&self, leaf: &LeafOnRay, t: f64) -> f64 {
        let Some(present) = leaf.present else {
            return f64::NEG_INFINITY;
        };
        if t < present.lo || t > present.hi {
            return f64::NEG_INFINITY;
        }
        let mut v = leaf.base.eval(t);
        for &(f, q) in
            &self.perturbations[leaf.perturbations.0 as usize..leaf.perturbations.1 as usize]
        {
            let qt = q.eval(t);
            if qt > 0.0 {
                v += f * qt * qt * qt;
            }
        }
        v
    }

    fn bound(&mut self, program: &[CsgOp], seg: Interval, stats: &mut CastStats) -> Bound {
        stats.bound_evaluations += 1;
        if let [CsgOp::Leaf(i)] = program {
            return self.leaf_bound(&self.leaves[*i as usize], seg);
        }
        let mut stack = std::mem::take(&mut self.bounds);
        stack.clear();
        for op in program {
            match *op {
                CsgOp::Leaf(i) => stack.push(self.leaf_bound(&self.leaves[i as usize], seg)),
                CsgOp::Max | CsgOp::Min => {
                    let b = stack.pop().unwrap_or(ABSENT);
                    let a = stack.pop().unwrap_or(ABSENT);
                    let is_max = *op == CsgOp::Max;
                    // If one operand dominates over the whole segment, the result *is* that
                    // operand; otherwise its slope lies between the two operands' slopes.
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
                    stack.push(if a_wins {
                        a
                    } else if b_wins {
                        b
                    } else {
                        Bound {
                            value: if is_max {
                                a.value.max(b.value)
                            } else {
                                a.value.min(b.value)
                            },
                            slope: a.slope.hull(b.slope),
                        }
                    });
                }
                CsgOp::Neg => {
                    if let Some(top) = stack.last_mut() {
                        top.value = -top.value;
                        top.slope = -top.slope;
                    }
                }
            }
        }
        let result = stack.pop().unwrap_or(ABSENT);
        self.bounds = stack;
        result
    }

    fn value(&mut self, program: &[CsgOp], t: f64, stats: &mut CastStats) -> f64 {
        stats.point_evaluations += 1;
        if let [CsgOp::Leaf(i)] = program {
            return self.leaf_value(&self.leaves[*i as usize], t);
        }
        let mut stack = std::mem::take(&mut self.values);
        stack.clear();
        for op in program {
            match *op {
                CsgOp::Leaf(i) => stack.push(self.leaf_value(&self.leaves[i as usize], t)),
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
        let result = stack.pop().unwrap_or(f64::NEG_INFINITY);
        self.values = stack;
        result
    }

    fn search(
        &mut self,
        program: &[CsgOp],
        range: Interval,
        eps: f64,
        stats: &mut CastStats,
    ) -> Option<f64> {
        if self.value(program, range.lo, stats) >= 0.0 {
            return Some(range.lo);
        }
        let mut segments = std::mem::take(&mut self.segments);
        segments.clear();
        segments.push((range.lo, range.hi));
        let mut hit = None;
        while let Some((a, b)) = segments.pop() {
            let bound = self.bound(program, Interval { lo: a, hi: b }, stats);
            if bound.value.hi < 0.0 {
                continue; // proven empty
            }
            if bound.value.lo >= 0.0 {
                hit = Some(a); // everything before `a` was proven or tested negative
                break;
            }
            if bound.slope.lo > 0.0 {
                // Increasing: a root exists iff F′(b) ≥ 0, and it is unique.
                let fb = self.value(program, b, stats);
                if fb < 0.0 {
                    continue;
                }
                let fa = self.value(program, a, stats);
                if fa >= 0.0 {
                    hit = Some(a);
                } else {
                    hit = Some(self.illinois(program, (a, fa), (b, fb), eps, stats));
                }
                break;
            }
            if bound.slope.hi < 0.0 {
                // Decreasing: the maximum is at `a`.
                if self.value(program, a, stats) >= 0.0 {
                    hit = Some(a);
                    break;
                }
                continue;
            }
            let m = a + 0.5 * (b - a);
            if b - a <= eps || m <= a || m >= b {
                // Shorter than ε (or than the float spacing): test it directly.
                if self.value(program, m, stats) >= 0.0 {
                    hit = Some(m);
                    break;
                }
                if self.value(program, b, stats) >= 0.0 {
                    hit = Some(b);
                    break;
                }
                continue;
            }
            segments.push((m, b));
            segments.push((a, m));
        }
        self.segments = segments;
        hit
    }

    /// Illinois regula falsi on a bracket with `f(a) < 0 ≤ f(b)` and a single root; returns a
    /// point `t ≥ root` with `t − root ≤ eps` and `f(t) ≥ 0`.
    fn illinois(
        &mut self,
        program: &[CsgOp],
        (mut a, mut fa): (f64, f64),
        (mut b, mut fb): (f64, f64),
        eps: f64,
        stats: &mut CastStats,
    ) -> f64 {
        let mut last_side = 0i8;
        let mut width_before = b - a;
        for iteration in 0..200 {
            if b - a <= eps || fb == 0.0 {
                break;
            }
            let mut c = b - fb * (b - a) / (fb - fa);
            // Every fourth step, insist on halving progress; always stay strictly inside.
            if iteration % 4 == 3 {
                if b - a > 0.5 * width_before {
                    c = a + 0.5 * (b - a);
                }
                width_before = b - a;
            }
            if !(c > a && c < b) {
                c = a + 0.5 * (b - a);
                if !(c > a && c < b) {
                    break; // no float between a and b
                }
            }
            let fc = self.value(program, c, stats);
            if fc >= 0.0 {
                b = c;
                fb = fc;
                if last_side == 1 {
                    fa *= 0.5;
                }
                last_side = 1;
            } else {
                a = c;
                fa = fc;
                if last_side == -1 {
                    fb *= 0.5;
                }
                last_side = -1;
            }
        }
        b
    }
}

impl Solid {
    /// Convenience: [`RayCaster::cast`] with a fresh scratch space.
    pub fn cast(&self, ray: &Ray, range: Interval, eps: f64) -> Option<f64> {
        RayCaster::new().cast(self, ray, range, eps, &mut CastStats::default())
    }
}
