// intersect_terrain.wgsl — the terrain intersection pass: one workgroup per work item of the
// band, each pixel's camera rays cast against the item's terrain candidates (terrain.wgsl, at
// the terrain's pixel level of detail) over [t_near, the nearest hit so far], narrowing the
// path's hit — after the free-form pass, so a tie keeps the free form, as on the CPU. A terrain
// hit carries its shading normal (a LOD hit: the interpolant's beneath) and its level.
//
// #bindings frame, work, terrains
// #include "ray.wgsl"
// #include "terrain.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"

@compute @workgroup_size(TILE_THREADS, TILE_THREADS)
fn main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_id) local: vec3<u32>,
    @builtin(local_invocation_index) local_index: u32,
) {
    let k = group.y * groups.x + group.x;
    if k >= frame.items {
        return;
    }
    zero_counts(local_index);
    workgroupBarrier();
    let item = items[frame.first_item + k];
    terrain_rays = 0u;
    terrain_segments = 0u;
    terrain_cells = 0u;
    terrain_stops = 0u;
    terrain_stop_levels = 0u;
    let rays = item_rays(item, local);
    let eps = frame.epsilon;
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
            if cand.kind != KIND_TERRAIN {
                continue;
            }
            var hi = BIG;
            if best >= 0.0 {
                hi = best;
            }
            let h = cast_terrain(cand.object, o, d, path.origin.w, hi, eps, true);
            if h.t >= 0.0 && (best < 0.0 || h.t < best) {
                best = h.t;
                let normal = terrain_shading_normal(cand.object, o, d, h);
                paths[r].hit = vec4<f32>(h.t, normal);
                paths[r].kind = KIND_TERRAIN;
                paths[r].index = cand.object;
                paths[r].part = h.levels_above;
            }
        }
    }
    count(COUNT_TERRAIN_RAYS, terrain_rays);
    count(COUNT_TERRAIN_SEGMENTS, terrain_segments);
    count(COUNT_TERRAIN_CELLS, terrain_cells);
    count(COUNT_TERRAIN_STOPS, terrain_stops);
    count(COUNT_TERRAIN_STOP_LEVELS, terrain_stop_levels);
    workgroupBarrier();
    flush_counts(local_index);
}
