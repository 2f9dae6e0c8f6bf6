// clouds_media.wgsl — the clouds' hook in media.wgsl for a scene with a cloud volume: a camera
// ray's terms over [lo, hi] as fray-trace's Media::terms_jittered composes them. The cloud's
// march over its clip [a, b] of the range (clouds.wgsl, its samples offset by the pixel's
// jitter) is inserted at its entry a: with `whole` the fog's and air's terms over the ray (a
// miss's sky table holding the air along all of it) and `front` theirs over [lo, a], the terms
// are front ∘ cloud ∘ front⁻¹ ∘ whole (whole alone where front lets nothing through, T ≤ 1e-12,
// and for a ray that misses the box). Straight-line: every case computed, one selected.
//
// #if clouds
// #include "clouds.wgsl"

fn media_terms(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, hit: bool, ray: u32) -> MediaTerms {
    let whole = media_atmosphere_with(fog_media(o, d, lo, hi), media_air(o, d, hi, hit));
    let span = clip_box(clouds.region_min.xyz, clouds.region_max.xyz, o, d, lo, hi);
    let clipped = span.x <= span.y;
    let a = select(lo, span.x, clipped);
    let b = select(lo, span.y, clipped);
    // The jitter of the ray's pixel (Media::camera_jitter): every sample of a pixel takes it; a
    // ray of no pixel (NO_PIXEL: Whitted's) the middle, as Media::terms.
    let pixel = ray / frame.rays_per_pixel;
    let px = pixel % frame.width;
    let py = frame.band_y0 + pixel / frame.width;
    let jitter = select(0.5, cloud_pixel_jitter(px, py), clouds.jitter != 0u && ray != NO_PIXEL);
    let marched = cloud_march(o, d, a, b, jitter);
    cloud_samples = select(0u, marched.samples, clipped);
    let cloud = MediaTerms(vec3<f32>(marched.transmittance), marched.in_scatter);
    // The fog and air in front of the cloud (the air over [0, a]), peeled off the whole.
    let front = media_atmosphere_with(fog_media(o, d, lo, a), media_air(o, d, a, true));
    let inv = 1.0 / max(front.transmittance, vec3<f32>(1.0e-30));
    let peel = MediaTerms(inv, -front.in_scatter * inv);
    let terms = media_then(media_then(media_then(front, cloud), peel), whole);
    let seen = clipped && all(front.transmittance > vec3<f32>(1.0e-12));
    return media_select(whole, terms, seen);
}

// #else
// Without it: the clouds' hook in media.wgsl for a scene without clouds (but with fog
// or a sky): the atmosphere's terms over the ray's range alone; no cloud code, parameter or
// texture is compiled.

fn media_terms(o: vec3<f32>, d: vec3<f32>, lo: f32, hi: f32, hit: bool, ray: u32) -> MediaTerms {
    return media_atmosphere_with(fog_media(o, d, lo, hi), media_air(o, d, hi, hit));
}
// #endif
