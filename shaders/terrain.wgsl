// terrain.wgsl — height-map terrain ray casting (docs/methods.md §4), the f32 twin of
// fray_terrain::Terrain::cast_footprint for bilinear patches and uniform cubic B-splines, for any
// number of terrains: terrain `k` is `terrains[k]` (a GpuTerrainParams block declared in Rust,
// fray_terrain::gpu_layout, and prepended), its pyramid and samples at its own offsets in the
// concatenated `pyramid` and `samples` arrays. One invocation per ray: the ray segment clipped to
// the terrain box in map space (u, v, r), halved nearer-first with the footprint level rule
// against the max pyramid (rectangular levels: level k has ⌈cells / 2^(n−k)⌉ columns and rows),
// finest cells intersected exactly (bilinear: a quadratic per cell; bicubic: halving with the
// B-spline's slope bounds, monotone pieces finished by Illinois), or, at a LOD stop level, the
// max-column tops. Every rule is the CPU's, line for line, in f32:
// - the level of a footprint `extent`: `n − ⌈log₂ extent⌉` from the exponent bits (exact at
//   powers of two), for both the segment's level and the pixel stop level;
// - a hit where the ray is already inside a cell's solid (Terrain::entry_hit): a wall (the
//   entry face's normal) where it entered the cell through its side with no solid neighbour
//   there or through the base, the ray's start (normal −dir) where it starts inside, else the
//   patch's normal; LOD column hits likewise (Start, Wall, else the top);
// - the bicubic tolerance: max(ε, 8 ε_f32 (|lo| + |hi|)) (the CPU: 8 ε_f64), which bounds the
//   halving's depth, so its stack is sized by proof and never drops a piece;
// - ties between finest cells go to the later cell, between columns to the earlier;
// - a LOD hit is shaded with the normal of the cell beneath it, inside the column at a wall.
//
// cast_terrain(k, origin, dir, t_lo, t_hi, eps, pixel_lod): camera-relative ray → TerrainHit
// (t < 0 for a miss); `pixel_lod` (camera rays) stops at the pixel footprint level when this
// view's terrain_lods[k].z is set. terrain_shading_normal(k, origin, dir, hit) is
// Terrain::shading_normal (LOD hits shaded with the interpolant's normal beneath, inside the
// column at a wall).

// The module that includes this file binds the terrains group (fray_gpu::bindings::TERRAINS:
// `terrains`, `terrain_lods`, `pyramid`, `samples`). `intersect_terrain.wgsl` casts camera rays,
// `terrain_hooks.wgsl` shadow rays and secondary rays, `terrain_batch.wgsl` ray batches.

// Pending segments of the pyramid search: a segment is split only while its footprint is wider
// than a stop-level cell (≥ 1 finest cell) and a split halves it, so a search has at most
// n + 2 ≤ 17 levels pending (more only where rounding widens every footprint by ≥ ¼ cell, on
// coordinates past 2¹⁸ cells); at the cap a segment is tested at its stop level directly, as the
// CPU does (correct, only slower).
const TERRAIN_STACK: u32 = 48u;
// Pending pieces of the bicubic halving: only pieces wider than 2⁻²⁰ (|lo| + |hi|) are split,
// so at most depth 19, 21 pending; 24 leaves room for rounding (the CPU's bound: 50 of 56).
const TERRAIN_BICUBIC_STACK: u32 = 24u;
const TERRAIN_ILLINOIS_STEPS: u32 = 100u;
const HIT_SURFACE: u32 = 0u;
const HIT_WALL: u32 = 1u;
const HIT_START: u32 = 2u;

// The current invocation's terrain work on camera rays (`pixel_lod`), as fray-trace and
// fray_terrain's TerrainStats count it: rays cast at a terrain, segments popped, finest cells
// intersected, segments stopped at their level, and the sum of those levels' distances above the
// finest. Shadow rays are not counted (the CPU does not count them either).
var<private> terrain_rays: u32;
var<private> terrain_segments: u32;
var<private> terrain_cells: u32;
var<private> terrain_stops: u32;
var<private> terrain_stop_levels: u32;
// The terrain being cast (terrains[k], read once per cast) and this view's level-of-detail
// parameters of it (terrain_lods[k]: the pixel footprint's size and growth in finest cells, on
// or off, the coarsest level a pixel stop may take; GpuTerrainParams::with_pixel_lod).
var<private> T: GpuTerrainParams;
var<private> TL: vec4<f32>;
const F32_EPS: f32 = 1.1920929e-7;
const NO_SURFACE_BELOW: f32 = -3.0e38;

struct TerrainHit {
    // World distance along the ray; < 0 for a miss.
    t: f32,
    // Outward world unit normal (see Terrain::cast).
    normal: vec3<f32>,
    // HIT_SURFACE, HIT_WALL or HIT_START.
    kind: u32,
    // 0 for the exact surface; k > 0 for a hit on a level-(n − k) max column.
    levels_above: u32,
    // The cell (column) hit, at the stop level's resolution.
    cell: vec2<u32>,
}

fn terrain_miss() -> TerrainHit {
    var h: TerrainHit;
    h.t = -1.0;
    return h;
}

// The material index of terrain k.
fn terrain_material(k: u32) -> u32 {
    return terrains[k].material.x;
}

// Columns of pyramid level `level` (rectangular levels).
fn level_columns(level: u32) -> u32 {
    let shift = T.grid.z - level;
    return (T.grid.x + (1u << shift) - 1u) >> shift;
}

fn level_rows(level: u32) -> u32 {
    let shift = T.grid.z - level;
    return (T.grid.y + (1u << shift) - 1u) >> shift;
}

fn pyr(level: u32, a: u32, b: u32) -> f32 {
    return pyramid[T.levels[level >> 2u][level & 3u] + b * level_columns(level) + a];
}

fn sample(i: u32, j: u32) -> f32 {
    return samples[T.sizes.z + j * T.sizes.x + i];
}

// The part [t0, t1] of a map ray inside a box and the face it enters through: `entry` −1 when
// t0 is the start of the outer range (the ray starts inside), else 2·axis + (1 if the face's
// outward direction is +, 0 if −), axis 0 = u, 1 = v, 2 = r. Empty when t0 > t1.
struct Clip {
    t0: f32,
    t1: f32,
    entry: i32,
}

// The box [lo, hi] within an earlier clip, whose entry face stands when this box adds none
// (fray_terrain's clip_within; closed slabs: a ray along a face is inside).
fn clip_within(o: vec3<f32>, d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, outer: Clip) -> Clip {
    var c = outer;
    for (var k = 0; k < 3; k++) {
        if (d[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k]) {
                c.t0 = 1.0;
                c.t1 = -1.0;
                return c;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let a = (lo[k] - o[k]) * inv;
        let b = (hi[k] - o[k]) * inv;
        var near = a;
        var far = b;
        var plus = 0;
        if (a > b) {
            near = b;
            far = a;
            plus = 1;
        }
        if (near > c.t0) {
            c.t0 = near;
            c.entry = 2 * k + plus;
        }
        c.t1 = min(c.t1, far);
        if (c.t0 > c.t1) {
            return c;
        }
    }
    return c;
}

// k with 2^(n−k−1) < extent ≤ 2^(n−k), clamped to 0..=n: n − ⌈log₂ extent⌉ from the exponent
// bits, exact for powers of two (fray_terrain's level_for). NaN and extents ≤ 1 give n.
fn level_for(extent: f32, n: u32) -> u32 {
    if (!(extent > 1.0)) {
        return n;
    }
    let bits = bitcast<u32>(extent);
    let e = i32((bits >> 23u) & 0xffu) - 127;
    let ceil_log2 = e + select(1, 0, (bits & 0x7fffffu) == 0u);
    return u32(clamp(i32(n) - ceil_log2, 0, i32(n)));
}

// Level-`level` cells whose closed squares meet [lo, hi] (finest-cell units), clamped to the
// level's `count` cells: (first, last), first > last when none.
fn cell_range(lo: f32, hi: f32, level: u32, n: u32, count: u32) -> vec2<i32> {
    let scale = 1.0 / f32(1u << (n - level));
    let last = f32(count - 1u);
    let a = max(ceil(lo * scale) - 1.0, 0.0);
    let b = min(floor(hi * scale), last);
    if (a > b) {
        return vec2<i32>(1, 0);
    }
    return vec2<i32>(i32(a), i32(b));
}

fn surface_normal(su: f32, sv: f32) -> vec3<f32> {
    let s = T.scale.z;
    let n = T.axis_u.xyz * (-s * su / T.scale.x) + T.axis_up.xyz + T.axis_v.xyz * (-s * sv / T.scale.y);
    return normalize(n);
}

// The world unit normal of map axis `axis` (0 = u, 1 = v, 2 = r) with sign + when `plus`.
fn axis_normal(axis: i32, plus: bool) -> vec3<f32> {
    var n = T.axis_up.xyz;
    if (axis == 0) {
        n = T.axis_u.xyz;
    } else if (axis == 1) {
        n = T.axis_v.xyz;
    }
    return select(-n, n, plus);
}

fn cell_is_solid(i: u32, j: u32) -> bool {
    return pyr(T.grid.z, i, j) > NO_SURFACE_BELOW;
}

// B-spline control point (column i − 1 + l, row j − 1 + m) of solid cell (i, j): the sample, or
// the cell's nearest corner where the neighbour is off the map or below the threshold.
fn control(i: u32, j: u32, l: i32, m: i32) -> f32 {
    let x = i32(i) - 1 + l;
    let y = i32(j) - 1 + m;
    let inside = x >= 0 && y >= 0 && x < i32(T.sizes.x) && y < i32(T.sizes.y);
    if (inside) {
        let v = sample(u32(x), u32(y));
        if (v >= T.heights.z) {
            return v;
        }
    }
    return sample(u32(clamp(x, i32(i), i32(i) + 1)), u32(clamp(y, i32(j), i32(j) + 1)));
}

fn basis(s: f32) -> vec4<f32> {
    let t = 1.0 - s;
    let s2 = s * s;
    let s3 = s2 * s;
    return vec4<f32>(t * t * t, 3.0 * s3 - 6.0 * s2 + 4.0, -3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0, s3) / 6.0;
}

fn basis_d(s: f32) -> vec4<f32> {
    let t = 1.0 - s;
    let s2 = s * s;
    return vec4<f32>(-t * t, 3.0 * s2 - 4.0 * s, -3.0 * s2 + 2.0 * s + 1.0, s2) * 0.5;
}

// The control points of bicubic cell (i, j), row m = p[m].
fn control_points(i: u32, j: u32) -> array<vec4<f32>, 4> {
    var p: array<vec4<f32>, 4>;
    for (var m = 0; m < 4; m++) {
        p[m] = vec4<f32>(control(i, j, 0, m), control(i, j, 1, m), control(i, j, 2, m), control(i, j, 3, m));
    }
    return p;
}

// The interpolant's slopes (∂S/∂s, ∂S/∂w) of solid cell (i, j) at (s, w).
fn cell_slope(i: u32, j: u32, s: f32, w: f32) -> vec2<f32> {
    if (T.sizes.w == 1u) {
        let p = control_points(i, j);
        let bs = basis(s);
        let ds = basis_d(s);
        let bw = basis(w);
        let dw = basis_d(w);
        var vs = 0.0;
        var vw = 0.0;
        for (var m = 0; m < 4; m++) {
            vs += bw[m] * dot(ds, p[m]);
            vw += dw[m] * dot(bs, p[m]);
        }
        return vec2<f32>(vs, vw);
    }
    let h00 = sample(i, j);
    let h10 = sample(i + 1u, j);
    let h01 = sample(i, j + 1u);
    let h11 = sample(i + 1u, j + 1u);
    let k = h00 - h10 - h01 + h11;
    return vec2<f32>(h10 - h00 + k * w, h01 - h00 + k * s);
}

fn neighbour_is_solid(i: u32, j: u32, axis: i32, plus: bool) -> bool {
    var x = i32(i);
    var y = i32(j);
    let delta = select(-1, 1, plus);
    if (axis == 0) {
        x += delta;
    } else {
        y += delta;
    }
    return x >= 0 && y >= 0 && x < i32(T.grid.x) && y < i32(T.grid.y) && cell_is_solid(u32(x), u32(y));
}

// A hit at `t` where the ray is already inside cell (i, j)'s solid (Terrain::entry_hit): a wall
// or the base when it entered the cell there from outside the solid, the ray's start when it
// starts inside, else (rounding at a shared edge with a solid neighbour, or a segment start) the
// surface.
fn entry_hit(o: vec3<f32>, d: vec3<f32>, dir: vec3<f32>, c: Clip, t: f32, i: u32, j: u32) -> TerrainHit {
    var h: TerrainHit;
    h.t = t;
    h.cell = vec2<u32>(i, j);
    h.kind = HIT_SURFACE;
    h.levels_above = 0u;
    var surface = true;
    if (t == c.t0) {
        if (c.entry < 0) {
            h.kind = HIT_START;
            h.normal = -dir;
            return h;
        }
        let axis = c.entry / 2;
        let plus = (c.entry & 1) == 1;
        if (!(axis == 2 && plus) && !(axis < 2 && neighbour_is_solid(i, j, axis, plus))) {
            h.kind = HIT_WALL;
            h.normal = axis_normal(axis, plus);
            return h;
        }
    }
    let q = o + d * t;
    let s = clamp(q.x - f32(i), 0.0, 1.0);
    let w = clamp(q.y - f32(j), 0.0, 1.0);
    let g = cell_slope(i, j, s, w);
    h.normal = surface_normal(g.x, g.y);
    return h;
}

// The ray in cell (i, j)'s column (the cell's square, the terrain's height range) within `clip`:
// the clip `c`, the ray's point `start` there (at c.t0) with its offsets `s0`, `w0` in the cell,
// and [ta, tb] within it — from `a`, and as [lo_t, hi_t] from c.t0; `empty` where they do not meet.
struct CellSpan {
    c: Clip,
    a: f32,
    lo_t: f32,
    hi_t: f32,
    start: vec3<f32>,
    s0: f32,
    w0: f32,
    empty: bool,
}

fn cell_span(o: vec3<f32>, d: vec3<f32>, i: u32, j: u32, clip: Clip, ta: f32, tb: f32) -> CellSpan {
    let lo = vec3<f32>(f32(i), f32(j), T.heights.x);
    let hi = vec3<f32>(f32(i + 1u), f32(j + 1u), T.heights.y);
    var s: CellSpan;
    s.c = clip_within(o, d, lo, hi, clip);
    s.a = max(s.c.t0, ta);
    let b = min(s.c.t1, tb);
    s.empty = s.c.t0 > s.c.t1 || s.a > b;
    s.start = o + d * s.c.t0;
    s.s0 = s.start.x - f32(i);
    s.w0 = s.start.y - f32(j);
    s.lo_t = s.a - s.c.t0;
    s.hi_t = b - s.c.t0;
    return s;
}

// First hit on bilinear cell (i, j) within [ta, tb] ∩ the cell column (inside `clip`).
fn cell_hit(o: vec3<f32>, d: vec3<f32>, dir: vec3<f32>, i: u32, j: u32, clip: Clip, ta: f32, tb: f32) -> TerrainHit {
    let span = cell_span(o, d, i, j, clip, ta, tb);
    if (span.empty) {
        return terrain_miss();
    }
    let h00 = sample(i, j);
    let h10 = sample(i + 1u, j);
    let h01 = sample(i, j + 1u);
    let h11 = sample(i + 1u, j + 1u);
    let ka = h10 - h00;
    let kb = h01 - h00;
    let kk = h00 - h10 - h01 + h11;
    let qa = -kk * d.x * d.y;
    let qb = d.z - (ka * d.x + kb * d.y + kk * (span.s0 * d.y + span.w0 * d.x));
    let qc = span.start.z - (h00 + ka * span.s0 + kb * span.w0 + kk * span.s0 * span.w0);
    let f_lo = (qa * span.lo_t + qb) * span.lo_t + qc;
    if (f_lo <= 0.0) {
        return entry_hit(o, d, dir, span.c, span.a, i, j);
    }
    var tau = -1.0;
    if (qa == 0.0) {
        if (qb < 0.0) {
            let r = -qc / qb;
            if (r >= span.lo_t && r <= span.hi_t) {
                tau = r;
            }
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if (disc >= 0.0) {
            let q = -0.5 * (qb + select(-1.0, 1.0, qb >= 0.0) * sqrt(disc));
            var r1 = q / qa;
            var r2 = select(q / qa, qc / q, q != 0.0);
            if (r1 > r2) {
                let tmp = r1;
                r1 = r2;
                r2 = tmp;
            }
            if (r1 >= span.lo_t && r1 <= span.hi_t) {
                tau = r1;
            } else if (r2 >= span.lo_t && r2 <= span.hi_t) {
                tau = r2;
            }
        }
    }
    if (tau < 0.0) {
        return terrain_miss();
    }
    let s = clamp(span.s0 + tau * d.x, 0.0, 1.0);
    let w = clamp(span.w0 + tau * d.y, 0.0, 1.0);
    var h: TerrainHit;
    h.t = span.c.t0 + tau;
    h.normal = surface_normal(ka + kk * w, kb + kk * s);
    h.kind = HIT_SURFACE;
    h.levels_above = 0u;
    h.cell = vec2<u32>(i, j);
    return h;
}

// (f, f', S_s, S_w) at τ for the ray (s0 + τ ds, w0 + τ dw, r0 + τ dr) against the patch `p`.
fn bspline_f(p: array<vec4<f32>, 4>, s0: f32, w0: f32, r0: f32, d: vec3<f32>, tau: f32) -> vec4<f32> {
    let bs = basis(s0 + tau * d.x);
    let ds = basis_d(s0 + tau * d.x);
    let bw = basis(w0 + tau * d.y);
    let dw = basis_d(w0 + tau * d.y);
    var v = 0.0;
    var vs = 0.0;
    var vw = 0.0;
    for (var m = 0; m < 4; m++) {
        let r = dot(bs, p[m]);
        v += bw[m] * r;
        vs += bw[m] * dot(ds, p[m]);
        vw += dw[m] * r;
    }
    return vec4<f32>(r0 + tau * d.z - v, d.z - (vs * d.x + vw * d.y), vs, vw);
}

// Illinois (modified regula falsi) on a bracket f(a) > 0 ≥ f(b), to |b − a| ≤ eps.
fn bspline_illinois(p: array<vec4<f32>, 4>, s0: f32, w0: f32, r0: f32, d: vec3<f32>, a_in: f32, b_in: f32, fa_in: f32, fb_in: f32, eps: f32) -> f32 {
    var a = a_in;
    var b = b_in;
    var fa = fa_in;
    var fb = fb_in;
    var side = 0;
    for (var it = 0u; it < TERRAIN_ILLINOIS_STEPS; it++) {
        if (b - a <= eps || fb == 0.0) {
            break;
        }
        var t = (a * fb - b * fa) / (fb - fa);
        if (!(t > a && t < b)) {
            t = 0.5 * (a + b);
        }
        let ft = bspline_f(p, s0, w0, r0, d, t).x;
        if (ft > 0.0) {
            a = t;
            fa = ft;
            if (side == 1) {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = t;
            fb = ft;
            if (side == -1) {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    return b;
}

// First hit on bicubic cell (i, j) within [ta, tb] ∩ the cell column (fray_terrain's cell_hit
// and bicubic_root).
fn bicubic_hit(o: vec3<f32>, d: vec3<f32>, dir: vec3<f32>, i: u32, j: u32, clip: Clip, ta: f32, tb: f32, eps_in: f32) -> TerrainHit {
    let span = cell_span(o, d, i, j, clip, ta, tb);
    if (span.empty) {
        return terrain_miss();
    }
    let p = control_points(i, j);
    let f_lo = bspline_f(p, span.s0, span.w0, span.start.z, d, span.lo_t);
    if (f_lo.x <= 0.0) {
        return entry_hit(o, d, dir, span.c, span.a, i, j);
    }
    // Slope bounds (first and second differences), as in fray_terrain::BicubicCell.
    var d1 = vec2<f32>(0.0);
    var d2 = vec3<f32>(0.0);
    for (var m = 0; m < 4; m++) {
        for (var l = 0; l < 3; l++) {
            d1.x = max(d1.x, abs(p[m][l + 1] - p[m][l]));
            d1.y = max(d1.y, abs(p[l + 1][m] - p[l][m]));
        }
        for (var l = 0; l < 2; l++) {
            d2.x = max(d2.x, abs(p[m][l + 2] - 2.0 * p[m][l + 1] + p[m][l]));
            d2.z = max(d2.z, abs(p[l + 2][m] - 2.0 * p[l + 1][m] + p[l][m]));
        }
    }
    for (var m = 0; m < 3; m++) {
        for (var l = 0; l < 3; l++) {
            d2.y = max(d2.y, abs(p[m + 1][l + 1] - p[m + 1][l] - p[m][l + 1] + p[m][l]));
        }
    }
    let k1 = abs(d.z) + d1.x * abs(d.x) + d1.y * abs(d.y);
    let k2 = d2.x * d.x * d.x + 2.0 * d2.y * abs(d.x * d.y) + d2.z * d.y * d.y;
    let eps = max(eps_in, 8.0 * F32_EPS * (abs(span.lo_t) + abs(span.hi_t)));
    var root = -1.0;
    var stack: array<vec4<f32>, TERRAIN_BICUBIC_STACK>;
    stack[0] = vec4<f32>(span.lo_t, span.hi_t, f_lo.x, bspline_f(p, span.s0, span.w0, span.start.z, d, span.hi_t).x);
    var len = 1u;
    while (len > 0u) {
        len -= 1u;
        let seg = stack[len];
        let mid = 0.5 * (seg.x + seg.y);
        let half = 0.5 * (seg.y - seg.x);
        let fm = bspline_f(p, span.s0, span.w0, span.start.z, d, mid);
        let monotone = abs(fm.y) > k2 * half;
        // No wider than the tolerance (or, never at a normal tolerance, out of stack).
        let small = seg.y - seg.x <= eps || len + 2u > TERRAIN_BICUBIC_STACK;
        if (seg.w <= 0.0) {
            if (monotone || small) {
                root = bspline_illinois(p, span.s0, span.w0, span.start.z, d, seg.x, seg.y, seg.z, seg.w, eps);
                break;
            }
        } else if (fm.x - k1 * half > 0.0 || monotone) {
            continue;
        } else if (small) {
            if (fm.x <= 0.0) {
                root = bspline_illinois(p, span.s0, span.w0, span.start.z, d, seg.x, mid, seg.z, fm.x, eps);
                break;
            }
            continue;
        }
        stack[len] = vec4<f32>(mid, seg.y, fm.x, seg.w);
        stack[len + 1u] = vec4<f32>(seg.x, mid, seg.z, fm.x);
        len += 2u;
    }
    if (root < 0.0) {
        return terrain_miss();
    }
    let g = bspline_f(p, span.s0, span.w0, span.start.z, d, root);
    var h: TerrainHit;
    h.t = span.c.t0 + root;
    h.normal = surface_normal(g.z, g.w);
    h.kind = HIT_SURFACE;
    h.levels_above = 0u;
    h.cell = vec2<u32>(i, j);
    return h;
}

// LOD hit: the entry into the nearest max column `[cell] × [bottom, max]` of level `level`
// among cells ra × rb (Terrain::column_hit). `counted` (0 or 1) adds the columns tested to
// `terrain_cells`.
fn column_hit(o: vec3<f32>, d: vec3<f32>, dir: vec3<f32>, level: u32, n: u32, ra: vec2<i32>, rb: vec2<i32>, clip: Clip, ta: f32, tb: f32, counted: u32) -> TerrainHit {
    let size = f32(1u << (n - level));
    var best = terrain_miss();
    for (var b = rb.x; b <= rb.y; b++) {
        for (var a = ra.x; a <= ra.y; a++) {
            let top = pyr(level, u32(a), u32(b));
            if (top <= NO_SURFACE_BELOW) {
                continue;
            }
            terrain_cells += counted;
            let lo = vec3<f32>(f32(a) * size, f32(b) * size, T.heights.x);
            let hi = vec3<f32>(min(f32(a + 1) * size, f32(T.grid.x)), min(f32(b + 1) * size, f32(T.grid.y)), top);
            let c = clip_within(o, d, lo, hi, clip);
            if (c.t0 > c.t1) {
                continue;
            }
            let t = max(c.t0, ta);
            if (t > min(c.t1, tb) || (best.t >= 0.0 && best.t <= t)) {
                continue;
            }
            best.t = t;
            best.kind = HIT_SURFACE;
            best.normal = T.axis_up.xyz;
            if (t == c.t0) {
                let axis = c.entry / 2;
                let plus = (c.entry & 1) == 1;
                if (c.entry < 0) {
                    best.kind = HIT_START;
                    best.normal = -dir;
                } else if (axis < 2 || !plus) {
                    best.kind = HIT_WALL;
                    best.normal = axis_normal(axis, plus);
                }
            }
            best.levels_above = n - level;
            best.cell = vec2<u32>(u32(a), u32(b));
        }
    }
    return best;
}

// The ray in terrain T's map space: (o, d) with components (u, v, r).
fn map_origin(origin: vec3<f32>) -> vec3<f32> {
    let rel = origin - T.origin.xyz;
    return vec3<f32>(dot(rel, T.axis_u.xyz) / T.scale.x, dot(rel, T.axis_v.xyz) / T.scale.y, dot(rel, T.axis_up.xyz) / T.scale.z);
}

fn map_dir(dir: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(dir, T.axis_u.xyz) / T.scale.x, dot(dir, T.axis_v.xyz) / T.scale.y, dot(dir, T.axis_up.xyz) / T.scale.z);
}

// The nearest hit on terrain k within [t_lo, t_hi] (Terrain::cast_footprint; `eps` is the
// bicubic root tolerance in world units).
fn cast_terrain(k: u32, origin: vec3<f32>, dir: vec3<f32>, t_lo: f32, t_hi: f32, eps: f32, pixel_lod: bool) -> TerrainHit {
    T = terrains[k];
    TL = terrain_lods[k];
    let o = map_origin(origin);
    let d = map_dir(dir);
    let box_lo = vec3<f32>(0.0, 0.0, T.heights.x);
    let box_hi = vec3<f32>(f32(T.grid.x), f32(T.grid.y), T.heights.y);
    let counted = u32(pixel_lod);
    terrain_rays += counted;
    var range: Clip;
    range.t0 = t_lo;
    range.t1 = t_hi;
    range.entry = -1;
    let c = clip_within(o, d, box_lo, box_hi, range);
    if (c.t0 > c.t1) {
        return terrain_miss();
    }
    let n = T.grid.z;
    let err = (abs(o) + abs(d) * max(abs(c.t0), abs(c.t1))) * (8.0 * F32_EPS) + vec3<f32>(1e-30);
    let bicubic = T.sizes.w == 1u;
    var stack: array<vec2<f32>, TERRAIN_STACK>;
    stack[0] = vec2<f32>(c.t0, c.t1);
    var len = 1u;
    while (len > 0u) {
        len -= 1u;
        let seg = stack[len];
        terrain_segments += counted;
        // Pixel level of detail (Terrain::cast_footprint), camera rays only: stop where a cell
        // covers the pixel at the segment's start, never coarser than the floor level. Shadow
        // rays are exact, as on the CPU.
        var stop = T.grid.w;
        if (pixel_lod && TL.z > 0.5) {
            stop = min(stop, max(level_for(TL.x + TL.y * seg.x, n), u32(TL.w)));
        }
        let pa = o + d * seg.x;
        let pb = o + d * seg.y;
        let u0 = min(pa.x, pb.x) - err.x;
        let u1 = max(pa.x, pb.x) + err.x;
        let v0 = min(pa.y, pb.y) - err.y;
        let v1 = max(pa.y, pb.y) + err.y;
        let r_min = min(pa.z, pb.z) - err.z;
        let tm = 0.5 * (seg.x + seg.y);
        let splittable = seg.x < tm && tm < seg.y && len + 2u <= TERRAIN_STACK;
        var level = min(level_for(max(u1 - u0, v1 - v0), n), stop);
        if (!splittable) {
            level = stop;
        }
        let ra = cell_range(u0, u1, level, n, level_columns(level));
        let rb = cell_range(v0, v1, level, n, level_rows(level));
        if (ra.x > ra.y || rb.x > rb.y) {
            continue;
        }
        var top = -3.4e38;
        for (var b = rb.x; b <= rb.y; b++) {
            for (var a = ra.x; a <= ra.y; a++) {
                top = max(top, pyr(level, u32(a), u32(b)));
            }
        }
        if (r_min > top) {
            continue;
        }
        if (level == stop) {
            terrain_stops += counted;
            terrain_stop_levels += counted * (n - stop);
            var best = terrain_miss();
            if (stop == n) {
                for (var b = rb.x; b <= rb.y; b++) {
                    for (var a = ra.x; a <= ra.y; a++) {
                        if (r_min > pyr(n, u32(a), u32(b))) {
                            continue; // also skips cut-out cells (NO_SURFACE)
                        }
                        terrain_cells += counted;
                        let end = select(seg.y, best.t, best.t >= 0.0);
                        var h: TerrainHit;
                        if (bicubic) {
                            h = bicubic_hit(o, d, dir, u32(a), u32(b), c, seg.x, end, eps);
                        } else {
                            h = cell_hit(o, d, dir, u32(a), u32(b), c, seg.x, end);
                        }
                        // Within [seg.x, best]: a tie goes to the later cell, as on the CPU.
                        if (h.t >= 0.0) {
                            best = h;
                        }
                    }
                }
            } else {
                best = column_hit(o, d, dir, level, n, ra, rb, c, seg.x, seg.y, counted);
            }
            if (best.t >= 0.0) {
                return best;
            }
            continue;
        }
        stack[len] = vec2<f32>(tm, seg.y);
        stack[len + 1u] = vec2<f32>(seg.x, tm);
        len += 2u;
    }
    return terrain_miss();
}

// The finest cell under map coordinate x (clamped to the map's `cells`).
fn cell_under(x: f32, cells: u32) -> u32 {
    return min(u32(clamp(floor(x), 0.0, 4.0e9)), cells - 1u);
}

// The cell inside a column wall on the line nearest x, opposite its outward normal's
// component `outward` along that axis.
fn cell_inside(x: f32, outward: f32, cells: u32) -> u32 {
    let line = u32(clamp(round(x), 0.0, 4.0e9));
    var i = line;
    if (outward > 0.0) {
        i = max(line, 1u) - 1u;
    }
    return min(i, cells - 1u);
}

// The normal to shade hit `h` of terrain k with (Terrain::shading_normal): its own on the exact
// surface; a LOD hit's is the interpolant's normal at the finest cell under the hit point — on a
// column's side wall (a normal along u or v) the cell inside the wall, opposite its outward
// normal — or its own where that cell is cut out.
fn terrain_shading_normal(k: u32, origin: vec3<f32>, dir: vec3<f32>, h: TerrainHit) -> vec3<f32> {
    T = terrains[k];
    if (h.levels_above == 0u) {
        return h.normal;
    }
    let q = map_origin(origin) + map_dir(dir) * h.t;
    let along_u = dot(h.normal, T.axis_u.xyz);
    let along_v = dot(h.normal, T.axis_v.xyz);
    var i = cell_under(q.x, T.grid.x);
    var j = cell_under(q.y, T.grid.y);
    if (abs(along_u) > 0.5) {
        i = cell_inside(q.x, along_u, T.grid.x);
    } else if (abs(along_v) > 0.5) {
        j = cell_inside(q.y, along_v, T.grid.y);
    }
    if (!cell_is_solid(i, j)) {
        return h.normal;
    }
    let s = clamp(q.x - f32(i), 0.0, 1.0);
    let w = clamp(q.y - f32(j), 0.0, 1.0);
    let g = cell_slope(i, j, s, w);
    return surface_normal(g.x, g.y);
}
