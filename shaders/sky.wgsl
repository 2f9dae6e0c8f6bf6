// sky.wgsl — the physically based sky in f32, the twin of fray_atmosphere::sky (docs/sky.md
// gives every parameterisation): rays by altitude and direction cosine over a spherical planet,
// the transmittance table (Bruneton's (r, μ) mapping, texel centres, bilinear on the optical
// depth τ, then e^{−τ}), the sky-view table (Hillaire's mapping, bilinear within the half of the
// horizon a ray is on), the sun's disc, the Rayleigh and Cornette–Shanks phases, the densities
// with the ozone tent, and the aerial-perspective march exactly as march.rs places and samples
// its steps. No bindings: it reads `sky` (a GpuSky from fray_atmosphere::gpu_layout, written per
// frame in f64), `sky_transmittance_table` and `sky_view_table` (the tables' [f32; 4] texels as
// textures) from the including module's groups.
//
// f32 care: the planet's radii are ≈ 6.4e6 m, where f32 keeps half a metre, so no altitude is
// ever `r − R_g`: every point carries its altitude h (from the eye's, computed in f64) and the
// radius `R_g + h` is only used where relative precision suffices (products with μ, ratios).
// Along a ray from radius r0 with cosine μ, `r(t) − r0 = t (t + 2 r0 μ) / (r(t) + r0)`, and the
// radii's squared differences are `r² − R² = (r − R)(r + R)` from altitudes. Like fog.wgsl the
// code is straight-line where it can be — both sides computed, one selected; every divisor kept
// off zero (SKY_TINY) — since lavapipe's compiler crashes on an `exp` under a branch that
// depends on the hit point.
//
// #include "ray.wgsl"
// #include "decay.wgsl"

// The smallest divisor: keeps the cases a lane does not select finite.
const SKY_TINY: f32 = 1.0e-30;

// r = R_g + h for an altitude h.
fn sky_radius(h: f32) -> f32 {
    return sky.ground_radius + h;
}

// r² − R_g² = h (2 R_g + h), from the altitude (no cancellation).
fn sky_rho2(h: f32) -> f32 {
    return h * (2.0 * sky.ground_radius + h);
}

// Whether the ray from altitude h ≥ 0 with direction cosine mu meets the ground (Planet::
// hits_ground: μ < 0 and (rμ)² − (r² − R_g²) ≥ 0; a tangent ray meets it).
fn sky_hits_ground(h: f32, mu: f32) -> bool {
    let rm = sky_radius(h) * mu;
    return mu < 0.0 && rm * rm - sky_rho2(h) >= 0.0;
}

// The distance to the ground along a ray that meets it (Planet::distance_to_ground:
// (r² − R_g²) / (−rμ + √disc), 0 for an eye on the ground).
fn sky_distance_to_ground(h: f32, mu: f32) -> f32 {
    let r = sky_radius(h);
    let num = max(sky_rho2(h), 0.0);
    let disc = max((r * mu) * (r * mu) - num, 0.0);
    let den = -r * mu + sqrt(disc);
    return select(0.0, num / max(den, SKY_TINY), den > 0.0);
}

// R_t² − r² = (Z − h)(2 R_g + Z + h), Z the top's altitude.
fn sky_to_top2(h: f32) -> f32 {
    return (sky.top_altitude - h) * (2.0 * sky.ground_radius + sky.top_altitude + h);
}

// The distance from altitude h ≤ Z to the top of the atmosphere (Planet::distance_to_top):
// (R_t² − r²) / (rμ + √disc) looking up, −rμ + √disc looking down (no cancellation either way).
fn sky_distance_to_top(h: f32, mu: f32) -> f32 {
    let r = sky_radius(h);
    let num = max(sky_to_top2(h), 0.0);
    let root = sqrt(max((r * mu) * (r * mu) + sky_to_top2(h), 0.0));
    let den = r * mu + root;
    let up = select(0.0, num / max(den, SKY_TINY), den > 0.0);
    return select(-r * mu + root, up, mu >= 0.0);
}

// Bilinear interpolation of `table` (texel centres at integers; texels_per_row wide) at (x, y),
// x clamped to the table and y to the rows [row_lo, row_hi] (fray_atmosphere's texels.rs
// `bilinear`, in f32).
fn sky_bilinear(table: texture_2d<f32>, texels_per_row: u32, x_in: f32, y_in: f32, row_lo: u32, row_hi: u32) -> vec3<f32> {
    let x_max = f32(texels_per_row - 1u);
    // NaN falls to the first texel (max/min drop it where clamp keeps it).
    let x = min(max(x_in, 0.0), x_max);
    let y = min(max(y_in, f32(row_lo)), f32(row_hi));
    let i0 = min(u32(floor(x)), texels_per_row - 1u);
    let j0 = clamp(u32(floor(y)), row_lo, row_hi);
    let i1 = min(i0 + 1u, texels_per_row - 1u);
    let j1 = min(j0 + 1u, row_hi);
    let fx = x - f32(i0);
    let fy = y - f32(j0);
    let a = textureLoad(table, vec2<u32>(i0, j0), 0).xyz;
    let b = textureLoad(table, vec2<u32>(i1, j0), 0).xyz;
    let c = textureLoad(table, vec2<u32>(i0, j1), 0).xyz;
    let d = textureLoad(table, vec2<u32>(i1, j1), 0).xyz;
    let top = a * (1.0 - fx) + b * fx;
    let bottom = c * (1.0 - fx) + d * fx;
    return top * (1.0 - fy) + bottom * fy;
}

// The transmittance from altitude h toward cosine mu to the top of the atmosphere
// (TransmittanceTable::lookup): h clamped to [0, Z]; 0 if the ray meets the ground; else
// e^{−τ}, τ bilinear at the texel coordinates (x_μ (W − 1), x_r (H − 1)) of Bruneton's mapping
// x_μ = (d − d_min) / (d_max − d_min), x_r = ρ / H_top.
fn sky_transmittance(h_in: f32, mu_in: f32) -> vec3<f32> {
    // NaN falls to the ground looking up, as on the CPU.
    let h = select(clamp(h_in, 0.0, sky.top_altitude), 0.0, h_in != h_in);
    let mu = select(clamp(mu_in, -1.0, 1.0), 1.0, mu_in != mu_in);
    let rho = sqrt(max(sky_rho2(h), 0.0));
    let d = sky_distance_to_top(h, mu);
    let d_min = sky.top_altitude - h;
    let d_max = rho + sky.horizon_distance;
    let x_mu = select(0.0, (d - d_min) / max(d_max - d_min, SKY_TINY), d_max > d_min);
    let x_r = rho / sky.horizon_distance;
    let w = sky.transmittance_width;
    let rows = sky.transmittance_height;
    let x = clamp(x_mu, 0.0, 1.0) * f32(w - 1u);
    let y = clamp(x_r, 0.0, 1.0) * f32(rows - 1u);
    let tau = sky_bilinear(sky_transmittance_table, w, x, y, 0u, rows - 1u);
    return select(exp(-tau), vec3<f32>(0.0), sky_hits_ground(h, mu));
}

// atan(a) for a ∈ [0, 1], to a few f32 ulps (Cephes' atanf: a reduction by tan(π/8) and an
// odd polynomial). The driver's atan2 and acos may be far coarser — Vulkan allows 4096 ulps —
// and the sky-view table's rows crowd toward the horizon so steeply that a zenith angle off by
// 10⁻⁴ rad moves a lookup there by a third of a row; so the sky takes its angles from here.
fn sky_atan01(a: f32) -> f32 {
    let reduced = a > 0.41421356237;
    let x = select(a, (a - 1.0) / (a + 1.0), reduced);
    let z = x * x;
    let p = (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * x + x;
    return select(p, 0.785398163397448 + p, reduced);
}

// atan2(y, x) ∈ [0, π] for y ≥ 0, from sky_atan01 (0 for y = x = 0).
fn sky_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let r = sky_atan01(min(y, ax) / max(max(y, ax), SKY_TINY));
    let quadrant = select(r, 0.5 * PI - r, y > ax);
    return select(quadrant, PI - quadrant, x < 0.0);
}

// The unit direction of `dir` (+Y for a zero one, as the CPU's try_normalize fallback).
fn sky_unit(dir: vec3<f32>) -> vec3<f32> {
    let len = length(dir);
    return select(vec3<f32>(0.0, 1.0, 0.0), dir / max(len, SKY_TINY), len > 0.0);
}

// The sky's in-scattered radiance toward the eye along `dir`, from the sky-view table
// (SkyViewTable::lookup): column φ/π (W − 1) with φ the azimuth from the sun's; the ground half
// (the ray meets the ground) at row h + √((θ − θ_h)/β)(h − 1), the sky half at
// (1 − √(1 − θ/θ_h))(h − 1), h = H/2, each interpolated within its own rows only. Both rows
// depend on θ_h − θ, the direction's angle above the dipped horizon: it is taken as the
// direction's elevation plus the horizon's dip (from f64), not as a difference of two angles
// near π/2 — the rows crowd so steeply at the horizon that f32 would move a lookup there.
fn sky_view_lookup(dir: vec3<f32>) -> vec3<f32> {
    let d = sky_unit(dir);
    let mu = clamp(d.y, -1.0, 1.0);
    let elevation = sky_atan2(abs(d.y), length(d.xz)) * select(1.0, -1.0, d.y < 0.0);
    let above = elevation + sky.horizon_dip;
    let half = sky.view_height / 2u;
    let rows = f32(half - 1u);
    let phi = sky_atan2(abs(dot(d, sky.sun_side.xyz)), dot(d, sky.sun_horizontal.xyz));
    let x = phi / PI * f32(sky.view_width - 1u);
    let ground = sky_hits_ground(sky.eye_altitude, mu);
    let c_ground = sqrt(clamp(-above / sky.horizon_nadir, 0.0, 1.0));
    let c_sky = 1.0 - sqrt(max(above / sky.horizon_zenith, 0.0));
    let y = select(c_sky * rows, f32(half) + c_ground * rows, ground);
    let lo = select(0u, half, ground);
    let hi = select(half - 1u, sky.view_height - 1u, ground);
    return sky_bilinear(sky_view_table, sky.view_width, x, y, lo, hi);
}

// The transmittance from the eye along the unit direction d out of the atmosphere
// (SkyView::transmittance): 0 into the ground; from above the top, from where the ray enters
// the shell (its cosine there is −√disc / R_t: the entry point's rμ is rμ + t0 = −√disc, written
// so to keep f32 from cancelling), 1 for a ray that misses the shell.
fn sky_view_transmittance(d: vec3<f32>) -> vec3<f32> {
    let mu = clamp(d.y, -1.0, 1.0);
    let h = sky.eye_altitude;
    let rm = sky.eye_radius * mu;
    let disc = rm * rm + sky_to_top2(h);
    let entry = clamp(-sqrt(max(disc, 0.0)) / sky.top_radius, -1.0, 1.0);
    let misses = mu >= 0.0 || disc < 0.0;
    let from_above = select(sky_transmittance(sky.top_altitude, entry), vec3<f32>(1.0), misses);
    let through = select(from_above, sky_transmittance(h, mu), h <= sky.top_altitude);
    return select(through, vec3<f32>(0.0), sky_hits_ground(h, mu));
}

// The sun's disc alone along the unit direction d (SkyView::sun_disc): E/Ω through the view
// transmittance inside the disc, 0 outside (the test |d − s|² ≤ 4 sin²(α/2) is d·s ≥ cos α).
fn sky_sun_disc(d: vec3<f32>) -> vec3<f32> {
    let e = d - sky.sun_direction.xyz;
    let inside = dot(e, e) <= sky.sun_direction.w;
    return select(vec3<f32>(0.0), sky.sun_radiance.xyz * sky_view_transmittance(d), inside);
}

// The radiance of a camera ray along the unit direction d that hits nothing, before any fog
// (fray-trace's Media::background): the table, and the disc where the scene draws it.
fn sky_background(d: vec3<f32>) -> vec3<f32> {
    let disc = select(vec3<f32>(0.0), sky_sun_disc(d), (sky.flags & SKY_SUN_DISC) != 0u);
    return sky_view_lookup(d) + disc;
}

// The transmittance of sunlight from the top of the atmosphere to the camera-relative point p
// (Sky::transmittance_to_sun): the point at q = p + (0, r_eye, 0) from the planet's centre, its
// altitude the eye's plus |q| − r_eye = (|p|² + 2 p.y r_eye) / (|q| + r_eye) (at least the
// ground's), and the table at its cosine to the sun.
fn sky_transmittance_to_sun(p: vec3<f32>) -> vec3<f32> {
    let re = sky.eye_radius;
    let l = sky.sun_direction.xyz;
    let s = dot(p, p) + 2.0 * p.y * re;
    let len = sqrt(max(s + re * re, 0.0));
    let h = max(sky.eye_altitude + s / max(len + re, SKY_TINY), 0.0);
    let mu = select(1.0, clamp((dot(p, l) + re * l.y) / max(len, SKY_TINY), -1.0, 1.0), len > 0.0);
    return sky_transmittance(h, mu);
}

// Rayleigh's phase 3/(16π)(1 + ν²).
fn sky_rayleigh(nu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + nu * nu);
}

// Cornette–Shanks' phase 3/(8π)(1 − g²)(1 + ν²)/((2 + g²)(1 + g² − 2gν)^{3/2}) for the unit view
// direction d and sun direction l (ν = d·l). 1 + g² − 2gν is summed from non-negative terms —
// (1 − g)² + g|d − l|² for g ≥ 0, (1 + g)² − g|d + l|² for g < 0 (|d ∓ l|² = 2(1 ∓ ν)) — so the
// forward peak loses nothing to cancellation in f32.
fn sky_cornette_shanks(d: vec3<f32>, l: vec3<f32>, nu: f32) -> f32 {
    let g = sky.mie_g;
    let e = d - l;
    let f = d + l;
    let forward = (1.0 - g) * (1.0 - g) + g * dot(e, e);
    let backward = (1.0 + g) * (1.0 + g) - g * dot(f, f);
    let q = max(select(backward, forward, g >= 0.0), 1.17549435e-38);
    return 3.0 / (8.0 * PI) * (1.0 - g * g) * (1.0 + nu * nu) / ((2.0 + g * g) * q * sqrt(q));
}

// The in-scatter and transmittance of a path (ScatterTerms).
struct SkyScatter {
    in_scatter: vec3<f32>,
    transmittance: vec3<f32>,
}

// The constants of one march: the ray from radius r0 (altitude h0) with cosine mu toward unit d.
struct SkyRay {
    h0: f32,
    r0: f32,
    mu: f32,
    nu: f32,
    p_r: f32,
    p_m: f32,
}

// r(t) − r0 along the ray (Planet::radius_at minus r0), from t (t + 2 r0 μ) without cancellation.
fn sky_rise(r0: f32, mu: f32, t: f32) -> f32 {
    let q = t * (t + 2.0 * r0 * mu);
    let r = sqrt(max(q + r0 * r0, 0.0));
    return q / max(r + r0, SKY_TINY);
}

// The part of the ray from altitude h0 with cosine mu inside the atmosphere, stopped on the
// ground and at t_max (Planet::segment with ground_stops); x ≥ y when it has none. An eye above
// the top enters the shell later, or never.
fn sky_segment(h0: f32, mu: f32, t_max: f32) -> vec2<f32> {
    let r = sky_radius(h0);
    let inside = h0 <= sky.top_altitude;
    let num = -sky_to_top2(h0);
    let disc = (r * mu) * (r * mu) - num;
    let root = sqrt(max(disc, 0.0));
    let never = !inside && (mu >= 0.0 || disc < 0.0);
    let t0 = select(num / max(-r * mu + root, SKY_TINY), 0.0, inside);
    var t1 = select(-r * mu + root, sky_distance_to_top(h0, mu), inside);
    t1 = select(t1, min(t1, sky_distance_to_ground(h0, mu)), sky_hits_ground(h0, mu));
    // `!(t_max > 0)` also catches NaN: an empty path.
    t1 = min(t1, select(0.0, t_max, t_max > 0.0));
    return select(vec2<f32>(t0, t1), vec2<f32>(0.0, 0.0), never || !(t1 > t0));
}

// Where the planet's shadow starts or stops along the ray (Planet::sun_tangent_crossings of the
// ground, kept where t0 < t < t1 and the sun ray leaves the point toward the planet, P·l < 0):
// the real roots of a t² + b t + c by the stable form, sorted, BIG for none.
fn sky_shadow_edges(ray: SkyRay, mu_sun: f32, t0: f32, t1: f32) -> vec2<f32> {
    let r = ray.r0;
    let a = (ray.nu - 1.0) * (ray.nu + 1.0);
    let b = 2.0 * r * (mu_sun * ray.nu - ray.mu);
    let c = (r * mu_sun) * (r * mu_sun) - sky_rho2(ray.h0);
    let disc = b * b - 4.0 * a * c;
    let real = disc >= 0.0;
    let q = -0.5 * (b + select(-1.0, 1.0, b >= 0.0) * sqrt(max(disc, 0.0)));
    let e1 = q / select(a, 1.0, a == 0.0);
    let e2 = c / select(q, 1.0, q == 0.0);
    let ok1 = real && a != 0.0 && e1 > t0 && e1 < t1 && r * mu_sun + e1 * ray.nu < 0.0;
    let ok2 = real && q != 0.0 && e2 > t0 && e2 < t1 && r * mu_sun + e2 * ray.nu < 0.0;
    let u = select(BIG, e1, ok1);
    let v = select(BIG, e2, ok2);
    return vec2<f32>(min(u, v), max(u, v));
}

// One step of length `len` sampled at t (march.rs `step`): the sun's transmittance from the
// table at the sample (0 where its ray meets the ground), the densities, and the step's
// in-scatter integrated exactly for constant coefficients, T σ_s p T_sun (1 − e^{−σ_t Δ})/σ_t,
// before T ← T e^{−σ_t Δ}. A zero length adds nothing and keeps T.
fn sky_step(ray: SkyRay, t: f32, len: f32, sums: SkyScatter) -> SkyScatter {
    let l = sky.sun_direction.xyz;
    let rise = sky_rise(ray.r0, ray.mu, t);
    let r = ray.r0 + rise;
    let h = max(ray.h0 + rise, 0.0);
    let mu_sun = select(1.0, (ray.r0 * l.y + t * ray.nu) / max(r, SKY_TINY), r > 0.0);
    let sun_t = sky_transmittance(h, mu_sun);
    let rho_r = exp(-h / sky.rayleigh.w);
    let rho_m = exp(-h / sky.mie_scale_height);
    let rho_o = max(1.0 - abs(h - sky.ozone.w) / sky.ozone_half_width, 0.0);
    let extinction = sky.rayleigh.xyz * rho_r + vec3<f32>(sky.mie_extinction * rho_m) + sky.ozone.xyz * rho_o;
    let scattering = sky.rayleigh.xyz * (rho_r * ray.p_r) + vec3<f32>(sky.mie_scattering * rho_m * ray.p_m);
    let weight = len * mean_decay3(extinction * len);
    var out: SkyScatter;
    out.in_scatter = sums.in_scatter + sums.transmittance * scattering * sun_t * weight;
    out.transmittance = sums.transmittance * exp(-extinction * len);
    return out;
}

// A piece [a, b] of the segment, crowded toward a (`dense_at_start`) or b, with n steps and the
// crowding exponent p.
struct SkyPiece {
    a: f32,
    b: f32,
    dense_at_start: bool,
    n: u32,
    p: f32,
}

fn sky_piece(ray: SkyRay, a: f32, b: f32, dense_at_start: bool, n: u32) -> SkyPiece {
    // Crowd only as much as the density changes: 1 (uniform) for a level piece, 2 for one that
    // climbs two Rayleigh scale heights or more.
    let climb = abs(sky_rise(ray.r0, ray.mu, b) - sky_rise(ray.r0, ray.mu, a));
    return SkyPiece(a, b, dense_at_start, n, 1.0 + min(climb / (2.0 * sky.rayleigh.w), 1.0));
}

// t at fraction k of the piece's steps from its dense end (march.rs: x = k/n from the dense end,
// t = a + L xᵖ or b − L xᵖ; xᵖ exact for p = 1 and at x = 0).
fn sky_piece_at(piece: SkyPiece, k: f32) -> f32 {
    let n = f32(piece.n);
    let x = select(1.0 - k / n, k / n, piece.dense_at_start);
    let xp = select(select(pow(x, piece.p), x, piece.p == 1.0), 0.0, x <= 0.0);
    let length = piece.b - piece.a;
    return select(piece.b - length * xp, piece.a + length * xp, piece.dense_at_start);
}

// Single scattering and transmittance over [t0, t1] of the ray (march.rs `march`): cut at the
// perigee t_p = −r0 μ when t0 < t_p < t1 and steps ≥ 2 — n₁ = clamp(round(N (t_p − t0)/(t1 − t0)),
// 1, N − 1) steps before it, N − n₁ after — else N steps over the whole, crowded at the end
// nearer the perigee; a step containing a shadow edge is taken as two, split there (at most
// one edge per step). Every step runs two samples, the second of zero length unless split.
fn sky_march(ray: SkyRay, t0: f32, t1: f32, steps: u32) -> SkyScatter {
    var sums: SkyScatter;
    sums.in_scatter = vec3<f32>(0.0);
    sums.transmittance = vec3<f32>(1.0);
    let l = sky.sun_direction.xyz;
    let edges = sky_shadow_edges(ray, l.y, t0, t1);
    let tp = -ray.r0 * ray.mu;
    let n = max(steps, 1u);
    let cut = n >= 2u && tp > t0 && tp < t1;
    // round() half away from zero, as Rust's (WGSL's rounds half to even); the share is ≥ 0.
    let share = floor(f32(n) * (tp - t0) / max(t1 - t0, SKY_TINY) + 0.5);
    let n1 = select(n, clamp(u32(max(share, 0.0)), 1u, max(n, 2u) - 1u), cut);
    let first = sky_piece(ray, t0, select(t1, tp, cut), select(tp <= t0, false, cut), n1);
    let second = sky_piece(ray, tp, t1, true, n - n1);
    for (var k = 0u; k < n; k++) {
        let later = k >= n1;
        var piece = first;
        if later {
            piece = second;
        }
        let kk = f32(select(k, k - n1, later));
        let lo = sky_piece_at(piece, kk);
        let hi = sky_piece_at(piece, kk + 1.0);
        let in0 = edges.x > lo && edges.x < hi;
        let in1 = edges.y > lo && edges.y < hi;
        let split = in0 || in1;
        let e = select(edges.y, edges.x, in0);
        let t_a = select(sky_piece_at(piece, kk + 0.5), 0.5 * (lo + e), split);
        let len_a = select(abs(hi - lo), e - lo, split);
        sums = sky_step(ray, t_a, len_a, sums);
        sums = sky_step(ray, 0.5 * (e + hi), select(0.0, hi - e, split), sums);
    }
    sums.in_scatter *= sky.sun_irradiance.xyz;
    return sums;
}

// The aerial perspective of a surface t along the camera-relative ray o + s d (unit d)
// (Sky::aerial_perspective): the air over [0, t] from the ray's origin — the planet's centre
// below it, at altitude eye_height + o.y clamped to [0, max_altitude] — clipped to the shell and
// stopped on the ground, in `sky.steps` steps; t ≤ 0 (or NaN) is the empty path.
fn sky_aerial_perspective(o: vec3<f32>, d: vec3<f32>, t: f32) -> SkyScatter {
    let h0 = clamp(sky.eye_height + o.y, 0.0, sky.max_altitude);
    let mu = clamp(d.y, -1.0, 1.0);
    let nu = clamp(dot(d, sky.sun_direction.xyz), -1.0, 1.0);
    let ray = SkyRay(h0, sky_radius(h0), mu, nu, sky_rayleigh(nu), sky_cornette_shanks(d, sky.sun_direction.xyz, nu));
    let segment = sky_segment(h0, mu, t);
    return sky_march(ray, segment.x, segment.y, sky.steps);
}
