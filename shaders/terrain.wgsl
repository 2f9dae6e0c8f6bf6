// terrain.wgsl — height-map terrain ray casting (DESIGN §4), the f32 twin of
// fray_terrain::Terrain::cast for bilinear patches and uniform cubic B-splines (sizes.w = 1):
// one invocation per ray, the ray segment
// clipped to the terrain box in map space (u, v, r), halved nearer-first with the footprint
// level rule against the max pyramid, finest cells intersected exactly (bilinear: a quadratic
// per cell; bicubic: halving with the B-spline's slope bounds, monotone pieces finished by
// Illinois), or, with a LOD bias, the stop level's max-column tops. The struct TerrainParams is generated
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

// B-spline control point (column i − 1 + l, row j − 1 + m) of solid cell (i, j): the sample, or
// the cell's nearest corner where the neighbour is off the map or below the threshold.
fn control(i: u32, j: u32, l: i32, m: i32) -> f32 {
    let x = i32(i) - 1 + l;
    let y = i32(j) - 1 + m;
    let inside = x >= 0 && y >= 0 && x < i32(P.sizes.x) && y < i32(P.sizes.y);
    if (inside) {
        let v = sample(u32(x), u32(y));
        if (v >= P.heights.z) {
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

// First hit on bicubic cell (i, j) within [ta, tb] ∩ the cell column: (t, normal), t < 0 none.
fn bicubic_hit(o: vec3<f32>, d: vec3<f32>, i: u32, j: u32, c0: f32, c1: f32, ta: f32, tb: f32) -> vec4<f32> {
    let miss = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    let lo = vec3<f32>(f32(i), f32(j), P.heights.x);
    let hi = vec3<f32>(f32(i + 1u), f32(j + 1u), P.heights.y);
    let c = clip(o, d, lo, hi, c0, c1);
    let a0 = max(c.x, ta);
    let b0 = min(c.y, tb);
    if (a0 > b0) {
        return miss;
    }
    var p: array<vec4<f32>, 4>;
    for (var m = 0; m < 4; m++) {
        p[m] = vec4<f32>(control(i, j, 0, m), control(i, j, 1, m), control(i, j, 2, m), control(i, j, 3, m));
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
    let start = o + d * c.x;
    let s0 = start.x - f32(i);
    let w0 = start.y - f32(j);
    let r0 = start.z;
    let k1 = abs(d.z) + d1.x * abs(d.x) + d1.y * abs(d.y);
    let k2 = d2.x * d.x * d.x + 2.0 * d2.y * abs(d.x * d.y) + d2.z * d.y * d.y;
    let lo_t = a0 - c.x;
    let hi_t = b0 - c.x;
    let eps = max(1e-6 * (abs(a0) + abs(b0)), 1e-30);
    let f_lo = bspline_f(p, s0, w0, r0, d, lo_t);
    var root = -1.0;
    if (f_lo.x <= 0.0) {
        root = lo_t;
    } else {
        var stack: array<vec4<f32>, 24>;
        stack[0] = vec4<f32>(lo_t, hi_t, f_lo.x, bspline_f(p, s0, w0, r0, d, hi_t).x);
        var len = 1u;
        loop {
            if (len == 0u || root >= 0.0) {
                break;
            }
            len -= 1u;
            let seg = stack[len];
            let mid = 0.5 * (seg.x + seg.y);
            let half = 0.5 * (seg.y - seg.x);
            let fm = bspline_f(p, s0, w0, r0, d, mid);
            let monotone = abs(fm.y) > k2 * half;
            if (seg.w <= 0.0) {
                if (monotone || seg.y - seg.x <= eps || len + 2u > 24u) {
                    // Illinois on the bracket f(a) > 0 ≥ f(b).
                    var a = seg.x;
                    var b = seg.y;
                    var fa = seg.z;
                    var fb = seg.w;
                    var side = 0;
                    for (var it = 0; it < 40; it++) {
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
                    root = b;
                    break;
                }
            } else if (fm.x - k1 * half > 0.0 || monotone || seg.y - seg.x <= eps || len + 2u > 24u) {
                continue;
            }
            stack[len] = vec4<f32>(mid, seg.y, fm.x, seg.w);
            stack[len + 1u] = vec4<f32>(seg.x, mid, seg.z, fm.x);
            len += 2u;
        }
    }
    if (root < 0.0) {
        return miss;
    }
    let g = bspline_f(p, s0, w0, r0, d, root);
    return vec4<f32>(c.x + root, surface_normal(g.z, g.w));
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
                        var h: vec4<f32>;
                        if (P.sizes.w == 1u) {
                            h = bicubic_hit(o, d, u32(a), u32(b), c.x, c.y, seg.x, end);
                        } else {
                            h = cell_hit(o, d, u32(a), u32(b), c.x, c.y, seg.x, end);
                        }
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
