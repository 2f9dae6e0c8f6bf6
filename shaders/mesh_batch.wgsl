// mesh_batch.wgsl — mesh.wgsl's nearest and any hit over every instance on rays given by the
// caller (fray_gpu::testing::MeshBatch), for its parity tests against fray_mesh.
//
// #bindings batch, meshes
// #include "batch.wgsl"
// #include "ray.wgsl"
// #include "mesh.wgsl"
//
// Batch: (ray count, instance count, 0, 0).
// Queries: two rows per ray, relative to the reference point — (origin.xyz, t_lo), (dir.xyz,
// t_hi), t_hi at most BIG (larger is clamped).
// Answers: four rows per ray, floats as their bits —
//   (t, barycentric a, b, c), t = −1 for a miss;
//   (instance, triangle, any hit over the same range 0/1, slot);
//   (world geometric normal xyz, u); (world shading normal xyz, v) — zero for a miss.

const QUERY_ROWS: u32 = 2u;
const ANSWER_ROWS: u32 = 4u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let hi = min(b.w, BIG);
    let h = mesh_nearest(a.xyz, b.xyz, a.w, hi, batch.y);
    let any = mesh_any(a.xyz, b.xyz, a.w, hi, batch.y);
    put(k, 0u, vec4<f32>(h.t, h.barycentric));
    put_words(k, 1u, vec4<u32>(h.instance, h.triangle, select(0u, 1u, any), h.slot));
    var s: MeshSurface;
    if h.instance != MESH_NO_HIT {
        s = mesh_surface(h);
    }
    put(k, 2u, vec4<f32>(s.normal, s.uv.x));
    put(k, 3u, vec4<f32>(s.shading_normal, s.uv.y));
}
