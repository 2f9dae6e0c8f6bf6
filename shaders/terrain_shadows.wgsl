// terrain_shadows.wgsl — shadow rays against every terrain, exactly (no level of detail), as
// fray-trace's TerrainPrimitive::transmittance.
//
// #if terrain
fn occluded_by_terrains(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    for (var k = 0u; k < frame.terrains; k++) {
        if cast_terrain(k, o, d, 0.0, distance, eps, false).t >= 0.0 {
            return true;
        }
    }
    return false;
}

// Narrows `best` to the nearest terrain hit in (0, best) — (0, limit) before the first — of a
// ray leaving a surface: exactly, at the finest level (fray-trace's secondary rays have no pixel
// footprint).
fn terrains_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, eps: f32, best: ptr<function, SurfaceHit>) {
    for (var k = 0u; k < frame.terrains; k++) {
        let hi = select(limit, (*best).t, (*best).t >= 0.0);
        let h = cast_terrain(k, o, d, 0.0, hi, eps, false);
        if h.t >= 0.0 && ((*best).t < 0.0 || h.t < (*best).t) {
            *best = SurfaceHit(h.t, KIND_TERRAIN, k, h.levels_above, terrain_shading_normal(k, o, d, h));
        }
    }
}

// #else
// Without it: the terrain hooks of a scene without terrain: nothing to hit, no terrain code
// or binding compiled.

fn occluded_by_terrains(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    return false;
}

fn terrain_material(k: u32) -> u32 {
    return 0u;
}

fn terrains_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, eps: f32, best: ptr<function, SurfaceHit>) {}
// #endif
