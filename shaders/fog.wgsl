// fog.wgsl — Klassen's fog layer in f32, the twin of fray_atmosphere's FogLayer (fog.rs,
// single_scattering.rs, method.rs, phase.rs): the part of a ray segment inside the layer, its
// optical depth (homogeneous or falling off exponentially), the sun's depth from a height to
// the top, the phase functions, and the per-light factors of the in-scattered light by the
// exact closed form or the method's formula. No bindings: it reads `fog` (a GpuFog from
// fray_atmosphere::gpu_layout, heights relative to the camera's) from the including module's
// groups. "∞" is BIG (ray.wgsl): a depth ≥ BIG is an unbounded one and e^{−BIG} is 0.
//
// Straight-line code: every case is computed and the answer chosen with `select` (no branch
// depends on the ray). Divergent lanes would run both sides anyway, and lavapipe (Mesa 22.3,
// the CI's software Vulkan) crashes compiling the shade module when an `exp` sits under a
// branch on the hit point there. Every divisor is kept off zero (TINY: a homogeneous layer's
// zero scale height, a sun on the horizon), so no lane divides by zero; a case a lane does not
// select may overflow, the value it selects is always finite.
//
// #include "ray.wgsl"
// #include "decay.wgsl"

// 1 − e^{−τ} for τ ≥ 0, exact for small τ (the Rust's `-(-τ).exp_m1()`): τ · mean_decay(τ),
// stable for the same reason (decay.wgsl); 1 for an unbounded depth.
fn fog_one_minus_exp(tau: f32) -> f32 {
    return select(tau * mean_decay(tau), 1.0, tau >= BIG);
}

// The smallest divisor: keeps the cases a lane does not select finite.
const TINY: f32 = 1.0e-30;

// The scale height as a divisor (any value for a homogeneous layer, which does not use it).
fn fog_scale() -> f32 {
    return max(fog.scale_height, TINY);
}

// e^{−τ}, 0 for an unbounded depth.
fn fog_exp(tau: f32) -> f32 {
    return select(exp(-tau), 0.0, tau >= BIG);
}

// Whether the camera-relative height y is in the layer (its boundary included).
fn fog_contains(y: f32) -> bool {
    return y >= fog.base && y <= fog.top;
}

// The extinction at camera-relative height y (0 outside the layer): FogLayer::density.
fn fog_density(y: f32) -> f32 {
    let falling = fog.extinction * exp(-(y - fog.base) / fog_scale());
    let density = select(falling, fog.extinction, fog.scale_height <= 0.0);
    return select(0.0, density, fog_contains(y));
}

// The part of [lo, hi] where the ray from height y with vertical direction dy is inside the
// layer (FogLayer::span); x > y when it never is. Horizontal rays are inside for all of the
// range or none of it. The cuts are clamped to ±BIG so that a nearly horizontal ray's stay
// finite (hi = BIG stands for ∞).
fn fog_span(y: f32, dy: f32, lo_in: f32, hi_in: f32) -> vec2<f32> {
    let horizontal = dy == 0.0;
    let divisor = select(dy, 1.0, horizontal);
    let a = clamp((fog.base - y) / divisor, -BIG, BIG);
    let b = clamp((fog.top - y) / divisor, -BIG, BIG);
    let cut = vec2<f32>(max(lo_in, min(a, b)), min(hi_in, max(a, b)));
    let span = select(cut, vec2<f32>(lo_in, hi_in), horizontal);
    let never = !(lo_in <= hi_in) || (horizontal && !fog_contains(y));
    return select(span, vec2<f32>(1.0, -1.0), never);
}

// The optical depth over `span` (inside the layer; FogLayer::span_depth). An unbounded span
// (hi ≥ BIG) has an unbounded depth wherever it has density.
fn fog_span_depth(y: f32, dy: f32, span: vec2<f32>) -> f32 {
    let unbounded = span.y >= BIG;
    let length = span.y - span.x;
    let h = fog_scale();
    let homogeneous = select(min(fog.extinction * length, BIG), BIG, unbounded && fog.extinction > 0.0);
    // The densest end times the length times the mean of the exponential; the rise is
    // |dy| · length, the difference of the two ends' heights without their cancellation.
    let low = clamp(min(y + dy * span.x, y + dy * span.y), fog.base, fog.top);
    let rise = abs(dy) * length / h;
    let falling = min(fog.extinction * exp(-(low - fog.base) / h) * length * mean_decay(rise), BIG);
    // Only a horizontal ray stays in a falling-off layer for ever.
    let forever = select(0.0, BIG, fog_density(y) > 0.0);
    return select(select(falling, forever, unbounded), homogeneous, fog.scale_height <= 0.0);
}

// The optical depth of the ray over [lo, hi] (FogLayer::optical_depth): 0 outside the layer.
fn fog_optical_depth(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32) -> f32 {
    let span = fog_span(o.y, d.y, lo, hi);
    let inside = span.x <= span.y && fog.extinction > 0.0;
    return select(0.0, fog_span_depth(o.y, d.y, span), inside);
}

// The optical depth of a rise `rise` from camera-relative height y (in the layer) toward a sun
// at sin β = sin_b: FogLayer::sun_depth past its clamp; unbounded for a sun at or below the
// horizon.
fn fog_rise_depth(rise: f32, y: f32, sin_b: f32) -> f32 {
    let path = rise / max(sin_b, TINY);
    let h = fog_scale();
    let homogeneous = min(fog.extinction * path, BIG);
    let falling = min(fog.extinction * exp(-(y - fog.base) / h) * path * mean_decay(rise / h), BIG);
    let lit = select(falling, homogeneous, fog.scale_height <= 0.0);
    let depth = select(lit, BIG, !(sin_b > 0.0));
    return select(depth, 0.0, rise <= 0.0 || fog.extinction == 0.0);
}

// The optical depth from camera-relative height y to the layer's top toward a sun at
// sin β = sin_b (FogLayer::sun_depth).
fn fog_sun_depth(y: f32, sin_b: f32) -> f32 {
    let yc = clamp(y, fog.base, fog.top);
    return fog_rise_depth(fog.top - yc, yc, sin_b);
}

// The method's sun path: the whole layer from its bottom, e^{−B H cosec β} (the thickness from
// f64, not top − base in f32).
fn fog_whole_layer_depth(sin_b: f32) -> f32 {
    return fog_rise_depth(fog.thickness, fog.base, sin_b);
}

// The phase function p(cos θ) in 1/sr (Phase::eval). 1 + g² − 2gc is written as a sum of
// non-negative terms — (1 − g)² + 2g(1 − c) for g ≥ 0, (1 + g)² − 2g(1 + c) for g < 0 — so the
// forward (or backward) peak loses nothing to cancellation in f32.
fn fog_phase(cos_theta: f32) -> f32 {
    let c = clamp(cos_theta, -1.0, 1.0);
    let g = fog.g;
    let forward = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c);
    let backward = (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + c);
    let q = max(select(backward, forward, g >= 0.0), 1.17549435e-38);
    let denominator = q * sqrt(q);
    let hg = (1.0 - g * g) / (4.0 * PI * denominator);
    let printed = (1.0 - g) * (1.0 - g) / denominator;
    let shaped = select(printed, hg, fog.phase == PHASE_HENYEY_GREENSTEIN);
    return select(shaped, 1.0 / (4.0 * PI), fog.phase == PHASE_ISOTROPIC);
}

// What the fog does to a ray over [lo, hi] before any light: whether it meets the layer, where,
// and the optical depth there (0 where it does not).
struct FogSegment {
    inside: bool,
    span: vec2<f32>,
    depth: f32,
}

fn fog_segment(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32) -> FogSegment {
    var s: FogSegment;
    s.span = fog_span(o.y, d.y, lo, hi);
    s.inside = s.span.x <= s.span.y && fog.extinction > 0.0;
    s.depth = select(0.0, fog_span_depth(o.y, d.y, s.span), s.inside);
    return s;
}

// The segment's transmittance e^{−τ} (1 outside the layer: τ = 0 there).
fn fog_segment_transmittance(s: FogSegment) -> f32 {
    return select(1.0, fog_exp(s.depth), s.inside);
}

// The ambient light's factor: albedo · ambient times this is its in-scatter, 1 − e^{−τ}.
fn fog_ambient_factor(s: FogSegment) -> f32 {
    return select(0.0, fog_one_minus_exp(s.depth), s.inside);
}

// The exact sun integral ∫ σ_t e^{−τ_view} e^{−τ_sun} ds over the segment (single_scattering.rs'
// sun_integral): the total depth is affine in the view depth with slope κ = 1 − d_y / sin β, so
// the integral is e^{−E_min} (1 − e^{−|κ|τ₁}) / |κ|, from the end where E is smallest — the
// near end, or for a ray climbing faster than the sun (κ < 0, which leaves the layer: a finite
// depth) the far one.
fn fog_sun_integral(o: vec3<f32>, d: vec3<f32>, s: FogSegment, sin_b: f32) -> f32 {
    let slope = 1.0 - d.y / max(sin_b, TINY);
    let near = fog_sun_depth(o.y + d.y * s.span.x, sin_b);
    let far = min(s.depth + fog_sun_depth(o.y + d.y * s.span.y, sin_b), BIG);
    let smallest = select(far, near, slope >= 0.0);
    // A horizontal ray in the layer for ever: slope 1, ∫₀^∞ e^{−τ} dτ.
    let unbounded = 1.0 / max(abs(slope), TINY);
    let spread = select(s.depth * mean_decay(abs(slope) * s.depth), unbounded, s.depth >= BIG);
    // A sun at or below the horizon lights no point under the top through the slab.
    return select(0.0, fog_exp(smallest) * spread, sin_b > 0.0);
}

// A sun's factor along the ray (unit direction d) toward the sun at `to_sun`: albedo ·
// irradiance times this is its in-scatter — the phase times the exact integral, or the
// method's (15): the phase, the whole layer's transmittance toward the sun and 1 − e^{−τ}.
fn fog_sun_factor(o: vec3<f32>, d: vec3<f32>, s: FogSegment, to_sun: vec3<f32>) -> f32 {
    let phase = fog_phase(dot(to_sun, d));
    let method = phase * fog_exp(fog_whole_layer_depth(to_sun.y)) * fog_one_minus_exp(s.depth);
    let exact = phase * fog_sun_integral(o, d, s, to_sun.y);
    return select(0.0, select(exact, method, fog.model == FOG_METHOD), s.inside);
}

// The transmittance toward a sun at sin β = sin_b from a surface point at camera-relative
// height y (FogLayer::sun_transmittance): exact, from y to the top; the method, the whole layer
// for every point in it.
fn fog_sun_transmittance(y: f32, sin_b: f32) -> f32 {
    let depth = select(fog_sun_depth(y, sin_b), fog_whole_layer_depth(sin_b), fog.model == FOG_METHOD);
    return select(fog_exp(depth), 1.0, y > fog.top);
}

// The transmittance along the segment from p toward a point light `distance` away in unit
// direction `to_light` (FogLayer::transmittance over [0, distance]).
fn fog_point_transmittance(p: vec3<f32>, to_light: vec3<f32>, distance: f32) -> f32 {
    return fog_exp(fog_optical_depth(p, to_light, 0.0, distance));
}
