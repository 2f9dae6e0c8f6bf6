// fog_batch.wgsl — fog.wgsl on rays given by the caller (fray_gpu::testing::FogBatch), for its
// parity tests against fray_atmosphere's FogLayer.
//
// #bindings batch, fog_layer
// #include "batch.wgsl"
// #include "fog.wgsl"
//
// Queries: three rows per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi; ≥ BIG:
// unbounded), (unit direction toward a sun.xyz, 0).
// Answers: two rows per ray — (transmittance, ambient factor, sun factor, optical depth) over
// [t_lo, t_hi]; (the sun's transmittance to the origin's height, the segment's transmittance by
// fog_optical_depth, 0, 0).

const QUERY_ROWS: u32 = 3u;
const ANSWER_ROWS: u32 = 2u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let sun = query(k, 2u).xyz;
    let s = fog_segment(a.xyz, b.xyz, a.w, b.w);
    put(k, 0u, vec4<f32>(
        fog_segment_transmittance(s),
        fog_ambient_factor(s),
        fog_sun_factor(a.xyz, b.xyz, s, sun),
        s.depth,
    ));
    put(k, 1u, vec4<f32>(
        fog_sun_transmittance(a.y, sun.y),
        fog_exp(fog_optical_depth(a.xyz, b.xyz, a.w, b.w)),
        0.0,
        0.0,
    ));
}
