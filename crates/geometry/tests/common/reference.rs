//! The high-precision reference of the accuracy tests: where a solid is inside along a ray,
//! computed in double-double ([`Dd`]) from the f64 inputs taken as exact binary values (quadric
//! coefficients and origins, box corners, ray origin and direction) — never by the caster's f64
//! formulas.
//!
//! Besides the exact inside set `E = {t : F′(t) ≥ 0}` it gives the **loose** set `L` that the
//! caster's contract is stated with (docs/accuracy.md): each leaf's value known only to within
//! `r(t) = Δ + δ(t)` — `Δ` the widening the caster applies to the leaf ([`widening`]), `δ(t)` the
//! bound on the rounding of one f64 evaluation at `t` ([`QuadricOnRay::delta`],
//! [`perturbed_delta`]) — and clipping boxes grown by the rounding of the slab test: `L` is
//! where the program's upper bound is `≥ 0`, so `E ⊆ L`, and a hit must lie in `L`.

#![allow(dead_code)] // each test binary uses a different subset

use super::dd::Dd;
use fray_core::{Aabb, Interval, Ray};
use fray_geometry::{CsgOp, FreeForm, Quadric, Solid};

/// The unit roundoff of f64, `2⁻⁵³`.
pub const U: f64 = f64::EPSILON / 2.0;
/// Rounding units per unit of term magnitude in one f64 evaluation of a quadric on a ray,
/// everything included: `o − origin` (1), the coefficients `F(o)`, `∇F(o)·d`, `dᵀAd` (≤ 9
/// more), Horner in `t` (≤ 4), and where a root, a vertex or a bound stands in for the value
/// (≤ 10 more). Derived in docs/accuracy.md, and the caster's number too.
pub const K: f64 = 24.0;
/// The relative rounding of a box face's ray parameter `(b − o) · (1/d)`: three roundings.
pub const FACE: f64 = 4.0 * U;

/// A quadratic `a t² + b t + c` in double-double.
#[derive(Clone, Copy, Debug)]
pub struct DdQuadratic {
    pub a: Dd,
    pub b: Dd,
    pub c: Dd,
}

impl DdQuadratic {
    pub fn eval(&self, t: f64) -> Dd {
        let t = Dd::from(t);
        (self.a * t + self.b) * t + self.c
    }

    /// Where the quadratic is `≥ 0` on the whole line: sorted disjoint closed spans.
    pub fn nonnegative(&self) -> Spans {
        let (a, b, c) = (self.a, self.b, self.c);
        let all = vec![(f64::NEG_INFINITY, f64::INFINITY)];
        if a.is_zero() {
            if b.is_zero() {
                return if c.is_negative() { vec![] } else { all };
            }
            let r = (-c / b).to_f64();
            return if b.is_negative() {
                vec![(f64::NEG_INFINITY, r)]
            } else {
                vec![(r, f64::INFINITY)]
            };
        }
        let disc = b * b - a * c.scale(4.0);
        if disc.is_negative() {
            return if a.is_negative() { vec![] } else { all };
        }
        // Cancellation-free, in double-double.
        let half = (b + disc.sqrt().scale(b.signum())).scale(-0.5);
        let (r0, r1) = if half.is_zero() {
            (0.0, 0.0)
        } else {
            ((half / a).to_f64(), (c / half).to_f64())
        };
        let (r0, r1) = (r0.min(r1), r0.max(r1));
        if a.is_negative() {
            vec![(r0, r1)]
        } else if r0 == r1 {
            all // a double root touches zero from above
        } else {
            vec![(f64::NEG_INFINITY, r0), (r1, f64::INFINITY)]
        }
    }
}

/// A quadric restricted to a ray, exactly, with the magnitudes of its terms.
#[derive(Clone, Copy, Debug)]
pub struct QuadricOnRay {
    pub q: DdQuadratic,
    /// `S_a, S_b, S_c`: the sums of the absolute values of the terms that make `dᵀAd`,
    /// `∇F(o)·d` and `F(o)` (the quadric's coefficients in absolute value at `|o − origin|` and
    /// `|d|`).
    pub s: [f64; 3],
}

/// `q` on `ray`, exactly (to `2⁻¹⁰⁰` relative to the terms).
pub fn quadric_on_ray(q: &Quadric, ray: &Ray) -> QuadricOnRay {
    let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = q.coefficients.map(Dd::from);
    let x = [
        Dd::diff(ray.origin.x, q.origin.x),
        Dd::diff(ray.origin.y, q.origin.y),
        Dd::diff(ray.origin.z, q.origin.z),
    ];
    let d = [ray.dir.x, ray.dir.y, ray.dir.z].map(Dd::from);
    let two = |v: Dd| v.scale(2.0);
    let c = a11 * x[0] * x[0]
        + a22 * x[1] * x[1]
        + a33 * x[2] * x[2]
        + a12 * x[0] * x[1]
        + a13 * x[0] * x[2]
        + a23 * x[1] * x[2]
        + a14 * x[0]
        + a24 * x[1]
        + a34 * x[2]
        + a44;
    let g = [
        two(a11 * x[0]) + a12 * x[1] + a13 * x[2] + a14,
        two(a22 * x[1]) + a12 * x[0] + a23 * x[2] + a24,
        two(a33 * x[2]) + a13 * x[0] + a23 * x[1] + a34,
    ];
    let b = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
    let a = a11 * d[0] * d[0]
        + a22 * d[1] * d[1]
        + a33 * d[2] * d[2]
        + a12 * d[0] * d[1]
        + a13 * d[0] * d[2]
        + a23 * d[1] * d[2];
    // The magnitudes, in f64 (their own rounding is immaterial beside K).
    let [m11, m22, m33, m12, m13, m23, m14, m24, m34, m44] = q.coefficients.map(f64::abs);
    let xa = [
        x[0].to_f64().abs(),
        x[1].to_f64().abs(),
        x[2].to_f64().abs(),
    ];
    let da = ray.dir.abs();
    let (da, xa) = ([da.x, da.y, da.z], xa);
    let s_a = m11 * da[0] * da[0]
        + m22 * da[1] * da[1]
        + m33 * da[2] * da[2]
        + m12 * da[0] * da[1]
        + m13 * da[0] * da[2]
        + m23 * da[1] * da[2];
    let s_b = (2.0 * m11 * xa[0] + m12 * xa[1] + m13 * xa[2] + m14) * da[0]
        + (2.0 * m22 * xa[1] + m12 * xa[0] + m23 * xa[2] + m24) * da[1]
        + (2.0 * m33 * xa[2] + m13 * xa[0] + m23 * xa[1] + m34) * da[2];
    let s_c = m11 * xa[0] * xa[0]
        + m22 * xa[1] * xa[1]
        + m33 * xa[2] * xa[2]
        + m12 * xa[0] * xa[1]
        + m13 * xa[0] * xa[2]
        + m23 * xa[1] * xa[2]
        + m14 * xa[0]
        + m24 * xa[1]
        + m34 * xa[2]
        + m44;
    QuadricOnRay {
        q: DdQuadratic { a, b, c },
        s: [s_a, s_b, s_c],
    }
}

impl QuadricOnRay {
    /// `S(t) = S_a t² + S_b |t| + S_c`: the magnitude of the terms evaluated at `t`.
    pub fn magnitude(&self, t: f64) -> f64 {
        let [sa, sb, sc] = self.s;
        sa * t * t + sb * t.abs() + sc
    }

    /// `δ(t) = K u S(t)`: the bound on the rounding of the caster's value at `t`.
    pub fn delta(&self, t: f64) -> f64 {
        K * U * self.magnitude(t)
    }

    /// `{t ≥ 0 : q(t) ≥ level · (widening + δ(t))}` (`level` −1: loose, 0: exact, +1: the
    /// complement of the loose set of `−q`).
    pub fn spans(&self, level: f64, widening: f64) -> Spans {
        let k = level * K * U;
        let [sa, sb, sc] = self.s;
        let shifted = DdQuadratic {
            a: self.q.a - Dd::from(k * sa),
            b: self.q.b - Dd::from(k * sb),
            c: self.q.c - Dd::from(k * sc + level * widening),
        };
        intersect(&shifted.nonnegative(), &[(0.0, f64::INFINITY)])
    }

    /// The largest value over `[lo, hi]` (finite), rounded.
    pub fn max_over(&self, lo: f64, hi: f64) -> f64 {
        let mut m = self.q.eval(lo).to_f64().max(self.q.eval(hi).to_f64());
        if let Some(v) = self.vertex()
            && v > lo
            && v < hi
        {
            m = m.max(self.q.eval(v).to_f64());
        }
        m
    }

    /// The vertex `−b / 2a` (`None` for a linear `q`).
    pub fn vertex(&self) -> Option<f64> {
        (!self.q.a.is_zero()).then(|| (-self.q.b / self.q.a.scale(2.0)).to_f64())
    }
}

/// Sorted, disjoint closed spans of `t`.
pub type Spans = Vec<(f64, f64)>;

pub fn union(a: &[(f64, f64)], b: &[(f64, f64)]) -> Spans {
    let mut all: Spans = a.iter().chain(b).copied().collect();
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Spans = Vec::new();
    for (lo, hi) in all {
        match out.last_mut() {
            Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
            _ => out.push((lo, hi)),
        }
    }
    out
}

pub fn intersect(a: &[(f64, f64)], b: &[(f64, f64)]) -> Spans {
    let mut out = Vec::new();
    for &(a0, a1) in a {
        for &(b0, b1) in b {
            let (lo, hi) = (a0.max(b0), a1.min(b1));
            if lo <= hi {
                out.push((lo, hi));
            }
        }
    }
    union(&out, &[])
}

/// The closure of the complement.
pub fn complement(a: &[(f64, f64)]) -> Spans {
    let mut out = Vec::new();
    let mut from = f64::NEG_INFINITY;
    for &(lo, hi) in a {
        if lo > from {
            out.push((from, lo));
        }
        from = hi;
    }
    if from < f64::INFINITY {
        out.push((from, f64::INFINITY));
    }
    out
}

/// The exact parameter interval of `ray` inside box `b` (`None`: missed), in double-double.
pub fn box_interval(b: &Aabb, ray: &Ray) -> Option<(Dd, Dd)> {
    let mut lo = Dd::from(f64::NEG_INFINITY);
    let mut hi = Dd::from(f64::INFINITY);
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        if d == 0.0 {
            if o < b.min[axis] || o > b.max[axis] {
                return None;
            }
            continue;
        }
        let t0 = Dd::diff(b.min[axis], o) / Dd::from(d);
        let t1 = Dd::diff(b.max[axis], o) / Dd::from(d);
        let (t0, t1) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        lo = lo.max(t0);
        hi = hi.min(t1);
    }
    (lo <= hi).then_some((lo, hi))
}

/// A clipping box's interval grown (`level` −1), exact (0) or shrunk (+1) by the rounding of
/// the slab test, as spans.
fn box_spans(b: &Aabb, ray: &Ray, level: f64) -> Spans {
    let Some((lo, hi)) = box_interval(b, ray) else {
        return vec![];
    };
    let (lo, hi) = (lo.to_f64(), hi.to_f64());
    let (lo, hi) = (lo + level * FACE * lo.abs(), hi - level * FACE * hi.abs());
    if lo <= hi { vec![(lo, hi)] } else { vec![] }
}

/// `Φ(R)`: the sum of the absolute values of `q`'s terms at any point within distance `R` of
/// its origin, `α R² + λ R + κ` (`α` the largest row sum of `|M|`, `λ = ‖b‖₂`, `κ = |k|`),
/// with `R = ‖o − origin‖₁ + reach`: the stated magnitude behind the caster's widening.
pub fn magnitude_bound(q: &Quadric, ray: &Ray, reach: f64) -> f64 {
    let [a11, a22, a33, a12, a13, a23, a14, a24, a34, a44] = q.coefficients.map(f64::abs);
    let alpha = (a11 + 0.5 * (a12 + a13))
        .max(a22 + 0.5 * (a12 + a23))
        .max(a33 + 0.5 * (a13 + a23));
    let lambda = (a14 * a14 + a24 * a24 + a34 * a34).sqrt();
    let x: f64 = (0..3)
        .map(|i| Dd::diff(ray.origin[i], q.origin[i]).to_f64().abs())
        .sum();
    let r = x + reach;
    (alpha * r + lambda) * r + a44
}

/// How far along the ray the caster's bounds must hold over `range`: the largest `|t|` of the
/// range clipped to the solid's box (grown by the slab rounding); 0 if the box is missed.
pub fn reach(solid: &Solid, ray: &Ray, range: Interval) -> f64 {
    let Some((lo, hi)) = box_interval(&solid.bounds(), ray) else {
        return 0.0;
    };
    let (lo, hi) = (lo.to_f64(), hi.to_f64());
    let lo = range.lo.max(lo - FACE * lo.abs());
    let hi = range.hi.min(hi + FACE * hi.abs());
    if lo > hi { 0.0 } else { hi.max(-lo) }
}

/// The widening `Δ` the caster applies to `leaf` on this ray (docs/accuracy.md), as stated:
/// `K u Φ_F(R)` for the base; per perturbation whose support the ray may enter over the leaf's
/// part of `range`, `|f| (3 q̄² δ_Q + 3 q̄ δ_Q² + δ_Q³ + 4u q̄³)` with `δ_Q = K u Φ_Q(R)` and `q̄`
/// the largest `Q` there plus `2δ_Q`; and `n u` times the magnitudes summed. With a 1 % margin
/// for the f64 arithmetic of the caster's own estimate.
pub fn widening(leaf: &FreeForm, ray: &Ray, range: Interval, reach: f64) -> f64 {
    let base = magnitude_bound(leaf.base(), ray, reach);
    let mut w = K * U * base;
    let part = box_interval(&leaf.bounds(), ray)
        .map(|(lo, hi)| (range.lo.max(lo.to_f64()), range.hi.min(hi.to_f64())));
    let (mut terms, mut size, mut n) = (0.0, 0.0, 0.0);
    if let Some((lo, hi)) = part.filter(|p| p.0 <= p.1) {
        let (lo, hi) = (lo - FACE * lo.abs(), hi + FACE * hi.abs());
        for p in leaf.perturbations() {
            if p.form_factor == 0.0 {
                continue;
            }
            let dq = K * U * magnitude_bound(&p.quadric, ray, reach);
            let top = quadric_on_ray(&p.quadric, ray).max_over(lo, hi);
            if top <= -dq {
                continue;
            }
            let qb = top.max(0.0) + 2.0 * dq;
            let f = p.form_factor.abs();
            terms += f
                * (3.0 * qb * qb * dq + 3.0 * qb * dq * dq + dq * dq * dq + 4.0 * U * qb * qb * qb);
            size += f * qb * qb * qb;
            n += 1.0;
        }
    }
    w += terms + n * U * (base + size);
    1.01 * w
}

/// The exact and loose sets of one plain leaf (no perturbation), with its widening `Δ`; `deflated`
/// is the complement of the loose set of `−F` (what a negation turns into its loose set).
#[derive(Clone, Debug)]
pub struct Sets {
    pub deflated: Spans,
    pub exact: Spans,
    pub loose: Spans,
}

pub fn leaf_sets(leaf: &FreeForm, ray: &Ray, widening: f64) -> Sets {
    assert!(leaf.perturbations().is_empty(), "plain leaves only");
    let q = quadric_on_ray(leaf.base(), ray);
    let mut sets = Sets {
        deflated: q.spans(1.0, widening),
        exact: q.spans(0.0, 0.0),
        loose: q.spans(-1.0, widening),
    };
    if leaf.clips() {
        let b = leaf.bounds();
        sets.deflated = intersect(&sets.deflated, &box_spans(&b, ray, 1.0));
        sets.exact = intersect(&sets.exact, &box_spans(&b, ray, 0.0));
        sets.loose = intersect(&sets.loose, &box_spans(&b, ray, -1.0));
    }
    sets
}

/// The widenings of every leaf of `solid` on this ray over `range`.
pub fn widenings(solid: &Solid, ray: &Ray, range: Interval) -> Vec<f64> {
    let reach = reach(solid, ray, range);
    solid
        .leaves()
        .iter()
        .map(|l| widening(l, ray, range, reach))
        .collect()
}

/// The exact and loose sets (`t ≥ 0`) of a solid whose leaves are all plain, from its program.
pub fn solid_sets(solid: &Solid, ray: &Ray, range: Interval) -> Sets {
    let w = widenings(solid, ray, range);
    let leaves: Vec<Sets> = solid
        .leaves()
        .iter()
        .zip(&w)
        .map(|(l, &w)| leaf_sets(l, ray, w))
        .collect();
    let mut stack: Vec<Sets> = Vec::new();
    for op in solid.program() {
        match *op {
            CsgOp::Leaf(i) => stack.push(leaves[i as usize].clone()),
            CsgOp::Neg => {
                let s = stack.pop().expect("operand");
                stack.push(Sets {
                    deflated: complement(&s.loose),
                    exact: complement(&s.exact),
                    loose: complement(&s.deflated),
                });
            }
            CsgOp::Max | CsgOp::Min => {
                let b = stack.pop().expect("operand");
                let a = stack.pop().expect("operand");
                let f = if *op == CsgOp::Max { union } else { intersect };
                stack.push(Sets {
                    deflated: f(&a.deflated, &b.deflated),
                    exact: f(&a.exact, &b.exact),
                    loose: f(&a.loose, &b.loose),
                });
            }
        }
    }
    let whole = stack.pop().expect("a program");
    let pos = [(0.0, f64::INFINITY)];
    Sets {
        deflated: intersect(&whole.deflated, &pos),
        exact: intersect(&whole.exact, &pos),
        loose: intersect(&whole.loose, &pos),
    }
}

/// What the contract says about one cast over `range` (`range.lo ≥ 0`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Truth {
    /// The true first hit `t*`: the first point of the exact set in the range.
    pub first: Option<f64>,
    /// `t₁`: the start of the first span of the exact set in the range at least `ε` long. The
    /// hit must exist and lie at or before `t₁ + ε`.
    pub first_long: Option<f64>,
    /// The first point of the loose set in the range, when known: `t* − ρ⁻`.
    pub loose_first: Option<f64>,
}

pub fn first_in(s: &[(f64, f64)], range: Interval) -> Option<f64> {
    s.iter()
        .find(|sp| sp.1 >= range.lo && sp.0 <= range.hi)
        .map(|sp| sp.0.max(range.lo))
}

/// The truth from a plain solid's sets.
pub fn truth_from_sets(sets: &Sets, range: Interval, eps: f64) -> Truth {
    let within = intersect(&sets.exact, &[(range.lo, range.hi)]);
    Truth {
        first: first_in(&sets.exact, range),
        first_long: within.iter().find(|s| s.1 - s.0 >= eps).map(|s| s.0),
        loose_first: first_in(&sets.loose, range),
    }
}

/// The exact value of the solid's program at `t` (double-double per leaf, rounded; `−∞` outside
/// a clipping box, exactly).
pub fn exact_value(solid: &Solid, ray: &Ray, t: f64) -> f64 {
    let boxes: Vec<Option<(f64, f64)>> = solid
        .leaves()
        .iter()
        .map(|l| box_interval(&l.bounds(), ray).map(|(a, b)| (a.to_f64(), b.to_f64())))
        .collect();
    program(solid, |i, l| {
        if l.clips() && boxes[i].is_none_or(|(a, b)| t < a || t > b) {
            return (f64::NEG_INFINITY, f64::NEG_INFINITY);
        }
        let v = leaf_value(l, ray, t).0;
        (v, v)
    })
    .0
}

/// The truth for any solid by sampling: `samples` equal steps over the range clipped to the
/// solid's box (grown by 1 %), and bisection in `t` (values in double-double) where the exact
/// value turns non-negative. A span that falls between samples is not seen, so `first` may be
/// later than the true one: the checks made with it stay valid, only weaker.
pub fn truth_by_sampling(
    solid: &Solid,
    ray: &Ray,
    range: Interval,
    eps: f64,
    samples: usize,
) -> Truth {
    let Some((lo, hi)) = box_interval(
        &solid.bounds().expanded(0.01 * solid.bounds().diagonal()),
        ray,
    ) else {
        return Truth::default();
    };
    let (lo, hi) = (range.lo.max(lo.to_f64()), range.hi.min(hi.to_f64()));
    if lo > hi {
        return Truth::default();
    }
    let f = |t: f64| exact_value(solid, ray, t);
    let inside = |t: f64| f(t) >= 0.0;
    let h = (hi - lo) / samples as f64;
    let mut truth = Truth::default();
    let mut prev = lo;
    for k in 0..=samples {
        let t = if k == samples { hi } else { lo + h * k as f64 };
        if inside(t) {
            // Bisect (prev, t] down to adjacent floats: the crossing.
            let start = if k == 0 || inside(prev) {
                t
            } else {
                let (mut a, mut b) = (prev, t);
                loop {
                    let m = a + 0.5 * (b - a);
                    if m <= a || m >= b {
                        break b;
                    }
                    if inside(m) { b = m } else { a = m }
                }
            };
            truth.first.get_or_insert(start);
            // A span at least ε long: inside at five points across [start, start + ε].
            if (0..=4).all(|j| inside(start + 0.25 * f64::from(j) * eps)) {
                truth.first_long = Some(start);
                break;
            }
        }
        prev = t;
    }
    truth
}

/// Whether `t` lies in the loose set: the program's upper bound at `t` (each leaf's exact value
/// plus its widening and `δ(t)`, boxes grown by their rounding) is `≥ 0`.
pub fn loose_at(solid: &Solid, ray: &Ray, widenings: &[f64], t: f64) -> bool {
    let boxes: Vec<Option<(f64, f64)>> = solid
        .leaves()
        .iter()
        .map(|l| box_interval(&l.bounds(), ray).map(|(a, b)| (a.to_f64(), b.to_f64())))
        .collect();
    program(solid, |i, l| {
        let (v, d) = leaf_value(l, ray, t);
        let r = widenings[i] + d;
        let (mut lo, mut hi) = (v - r, v + r);
        if l.clips() {
            let inside = |level: f64| {
                boxes[i].is_some_and(|(b0, b1)| {
                    t >= b0 + level * FACE * b0.abs() && t <= b1 - level * FACE * b1.abs()
                })
            };
            if !inside(1.0) {
                lo = f64::NEG_INFINITY;
            }
            if !inside(-1.0) {
                hi = f64::NEG_INFINITY;
            }
        }
        (lo, hi)
    })
    .1 >= 0.0
}

/// The program over per-leaf `(lower, upper)` bounds.
fn program(solid: &Solid, mut leaf: impl FnMut(usize, &FreeForm) -> (f64, f64)) -> (f64, f64) {
    let mut stack: Vec<(f64, f64)> = Vec::new();
    for op in solid.program() {
        match *op {
            CsgOp::Leaf(i) => stack.push(leaf(i as usize, &solid.leaves()[i as usize])),
            CsgOp::Neg => {
                let (lo, hi) = stack.pop().expect("operand");
                stack.push((-hi, -lo));
            }
            CsgOp::Max | CsgOp::Min => {
                let b = stack.pop().expect("operand");
                let a = stack.pop().expect("operand");
                stack.push(if *op == CsgOp::Max {
                    (a.0.max(b.0), a.1.max(b.1))
                } else {
                    (a.0.min(b.0), a.1.min(b.1))
                });
            }
        }
    }
    stack.pop().expect("a program")
}

/// A leaf's exact value `F′(t)` (double-double, rounded) and the bound `δ(t)` on the rounding
/// of one f64 evaluation of it (without its box).
pub fn leaf_value(leaf: &FreeForm, ray: &Ray, t: f64) -> (f64, f64) {
    let base = quadric_on_ray(leaf.base(), ray);
    let mut v = base.q.eval(t);
    let mut terms = Vec::new();
    for p in leaf.perturbations() {
        let q = quadric_on_ray(&p.quadric, ray);
        let qt = q.q.eval(t);
        if !qt.is_negative() && !qt.is_zero() {
            v = v + Dd::from(p.form_factor) * qt * qt * qt;
        }
        terms.push((p.form_factor, qt.to_f64(), q.delta(t)));
    }
    (
        v.to_f64(),
        perturbed_delta(base.delta(t), base.magnitude(t), &terms),
    )
}

/// The rounding bound of a perturbed leaf's f64 value: the base's `δ`, and for each
/// perturbation `f·max(Q, 0)³` with `Q` known to `δ_Q` — `(f, Q, δ_Q)` —
/// `|f| (3 Q̄² δ_Q + 3 Q̄ δ_Q² + δ_Q³ + 4u Q̄³)`, `Q̄ = max(Q, 0) + δ_Q`, where `Q > −δ_Q`
/// (elsewhere both are exactly 0); plus the rounding of the running sum, `n u` of the
/// magnitudes summed.
pub fn perturbed_delta(base_delta: f64, base_magnitude: f64, terms: &[(f64, f64, f64)]) -> f64 {
    let n = terms.len() as f64;
    let mut delta = base_delta;
    let mut sum = base_magnitude;
    for &(f, q, dq) in terms {
        if q <= -dq {
            continue;
        }
        let qb = q.max(0.0) + dq;
        delta += f.abs()
            * (3.0 * qb * qb * dq + 3.0 * qb * dq * dq + dq * dq * dq + 4.0 * U * qb * qb * qb);
        sum += f.abs() * qb * qb * qb;
    }
    delta + n * U * sum
}
