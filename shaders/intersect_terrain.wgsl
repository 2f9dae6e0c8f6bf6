// intersect_terrain.wgsl — the terrain intersection pass (intersect_items.wgsl for terrains):
// each pixel's camera rays cast against the item's terrain candidates (terrain.wgsl, at the
// terrain's pixel level of detail). A terrain hit carries its shading normal (a LOD hit: the
// interpolant's beneath) and its level.
//
// #bindings frame, work, terrains
// #include "ray.wgsl"
// #include "terrain.wgsl"
// #include "work_item.wgsl"
// #include "counters.wgsl"
// #instantiate "intersect_items.wgsl" { KIND: KIND_TERRAIN; PREFIX: terrain }

fn terrain_counts_begin() {
    terrain_rays = 0u;
    terrain_segments = 0u;
    terrain_cells = 0u;
    terrain_stops = 0u;
    terrain_stop_levels = 0u;
}

fn terrain_counts_end() {
    count(COUNT_TERRAIN_RAYS, terrain_rays);
    count(COUNT_TERRAIN_SEGMENTS, terrain_segments);
    count(COUNT_TERRAIN_CELLS, terrain_cells);
    count(COUNT_TERRAIN_STOPS, terrain_stops);
    count(COUNT_TERRAIN_STOP_LEVELS, terrain_stop_levels);
}

fn terrain_candidate(c: u32, o: vec3<f32>, d: vec3<f32>, t_near: f32, hi: f32) -> CandidateHit {
    let object = candidates[c].object;
    let h = cast_terrain(object, o, d, t_near, hi, frame.epsilon, true);
    if h.t < 0.0 {
        return CandidateHit(NO_HIT, vec3<f32>(0.0), object, 0u);
    }
    return CandidateHit(h.t, terrain_shading_normal(object, o, d, h), object, h.levels_above);
}
