// fog_batch.wgsl — fog.wgsl over a batch of rays given by the caller (fray_gpu::fog_pass), for
// its parity tests against fray_atmosphere's FogLayer.
//
// #bindings fog_batch
// #include "fog.wgsl"
//
// Rays: three vec4 per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi; ≥ BIG:
// unbounded), (unit direction toward a sun.xyz, 0).
// Results: two vec4 per ray — (transmittance, ambient factor, sun factor, optical depth) over
// [t_lo, t_hi]; (the sun's transmittance to the origin's height, the segment's transmittance by
// fog_optical_depth, 0, 0).

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= arrayLength(&fog_results) / 2u {
        return;
    }
    let a = fog_rays[3u * k];
    let b = fog_rays[3u * k + 1u];
    let sun = fog_rays[3u * k + 2u].xyz;
    let s = fog_segment(a.xyz, b.xyz, a.w, b.w);
    fog_results[2u * k] = vec4<f32>(
        fog_segment_transmittance(s),
        fog_ambient_factor(s),
        fog_sun_factor(a.xyz, b.xyz, s, sun),
        s.depth,
    );
    fog_results[2u * k + 1u] = vec4<f32>(
        fog_sun_transmittance(a.y, sun.y),
        fog_exp(fog_optical_depth(a.xyz, b.xyz, a.w, b.w)),
        0.0,
        0.0,
    );
}
