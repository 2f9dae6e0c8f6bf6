// no_clouds.wgsl — the clouds' hook in shade.wgsl for a scene without clouds: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before clouds
// existed); no cloud code, parameter or texture is compiled.

fn cloud_light_transmittance(p: vec3<f32>, to_light: vec3<f32>, distance: f32) -> f32 {
    return 1.0;
}
