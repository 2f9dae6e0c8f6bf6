// intersect_items.wgsl — template of a kind's intersection pass, instantiated once per kind by
// its entry module (intersect_<kind>.wgsl: `// #instantiate "intersect_items.wgsl" { KIND: …;
// PREFIX: … }`): one workgroup per work item of the band (its invocations are the pixels of the
// item's tile), each pixel's camera rays cast against the item's candidates of kind {{KIND}}
// over [t_near, the nearest hit so far] — the earlier kinds' passes have narrowed it, so a tie
// keeps the earlier kind's hit, as on the CPU, and among candidates the earlier one's. Pixels no
// item covers are never run: their paths stay as they are. The kind's hooks:
// - `{{PREFIX}}_counts_begin()` / `{{PREFIX}}_counts_end()`: zero its private counters, add
//   them to the workgroup's;
// - `{{PREFIX}}_candidate(c, o, d, t_near, hi) -> CandidateHit`: candidate `c` of the work
//   list on a ray (origin `o`, direction `d`) over [t_near, hi]: its hit's t (< 0: none), the
//   kind's detail for the shade pass (`hit.yzw`), the primitive's index and the part hit.
// The nearest hit over the candidates is written to the path, the kind's code with it.

struct CandidateHit {
    t: f32,
    detail: vec3<f32>,
    index: u32,
    part: u32,
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
    {{PREFIX}}_counts_begin();
    let rays = item_rays(item, local);
    for (var r = rays.x; r < rays.y; r++) {
        let path = paths[r];
        if path.origin.w < 0.0 {
            continue;
        }
        var best = path.hit.x;
        for (var c = item.candidate_start; c < item.candidate_start + item.candidate_count; c++) {
            if candidates[c].kind != {{KIND}} {
                continue;
            }
            var hi = BIG;
            if best >= 0.0 {
                hi = best;
            }
            let h = {{PREFIX}}_candidate(c, path.origin.xyz, path.dir.xyz, path.origin.w, hi);
            if h.t >= 0.0 && (best < 0.0 || h.t < best) {
                best = h.t;
                paths[r].hit = vec4<f32>(h.t, h.detail);
                paths[r].kind = {{KIND}};
                paths[r].index = h.index;
                paths[r].part = h.part;
            }
        }
    }
    {{PREFIX}}_counts_end();
    workgroupBarrier();
    flush_counts(local_index);
}
