// terrain.wgsl — height-map terrain ray casting (DESIGN §4), the f32 twin of
// fray_terrain::Terrain::cast for bilinear patches: one invocation per ray, the ray segment
// clipped to the terrain box in map space (u, v, r), halved nearer-first with the footprint
// level rule against the max pyramid, finest cells intersected exactly (a quadratic per cell),
// or, with a LOD bias, the stop level's max-column tops. The struct TerrainParams is generated
// from Rust (fray_terrain::gpu_layout) and prepended.
//
// Rays: two vec4 per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi).
// Hits: one vec4 per ray — (t, normal.xyz), t < 0 for a miss.

@group(0) @binding(0) var<uniform> P: TerrainParams;
@group(0) @binding(1) var<storage, read> pyramid: array<f32>;
@group(0) @binding(2) var<storage, read> samples: array<f32>;
@group(0) @binding(3) var<storage, read> rays: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> hits: array<vec4<f32>>;

const STACK: u32 = 48u;
const F32_EPS: f32 = 1.1920929e-7;

fn pyr(level: u32, a: u32, b: u32) -> f32 {
    let off = ((1u << (2u * level)) - 1u) / 3u;
    return pyramid[off + (b << level) + a];
}

fn sample(i: u32, j: u32) -> f32 {
    return samples[j * P.sizes.x + i];
}

// The part [x, y] of the map ray inside [lo, hi] within [t0, t1]; empty when x > y.
fn clip(o: vec3<f32>, d: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, t0: f32, t1: f32) -> vec2<f32> {
    var a = t0;
    var b = t1;
    for (var k = 0; k < 3; k++) {
        if (d[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k]) {
                return vec2<f32>(1.0, -1.0);
            }
        } else {
            let inv = 1.0 / d[k];
            let p = (lo[k] - o[k]) * inv;
            let q = (hi[k] - o[k]) * inv;
            a = max(a, min(p, q));
            b = min(b, max(p, q));
        }
    }
    return vec2<f32>(a, b);
}

// k with 2^(n−k−1) < extent ≤ 2^(n−k), clamped to 0..=n. (Any level is correct — the cell
// range below covers the whole footprint — the rule only keeps the range small.)
fn level_for(extent: f32, n: u32) -> u32 {
    if (extent <= 1.0) {
        return n;
    }
    let k = i32(ceil(log2(extent)));
    return u32(clamp(i32(n) - k, 0, i32(n)));
}

// Level-`level` cells whose closed squares meet [lo, hi] (finest-cell units): (first, last).
fn cell_range(lo: f32, hi: f32, level: u32, n: u32) -> vec2<i32> {
    let scale = 1.0 / f32(1u << (n - level));
    let last = f32((1u << level) - 1u);
    let a = max(ceil(lo * scale) - 1.0, 0.0);
    let b = min(floor(hi * scale), last);
    if (a > b) {
        return vec2<i32>(1, 0);
    }
    return vec2<i32>(i32(a), i32(b));
}

fn surface_normal(su: f32, sv: f32) -> vec3<f32> {
    let s = P.scale.z;
    let n = P.axis_u.xyz * (-s * su / P.scale.x) + P.axis_up.xyz + P.axis_v.xyz * (-s * sv / P.scale.y);
    return normalize(n);
}

// First hit on bilinear cell (i, j) within [ta, tb] ∩ the cell column (inside clip [c0, c1]):
// (t, normal), t < 0 for none.
fn cell_hit(o: vec3<f32>, d: vec3<f32>, i: u32, j: u32, c0: f32, c1: f32, ta: f32, tb: f32) -> vec4<f32> {
    let lo = vec3<f32>(f32(i), f32(j), P.heights.x);
    let hi = vec3<f32>(f32(i + 1u), f32(j + 1u), P.heights.y);
    let c = clip(o, d, lo, hi, c0, c1);
    let a = max(c.x, ta);
    let b = min(c.y, tb);
    if (a > b) {
        return vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    }
    let h00 = sample(i, j);
    let h10 = sample(i + 1u, j);
    let h01 = sample(i, j + 1u);
    let h11 = sample(i + 1u, j + 1u);
    let ka = h10 - h00;
    let kb = h01 - h00;
    let kk = h00 - h10 - h01 + h11;
    let start = o + d * c.x;
    let s0 = start.x - f32(i);
    let w0 = start.y - f32(j);
    let qa = -kk * d.x * d.y;
    let qb = d.z - (ka * d.x + kb * d.y + kk * (s0 * d.y + w0 * d.x));
    let qc = start.z - (h00 + ka * s0 + kb * w0 + kk * s0 * w0);
    let lo_t = a - c.x;
    let hi_t = b - c.x;
    var tau = -1.0;
    let f_lo = (qa * lo_t + qb) * lo_t + qc;
    if (f_lo <= 0.0) {
        tau = lo_t;
    } else if (qa == 0.0) {
        if (qb < 0.0) {
            let r = -qc / qb;
            if (r >= lo_t && r <= hi_t) {
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
            if (r1 >= lo_t && r1 <= hi_t) {
                tau = r1;
            } else if (r2 >= lo_t && r2 <= hi_t) {
                tau = r2;
            }
        }
    }
    if (tau < 0.0) {
        return vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    }
    let s = clamp(s0 + tau * d.x, 0.0, 1.0);
    let w = clamp(w0 + tau * d.y, 0.0, 1.0);
    return vec4<f32>(c.x + tau, surface_normal(ka + kk * w, kb + kk * s));
}

// LOD hit: entry into the nearest max column of level `level` among cells ra × rb.
fn column_hit(o: vec3<f32>, d: vec3<f32>, level: u32, n: u32, ra: vec2<i32>, rb: vec2<i32>, c0: f32, c1: f32, ta: f32, tb: f32) -> vec4<f32> {
    let size = f32(1u << (n - level));
    var best = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    for (var b = rb.x; b <= rb.y; b++) {
        for (var a = ra.x; a <= ra.y; a++) {
            let top = pyr(level, u32(a), u32(b));
            if (top <= -3.0e38) {
                continue;
            }
            let lo = vec3<f32>(f32(a) * size, f32(b) * size, P.heights.x);
            let hi = vec3<f32>(min(f32(a + 1) * size, f32(P.grid.x)), min(f32(b + 1) * size, f32(P.grid.y)), top);
            let c = clip(o, d, lo, hi, c0, c1);
            let t = max(c.x, ta);
            if (t <= min(c.y, tb) && (best.x < 0.0 || t < best.x)) {
                best = vec4<f32>(t, P.axis_up.xyz);
            }
        }
    }
    return best;
}

fn cast_terrain(origin: vec3<f32>, dir: vec3<f32>, t_lo: f32, t_hi: f32) -> vec4<f32> {
    let miss = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    // Map space: o, d with components (u, v, r).
    let rel = origin - P.origin.xyz;
    let o = vec3<f32>(dot(rel, P.axis_u.xyz) / P.scale.x, dot(rel, P.axis_v.xyz) / P.scale.y, dot(rel, P.axis_up.xyz) / P.scale.z);
    let d = vec3<f32>(dot(dir, P.axis_u.xyz) / P.scale.x, dot(dir, P.axis_v.xyz) / P.scale.y, dot(dir, P.axis_up.xyz) / P.scale.z);
    let box_lo = vec3<f32>(0.0, 0.0, P.heights.x);
    let box_hi = vec3<f32>(f32(P.grid.x), f32(P.grid.y), P.heights.y);
    let c = clip(o, d, box_lo, box_hi, t_lo, t_hi);
    if (c.x > c.y) {
        return miss;
    }
    let n = P.grid.z;
    let stop = P.grid.w;
    let err = (abs(o) + abs(d) * max(abs(c.x), abs(c.y))) * (8.0 * F32_EPS) + vec3<f32>(1e-30);
    var stack: array<vec2<f32>, STACK>;
    stack[0] = c;
    var len = 1u;
    loop {
        if (len == 0u) {
            break;
        }
        len -= 1u;
        let seg = stack[len];
        let pa = o + d * seg.x;
        let pb = o + d * seg.y;
        let u0 = min(pa.x, pb.x) - err.x;
        let u1 = max(pa.x, pb.x) + err.x;
        let v0 = min(pa.y, pb.y) - err.y;
        let v1 = max(pa.y, pb.y) + err.y;
        let r_min = min(pa.z, pb.z) - err.z;
        let tm = 0.5 * (seg.x + seg.y);
        let splittable = seg.x < tm && tm < seg.y && len + 2u <= STACK;
        var level = min(level_for(max(u1 - u0, v1 - v0), n), stop);
        if (!splittable) {
            level = stop;
        }
        let ra = cell_range(u0, u1, level, n);
        let rb = cell_range(v0, v1, level, n);
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
            var best = miss;
            if (stop == n) {
                for (var b = rb.x; b <= rb.y; b++) {
                    for (var a = ra.x; a <= ra.y; a++) {
                        if (r_min > pyr(n, u32(a), u32(b))) {
                            continue;
                        }
                        let end = select(seg.y, best.x, best.x >= 0.0);
                        let h = cell_hit(o, d, u32(a), u32(b), c.x, c.y, seg.x, end);
                        if (h.x >= 0.0 && (best.x < 0.0 || h.x < best.x)) {
                            best = h;
                        }
                    }
                }
            } else {
                best = column_hit(o, d, level, n, ra, rb, c.x, c.y, seg.x, seg.y);
            }
            if (best.x >= 0.0) {
                return best;
            }
            continue;
        }
        stack[len] = vec2<f32>(tm, seg.y);
        stack[len + 1u] = vec2<f32>(seg.x, tm);
        len += 2u;
    }
    return miss;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if (k >= P.sizes.z) {
        return;
    }
    let a = rays[2u * k];
    let b = rays[2u * k + 1u];
    hits[k] = cast_terrain(a.xyz, b.xyz, a.w, b.w);
}
