// intersect_freeform.wgsl — the free-form intersection pass: one workgroup per work item of the
// band (its invocations are the pixels of the item's tile), each pixel's camera rays cast
// against the item's free-form candidates only (active leaves and perturbations, pruned CSG
// programs; freeform.wgsl), nearest hit over them written to the ray's path (a tie keeps the
// earlier candidate). Pixels no item covers are never run: their paths stay misses.
//
// #bindings frame, free_forms, work
// #include "freeform.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"

// The parts of candidate `c` of the work list.
fn candidate_parts(c: u32) -> Parts {
    let cand = candidates[c];
    var parts: Parts;
    parts.all = false;
    parts.leaf_start = cand.leaf_start;
    parts.leaf_count = cand.leaf_count;
    parts.pert_start = cand.perturbation_start;
    parts.pert_count = cand.perturbation_count;
    let at = frame.programs_base + 2u * c;
    parts.program = vec2<u32>(indices[at], indices[at + 1u]);
    return parts;
}

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
    bound_evals = 0u;
    point_evals = 0u;
    let rays = item_rays(item, local);
    let eps = frame.epsilon;
    for (var r = rays.x; r < rays.y; r++) {
        let path = paths[r];
        if path.origin.w < 0.0 {
            continue;
        }
        let o = path.origin.xyz;
        let d = path.dir.xyz;
        var best = NO_HIT;
        var solid = 0u;
        for (var c = item.candidate_start; c < item.candidate_start + item.candidate_count; c++) {
            let cand = candidates[c];
            if cand.kind != KIND_FREE_FORM {
                continue;
            }
            var hi = BIG;
            if best >= 0.0 {
                hi = best;
            }
            let t = cast_solid(cand.object, candidate_parts(c), o, d, path.origin.w, hi, eps);
            if t >= 0.0 && (best < 0.0 || t < best) {
                best = t;
                solid = cand.object;
            }
        }
        if best >= 0.0 {
            paths[r].hit = vec4<f32>(best, 0.0, 0.0, 0.0);
            paths[r].kind = KIND_FREE_FORM;
            paths[r].index = solid;
        }
    }
    count(COUNT_BOUND_EVALUATIONS, bound_evals);
    count(COUNT_POINT_EVALUATIONS, point_evals);
    workgroupBarrier();
    flush_counts(local_index);
}
