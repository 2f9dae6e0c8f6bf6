// no_sky.wgsl — the sky's hook in shade.wgsl for a scene without a sky: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before the sky
// existed); no sky code, parameter or table is compiled.

fn sky_light_transmittance(p: vec3<f32>, light: u32) -> vec3<f32> {
    return vec3<f32>(1.0);
}
