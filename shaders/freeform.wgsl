// freeform.wgsl — ray casting of free-form solids (quadrics + perturbations + CSG) by binary
// search along a ray: the f32 twin of fray-geometry's RayCaster, with its rules — a clipped
// leaf's sign pattern at its box faces, the CSG sign-slope rule, monotone segments finished by
// Illinois — and the surface (normal and leaf) at a hit. One rule is the CPU's alone: leaves are
// not widened by their rounding bound, which in f32 (K · 2⁻²⁴ · Φ) would move grazing hits by
// more than the parity bound with the CPU (docs/accuracy.md). No bindings and no entry
// point: the including module declares `solids`, `leaves`, `perturbations` and `indices` (the
// CSG programs, then the frame's work-list index arrays), all camera-relative.
//
// #include "ray.wgsl"
// #include "quadric.wgsl"
// #instantiate "csg.wgsl" { NAME: bound; T: vec4<f32>; PARAMS: lo: f32, hi: f32; ARGS: lo, hi; LEAF: bound_of_word; NEG: bound_neg; COMBINE: bound_combine }
// #instantiate "csg.wgsl" { NAME: value; T: f32; PARAMS: s: f32; ARGS: s; LEAF: value_of_word; NEG: value_neg; COMBINE: value_combine }
// #instantiate "csg.wgsl" { NAME: surface; T: LeafGradient; PARAMS: p: vec3<f32>; ARGS: p; LEAF: surface_of_word; NEG: surface_neg; COMBINE: surface_combine }

override HAS_PERTURBATIONS: bool = true;
override HAS_CSG: bool = true;

// Pending segments of the halving search: one per level plus one. With ε ≥ 2⁻²⁰ · camera
// distance a search has ≲ 22 levels; at the cap a segment is tested directly, like one below ε.
const SEG_STACK: u32 = 32u;
const ILLINOIS_STEPS: u32 = 100u;
// The slope of a segment whose sign changes at most once, from − to + (fray-geometry's
// SIGN_INCREASING), and from + to − (SIGN_DECREASING).
const SIGN_INCREASING: vec2<f32> = vec2<f32>(1.0e-30, 1.0e30);
const SIGN_DECREASING: vec2<f32> = vec2<f32>(-1.0e30, -1.0e-30);

// Which parts of a solid a cast uses: a work-list candidate's (`all` false: active leaves and
// perturbations listed in `indices`, and its pruned program), or all of them.
struct Parts {
    leaf_start: u32,
    leaf_count: u32,
    pert_start: u32,
    pert_count: u32,
    // (first word, length) of the program in `indices`.
    program: vec2<u32>,
    all: bool,
}

// One leaf restricted to the current ray (in the solid's shifted parameter s = t − t0).
struct LeafRay {
    lo: f32,
    hi: f32,
    present: bool,
    clips: bool,
    base: vec3<f32>,
    p0: u32,
    p1: u32,
}

var<private> leaf_ray: array<LeafRay, MAX_LEAVES>;
// (a, b, c, form factor) of each perturbation kept for the current ray.
var<private> pert_ray: array<vec4<f32>, MAX_PERTURBATIONS>;
var<private> bound_evals: u32;
var<private> point_evals: u32;
// The first leaf of the solid being cast (program words name global leaves).
var<private> cast_first_leaf: u32;

// ---- one solid along one ray ---------------------------------------------------------------

// Keeps perturbation `k` (global index) for the ray if it has a factor and its support meets the
// ray over [lo, hi]; returns the new count of kept perturbations.
fn keep_perturbation(k: u32, o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, np: u32) -> u32 {
    let p = perturbations[k];
    let q = q_on_ray(p.quadric, o, d);
    if p.form_factor != 0.0 && qr_range(q, lo, hi).y > 0.0 {
        pert_ray[np] = vec4<f32>(q, p.form_factor);
        return np + 1u;
    }
    return np;
}

// Restricts the leaves of solid `si` in `parts` to the ray o + s d, s ∈ [0, hi] (leaves left
// out are absent, perturbations left out are skipped); false if no leaf is reached.
fn prepare(si: u32, parts: Parts, o: vec3<f32>, d: vec3<f32>, hi: f32) -> bool {
    let solid = solids[si];
    // Object-wide perturbation k is global perturbation `first_pert + k`.
    let first_pert = leaves[solid.first_leaf].first_perturbation;
    var any = false;
    var np = 0u;
    var next_leaf = 0u;
    var next_pert = 0u;
    for (var i = 0u; i < solid.leaf_count; i++) {
        let leaf = leaves[solid.first_leaf + i];
        var in_parts = parts.all;
        if !parts.all && next_leaf < parts.leaf_count
            && indices[parts.leaf_start + next_leaf] == i {
            in_parts = true;
            next_leaf++;
        }
        var present = vec2<f32>(1.0, -1.0);
        if in_parts {
            present = clip_box(leaf.box_min.xyz, leaf.box_max.xyz, o, d, 0.0, hi);
        }
        var lr: LeafRay;
        lr.present = present.x <= present.y;
        lr.lo = present.x;
        lr.hi = present.y;
        lr.clips = leaf.clips != 0u;
        lr.p0 = np;
        if lr.present {
            // Read only for present leaves.
            lr.base = q_on_ray(leaf.base, o, d);
            if HAS_PERTURBATIONS {
                if parts.all {
                    for (var k = leaf.first_perturbation; k < leaf.end_perturbation; k++) {
                        np = keep_perturbation(k, o, d, present.x, present.y, np);
                    }
                } else {
                    // The active list is increasing: skip earlier leaves' entries, take this
                    // leaf's.
                    loop {
                        if next_pert >= parts.pert_count {
                            break;
                        }
                        let k = first_pert + indices[parts.pert_start + next_pert];
                        if k >= leaf.end_perturbation {
                            break;
                        }
                        if k >= leaf.first_perturbation {
                            np = keep_perturbation(k, o, d, present.x, present.y, np);
                        }
                        next_pert++;
                    }
                }
            }
        }
        any = any || lr.present;
        lr.p1 = np;
        leaf_ray[i] = lr;
    }
    return any;
}

const ABSENT: vec4<f32> = vec4<f32>(-BIG, -BIG, 0.0, 0.0);

// (value lo, value hi, slope lo, slope hi) of leaf `i` (solid-local) over [lo, hi]
// (fray-geometry's leaf_bound).
fn leaf_bound(i: u32, lo: f32, hi: f32) -> vec4<f32> {
    let lr = leaf_ray[i];
    if !lr.present || hi < lr.lo || lo > lr.hi {
        return ABSENT;
    }
    var ilo = lo;
    var ihi = hi;
    if lr.clips {
        ilo = max(lo, lr.lo);
        ihi = min(hi, lr.hi);
    }
    var value = qr_range(lr.base, ilo, ihi);
    var slope = qr_slope(lr.base, ilo, ihi);
    if HAS_PERTURBATIONS {
        for (var k = lr.p0; k < lr.p1; k++) {
            let p = pert_ray[k];
            let qr = max(qr_range(p.xyz, ilo, ihi), vec2<f32>(0.0));
            value += i_scale(qr * qr * qr, p.w);
            slope += i_scale(i_mul(qr * qr, qr_slope(p.xyz, ilo, ihi)), 3.0 * p.w);
        }
    }
    if ilo != lo || ihi != hi {
        // Part of the segment is outside the clipping box, where the value is −∞: entering the
        // box increasing or ≥ 0 the sign changes at most once, from − to +; leaving it
        // decreasing or ≥ 0, at most once from + to −.
        let before = lo < ilo;
        let after = hi > ihi;
        let nonnegative = value.x >= 0.0;
        if before && !after && (slope.x > 0.0 || nonnegative) {
            slope = SIGN_INCREASING;
        } else if after && !before && (slope.y < 0.0 || nonnegative) {
            slope = SIGN_DECREASING;
        } else {
            slope = vec2<f32>(-BIG, BIG);
        }
        value.x = -BIG;
    }
    return vec4<f32>(value, slope);
}

fn leaf_value(i: u32, s: f32) -> f32 {
    let lr = leaf_ray[i];
    if !lr.present || s < lr.lo || s > lr.hi {
        return -BIG;
    }
    var v = qr_eval(lr.base, s);
    if HAS_PERTURBATIONS {
        for (var k = lr.p0; k < lr.p1; k++) {
            let p = pert_ray[k];
            let q = qr_eval(p.xyz, s);
            if q > 0.0 {
                v += p.w * q * q * q;
            }
        }
    }
    return v;
}

// ---- the algebras of the CSG evaluator (csg.wgsl) ------------------------------------------

fn bound_of_word(word: u32, lo: f32, hi: f32) -> vec4<f32> {
    return leaf_bound((word >> OP_BITS) - cast_first_leaf, lo, hi);
}

fn bound_neg(v: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(-v.y, -v.x, -v.w, -v.z);
}

// max (`is_max`) or min of two bounds: an operand that dominates over the whole segment is the
// result; else the value range of max/min and the sign-slope rule (fray-geometry's
// combine_bounds and sign_slope): an operand whose sign is fixed so that it cannot decide
// (< 0 under max, ≥ 0 under min) leaves the other's slope.
fn bound_combine(is_max: bool, a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    var a_wins: bool;
    var b_wins: bool;
    var b_idle: bool;
    var a_idle: bool;
    if is_max {
        a_wins = a.x >= b.y;
        b_wins = b.x >= a.y;
        b_idle = b.y < 0.0;
        a_idle = a.y < 0.0;
    } else {
        a_wins = a.y <= b.x;
        b_wins = b.y <= a.x;
        b_idle = b.x >= 0.0;
        a_idle = a.x >= 0.0;
    }
    if a_wins {
        return a;
    }
    if b_wins {
        return b;
    }
    var slope: vec2<f32>;
    if b_idle {
        slope = a.zw;
    } else if a_idle {
        slope = b.zw;
    } else {
        slope = vec2<f32>(min(a.z, b.z), max(a.w, b.w));
    }
    if is_max {
        return vec4<f32>(max(a.x, b.x), max(a.y, b.y), slope);
    }
    return vec4<f32>(min(a.x, b.x), min(a.y, b.y), slope);
}

fn value_of_word(word: u32, s: f32) -> f32 {
    return leaf_value((word >> OP_BITS) - cast_first_leaf, s);
}

fn value_neg(v: f32) -> f32 {
    return -v;
}

fn value_combine(is_max: bool, a: f32, b: f32) -> f32 {
    if is_max {
        return max(a, b);
    }
    return min(a, b);
}

// A leaf's value and gradient at a point (xyz gradient, w value) and the leaf (global index).
struct LeafGradient {
    g: vec4<f32>,
    leaf: u32,
}

fn surface_of_word(word: u32, p: vec3<f32>) -> LeafGradient {
    var r: LeafGradient;
    r.leaf = word >> OP_BITS;
    r.g = leaf_value_gradient(r.leaf, p);
    return r;
}

fn surface_neg(v: LeafGradient) -> LeafGradient {
    var r = v;
    r.g = -v.g;
    return r;
}

// The operand that is active (Solid::surface_at: `a` wins ties).
fn surface_combine(is_max: bool, a: LeafGradient, b: LeafGradient) -> LeafGradient {
    var take_a: bool;
    if is_max {
        take_a = a.g.w >= b.g.w;
    } else {
        take_a = a.g.w <= b.g.w;
    }
    if take_a {
        return a;
    }
    return b;
}

// ---- the search ----------------------------------------------------------------------------

// The program of the solid being cast: (first word, length) in `indices`.
var<private> cast_program: vec2<u32>;
// The search's any-hit form (shadow rays, `occluded_by_solids`): any point proven inside ends it
// (fray-geometry's `search::<_, true>`).
var<private> search_any: bool;

fn solid_bound(lo: f32, hi: f32) -> vec4<f32> {
    bound_evals++;
    if !HAS_CSG {
        return leaf_bound(0u, lo, hi);
    }
    return csg_bound(cast_program.x, cast_program.y, lo, hi);
}

fn solid_value(s: f32) -> f32 {
    point_evals++;
    if !HAS_CSG {
        return leaf_value(0u, s);
    }
    return csg_value(cast_program.x, cast_program.y, s);
}

// Illinois regula falsi on f(a) < 0 ≤ f(b) with a single root; a point ≥ the root within eps
// (fray_core::root::illinois).
fn illinois(a_in: f32, fa_in: f32, b_in: f32, fb_in: f32, eps: f32) -> f32 {
    var a = a_in;
    var fa = fa_in;
    var b = b_in;
    var fb = fb_in;
    var last_side = 0;
    var width_before = b - a;
    for (var iteration = 0u; iteration < ILLINOIS_STEPS; iteration++) {
        if b - a <= eps || fb == 0.0 {
            break;
        }
        var c = b - fb * (b - a) / (fb - fa);
        // Windows of four steps: the fourth bisects unless the first three halved the bracket.
        if iteration % 4u == 0u {
            width_before = b - a;
        } else if iteration % 4u == 3u && b - a > 0.5 * width_before {
            c = a + 0.5 * (b - a);
        }
        if !(c > a && c < b) {
            c = a + 0.5 * (b - a);
            if !(c > a && c < b) {
                break;
            }
        }
        let fc = solid_value(c);
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
    return b;
}

// The first s in [lo, hi] with F′ ≥ 0 (to within eps), or NO_HIT: RayCaster's search.
fn search(lo: f32, hi: f32, eps: f32) -> f32 {
    var segments: array<vec2<f32>, SEG_STACK>;
    segments[0] = vec2<f32>(lo, hi);
    var n = 1u;
    var first = true;
    loop {
        if n == 0u {
            return NO_HIT;
        }
        n--;
        let a = segments[n].x;
        let b = segments[n].y;
        let bound = solid_bound(a, b);
        if bound.y < 0.0 {
            continue;
        }
        if first {
            // The range may start inside the solid: then the answer is its start.
            first = false;
            if solid_value(a) >= 0.0 {
                return a;
            }
        }
        if bound.x >= 0.0 {
            return a;
        }
        if bound.z > 0.0 {
            let fb = solid_value(b);
            if fb < 0.0 {
                continue;
            }
            if search_any {
                return b;
            }
            let fa = solid_value(a);
            if fa >= 0.0 {
                return a;
            }
            return illinois(a, fa, b, fb, eps);
        }
        if bound.w < 0.0 {
            if solid_value(a) >= 0.0 {
                return a;
            }
            continue;
        }
        let m = a + 0.5 * (b - a);
        if b - a <= eps || m <= a || m >= b || n + 2u > SEG_STACK {
            if solid_value(m) >= 0.0 {
                return m;
            }
            if solid_value(b) >= 0.0 {
                return b;
            }
            continue;
        }
        if search_any && solid_value(m) >= 0.0 {
            return m;
        }
        segments[n] = vec2<f32>(m, b);
        segments[n + 1u] = vec2<f32>(a, m);
        n += 2u;
    }
    return NO_HIT;
}

// The first t in [lo, hi] where solid `si` (its `parts`) is non-negative, or NO_HIT. The search
// runs in s = t − t0 from the solid's box entry t0, which keeps the quadratics well conditioned.
fn cast_solid(si: u32, parts: Parts, o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, eps: f32) -> f32 {
    let solid = solids[si];
    let range = clip_box(solid.box_min.xyz, solid.box_max.xyz, o, d, lo, hi);
    if range.x > range.y {
        return NO_HIT;
    }
    let t0 = range.x;
    let os = o + d * t0;
    let end = range.y - t0;
    if !prepare(si, parts, os, d, end) {
        return NO_HIT;
    }
    cast_program = parts.program;
    cast_first_leaf = solid.first_leaf;
    let s = search(0.0, end, eps);
    if s < 0.0 {
        return NO_HIT;
    }
    return t0 + s;
}

// Every part of solid `si`, with its whole program.
fn all_parts(si: u32) -> Parts {
    var parts: Parts;
    parts.all = true;
    let solid = solids[si];
    parts.program = vec2<u32>(solid.first_word, solid.word_count);
    return parts;
}

// Whether any of the first `count` solids lies on the ray within [lo, hi] (shadow rays: whole
// solids over [0, distance], the search's any-hit form).
fn occluded_by_solids(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, eps: f32, count: u32) -> bool {
    search_any = true;
    var blocked = false;
    for (var si = 0u; si < count; si++) {
        if cast_solid(si, all_parts(si), o, d, lo, hi, eps) >= 0.0 {
            blocked = true;
            break;
        }
    }
    search_any = false;
    return blocked;
}

// ---- surface -------------------------------------------------------------------------------

// Value and gradient of leaf `li` (global index) at p (FreeForm::eval_with_gradient): a clipping
// box's face where it is nearer than the surface decides.
fn leaf_value_gradient(li: u32, p: vec3<f32>) -> vec4<f32> {
    let leaf = leaves[li];
    var f = q_eval_local(leaf.base, p - leaf.base.origin.xyz);
    var g = q_gradient(leaf.base, p);
    if HAS_PERTURBATIONS {
        for (var k = leaf.first_perturbation; k < leaf.end_perturbation; k++) {
            let pq = perturbations[k];
            let q = q_eval_local(pq.quadric, p - pq.quadric.origin.xyz);
            if q > 0.0 {
                f += pq.form_factor * q * q * q;
                g += q_gradient(pq.quadric, p) * (3.0 * pq.form_factor * q * q);
            }
        }
    }
    if leaf.clips != 0u {
        var best = BIG;
        var n = vec3<f32>(1.0, 0.0, 0.0);
        for (var axis = 0u; axis < 3u; axis++) {
            let lo_d = p[axis] - leaf.box_min[axis];
            let hi_d = leaf.box_max[axis] - p[axis];
            if lo_d < best {
                best = lo_d;
                n = vec3<f32>(0.0);
                n[axis] = -1.0;
            }
            if hi_d < best {
                best = hi_d;
                n = vec3<f32>(0.0);
                n[axis] = 1.0;
            }
        }
        if best < f {
            return vec4<f32>(-n, best);
        }
    }
    return vec4<f32>(g, f);
}

struct Surface {
    normal: vec3<f32>,
    leaf: u32,
}

// Outward unit normal and the active leaf (global index) at p (Solid::surface_at).
fn surface_at(si: u32, p: vec3<f32>, fallback: vec3<f32>) -> Surface {
    let solid = solids[si];
    var deciding: LeafGradient;
    if !HAS_CSG {
        deciding = surface_of_word(solid.first_leaf << OP_BITS, p);
    } else {
        deciding = csg_surface(solid.first_word, solid.word_count, p);
    }
    var s: Surface;
    s.leaf = deciding.leaf;
    let g = deciding.g.xyz;
    let len = length(g);
    if len > 0.0 && len < BIG {
        s.normal = -g / len;
    } else {
        s.normal = fallback;
    }
    return s;
}
