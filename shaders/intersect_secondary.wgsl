// intersect_secondary.wgsl — Whitted's intersection pass: one invocation per ray of the queue's
// current level (queue.wgsl), its nearest hit over every primitive kind with no work list
// (secondary_hit.wgsl: a ray inside a transmissive free form finds where it leaves it), written
// to its path as the camera rays' passes write theirs: `t` and the kind's detail (a terrain's
// shading normal, a mesh's barycentrics, a box exit's face normal) in `hit`, the kind, index and
// part. Counts the secondary rays traced (fray-trace's secondary_rays).
//
// #bindings frame, free_forms, surfaces
// #include "freeform.wgsl"
// #include "kinds.wgsl"
// #include "queue.wgsl"
// #include "secondary_hit.wgsl"
// #include "counters.wgsl"

override HAS_FREE_FORMS: bool = true;

@compute @workgroup_size(64)
fn main(at: QueueInvocation) {
    let k = begin_queue_kernel(at);
    bound_evals = 0u;
    point_evals = 0u;
    let level = queue_current();
    if k < level.y {
        let slot = level.x + k;
        let path = paths[slot];
        let h = nearest_from_surface(path.origin.xyz, path.dir.xyz, BIG, frame.epsilon);
        if h.t >= 0.0 {
            paths[slot].hit = vec4<f32>(h.t, h.detail);
            paths[slot].kind = h.kind;
            paths[slot].index = h.index;
            paths[slot].part = h.part;
        }
        count(COUNT_SECONDARY_RAYS, 1u);
    }
    count(COUNT_BOUND_EVALUATIONS, bound_evals);
    count(COUNT_POINT_EVALUATIONS, point_evals);
    end_queue_kernel(at);
}
