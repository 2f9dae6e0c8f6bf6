// clouds_batch.wgsl — clouds.wgsl on rays given by the caller (fray_gpu::testing::CloudsBatch),
// for its parity tests against fray_clouds's march, optical_depth and pixel_jitter.
//
// #bindings batch, cloud_volume
// #include "batch.wgsl"
// #include "clouds.wgsl"
//
// Queries: three rows per ray, relative to the block's reference point — (origin.xyz, t0), (unit
// dir.xyz, t1; ≥ BIG: unbounded), (jitter, pixel x, pixel y, 0).
// Answers: two rows per ray — (the march's transmittance, its in-scatter rgb) over [t0, t1];
// (its density samples, the optical depth over [t0, t1], the density at the origin, the pixel's
// jitter).

const QUERY_ROWS: u32 = 3u;
const ANSWER_ROWS: u32 = 2u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let c = query(k, 2u);
    let marched = cloud_march(a.xyz, b.xyz, a.w, b.w, c.x);
    put(k, 0u, vec4<f32>(marched.transmittance, marched.in_scatter));
    put(k, 1u, vec4<f32>(
        f32(marched.samples),
        cloud_optical_depth(a.xyz, b.xyz, a.w, b.w),
        cloud_density_at(a.xyz),
        cloud_pixel_jitter(u32(c.y), u32(c.z)),
    ));
}
