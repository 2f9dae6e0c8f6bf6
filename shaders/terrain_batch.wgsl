// terrain_batch.wgsl — the terrain pass over a batch of rays (fray_gpu::TerrainPass): terrain.wgsl
// on rays given by the caller, for its parity tests against fray_terrain.
//
// #bindings terrain_batch, terrains
// #include "terrain.wgsl"
//
// Batch: (ray count, terrain index, pixel LOD 0/1, bits of the bicubic tolerance ε as f32).
// Rays: two vec4 per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi).
// Hits: two vec4 per ray — (t, normal.xyz), t < 0 for a miss; (kind, levels above the finest,
// cell column, cell row) as f32 (HIT_* kinds of terrain.wgsl).

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if (k >= batch.x) {
        return;
    }
    let a = rays[2u * k];
    let b = rays[2u * k + 1u];
    let h = cast_terrain(batch.y, a.xyz, b.xyz, a.w, b.w, bitcast<f32>(batch.w), batch.z == 1u);
    hits[2u * k] = vec4<f32>(h.t, h.normal);
    hits[2u * k + 1u] = vec4<f32>(f32(h.kind), f32(h.levels_above), f32(h.cell.x), f32(h.cell.y));
}
