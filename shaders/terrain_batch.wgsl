// terrain_batch.wgsl — terrain.wgsl's `cast_terrain` on rays given by the caller
// (fray_gpu::testing::TerrainBatch), for its parity tests against fray_terrain.
//
// #bindings batch, terrains
// #include "batch.wgsl"
// #include "terrain.wgsl"
//
// Batch: (ray count, terrain index, pixel LOD 0/1, bits of the bicubic tolerance ε as f32).
// Queries: two rows per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi).
// Answers: two rows per ray — (t, normal.xyz), t < 0 for a miss; (kind, levels above the finest,
// cell column, cell row) as f32 (HIT_* kinds of terrain.wgsl).

const QUERY_ROWS: u32 = 2u;
const ANSWER_ROWS: u32 = 2u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let h = cast_terrain(batch.y, a.xyz, b.xyz, a.w, b.w, bitcast<f32>(batch.w), batch.z == 1u);
    put(k, 0u, vec4<f32>(h.t, h.normal));
    put(k, 1u, vec4<f32>(f32(h.kind), f32(h.levels_above), f32(h.cell.x), f32(h.cell.y)));
}
