// quadric.wgsl — quadrics (fray_geometry::Quadric in f32, GpuQuadric) at points and along rays,
// and the interval arithmetic of their ranges over ray segments (fray_core::Interval).

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
