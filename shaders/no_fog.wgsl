// no_fog.wgsl — the fog's hook in shade.wgsl for a scene without fog: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before fog existed);
// no fog code or parameter is compiled.

fn fog_light_transmittance(p: vec3<f32>, kind: u32, to_light: vec3<f32>, distance: f32) -> f32 {
    return 1.0;
}
