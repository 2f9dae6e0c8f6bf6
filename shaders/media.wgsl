// media.wgsl — the media pass, between shade and resolve: one invocation per ray of the band,
// the radiance arriving at the camera through the fog (fray-trace's Integrator::through_media
// and miss_radiance, in f32) — `T · L_surface + L_in` over [t_near, t_hit] for a ray that hit,
// `T · background + L_in` over [t_near, ∞) for one that did not. L_in is the scene's suns and
// ambient light scattered by the layer (point lights do not scatter in fog), evaluated by the
// fog's model (fog.wgsl). Built only for scenes with fog; resolve then takes every ray's
// radiance, misses included (its HAS_MEDIA).
//
// #bindings frame, shading_fog
// #include "ray.wgsl"
// #include "fog.wgsl"

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= frame.width * frame.band_rows * frame.rays_per_pixel {
        return;
    }
    let path = paths[k];
    if path.origin.w < 0.0 {
        // No ray (a degenerate projector pair): resolve shows the background, as the CPU does.
        return;
    }
    let o = path.origin.xyz;
    let d = path.dir.xyz;
    var behind = frame.background.xyz;
    var hi = BIG;
    if path.hit.x >= 0.0 {
        behind = path.radiance.xyz;
        hi = path.hit.x;
    }
    let s = fog_segment(o, d, path.origin.w, hi);
    if !s.inside {
        paths[k].radiance = vec4<f32>(behind, 0.0);
        return;
    }
    var light = frame.ambient.xyz * fog_ambient_factor(s);
    for (var i = 0u; i < frame.lights; i++) {
        let sun = lights[i];
        if sun.kind != LIGHT_SUN {
            continue;
        }
        light += sun.colour.xyz * fog_sun_factor(o, d, s, sun.direction.xyz);
    }
    let in_scatter = fog.albedo.xyz * light;
    paths[k].radiance = vec4<f32>(behind * fog_segment_transmittance(s) + in_scatter, 0.0);
}
