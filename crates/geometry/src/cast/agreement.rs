//! Test: every algebra of the one CSG evaluator, run over the same random programs and rays,
//! agrees with the others where it must — the search's point values (with their deciding leaf)
//! with the solid's value at the point and with the normals' algebra; the point values with the
//! interval bound over any segment holding them (value and sign-slope); the span sets with the
//! point values' sign; the fold over absent leaves with the full program; the compile-time
//! facts (stack depth, negated leaves) with a recursive reading of the program.

use super::RayCaster;
use super::bound::{Bound, Bounds};
use super::closed_form::{SpanSet, SpanSets};
use super::on_ray::{LeafOnRay, leaf_value};
use super::program::{Deciding, NEGATED};
use crate::csg::{CsgAlgebra, Surface, run, run_in};
use crate::{ActiveSet, CsgOp, FreeForm, Perturbation, Quadric, Shape, Solid};
use fray_core::{Aabb, Interval, Ray};
use glam::DVec3;

/// Values are O(1) here (unit-sized shapes seen from a few units away); this is far above the
/// rounding (and the widening, ~10⁻¹⁴) and far below the values the checks compare.
const TOL: f64 = 1e-9;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn point(&mut self, r: f64) -> DVec3 {
        DVec3::new(
            self.uniform(-r, r),
            self.uniform(-r, r),
            self.uniform(-r, r),
        )
    }
    fn direction(&mut self) -> DVec3 {
        loop {
            let v = self.point(1.0);
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A random leaf: ellipsoids (derived boxes), perturbed spheres (bumps and dents), and
/// unbounded quadrics clipped by an explicit box.
fn leaf(rng: &mut Rng) -> Shape {
    let c = rng.point(0.8);
    let clip = |rng: &mut Rng, c: DVec3| {
        let half = DVec3::new(
            rng.uniform(0.3, 1.0),
            rng.uniform(0.3, 1.0),
            rng.uniform(0.3, 1.0),
        );
        Some(Aabb::from_center_half(c + rng.point(0.2), half))
    };
    let (base, perturbations, bounds) = match rng.below(6) {
        0 => (Quadric::sphere(c, rng.uniform(0.3, 1.0)), vec![], None),
        1 => {
            let radii = DVec3::new(
                rng.uniform(0.2, 1.0),
                rng.uniform(0.2, 1.0),
                rng.uniform(0.2, 1.0),
            );
            (Quadric::ellipsoid(c, radii), vec![], None)
        }
        2 => {
            let r = rng.uniform(0.4, 0.9);
            let bumps = (0..1 + rng.below(3))
                .map(|_| {
                    let at = c + rng.direction() * r;
                    Perturbation::new(
                        rng.uniform(-0.8, 2.0),
                        Quadric::sphere(at, rng.uniform(0.2, 0.5)),
                    )
                })
                .collect();
            (Quadric::sphere(c, r), bumps, None)
        }
        3 => {
            let q = Quadric::cylinder(c, rng.direction(), rng.uniform(0.2, 0.6));
            (q, vec![], clip(rng, c))
        }
        4 => {
            let q = Quadric::half_space(c, rng.direction());
            (q, vec![], clip(rng, c))
        }
        _ => {
            let q = Quadric::cone(c, rng.direction(), rng.uniform(0.3, 0.8));
            (q, vec![], clip(rng, c))
        }
    };
    Shape::FreeForm(FreeForm::new(base, perturbations, bounds).expect("a finite leaf"))
}

/// A random CSG tree of `n` leaves: unions (of two or three), intersections, differences.
fn shape(rng: &mut Rng, n: usize) -> Shape {
    if n == 1 {
        return leaf(rng);
    }
    let k = 1 + rng.below(n as u64 - 1) as usize;
    let (a, b) = (shape(rng, k), shape(rng, n - k));
    match rng.below(4) {
        0 => Shape::Union(vec![a, b]),
        1 if n - k >= 2 => Shape::Union(vec![a, shape(rng, 1), b]),
        1 | 2 => Shape::Intersection(vec![a, b]),
        _ => Shape::Difference(Box::new(a), Box::new(b)),
    }
}

/// Recursive reading of a postfix program: for the operand that ends at `end` (exclusive), its
/// start, its stack depth, and (into `negated`) the parity of negations above each leaf,
/// `flip` saying whether this operand is itself under an odd number.
fn read(program: &[CsgOp], end: usize, flip: bool, negated: &mut [bool]) -> (usize, usize) {
    match program[end - 1] {
        CsgOp::Leaf(i) => {
            negated[i as usize] = flip;
            (end - 1, 1)
        }
        CsgOp::Neg => read(program, end - 1, !flip, negated),
        CsgOp::Max | CsgOp::Min => {
            let (mid, db) = read(program, end - 1, flip, negated);
            let (start, da) = read(program, mid, flip, negated);
            (start, da.max(db + 1))
        }
    }
}

/// Values of a program at a point with the leaves outside `active` taken as absent (`−∞`): what
/// the fold must preserve.
struct Masked<'a> {
    leaves: &'a [FreeForm],
    active: &'a [bool],
    p: DVec3,
}

impl CsgAlgebra for Masked<'_> {
    type Value = f64;
    fn leaf(&mut self, i: u32) -> Option<f64> {
        Some(if self.active[i as usize] {
            self.leaves[i as usize].eval(self.p)
        } else {
            f64::NEG_INFINITY
        })
    }
    fn max(&mut self, a: f64, b: f64) -> Option<f64> {
        Some(a.max(b))
    }
    fn min(&mut self, a: f64, b: f64) -> Option<f64> {
        Some(a.min(b))
    }
    fn neg(&mut self, a: f64) -> Option<f64> {
        Some(-a)
    }
}

/// What the checks saw, so that the test cannot pass by checking nothing.
#[derive(Debug, Default)]
struct Seen {
    long_programs: usize,
    points: usize,
    signs_against_the_solid: usize,
    contained: usize,
    increasing: usize,
    decreasing: usize,
    memberships: usize,
    normals: usize,
    folds: usize,
}

/// The ray's algebras over `program`, on the leaves `caster` prepared.
struct OnRay<'a> {
    leaves: &'a [LeafOnRay],
    perturbations: &'a [(f64, crate::RayQuadratic)],
    program: &'a [CsgOp],
}

impl OnRay<'_> {
    fn value(&self, t: f64) -> (f64, u32) {
        let mut values = Deciding {
            leaves: self.leaves,
            perturbations: self.perturbations,
            t,
        };
        run_in(self.program, &mut values, &mut Vec::new()).expect("a compiled program")
    }
    fn bound(&self, seg: Interval) -> Bound {
        let mut bounds = Bounds {
            leaves: self.leaves,
            perturbations: self.perturbations,
            seg,
        };
        run_in(self.program, &mut bounds, &mut Vec::new()).expect("a compiled program")
    }
    fn set(&self) -> Option<SpanSet> {
        let mut sets = SpanSets {
            leaves: self.leaves,
        };
        run_in(self.program, &mut sets, &mut Vec::new())
    }
    /// Whether some leaf that does not clip is cut off by its (derived) box at `t` although
    /// the ray passes through that box elsewhere: there the search's value is `−∞` where the
    /// leaf's is merely negative — the same sign, not the same number.
    fn substituted(&self, t: f64) -> bool {
        self.leaves
            .iter()
            .any(|l| !l.clips && l.present.is_some_and(|p| !p.contains(t)))
    }
}

#[test]
fn every_algebra_agrees_with_the_others() {
    let mut rng = Rng(0x853c_49e6_748f_ea9b);
    let mut seen = Seen::default();
    let mut caster = RayCaster::new();
    for solid_index in 0..400 {
        let n = 1 + rng.below(7) as usize;
        let solid = Solid::new(shape(&mut rng, n)).expect("a valid tree");
        let program = solid.program();
        if program.len() > 4 {
            seen.long_programs += 1;
        }

        // Compile-time facts against a recursive reading.
        let mut negated = vec![false; solid.leaves().len()];
        let (start, depth) = read(program, program.len(), false, &mut negated);
        assert_eq!((start, depth), (0, solid.max_stack()), "{program:?}");
        for (i, &n) in negated.iter().enumerate() {
            assert_eq!(solid.leaf_is_negated(i), n, "leaf {i} of {program:?}");
        }

        for _ in 0..12 {
            let origin = rng.direction() * rng.uniform(3.0, 6.0);
            let Some(ray) = Ray::new(origin, rng.point(1.0) - origin) else {
                continue;
            };
            let Some(range) = caster.prepare_ray(&solid, &ray, Interval::new(0.0, f64::INFINITY))
            else {
                continue;
            };
            let on_ray = OnRay {
                leaves: &caster.leaves,
                perturbations: &caster.perturbations,
                program,
            };
            // Inside the range, off its ends (the faces of the solid's box, where the slab test
            // and a containment test of the rounded point may disagree).
            let samples: Vec<f64> = (0..64)
                .map(|k| range.lo + (range.hi - range.lo) * (f64::from(k) + 0.5) / 64.0)
                .collect();

            // Point values: the deciding leaf's value is the program's (negated if marked);
            // the solid's value at the point has the same sign (the search's leaves are widened
            // and cut off at derived boxes, which keeps signs, not numbers).
            for &t in &samples {
                let (v, decided) = on_ray.value(t);
                let leaf = &caster.leaves[(decided & !NEGATED) as usize];
                let (lo, hi) = leaf.perturbations;
                let own = leaf_value(leaf, &caster.perturbations[lo as usize..hi as usize], t);
                assert_eq!(v, if decided & NEGATED == 0 { own } else { -own });
                seen.points += 1;
                let exact = solid.eval(ray.at(t));
                if exact.abs() > TOL && v.abs() > TOL {
                    assert_eq!(exact > 0.0, v > 0.0, "solid {solid_index} at t = {t}");
                    seen.signs_against_the_solid += 1;
                }
            }

            // Bounds over random segments hold the point values in them (where no derived
            // box substitutes −∞), and their signs everywhere; a slope range that excludes 0
            // means one sign change at most, in that direction.
            for _ in 0..8 {
                let (a, b) = (
                    rng.uniform(range.lo, range.hi),
                    rng.uniform(range.lo, range.hi),
                );
                let seg = Interval::new(a, b);
                let bound = on_ray.bound(seg);
                let mut signs = Vec::new();
                for k in 0..=32 {
                    let t = seg.lo + (seg.hi - seg.lo) * f64::from(k) / 32.0;
                    let (v, _) = on_ray.value(t);
                    assert!(bound.value.hi >= -TOL || v < 0.0, "{bound:?} {v} at {t}");
                    assert!(bound.value.lo < TOL || v >= 0.0, "{bound:?} {v} at {t}");
                    if !on_ray.substituted(t) {
                        assert!(
                            bound.value.lo - TOL <= v && v <= bound.value.hi + TOL,
                            "solid {solid_index}: {v} at {t} outside {bound:?}"
                        );
                        seen.contained += 1;
                    }
                    if v.abs() > TOL {
                        signs.push(v > 0.0);
                    }
                }
                let changes = |from: bool| {
                    signs
                        .windows(2)
                        .filter(|w| w[0] == from && w[1] != from)
                        .count()
                };
                if bound.slope.lo > 0.0 {
                    assert_eq!(changes(true), 0, "solid {solid_index}: {bound:?} {signs:?}");
                    seen.increasing += 1;
                }
                if bound.slope.hi < 0.0 {
                    assert_eq!(
                        changes(false),
                        0,
                        "solid {solid_index}: {bound:?} {signs:?}"
                    );
                    seen.decreasing += 1;
                }
            }

            // Span sets (plain rays): membership is the point value's sign.
            if caster.perturbations.is_empty()
                && let Some(set) = on_ray.set()
            {
                for &t in &samples {
                    let (v, _) = on_ray.value(t);
                    if v.abs() > TOL {
                        let member = set.spans().iter().any(|&(lo, hi)| lo <= t && t <= hi);
                        assert_eq!(member, v > 0.0, "solid {solid_index}: {set:?} {v} at {t}");
                        seen.memberships += 1;
                    }
                }
            }

            // Normals: the value-and-gradient algebra's sign is the solid's, and its value and
            // gradient are the reported leaf's (negated as often as the program negates it).
            for &t in samples.iter().step_by(4) {
                let p = ray.at(t);
                let mut surface = Surface {
                    leaves: solid.leaves(),
                    eval: |_, leaf: &FreeForm| leaf.eval_with_gradient(p),
                };
                let (v, g, i) = run(program, &mut surface).expect("a compiled program");
                let exact = solid.eval(p);
                if exact.abs() > TOL && v.abs() > TOL {
                    assert_eq!(v > 0.0, exact > 0.0, "solid {solid_index} at {p}");
                }
                let (own, own_g) = solid.leaves()[i as usize].eval_with_gradient(p);
                assert!(
                    (v, g) == (own, own_g) || (v, g) == (-own, -own_g),
                    "{v} {g} vs leaf {i}: {own} {own_g}"
                );
                seen.normals += 1;
            }

            // The fold: with a random subset of leaves, the pruned program computes what the
            // full one does with the others absent — at points, and over the ray (bounds,
            // values, span sets) with the caster's leaves prepared for the subset.
            let active_leaves: Vec<u32> = (0..solid.leaves().len() as u32)
                .filter(|_| rng.below(3) != 0)
                .collect();
            let everything: Vec<u32> = (0..solid.perturbation_count() as u32).collect();
            let mut active = ActiveSet::new();
            let may_hit = active.set(&solid, &active_leaves, &everything);
            let mask: Vec<bool> = (0..solid.leaves().len())
                .map(|i| active.leaf_is_active(i))
                .collect();
            for &t in samples.iter().step_by(4) {
                let p = ray.at(t);
                let mut full = Masked {
                    leaves: solid.leaves(),
                    active: &mask,
                    p,
                };
                let full = run(program, &mut full).expect("a compiled program");
                if !may_hit {
                    assert_eq!(full, f64::NEG_INFINITY, "{program:?} {active_leaves:?}");
                    continue;
                }
                let mut pruned = Masked {
                    leaves: solid.leaves(),
                    active: &mask,
                    p,
                };
                let pruned = run(active.program(), &mut pruned).expect("a pruned program");
                assert_eq!(full.to_bits(), pruned.to_bits(), "{:?}", active.program());
            }
            if may_hit {
                let inv_dir = DVec3::ONE / ray.dir;
                // Leaves outside the subset become absent; whether any is left on the ray
                // does not matter here.
                let _ = caster.prepare(&solid, &ray, inv_dir, range, Some(&active));
                let full = OnRay {
                    leaves: &caster.leaves,
                    perturbations: &caster.perturbations,
                    program,
                };
                let pruned = OnRay {
                    program: active.program(),
                    ..full
                };
                for &t in samples.iter().step_by(4) {
                    let ((v, i), (w, j)) = (full.value(t), pruned.value(t));
                    assert_eq!(v.to_bits(), w.to_bits());
                    // Which absent leaf "decided" an infinite value is immaterial.
                    assert!(i == j || v.is_infinite(), "{v} by {i} or {j}");
                }
                let seg = Interval::new(range.lo, range.lo + 0.5 * (range.hi - range.lo));
                let (b, c) = (full.bound(seg), pruned.bound(seg));
                assert_eq!(
                    (b.value, b.slope),
                    (c.value, c.slope),
                    "{:?}",
                    active.program()
                );
                if caster.perturbations.is_empty() {
                    let spans = |s: Option<SpanSet>| s.map(|s| s.spans().to_vec());
                    assert_eq!(spans(full.set()), spans(pruned.set()));
                }
                seen.folds += 1;
            }
        }
    }
    assert!(seen.long_programs > 200, "{seen:?}");
    assert!(seen.signs_against_the_solid > 100_000, "{seen:?}");
    assert!(seen.contained > 300_000, "{seen:?}");
    assert!(seen.increasing > 2000 && seen.decreasing > 2000, "{seen:?}");
    assert!(seen.memberships > 100_000, "{seen:?}");
    assert!(seen.normals > 25_000 && seen.folds > 1000, "{seen:?}");
}
