// clouds_shading.wgsl — the clouds' hook in shade.wgsl for a scene with a cloud volume: the light
// reaching a surface point through the cloud (fray-trace's Media::light_transmittance):
// e^{−τ}, τ the cloud's optical depth from the point toward the light — a sun to infinity, a
// point light to it — marched at the view step (clouds.wgsl), whether or not shadows are on.
//
// #if clouds
// #include "clouds.wgsl"

fn cloud_light_transmittance(p: vec3<f32>, to_light: vec3<f32>, distance: f32) -> f32 {
    return exp(-cloud_optical_depth(p, to_light, 0.0, distance));
}

// #else
// Without it: the clouds' hook in shade.wgsl for a scene without clouds: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before clouds
// existed); no cloud code, parameter or texture is compiled.

fn cloud_light_transmittance(p: vec3<f32>, to_light: vec3<f32>, distance: f32) -> f32 {
    return 1.0;
}
// #endif
