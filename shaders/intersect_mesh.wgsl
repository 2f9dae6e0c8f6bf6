// intersect_mesh.wgsl — the mesh intersection pass: one workgroup per work item of the band,
// each pixel's camera rays cast against the item's mesh candidates (one instance each;
// mesh.wgsl, the f32 twin of fray_mesh's Instance::nearest_hit) over the open range
// (t_near, the nearest hit so far), narrowing the path's hit — after the free-form and terrain
// passes, so a tie keeps the earlier kind's hit, as on the CPU (and, among instances, the
// earlier candidate's). A mesh hit records the instance (`index`), the triangle's slot in the
// triangle array (`part`) and its barycentric weights (`hit.yzw`), what the shade pass's
// surface needs. One mesh ray counted per ray and instance searched (fray-trace's mesh_rays).
//
// #bindings frame, work, meshes
// #include "ray.wgsl"
// #include "mesh.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"

var<private> mesh_rays: u32;

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) local_index: u32,
) {
    let k = group.y * groups.x + group.x;
    // Uniform over the workgroup, so the barrier below stays in uniform control flow.
    if k >= frame.items {
        return;
    }
    zero_counts(local_index);
    workgroupBarrier();
    let item = items[frame.first_item + k];
    mesh_rays = 0u;
    let rays = item_rays(item, local);
    for (var r = rays.x; r < rays.y; r++) {
        let path = paths[r];
        if path.origin.w < 0.0 {
            continue;
        }
        let o = path.origin.xyz;
        let d = path.dir.xyz;
        var best = path.hit.x;
        for (var c = item.candidate_start; c < item.candidate_start + item.candidate_count; c++) {
            let cand = candidates[c];
            if cand.kind != KIND_MESH {
                continue;
            }
            var hi = BIG;
            if best >= 0.0 {
                hi = best;
            }
            mesh_rays++;
            var h = mesh_no_hit();
            mesh_instance_nearest(cand.object, o, d, path.origin.w, hi, &h);
            // The open range already keeps h.t < best: a tie stays with the earlier hit.
            if h.instance != MESH_NO_HIT && (best < 0.0 || h.t < best) {
                best = h.t;
                paths[r].hit = vec4<f32>(h.t, h.barycentric);
                paths[r].kind = KIND_MESH;
                paths[r].index = h.instance;
                paths[r].part = h.slot;
            }
        }
    }
    count(COUNT_MESH_RAYS, mesh_rays);
    workgroupBarrier();
    flush_counts(local_index);
}
