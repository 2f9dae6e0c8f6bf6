// clouds.wgsl — the cloud volume in f32, the twin of fray_clouds::march (docs/methods.md §6): the density
// grid's trilinear samples (cell-centred, clamped to the edge, exactly DensityGrid::sample; the
// grid is an r32float 3D texture read with textureLoad, no sampler), the max grid's empty-space
// skipping (MaxGrid::block_at: a block whose bound is 0 is jumped past), the march of a ray
// clipped to the box in equal jittered steps with a sun ray of `sun_steps` midpoint samples at
// every sample with density, the dual-lobe Henyey–Greenstein phase, the exact per-step
// `1 − e^{−σΔ}`, the early exit; the optical depth of a shadow ray; Jimenez's interleaved
// gradient noise for the per-pixel jitter. No bindings: it reads `clouds` (a GpuClouds from
// fray_clouds::gpu_layout, camera-relative, written per frame from f64), `cloud_density` and
// `cloud_max` from the including module's groups.
//
// #include "ray.wgsl"

// The density grid's value at integer sample (i, j, k), clamped to the grid.
fn cloud_texel(i: i32, j: i32, k: i32) -> f32 {
    let n = vec3<i32>(clouds.grid_size.xyz) - vec3<i32>(1);
    let c = clamp(vec3<i32>(i, j, k), vec3<i32>(0), n);
    return textureLoad(cloud_density, c, 0).x;
}

// The trilinear interpolation at `u` in the unit cube (DensityGrid::sample): samples at cell
// centres, clamped to the edge samples outside.
fn cloud_sample(u: vec3<f32>) -> f32 {
    let x = u * vec3<f32>(clouds.grid_size.xyz) - vec3<f32>(0.5);
    let f = floor(x);
    let t = x - f;
    let b = vec3<i32>(f);
    let c000 = cloud_texel(b.x, b.y, b.z);
    let c100 = cloud_texel(b.x + 1, b.y, b.z);
    let c010 = cloud_texel(b.x, b.y + 1, b.z);
    let c110 = cloud_texel(b.x + 1, b.y + 1, b.z);
    let c001 = cloud_texel(b.x, b.y, b.z + 1);
    let c101 = cloud_texel(b.x + 1, b.y, b.z + 1);
    let c011 = cloud_texel(b.x, b.y + 1, b.z + 1);
    let c111 = cloud_texel(b.x + 1, b.y + 1, b.z + 1);
    let y0 = mix_exact(mix_exact(c000, c100, t.x), mix_exact(c010, c110, t.x), t.y);
    let y1 = mix_exact(mix_exact(c001, c101, t.x), mix_exact(c011, c111, t.x), t.y);
    return mix_exact(y0, y1, t.z);
}

// a + t (b − a), as the CPU's lerp (WGSL's mix may be a (1 − t) + b t).
fn mix_exact(a: f32, b: f32, t: f32) -> f32 {
    return a + t * (b - a);
}

// The point's unit-cube coordinates in the grid.
fn cloud_unit(p: vec3<f32>) -> vec3<f32> {
    return (p - clouds.region_min.xyz) / clouds.extent.xyz;
}

// The extinction (1/m) at camera-relative p: scale × the grid's sample inside the box, 0
// outside (GridVolume::density).
fn cloud_density_at(p: vec3<f32>) -> f32 {
    let inside = all(p >= clouds.region_min.xyz) && all(p <= clouds.region_max.xyz);
    return select(0.0, clouds.scale * cloud_sample(cloud_unit(p)), inside);
}

// Empty-space skipping (GridVolume::empty_for): if the max grid's block holding p has bound 0,
// the distance along d (unit) to where the ray leaves the block (the first and last blocks reach
// out to ±∞ along each axis); −1 where the density is not known to be zero.
fn cloud_empty_for(p: vec3<f32>, d: vec3<f32>) -> f32 {
    if clouds.grid_size.w == 0u {
        return -1.0;
    }
    let u = cloud_unit(p);
    let n = vec3<f32>(clouds.grid_size.xyz);
    let block = clouds.blocks.w;
    let cell = vec3<u32>(clamp(floor(u * n), vec3<f32>(0.0), n - vec3<f32>(1.0)));
    let index = min(cell / vec3<u32>(block), clouds.blocks.xyz - vec3<u32>(1u));
    let bound = textureLoad(cloud_max, vec3<i32>(index), 0).x;
    if bound > 0.0 {
        return -1.0;
    }
    // The block's box in unit coordinates, clipped in them (the ray's parameter is the world's:
    // o_u + t d_u with d_u = d / extent).
    let lo = select(vec3<f32>(index * block) / n, vec3<f32>(-BIG), index == vec3<u32>(0u));
    let hi = select(vec3<f32>((index + vec3<u32>(1u)) * block) / n, vec3<f32>(BIG), index + vec3<u32>(1u) == clouds.blocks.xyz);
    let span = clip_box(lo, hi, u, d / clouds.extent.xyz, 0.0, BIG);
    return select(-1.0, span.y, span.x <= span.y);
}

// Henyey–Greenstein's lobe of asymmetry g at cos θ (1/sr).
fn cloud_hg(g: f32, cos_theta: f32) -> f32 {
    let d = max(1.0 + g * g - 2.0 * g * clamp(cos_theta, -1.0, 1.0), 1.0e-30);
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

// The dual-lobe phase (DualLobe::eval).
fn cloud_phase(cos_theta: f32) -> f32 {
    return (1.0 - clouds.weight) * cloud_hg(clouds.g1, cos_theta) + clouds.weight * cloud_hg(clouds.g2, cos_theta);
}

// The transmittance from p toward the sun (s, unit) out of the box by `sun_steps` midpoint
// samples (march.rs's sun_transmittance).
fn cloud_sun_transmittance(p: vec3<f32>, s: vec3<f32>) -> f32 {
    let span = clip_box(clouds.region_min.xyz, clouds.region_max.xyz, p, s, 0.0, BIG);
    let out = select(0.0, span.y, span.x <= span.y);
    let steps = clouds.sun_steps;
    let ds = out / f32(max(steps, 1u));
    // Not skipped, as on the CPU: a block lookup costs about what a sample does.
    var depth = 0.0;
    for (var k = 0u; k < steps; k++) {
        let u = (f32(k) + 0.5) * ds;
        depth += cloud_density_at(p + s * u) * ds;
    }
    return exp(-depth);
}

// Σ σ(o + t d) dt over the midpoints t = lo + (k + ½) dt, k < steps, jumping over what the max
// grid proves empty (fray_clouds::march's midpoint_depth: the same sum).
fn cloud_midpoint_depth(o: vec3<f32>, d: vec3<f32>, lo: f32, dt: f32, steps: u32) -> f32 {
    var depth = 0.0;
    var k = 0u;
    loop {
        if k >= steps {
            break;
        }
        let t = lo + (f32(k) + 0.5) * dt;
        let p = o + d * t;
        let empty = cloud_empty_for(p, d);
        if empty >= 0.0 {
            let next = ceil((t + empty - lo) / dt - 0.5);
            k = select(k + 1u, u32(min(next, f32(steps))), next > f32(k));
            continue;
        }
        k++;
        depth += cloud_density_at(p) * dt;
    }
    return depth;
}

// What the cloud does to a ray: L = transmittance · L_behind + in_scatter (MarchResult).
struct CloudMarch {
    transmittance: f32,
    in_scatter: vec3<f32>,
    samples: u32,
}

// The march of o + t d (d unit) over [t0, t1] (fray_clouds::march::march), its samples at
// lo + (k + jitter) dt.
fn cloud_march(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32, jitter_in: f32) -> CloudMarch {
    var result = CloudMarch(1.0, vec3<f32>(0.0), 0u);
    let span = clip_box(clouds.region_min.xyz, clouds.region_max.xyz, o, d, t0, t1);
    let lo = span.x;
    let length = select(0.0, span.y - span.x, span.x <= span.y);
    if !(length > 0.0) || !(clouds.step > 0.0) {
        return result;
    }
    let steps = u32(min(ceil(length / clouds.step), 1.0e7));
    let dt = length / f32(steps);
    let s = clouds.sun_direction.xyz;
    // The light travels along −s and is scattered toward the eye, along −d: cos θ = s · d.
    let phase = cloud_phase(dot(s, d));
    let sun_light = clouds.sun_irradiance.xyz * phase;
    let jitter = clamp(jitter_in, 0.0, 0.99999994);
    var k = 0u;
    loop {
        if k >= steps {
            break;
        }
        let t = lo + (f32(k) + jitter) * dt;
        let p = o + d * t;
        let empty = cloud_empty_for(p, d);
        if empty >= 0.0 {
            // The next sample at or past the empty stretch's end.
            let next = ceil((t + empty - lo) / dt - jitter);
            k = select(k + 1u, u32(min(next, f32(steps))), next > f32(k));
            continue;
        }
        k++;
        let sigma = cloud_density_at(p);
        result.samples++;
        if sigma <= 0.0 {
            continue;
        }
        let sun = cloud_sun_transmittance(p, s);
        let through = exp(-sigma * dt);
        let weight = result.transmittance * (1.0 - through) * clouds.albedo;
        result.in_scatter += weight * (sun_light * sun + clouds.ambient.xyz);
        result.transmittance *= through;
        if result.transmittance < clouds.min_transmittance {
            break;
        }
    }
    return result;
}

// The optical depth ∫ σ dt along o + t d over [t0, t1] by midpoint samples of about `step`
// (equal steps, at least one), skipping what the max grid proves empty
// (fray_clouds::march::optical_depth): what a shadow ray toward a light meets.
fn cloud_optical_depth(o: vec3<f32>, d: vec3<f32>, t0: f32, t1: f32) -> f32 {
    let span = clip_box(clouds.region_min.xyz, clouds.region_max.xyz, o, d, t0, t1);
    let lo = span.x;
    let length = select(0.0, span.y - span.x, span.x <= span.y);
    if !(length > 0.0) || !(clouds.step > 0.0) {
        return 0.0;
    }
    let steps = u32(clamp(ceil(length / clouds.step), 1.0, 1.0e7));
    return cloud_midpoint_depth(o, d, lo, length / f32(steps), steps);
}

// Jimenez's interleaved gradient noise of pixel (x, y), in [0, 1) (pixel_jitter, in f32).
fn cloud_pixel_jitter(x: u32, y: u32) -> f32 {
    let v = fract(52.9829189 * fract(0.06711056 * f32(x) + 0.00583715 * f32(y)));
    return min(v, 0.99999994);
}
