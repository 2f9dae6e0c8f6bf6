// intersect_mesh.wgsl — the mesh intersection pass (intersect_items.wgsl for meshes): each
// pixel's camera rays cast against the item's mesh candidates (one instance each; mesh.wgsl,
// the f32 twin of fray_mesh's Instance::nearest_hit) over the open range (t_near, the nearest
// hit so far). A mesh hit records the instance (`index`), the triangle's slot in the triangle
// array (`part`) and its barycentric weights (`hit.yzw`), what the shade pass's surface needs.
// One mesh ray counted per ray and instance searched (fray-trace's mesh_rays).
//
// #bindings frame, work, meshes
// #include "ray.wgsl"
// #include "mesh.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"
// #instantiate "intersect_items.wgsl" { KIND: KIND_MESH; PREFIX: mesh }

var<private> mesh_rays: u32;

fn mesh_counts_begin() {
    mesh_rays = 0u;
}

fn mesh_counts_end() {
    count(COUNT_MESH_RAYS, mesh_rays);
}

fn mesh_candidate(c: u32, o: vec3<f32>, d: vec3<f32>, t_near: f32, hi: f32) -> CandidateHit {
    mesh_rays++;
    var h = mesh_no_hit();
    mesh_instance_nearest(candidates[c].object, o, d, t_near, hi, &h);
    // The open range already keeps h.t below the nearest hit so far: a tie stays with it.
    if h.instance == MESH_NO_HIT {
        return CandidateHit(NO_HIT, vec3<f32>(0.0), 0u, 0u);
    }
    return CandidateHit(h.t, h.barycentric, h.instance, h.slot);
}
