// clouds_batch.wgsl — clouds.wgsl over a batch of rays given by the caller
// (fray_gpu::clouds_pass), for its parity tests against fray_clouds's march, optical_depth and
// pixel_jitter.
//
// #bindings clouds_batch
// #include "clouds.wgsl"
//
// Rays: three vec4 per ray, relative to the block's reference point — (origin.xyz, t0), (unit
// dir.xyz, t1; ≥ BIG: unbounded), (jitter, pixel x, pixel y, 0).
// Results: two vec4 per ray — (the march's transmittance, its in-scatter rgb) over [t0, t1];
// (its density samples, the optical depth over [t0, t1], the density at the origin, the pixel's
// jitter).

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= arrayLength(&cloud_results) / 2u {
        return;
    }
    let a = cloud_queries[3u * k];
    let b = cloud_queries[3u * k + 1u];
    let c = cloud_queries[3u * k + 2u];
    let marched = cloud_march(a.xyz, b.xyz, a.w, b.w, c.x);
    cloud_results[2u * k] = vec4<f32>(marched.transmittance, marched.in_scatter);
    cloud_results[2u * k + 1u] = vec4<f32>(
        f32(marched.samples),
        cloud_optical_depth(a.xyz, b.xyz, a.w, b.w),
        cloud_density_at(a.xyz),
        cloud_pixel_jitter(u32(c.y), u32(c.z)),
    );
}
