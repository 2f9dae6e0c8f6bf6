// sky_batch.wgsl — sky.wgsl on queries given by the caller (fray_gpu::testing::SkyBatch), for its
// parity tests against fray_atmosphere's Sky, SkyView and TransmittanceTable.
//
// #bindings batch, sky_tables
// #include "batch.wgsl"
// #include "sky.wgsl"
//
// Queries: three rows each, camera-relative — (ray origin.xyz, surface distance t; BIG: the
// whole ray), (unit ray direction.xyz, a transmittance-table altitude h), (a point p.xyz, a
// table cosine μ).
// Answers: six rows each (rgb, 0) — the sky-view table along the direction, the background
// (with the disc where the block says so), the aerial perspective's in-scatter and
// transmittance over [0, t], the transmittance to the sun at p, the table at (h, μ).

const QUERY_ROWS: u32 = 3u;
const ANSWER_ROWS: u32 = 6u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let c = query(k, 2u);
    let air = sky_aerial_perspective(a.xyz, b.xyz, a.w);
    put(k, 0u, vec4<f32>(sky_view_lookup(b.xyz), 0.0));
    put(k, 1u, vec4<f32>(sky_background(b.xyz), 0.0));
    put(k, 2u, vec4<f32>(air.in_scatter, 0.0));
    put(k, 3u, vec4<f32>(air.transmittance, 0.0));
    put(k, 4u, vec4<f32>(sky_transmittance_to_sun(c.xyz), 0.0));
    put(k, 5u, vec4<f32>(sky_transmittance(b.w, c.w), 0.0));
}
