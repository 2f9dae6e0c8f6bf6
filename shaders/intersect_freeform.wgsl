// intersect_freeform.wgsl — the free-form intersection pass (intersect_items.wgsl for free
// forms): each pixel's camera rays cast against the item's free-form candidates only (active
// leaves and perturbations, pruned CSG programs; freeform.wgsl), the nearest hit over them
// written to the ray's path.
//
// #bindings frame, free_forms, work
// #include "freeform.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"
// #instantiate "intersect_items.wgsl" { KIND: KIND_FREE_FORM; PREFIX: freeform }

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

fn freeform_counts_begin() {
    bound_evals = 0u;
    point_evals = 0u;
}

fn freeform_counts_end() {
    count(COUNT_BOUND_EVALUATIONS, bound_evals);
    count(COUNT_POINT_EVALUATIONS, point_evals);
}

fn freeform_candidate(c: u32, o: vec3<f32>, d: vec3<f32>, t_near: f32, hi: f32) -> CandidateHit {
    let t = cast_solid(candidates[c].object, candidate_parts(c), o, d, t_near, hi, frame.epsilon);
    return CandidateHit(t, vec3<f32>(0.0), candidates[c].object, 0u);
}
