// mesh_batch.wgsl — the mesh kernel over a batch of rays (fray_gpu::mesh_pass::MeshPass):
// mesh.wgsl's nearest and any hit over every instance, for its parity tests against fray_mesh.
//
// #bindings mesh_batch, meshes
// #include "ray.wgsl"
// #include "mesh.wgsl"
//
// mesh_batch: (ray count, instance count, 0, 0).
// Rays: two vec4 per ray, relative to the reference point — (origin.xyz, t_lo), (dir.xyz, t_hi),
// t_hi at most BIG (larger is clamped).
// Hits: four vec4<u32> per ray, floats as their bits —
//   (t, barycentric a, b, c), t = −1 for a miss;
//   (instance, triangle, any hit over the same range 0/1, slot);
//   (world geometric normal xyz, u); (world shading normal xyz, v) — zero for a miss.

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if (k >= mesh_batch.x) {
        return;
    }
    let a = mesh_rays[2u * k];
    let b = mesh_rays[2u * k + 1u];
    let hi = min(b.w, BIG);
    let h = mesh_nearest(a.xyz, b.xyz, a.w, hi, mesh_batch.y);
    let any = mesh_any(a.xyz, b.xyz, a.w, hi, mesh_batch.y);
    mesh_hits[4u * k] = bitcast<vec4<u32>>(vec4<f32>(h.t, h.barycentric));
    mesh_hits[4u * k + 1u] = vec4<u32>(h.instance, h.triangle, select(0u, 1u, any), h.slot);
    var s: MeshSurface;
    if h.instance != MESH_NO_HIT {
        s = mesh_surface(h);
    }
    mesh_hits[4u * k + 2u] = bitcast<vec4<u32>>(vec4<f32>(s.normal, s.uv.x));
    mesh_hits[4u * k + 3u] = bitcast<vec4<u32>>(vec4<f32>(s.shading_normal, s.uv.y));
}
