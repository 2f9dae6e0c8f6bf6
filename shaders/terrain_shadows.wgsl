// terrain_shadows.wgsl — shadow rays against every terrain, exactly (no level of detail), as
// fray-trace's TerrainPrimitive::transmittance.

fn occluded_by_terrains(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    for (var k = 0u; k < frame.terrains; k++) {
        if cast_terrain(k, o, d, 0.0, distance, eps, false).t >= 0.0 {
            return true;
        }
    }
    return false;
}
