// no_terrain.wgsl — the terrain hooks of a scene without terrain: nothing to hit, no terrain code
// or binding compiled.

fn occluded_by_terrains(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    return false;
}

fn terrain_material(k: u32) -> u32 {
    return 0u;
}

fn terrains_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, eps: f32, best: ptr<function, SurfaceHit>) {}
