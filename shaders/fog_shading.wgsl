// fog_shading.wgsl — the fog's hook in shade.wgsl for a scene with fog: the light reaching a
// surface point through the fog (fray-trace's Media::light_transmittance) — a sun through the
// layer as the fog's model sees it, a point light along the segment to it — whether or not
// shadows are on (the fog dims light, it does not cast shadows).
//
// #if fog
// #include "fog.wgsl"

fn fog_light_transmittance(p: vec3<f32>, kind: u32, to_light: vec3<f32>, distance: f32) -> f32 {
    if kind == LIGHT_SUN {
        return fog_sun_transmittance(p.y, to_light.y);
    }
    return fog_point_transmittance(p, to_light, distance);
}

// #else
// Without it: the fog's hook in shade.wgsl for a scene without fog: every light arrives
// whole (a factor of exactly 1, so the radiance is bit for bit what it was before fog existed);
// no fog code or parameter is compiled.

fn fog_light_transmittance(p: vec3<f32>, kind: u32, to_light: vec3<f32>, distance: f32) -> f32 {
    return 1.0;
}
// #endif
