// freeform.wgsl — ray casting of free-form solids (quadrics + perturbations + CSG) by binary
// search along each ray, with shading and shadow rays: the GPU twin of fray-geometry's RayCaster
// and fray-trace's shading. f32, every position relative to the camera (eye).
//
// One workgroup per quadtree work item (fray-gpu `work`): its invocations cover the item's tile,
// and each primary ray is cast only against the item's candidate objects, with their active
// leaves and perturbations and their pruned CSG programs (fray-geometry `ActiveSet`). Pixels no
// item covers are culled: nothing runs for them. Shadow rays and normals use whole solids.
//
// The structs, op codes and array sizes come from a Rust-generated prelude (fray-gpu
// `shader::prelude`), never written here. Specialisation by `override` constants: features the
// scene does not use fold away when the pipeline is built.

override HAS_PERTURBATIONS: bool = true;
override HAS_CSG: bool = true;
override SHADOWS: bool = true;
override HAS_SUN: bool = true;
override HAS_POINT: bool = true;
override PROJECTOR: u32 = 0u;
// The scene's terrains (terrain.wgsl's cast_terrain(k, …); without terrain a stub that always
// misses): each listed one cast after the free forms, nearest hit wins (a tie keeps the earlier
// candidate); shadow rays test every terrain.
override HAS_TERRAIN: bool = false;

const BIG: f32 = 1.0e30;
const NO_HIT: f32 = -1.0;
const PI: f32 = 3.14159265358979;
// Pending segments of the halving search: one per level plus one. With ε ≥ 2⁻²⁰ · camera
// distance a search has ≲ 22 levels; at the cap a segment is tested directly, like one below ε.
// (32 rather than 64: the smaller zero-initialised array is ≈ 15 % faster on lavapipe.)
const SEG_STACK: u32 = 32u;
const ILLINOIS_STEPS: u32 = 100u;

@group(0) @binding(0) var<uniform> frame: FrameParams;
@group(0) @binding(1) var<storage, read> solids: array<GpuSolid>;
@group(0) @binding(2) var<storage, read> leaves: array<GpuLeaf>;
@group(0) @binding(3) var<storage, read> perturbations: array<GpuPerturbation>;
@group(0) @binding(4) var<storage, read> program: array<u32>;
@group(0) @binding(5) var<storage, read> lights: array<GpuLight>;
@group(0) @binding(6) var<storage, read> materials: array<GpuMaterial>;
@group(0) @binding(7) var<storage, read_write> output: array<vec4<f32>>;
// Frame totals: hits, shadow rays, then (lo, hi) 64-bit pairs of bound evaluations, point
// evaluations, terrain rays, segments, cells, stops and stop levels.
@group(0) @binding(8) var<storage, read_write> counters: array<atomic<u32>, COUNTER_WORDS>;
// The work list: this dispatch's items, and the frame's candidates, active leaves (solid-local),
// active perturbations (object-wide) and per-candidate (first word, length) in `program`.
@group(0) @binding(9) var<storage, read> items: array<WorkItem>;
@group(0) @binding(10) var<storage, read> candidates: array<Candidate>;
@group(0) @binding(11) var<storage, read> active_leaves: array<u32>;
@group(0) @binding(12) var<storage, read> active_perturbations: array<u32>;
@group(0) @binding(13) var<storage, read> candidate_programs: array<vec2<u32>>;

// Which parts of a solid a cast uses: a work-list candidate's, or all of them (`all`).
struct Parts {
    leaf_start: u32,
    leaf_count: u32,
    pert_start: u32,
    pert_count: u32,
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
// The program of the solid being cast (first word, length) and its first leaf.
var<private> cast_program: vec2<u32>;
var<private> cast_first_leaf: u32;
var<private> point_evals: u32;

// ---- quadrics ----------------------------------------------------------------------------

fn q_eval_local(q: GpuQuadric, x: vec3<f32>) -> f32 {
    return x.x * (q.c0.x * x.x + q.c0.w * x.y + q.c1.x * x.z + q.c1.z)
        + x.y * (q.c0.y * x.y + q.c1.y * x.z + q.c1.w)
        + x.z * (q.c0.z * x.z + q.c2.x)
        + q.c2.y;
}

fn q_gradient(q: GpuQuadric, p: vec3<f32>) -> vec3<f32> {
    let x = p - q.origin.xyz;
    return vec3<f32>(
        2.0 * q.c0.x * x.x + q.c0.w * x.y + q.c1.x * x.z + q.c1.z,
        2.0 * q.c0.y * x.y + q.c0.w * x.x + q.c1.y * x.z + q.c1.w,
        2.0 * q.c0.z * x.z + q.c1.x * x.x + q.c1.y * x.y + q.c2.x,
    );
}

// The quadratic (a, b, c) in t of q along o + t d.
fn q_on_ray(q: GpuQuadric, ro: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let o = ro - q.origin.xyz;
    let a11 = q.c0.x; let a22 = q.c0.y; let a33 = q.c0.z; let a12 = q.c0.w;
    let a13 = q.c1.x; let a23 = q.c1.y; let a14 = q.c1.z; let a24 = q.c1.w;
    let a34 = q.c2.x;
    let a = d.x * (a11 * d.x + a12 * d.y + a13 * d.z) + d.y * (a22 * d.y + a23 * d.z) + a33 * d.z * d.z;
    let b = 2.0 * (a11 * o.x * d.x + a22 * o.y * d.y + a33 * o.z * d.z)
        + a12 * (o.x * d.y + o.y * d.x)
        + a13 * (o.x * d.z + o.z * d.x)
        + a23 * (o.y * d.z + o.z * d.y)
        + a14 * d.x + a24 * d.y + a34 * d.z;
    return vec3<f32>(a, b, q_eval_local(q, o));
}

fn qr_eval(q: vec3<f32>, t: f32) -> f32 {
    return (q.x * t + q.y) * t + q.z;
}

// Exact range of a quadratic over [lo, hi].
fn qr_range(q: vec3<f32>, lo: f32, hi: f32) -> vec2<f32> {
    let f0 = qr_eval(q, lo);
    let f1 = qr_eval(q, hi);
    var r = vec2<f32>(min(f0, f1), max(f0, f1));
    if q.x != 0.0 {
        let v = -q.y / (2.0 * q.x);
        if v > lo && v < hi {
            let fv = qr_eval(q, v);
            r = vec2<f32>(min(r.x, fv), max(r.y, fv));
        }
    }
    return r;
}

fn qr_slope(q: vec3<f32>, lo: f32, hi: f32) -> vec2<f32> {
    let d0 = 2.0 * q.x * lo + q.y;
    let d1 = 2.0 * q.x * hi + q.y;
    return vec2<f32>(min(d0, d1), max(d0, d1));
}

// ---- intervals (x = lo, y = hi) ------------------------------------------------------------

fn i_scale(x: vec2<f32>, k: f32) -> vec2<f32> {
    if k >= 0.0 {
        return x * k;
    }
    return vec2<f32>(x.y * k, x.x * k);
}

fn i_mul(x: vec2<f32>, y: vec2<f32>) -> vec2<f32> {
    let a = x.x * y.x;
    let b = x.x * y.y;
    let c = x.y * y.x;
    let d = x.y * y.y;
    return vec2<f32>(min(min(a, b), min(c, d)), max(max(a, b), max(c, d)));
}

// ---- rays and boxes ------------------------------------------------------------------------

// The part of [lo, hi] where o + t d is inside the box; x > y when empty.
fn clip_box(bmin: vec3<f32>, bmax: vec3<f32>, o: vec3<f32>, d: vec3<f32>, lo_in: f32, hi_in: f32) -> vec2<f32> {
    var lo = lo_in;
    var hi = hi_in;
    for (var axis = 0u; axis < 3u; axis++) {
        if d[axis] == 0.0 {
            if o[axis] < bmin[axis] || o[axis] > bmax[axis] {
                return vec2<f32>(1.0, -1.0);
            }
            continue;
        }
        let inv = 1.0 / d[axis];
        var t0 = (bmin[axis] - o[axis]) * inv;
        var t1 = (bmax[axis] - o[axis]) * inv;
        if t0 > t1 {
            let s = t0;
            t0 = t1;
            t1 = s;
        }
        lo = max(lo, t0);
        hi = min(hi, t1);
        if lo > hi {
            return vec2<f32>(1.0, -1.0);
        }
    }
    return vec2<f32>(lo, hi);
}

struct CameraRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
    t_near: f32,
    ok: bool,
}

// The projector's ray through the centre of pixel (px, py): fray_core::Projector::pixel_ray.
fn camera_ray(px: u32, py: u32) -> CameraRay {
    let w = f32(max(frame.size.x, 1u));
    let h = f32(max(frame.size.y, 1u));
    let x = f32(px) + 0.5;
    let y = f32(py) + 0.5;
    let aspect = w / h;
    let sx = (2.0 * x / w - 1.0) * aspect;
    let sy = 1.0 - 2.0 * y / h;
    let forward = frame.forward.xyz;
    let right = frame.right.xyz;
    let up = frame.up.xyz;
    var c = vec3<f32>(0.0);
    var d = vec3<f32>(0.0);
    var r: CameraRay;
    if PROJECTOR == PROJECTOR_PINHOLE {
        let k = frame.forward.w;
        d = (forward + right * (sx * k) + up * (sy * k)) * frame.right.w;
    } else if PROJECTOR == PROJECTOR_PARALLEL {
        let half = frame.forward.w;
        c = right * (sx * half) + up * (sy * half);
        if frame.right.w == 0.0 {
            r.origin = c;
            r.dir = forward;
            r.t_near = 0.0;
            r.ok = true;
            return r;
        }
        d = forward * frame.right.w;
    } else {
        let theta = 0.5 * frame.sphere.x * (2.0 * x / w - 1.0);
        let phi = 0.5 * frame.sphere.y * sy;
        let dir = forward * (cos(phi) * cos(theta)) + right * (cos(phi) * sin(theta)) + up * sin(phi);
        let radius = frame.centre.w
            * (1.0 + frame.sphere.z * cos(frame.sphere.w * theta) * cos(frame.sphere.w * phi));
        d = frame.centre.xyz + dir * radius;
    }
    let len = length(d);
    r.origin = c;
    r.ok = len > 0.0;
    r.dir = d / max(len, 1e-30);
    r.t_near = len;
    return r;
}

// ---- one solid along one ray ---------------------------------------------------------------

// Keeps perturbation `k` (global index) for the ray if it has a factor and its support meets the
// ray over [lo, hi]; returns the new count of kept perturbations.
fn keep_perturbation(k: u32, o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, np: u32) -> u32 {
    let p = perturbations[k];
    let q = q_on_ray(p.quadric, o, d);
    if p.params.x != 0.0 && qr_range(q, lo, hi).y > 0.0 {
        pert_ray[np] = vec4<f32>(q, p.params.x);
        return np + 1u;
    }
    return np;
}

// Restricts the leaves of solid `si` in `parts` to the ray o + s d, s ∈ [0, hi] (leaves left
// out are absent, perturbations left out are skipped); false if no leaf is reached.
fn prepare(si: u32, parts: Parts, o: vec3<f32>, d: vec3<f32>, hi: f32) -> bool {
    let info = solids[si].info;
    // Object-wide perturbation k is global perturbation `first_pert + k`.
    let first_pert = leaves[info.x].info.y;
    var any = false;
    var np = 0u;
    var next_leaf = 0u;
    var next_pert = 0u;
    for (var i = 0u; i < info.y; i++) {
        let leaf = leaves[info.x + i];
        var in_parts = parts.all;
        if !parts.all && next_leaf < parts.leaf_count
            && active_leaves[parts.leaf_start + next_leaf] == i {
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
        lr.clips = leaf.info.x != 0u;
        if lr.present {
            // Read only for present leaves.
            lr.base = q_on_ray(leaf.base, o, d);
        }
        lr.p0 = np;
        if HAS_PERTURBATIONS && lr.present {
            if parts.all {
                for (var k = leaf.info.y; k < leaf.info.z; k++) {
                    np = keep_perturbation(k, o, d, present.x, present.y, np);
                }
            } else {
                // The active list is increasing: skip earlier leaves' entries, take this leaf's.
                loop {
                    if next_pert >= parts.pert_count {
                        break;
                    }
                    let k = first_pert + active_perturbations[parts.pert_start + next_pert];
                    if k >= leaf.info.z {
                        break;
                    }
                    if k >= leaf.info.y {
                        np = keep_perturbation(k, o, d, present.x, present.y, np);
                    }
                    next_pert++;
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

// (value lo, value hi, slope lo, slope hi) of leaf `i` over [lo, hi].
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
        value.x = -BIG;
        slope = vec2<f32>(-BIG, BIG);
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

// The bound of the solid being cast (its program `cast_program`) over [lo, hi].
fn solid_bound(lo: f32, hi: f32) -> vec4<f32> {
    bound_evals++;
    if !HAS_CSG {
        return leaf_bound(0u, lo, hi);
    }
    let first = cast_program.x;
    if cast_program.y == 1u {
        return leaf_bound((program[first] >> OP_BITS) - cast_first_leaf, lo, hi);
    }
    var stack: array<vec4<f32>, MAX_STACK>;
    var top = 0u;
    for (var w = first; w < first + cast_program.y; w++) {
        let word = program[w];
        let op = word & ((1u << OP_BITS) - 1u);
        if op == OP_LEAF {
            stack[top] = leaf_bound((word >> OP_BITS) - cast_first_leaf, lo, hi);
            top++;
        } else if op == OP_NEG {
            let v = stack[top - 1u];
            stack[top - 1u] = vec4<f32>(-v.y, -v.x, -v.w, -v.z);
        } else {
            let b = stack[top - 1u];
            let a = stack[top - 2u];
            top--;
            let is_max = op == OP_MAX;
            var a_wins: bool;
            var b_wins: bool;
            if is_max {
                a_wins = a.x >= b.y;
                b_wins = b.x >= a.y;
            } else {
                a_wins = a.y <= b.x;
                b_wins = b.y <= a.x;
            }
            var r: vec4<f32>;
            if a_wins {
                r = a;
            } else if b_wins {
                r = b;
            } else {
                let slope = vec2<f32>(min(a.z, b.z), max(a.w, b.w));
                if is_max {
                    r = vec4<f32>(max(a.x, b.x), max(a.y, b.y), slope);
                } else {
                    r = vec4<f32>(min(a.x, b.x), min(a.y, b.y), slope);
                }
            }
            stack[top - 1u] = r;
        }
    }
    return stack[0];
}

// The value of the solid being cast at s.
fn solid_value(s: f32) -> f32 {
    point_evals++;
    if !HAS_CSG {
        return leaf_value(0u, s);
    }
    let first = cast_program.x;
    if cast_program.y == 1u {
        return leaf_value((program[first] >> OP_BITS) - cast_first_leaf, s);
    }
    var stack: array<f32, MAX_STACK>;
    var top = 0u;
    for (var w = first; w < first + cast_program.y; w++) {
        let word = program[w];
        let op = word & ((1u << OP_BITS) - 1u);
        if op == OP_LEAF {
            stack[top] = leaf_value((word >> OP_BITS) - cast_first_leaf, s);
            top++;
        } else if op == OP_NEG {
            stack[top - 1u] = -stack[top - 1u];
        } else {
            let b = stack[top - 1u];
            let a = stack[top - 2u];
            top--;
            if op == OP_MAX {
                stack[top - 1u] = max(a, b);
            } else {
                stack[top - 1u] = min(a, b);
            }
        }
    }
    return stack[0];
}

// Illinois regula falsi on f(a) < 0 ≤ f(b) with a single root; a point ≥ the root within eps.
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
        // Windows of four steps (fray_core::root::illinois): the fourth bisects unless the first
        // three halved the bracket.
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

// The first s in [lo, hi] with F′ ≥ 0 (to within eps), or NO_HIT: RayCaster::search.
fn search(lo: f32, hi: f32, eps: f32) -> f32 {
    if solid_value(lo) >= 0.0 {
        return lo;
    }
    var segments: array<vec2<f32>, SEG_STACK>;
    segments[0] = vec2<f32>(lo, hi);
    var n = 1u;
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
        if bound.x >= 0.0 {
            return a;
        }
        if bound.z > 0.0 {
            let fb = solid_value(b);
            if fb < 0.0 {
                continue;
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
        segments[n] = vec2<f32>(m, b);
        segments[n + 1u] = vec2<f32>(a, m);
        n += 2u;
    }
    return NO_HIT;
}

// The first t in [lo, hi] where solid `si` is non-negative, or NO_HIT. The search runs in
// s = t − t0 from the solid's box entry t0, which keeps the quadratics well conditioned in f32.
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
    cast_first_leaf = solid.info.x;
    let s = search(0.0, end, eps);
    if s < 0.0 {
        return NO_HIT;
    }
    return t0 + s;
}

// ---- surface -------------------------------------------------------------------------------

// Value and gradient of leaf `li` (global index) at p: FreeForm::eval_with_gradient.
fn leaf_value_gradient(li: u32, p: vec3<f32>) -> vec4<f32> {
    let leaf = leaves[li];
    var f = q_eval_local(leaf.base, p - leaf.base.origin.xyz);
    var g = q_gradient(leaf.base, p);
    if HAS_PERTURBATIONS {
        for (var k = leaf.info.y; k < leaf.info.z; k++) {
            let pq = perturbations[k];
            let q = q_eval_local(pq.quadric, p - pq.quadric.origin.xyz);
            if q > 0.0 {
                f += pq.params.x * q * q * q;
                g += q_gradient(pq.quadric, p) * (3.0 * pq.params.x * q * q);
            }
        }
    }
    if leaf.info.x != 0u {
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

// Outward unit normal and the active leaf (global index) at p: Solid::surface_at.
fn surface_at(si: u32, p: vec3<f32>, fallback: vec3<f32>) -> Surface {
    let info = solids[si].info;
    var g: vec3<f32>;
    var leaf = info.x;
    if !HAS_CSG || info.w == 1u {
        g = leaf_value_gradient(info.x, p).xyz;
    } else {
        var vals: array<vec4<f32>, MAX_STACK>;
        var ids: array<u32, MAX_STACK>;
        var top = 0u;
        for (var w = info.z; w < info.z + info.w; w++) {
            let word = program[w];
            let op = word & ((1u << OP_BITS) - 1u);
            if op == OP_LEAF {
                let li = word >> OP_BITS;
                vals[top] = leaf_value_gradient(li, p);
                ids[top] = li;
                top++;
            } else if op == OP_NEG {
                vals[top - 1u] = -vals[top - 1u];
            } else {
                let b = vals[top - 1u];
                let a = vals[top - 2u];
                let bid = ids[top - 1u];
                top--;
                var take_a: bool;
                if op == OP_MAX {
                    take_a = a.w >= b.w;
                } else {
                    take_a = a.w <= b.w;
                }
                if !take_a {
                    vals[top - 1u] = b;
                    ids[top - 1u] = bid;
                }
            }
        }
        g = vals[0].xyz;
        leaf = ids[0];
    }
    var s: Surface;
    s.leaf = leaf;
    let len = length(g);
    if len > 0.0 && len < BIG {
        s.normal = -g / len;
    } else {
        s.normal = fallback;
    }
    return s;
}

// ---- scene ---------------------------------------------------------------------------------

struct Hit {
    t: f32,
    // The solid hit, or for a terrain hit the terrain's index k (its candidate's `object`).
    solid: u32,
    // A terrain hit (its shading normal below); else solid `solid`.
    terrain: bool,
    normal: vec3<f32>,
}

// Every part of solid `si`, with its whole program.
fn all_parts(si: u32) -> Parts {
    var parts: Parts;
    parts.all = true;
    parts.program = solids[si].info.zw;
    return parts;
}

// The nearest hit over the candidates of `item` (objects in increasing order, each with its
// active parts; on a tie the earlier object keeps the hit), then the terrains the item lists.
fn nearest_hit(item: WorkItem, o: vec3<f32>, d: vec3<f32>, lo: f32, eps: f32) -> Hit {
    var best: Hit;
    best.t = NO_HIT;
    var hi = BIG;
    let end = item.candidate_start + item.candidate_count;
    for (var c = item.candidate_start; c < end; c++) {
        let cand = candidates[c];
        if cand.kind == KIND_TERRAIN {
            // A terrain: cast after the free forms.
            continue;
        }
        var parts: Parts;
        parts.all = false;
        parts.leaf_start = cand.leaf_start;
        parts.leaf_count = cand.leaf_count;
        parts.pert_start = cand.perturbation_start;
        parts.pert_count = cand.perturbation_count;
        parts.program = candidate_programs[c];
        let si = cand.object;
        let t = cast_solid(si, parts, o, d, lo, hi, eps);
        if t >= 0.0 && (best.t < 0.0 || t < best.t) {
            hi = t;
            best.t = t;
            best.solid = si;
        }
    }
    if HAS_TERRAIN {
        // The listed terrains k, in list order, each over [lo, best so far]: nearer hits only,
        // a tie keeps the earlier (fray-trace's terrain pass).
        for (var c = item.candidate_start; c < end; c++) {
            if candidates[c].kind != KIND_TERRAIN {
                continue;
            }
            let k = candidates[c].object;
            let th = cast_terrain(k, o, d, lo, select(BIG, best.t, best.t >= 0.0), eps, true);
            if th.t >= 0.0 && (best.t < 0.0 || th.t < best.t) {
                best.t = th.t;
                best.solid = k;
                best.terrain = true;
                best.normal = terrain_shading_normal(k, o, d, th);
            }
        }
    }
    return best;
}

fn occluded(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    for (var si = 0u; si < frame.size.w; si++) {
        if cast_solid(si, all_parts(si), o, d, 0.0, distance, eps) >= 0.0 {
            return true;
        }
    }
    if HAS_TERRAIN {
        for (var k = 0u; k < terrain_count(); k++) {
            if cast_terrain(k, o, d, 0.0, distance, eps, false).t >= 0.0 {
                return true;
            }
        }
    }
    return false;
}

var<private> shadow_rays: u32;

// Ambient + Lambert (albedo/π) + normalised Phong with hard shadows: fray-trace's shading.
fn radiance(p: vec3<f32>, n: vec3<f32>, to_viewer: vec3<f32>, m: GpuMaterial, eps: f32) -> vec3<f32> {
    var total = m.ambient.xyz * frame.ambient.xyz;
    let diffuse = m.diffuse.xyz / PI;
    let specular = m.specular.xyz;
    let shininess = m.specular.w;
    let specular_on = any(specular != vec3<f32>(0.0));
    let lobe_norm = (shininess + 2.0) / (2.0 * PI);
    for (var i = 0u; i < frame.mode.y; i++) {
        let light = lights[i];
        var to_light: vec3<f32>;
        var irradiance: vec3<f32>;
        var distance: f32;
        if light.kind.x == LIGHT_SUN {
            if !HAS_SUN {
                continue;
            }
            to_light = light.vector.xyz;
            irradiance = light.colour.xyz;
            distance = BIG;
        } else {
            if !HAS_POINT {
                continue;
            }
            let dl = light.vector.xyz - p;
            let r2 = dot(dl, dl);
            if r2 == 0.0 {
                continue;
            }
            let r = sqrt(r2);
            to_light = dl / r;
            irradiance = light.colour.xyz / r2;
            distance = r;
        }
        let cos_l = dot(n, to_light);
        if cos_l <= 0.0 {
            continue;
        }
        if SHADOWS {
            shadow_rays++;
            if occluded(p + n * frame.shade.x, to_light, distance, eps) {
                continue;
            }
        }
        var brdf = diffuse;
        if specular_on {
            let reflected = n * (2.0 * cos_l) - to_light;
            let rv = max(dot(reflected, to_viewer), 0.0);
            if rv > 0.0 {
                brdf += specular * (lobe_norm * pow(rv, shininess));
            }
        }
        total += brdf * irradiance * cos_l;
    }
    return total;
}

fn add_wide(lo: u32, value: u32) {
    if value == 0u {
        return;
    }
    let old = atomicAdd(&counters[lo], value);
    if old + value < old {
        atomicAdd(&counters[lo + 1u], 1u);
    }
}

// The workgroup's sums of the per-pixel counters (slots COUNT_*, words WORD_* of `counters`:
// generated from fray_gpu::counters; zeroed by the kernel, since the pipeline skips wgpu's
// workgroup zero-fill). Pixels add here and one invocation adds the sums to `counters`: on a
// real GPU, atomics from every pixel to the same few words serialise and cost more than the
// tracing.
var<workgroup> group_counts: array<atomic<u32>, GROUP_COUNTERS>;

// One pixel: camera ray, nearest hit, normal, shading. Writes colour + depth and normal + hit;
// true if it hit.
fn render_pixel(item: WorkItem, px: u32, py: u32, slot: u32) -> bool {
    let eps = frame.up.w;
    let miss_colour = vec4<f32>(frame.background.xyz, -1.0);
    output[2u * slot] = miss_colour;
    output[2u * slot + 1u] = vec4<f32>(0.0);
    let ray = camera_ray(px, py);
    if !ray.ok {
        return false;
    }
    let hit = nearest_hit(item, ray.origin, ray.dir, ray.t_near, eps);
    if hit.t < 0.0 {
        return false;
    }
    let p = ray.origin + ray.dir * hit.t;
    let to_viewer = -ray.dir;
    var normal: vec3<f32>;
    var material: u32;
    if HAS_TERRAIN && hit.terrain {
        normal = hit.normal;
        material = terrain_material(hit.solid);
    } else {
        let surface = surface_at(hit.solid, p, to_viewer);
        normal = surface.normal;
        material = leaves[surface.leaf].info.w;
    }
    if hit.t <= ray.t_near {
        normal = to_viewer;
    }
    var shading_normal = normal;
    if dot(normal, to_viewer) < 0.0 {
        shading_normal = -normal;
    }
    let m = materials[material];
    let colour = radiance(p, shading_normal, to_viewer, m, eps);
    output[2u * slot] = vec4<f32>(colour, hit.t);
    output[2u * slot + 1u] = vec4<f32>(normal, 1.0);
    return true;
}

// One workgroup per work item of this dispatch (`frame.mode.w` of them; a 2D grid of groups when
// there are more than a dimension holds); its TILE_THREADS² invocations are the pixels of the
// tile (tiles are at most TILE_THREADS wide and tall: the work list's cell size).
@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) local_index: u32,
) {
    let k = group.y * groups.x + group.x;
    // Uniform over the workgroup, so the barrier below stays in uniform control flow.
    if k >= frame.mode.w {
        return;
    }
    if local_index < GROUP_COUNTERS {
        atomicStore(&group_counts[local_index], 0u);
    }
    workgroupBarrier();
    let item = items[k];
    bound_evals = 0u;
    point_evals = 0u;
    shadow_rays = 0u;
    let px = item.x0 + local.x;
    let py = item.y0 + local.y;
    if px < item.x1 && py < item.y1 {
        if render_pixel(item, px, py, (py - frame.size.z) * frame.size.x + px) {
            atomicAdd(&group_counts[COUNT_HITS], 1u);
        }
        atomicAdd(&group_counts[COUNT_SHADOW_RAYS], shadow_rays);
        atomicAdd(&group_counts[COUNT_BOUND_EVALUATIONS], bound_evals);
        atomicAdd(&group_counts[COUNT_POINT_EVALUATIONS], point_evals);
        if HAS_TERRAIN {
            atomicAdd(&group_counts[COUNT_TERRAIN_RAYS], terrain_rays);
            atomicAdd(&group_counts[COUNT_TERRAIN_SEGMENTS], terrain_segments);
            atomicAdd(&group_counts[COUNT_TERRAIN_CELLS], terrain_cells);
            atomicAdd(&group_counts[COUNT_TERRAIN_STOPS], terrain_stops);
            atomicAdd(&group_counts[COUNT_TERRAIN_STOP_LEVELS], terrain_stop_levels);
        }
    }
    workgroupBarrier();
    if local_index == 0u {
        // A workgroup's sums fit 32 bits (TILE_THREADS² pixels); the frame's totals are 64-bit pairs.
        let hits = atomicLoad(&group_counts[COUNT_HITS]);
        if hits > 0u {
            atomicAdd(&counters[WORD_HITS], hits);
        }
        let shadows = atomicLoad(&group_counts[COUNT_SHADOW_RAYS]);
        if shadows > 0u {
            atomicAdd(&counters[WORD_SHADOW_RAYS], shadows);
        }
        add_wide(WORD_BOUND_EVALUATIONS, atomicLoad(&group_counts[COUNT_BOUND_EVALUATIONS]));
        add_wide(WORD_POINT_EVALUATIONS, atomicLoad(&group_counts[COUNT_POINT_EVALUATIONS]));
        if HAS_TERRAIN {
            add_wide(WORD_TERRAIN_RAYS, atomicLoad(&group_counts[COUNT_TERRAIN_RAYS]));
            add_wide(WORD_TERRAIN_SEGMENTS, atomicLoad(&group_counts[COUNT_TERRAIN_SEGMENTS]));
            add_wide(WORD_TERRAIN_CELLS, atomicLoad(&group_counts[COUNT_TERRAIN_CELLS]));
            add_wide(WORD_TERRAIN_STOPS, atomicLoad(&group_counts[COUNT_TERRAIN_STOPS]));
            add_wide(
                WORD_TERRAIN_STOP_LEVELS,
                atomicLoad(&group_counts[COUNT_TERRAIN_STOP_LEVELS]),
            );
        }
    }
}
