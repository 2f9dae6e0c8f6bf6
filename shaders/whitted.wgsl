// whitted.wgsl — Whitted's hooks of the shade pass (a scene whose materials reflect or
// transmit): the f32 twin of fray-trace's Integrator::whitted and of its shadow rays through
// glass. The pass shades the band's camera rays (level 0) or the queue's current level; each
// hit whose material reflects or transmits spawns its reflected and refracted rays into the
// next level — reflection about the shading normal (the face's where that points into the
// surface), Snell refraction, total internal reflection handing `kt` to the reflection,
// Fresnel-weighted if the material asks, each ray off the surface by the shadow offset to the
// side it leaves — unless its weight from the camera is below the cut-off, the ray is at the
// deepest level, or its share of the camera ray's secondary-ray budget is 0 (the shares are
// fray-trace's ray_budget rule: a ray's allowance split between the children that pass the
// cut-off, the reflected first, so the rays traced do not depend on the order the level's
// invocations run in). A ray's record (GpuSecondary) keeps its weight relative to its parent,
// its weight from the camera, its path length, its children and its allowance; the gather pass
// (whitted_gather.wgsl) adds the children's radiance back, deepest level first. A queue too small
// for a band's rays counts an overflow (the frame is rendered again in smaller bands).
//
// #if whitted
// #include "queue.wgsl"
// #include "secondary_hit.wgsl"

override TRANSMISSION: bool = true;

// The slots this dispatch shades: the band's camera rays, or the queue's current level.
fn shade_range() -> vec2<u32> {
    if queue_depth() == 0u {
        return vec2<u32>(0u, band_rays());
    }
    return queue_current();
}

// A camera ray's record: weight 1, no path behind it, no children yet, the whole budget.
fn whitted_begin(slot: u32) {
    if queue_depth() == 0u {
        secondaries[slot] = GpuSecondary(vec4<f32>(1.0, 1.0, 1.0, 0.0), vec4<f32>(1.0, 1.0, 1.0, 0.0), 0u, 0u, 0u, frame.max_secondary_rays);
    }
}

// The shares of `allowance` of a ray's `n` children that pass the cut-off (fray-trace's
// ray_budget::shares): two get ⌈a/2⌉ and ⌊a/2⌋ (the first spawned, the reflected one, the
// larger), one gets all; each share counts the child itself (0: not traced).
fn whitted_shares(allowance: u32, n: u32) -> vec2<u32> {
    if n == 2u {
        return vec2<u32>(allowance - allowance / 2u, allowance / 2u);
    }
    return vec2<u32>(allowance, 0u);
}

// The path's length from the camera to a hit at `t` along the ray of `slot` (what a texture's
// footprint grows with): the length to the ray's origin plus t.
fn whitted_path_length(slot: u32, t: f32) -> f32 {
    return secondaries[slot].weight.w + t;
}

// A secondary ray that hits nothing brings back the background (no media: fray-trace's
// miss_radiance without them).
fn whitted_miss(slot: u32) {
    if queue_depth() > 0u {
        paths[slot].radiance = vec4<f32>(frame.background.xyz, 0.0);
    }
}

// The mirror image of `d` about `n` (fray-trace's optics::reflect).
fn whitted_reflect(d: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return d - n * (2.0 * dot(d, n));
}

// The refracted direction (xyz) of `d` at normal `n` on its side, eta = n_from / n_to, and 1
// (w), or w = 0 past the critical angle (optics::refract).
fn whitted_refract(d: vec3<f32>, n: vec3<f32>, eta: f32) -> vec4<f32> {
    let cos_i = -dot(d, n);
    let sin2_t = eta * eta * max(1.0 - cos_i * cos_i, 0.0);
    if sin2_t > 1.0 {
        return vec4<f32>(0.0);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let t = d * eta + n * (eta * cos_i - cos_t);
    let len = length(t);
    if !(len > 0.0) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(t / len, 1.0);
}

// The unpolarised dielectric Fresnel reflectance (optics::fresnel_dielectric).
fn whitted_fresnel(cos_in: f32, n_from: f32, n_to: f32) -> f32 {
    let cos_i = clamp(cos_in, 0.0, 1.0);
    let eta = n_from / n_to;
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let rs = (n_from * cos_i - n_to * cos_t) / (n_from * cos_i + n_to * cos_t);
    let rp = (n_to * cos_i - n_from * cos_t) / (n_to * cos_i + n_from * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

fn max3(v: vec3<f32>) -> f32 {
    return max(v.x, max(v.y, v.z));
}

// The secondary rays of the hit at `p` (at distance `t` along the ray of `slot`, direction `d`)
// with outward normals `geometric` and `shading` and material `m`, into the next level.
fn whitted_spawn(slot: u32, p: vec3<f32>, d: vec3<f32>, geometric: vec3<f32>, shading: vec3<f32>, m: GpuMaterial, t: f32) {
    let record = secondaries[slot];
    if record.depth >= frame.max_depth {
        return;
    }
    // With anti-aliasing a pixel's centre ray gives depth and normal only.
    if record.depth == 0u && frame.rays_per_pixel > 1u && slot % frame.rays_per_pixel == 0u {
        return;
    }
    var kr = m.reflect.xyz;
    var kt = m.transmit.xyz;
    let transmits = any(kt != vec3<f32>(0.0));
    if !(transmits || any(kr != vec3<f32>(0.0))) {
        return;
    }
    // Both normals on the side the ray arrives from.
    let front = dot(d, geometric) <= 0.0;
    let side = select(-1.0, 1.0, front);
    let ng = geometric * side;
    var ns = shading * side;
    if !(dot(ns, ng) > 0.0) {
        ns = ng;
    }
    let ior = m.reflect.w;
    let n_from = select(ior, 1.0, front);
    let n_to = select(1.0, ior, front);
    var refracted = vec4<f32>(0.0);
    if transmits {
        let eta = n_from / n_to;
        refracted = whitted_refract(d, ns, eta);
        if refracted.w == 0.0 || !(dot(refracted.xyz, ng) < 0.0) {
            refracted = whitted_refract(d, ng, eta);
        }
        if m.transmit.w > 0.5 {
            let f = whitted_fresnel(-dot(d, ns), n_from, n_to);
            kr += kt * f;
            kt *= 1.0 - f;
        }
        if refracted.w == 0.0 {
            // Total internal reflection: what would have been transmitted is reflected.
            kr += kt;
            kt = vec3<f32>(0.0);
        }
    }
    let offset = frame.shadow_offset;
    var origins: array<vec3<f32>, 2>;
    var dirs: array<vec3<f32>, 2>;
    var weights: array<vec3<f32>, 2>;
    var n = 0u;
    if any(kr != vec3<f32>(0.0)) {
        var r = whitted_reflect(d, ns);
        // Reflected about a shading normal, a grazing ray may point into the surface.
        if !(dot(r, ng) > 0.0) {
            r = whitted_reflect(d, ng);
        }
        if max3(record.throughput.xyz * kr) >= frame.min_contribution && dot(r, r) > 0.0 {
            origins[n] = p + ng * offset;
            dirs[n] = normalize(r);
            weights[n] = kr;
            n++;
        }
    }
    if refracted.w > 0.0 && any(kt != vec3<f32>(0.0))
        && max3(record.throughput.xyz * kt) >= frame.min_contribution {
        origins[n] = p - ng * offset;
        dirs[n] = refracted.xyz;
        weights[n] = kt;
        n++;
    }
    // Only the children with a share of the budget are traced.
    let shares = whitted_shares(record.allowance, n);
    var allowances: array<u32, 2>;
    var kept = 0u;
    for (var i = 0u; i < n; i++) {
        if shares[i] > 0u {
            origins[kept] = origins[i];
            dirs[kept] = dirs[i];
            weights[kept] = weights[i];
            allowances[kept] = shares[i] - 1u;
            kept++;
        }
    }
    n = kept;
    if n == 0u {
        return;
    }
    let base = atomicAdd(&counters[WORD_QUEUE_TOP], n);
    if base + n > frame.queue_capacity {
        atomicAdd(&counters[WORD_QUEUE_OVERFLOWS], 1u);
        return;
    }
    let first = band_rays() + base;
    for (var i = 0u; i < n; i++) {
        var child: GpuPath;
        child.origin = vec4<f32>(origins[i], 0.0);
        child.dir = vec4<f32>(dirs[i], 1.0);
        child.hit = vec4<f32>(NO_HIT, 0.0, 0.0, 0.0);
        paths[first + i] = child;
        secondaries[first + i] = GpuSecondary(
            vec4<f32>(weights[i], record.weight.w + t),
            vec4<f32>(record.throughput.xyz * weights[i], 0.0),
            0u,
            0u,
            record.depth + 1u,
            allowances[i],
        );
    }
    secondaries[slot].first_child = first;
    secondaries[slot].children = n;
}

fn whitted_transmits() -> bool {
    return TRANSMISSION;
}

// The RGB transmittance of a shadow ray from `o` along `d` over (0, distance) through a scene
// with transmissive materials (transmittance_through_surfaces): the product of `kt` over every
// surface it crosses, 0 at the first opaque one or past MAX_SHADOW_CROSSINGS; each search starts
// twice the surface offset past the last crossing.
fn whitted_transmittance(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> vec3<f32> {
    var total = vec3<f32>(1.0);
    var lo = 0.0;
    for (var i = 0u; i < MAX_SHADOW_CROSSINGS; i++) {
        let start = o + d * lo;
        let h = nearest_from_surface(start, d, distance - lo, eps);
        if h.t < 0.0 {
            return total;
        }
        let m = materials[surface_hit_material(h, start, d)];
        if all(m.transmit.xyz == vec3<f32>(0.0)) {
            return vec3<f32>(0.0);
        }
        total *= m.transmit.xyz;
        if all(total == vec3<f32>(0.0)) {
            return total;
        }
        lo += h.t + 2.0 * frame.shadow_offset;
        if lo >= distance {
            return total;
        }
    }
    return vec3<f32>(0.0);
}

// #else
// Without it: the Whitted hooks of the shade pass in a scene whose materials neither
// reflect nor transmit: it shades the band's camera rays, spawns nothing, and shadow rays stop at
// the first surface (no Whitted code or binding compiled).

fn shade_range() -> vec2<u32> {
    return vec2<u32>(0u, frame.width * frame.band_rows * frame.rays_per_pixel);
}

fn whitted_begin(slot: u32) {}

// The path's length from the camera to a hit at `t` along the ray of `slot`: t.
fn whitted_path_length(slot: u32, t: f32) -> f32 {
    return t;
}

fn whitted_miss(slot: u32) {}

fn whitted_spawn(slot: u32, p: vec3<f32>, d: vec3<f32>, geometric: vec3<f32>, shading: vec3<f32>, m: GpuMaterial, t: f32) {}

fn whitted_transmits() -> bool {
    return false;
}

fn whitted_transmittance(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> vec3<f32> {
    return vec3<f32>(1.0);
}
// #endif
