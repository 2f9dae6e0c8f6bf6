// sky_batch.wgsl — sky.wgsl over a batch of queries given by the caller (fray_gpu::sky_pass), for
// its parity tests against fray_atmosphere's Sky, SkyView and TransmittanceTable.
//
// #bindings sky_batch
// #include "sky.wgsl"
//
// Queries: three vec4 each, camera-relative — (ray origin.xyz, surface distance t; BIG: the
// whole ray), (unit ray direction.xyz, a transmittance-table altitude h), (a point p.xyz, a
// table cosine μ).
// Results: six vec4 each (rgb, 0) — the sky-view table along the direction, the background
// (with the disc where the block says so), the aerial perspective's in-scatter and
// transmittance over [0, t], the transmittance to the sun at p, the table at (h, μ).

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= arrayLength(&sky_results) / 6u {
        return;
    }
    let a = sky_queries[3u * k];
    let b = sky_queries[3u * k + 1u];
    let c = sky_queries[3u * k + 2u];
    let air = sky_aerial_perspective(a.xyz, b.xyz, a.w);
    sky_results[6u * k] = vec4<f32>(sky_view_lookup(b.xyz), 0.0);
    sky_results[6u * k + 1u] = vec4<f32>(sky_background(b.xyz), 0.0);
    sky_results[6u * k + 2u] = vec4<f32>(air.in_scatter, 0.0);
    sky_results[6u * k + 3u] = vec4<f32>(air.transmittance, 0.0);
    sky_results[6u * k + 4u] = vec4<f32>(sky_transmittance_to_sun(c.xyz), 0.0);
    sky_results[6u * k + 5u] = vec4<f32>(sky_transmittance(b.w, c.w), 0.0);
}
