// terrain_batch.wgsl — the terrain pass over a batch of rays (fray_gpu::TerrainPass), after the
// generated prelude, the terrain bindings (0–2) and terrain.wgsl.
//
// Rays: two vec4 per ray, camera-relative — (origin.xyz, t_lo), (unit dir.xyz, t_hi).
// Hits: one vec4 per ray — (t, normal.xyz), t < 0 for a miss.

@group(0) @binding(3) var<storage, read> rays: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> hits: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if (k >= P.sizes.z) {
        return;
    }
    let a = rays[2u * k];
    let b = rays[2u * k + 1u];
    hits[k] = cast_terrain(a.xyz, b.xyz, a.w, b.w, true);
}
