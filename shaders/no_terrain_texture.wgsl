// no_terrain_texture.wgsl — the terrain hook of texture.wgsl for a scene without terrains: never
// called (no ray hits a terrain); no terrain code or binding compiled.

fn terrain_texturing(k: u32, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(0.5, 0.5, 0.0);
}
