// ray.wgsl — constants and the ray/box helper every pass shares (f32, camera-relative).

const BIG: f32 = 1.0e30;
const NO_HIT: f32 = -1.0;
const PI: f32 = 3.14159265358979;

// The part of [lo, hi] where o + t d is inside the box; x > y when empty (Aabb::clip_ray).
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

// The nearest hit of a ray leaving a surface, any kind (secondary_hit.wgsl; fray-trace's
// KindHit with its primitive): `t` (< 0: none), the kind and index, and what the kind's surface
// needs — a terrain's shading normal, a mesh's barycentrics (its triangle slot in `part`), or for
// a free form left through its clipping box (`part` = FREE_FORM_BOX_EXIT) that face's normal.
struct SurfaceHit {
    t: f32,
    kind: u32,
    index: u32,
    part: u32,
    detail: vec3<f32>,
}

const FREE_FORM_BOX_EXIT: u32 = 1u;

// A ray that belongs to no pixel (a secondary ray): its media take no pixel's jitter.
const NO_PIXEL: u32 = 0xffffffffu;
