// sky_shading.wgsl — the sky's hook in shade.wgsl for a scene with a sky: the sky's sun reaches
// a surface point through the air (fray-trace's Media::light_transmittance: the table at the
// point's altitude and cosine to the sun, sky.wgsl), whether or not shadows are on; every other
// light arrives whole.
//
// #if sky
// #include "sky.wgsl"

fn sky_light_transmittance(p: vec3<f32>, light: u32) -> vec3<f32> {
    return select(vec3<f32>(1.0), sky_transmittance_to_sun(p), light == sky.sun_light);
}

// #else
// Without it: the sky's hook in shade.wgsl for a scene without a sky: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before the sky
// existed); no sky code, parameter or table is compiled.

fn sky_light_transmittance(p: vec3<f32>, light: u32) -> vec3<f32> {
    return vec3<f32>(1.0);
}
// #endif
