// terrain_texture.wgsl — the terrain hook of texture.wgsl (a scene with terrains and textures):
// the drape's uv at camera-relative point `p` on terrain k — its map point (u, v) =
// (column, row) from the camera-relative placement, `((u + ½)/columns, 1 − (v + ½)/rows)`
// (fray-trace's drape_uv: texel centres on the samples, the image's top row on the map's row
// 0) — and the drape's uv per world unit, the larger of the two axes' (drape_uv_per_world).
//
// #if terrain
fn terrain_texturing(k: u32, p: vec3<f32>) -> vec3<f32> {
    let tp = terrains[k];
    let rel = p - tp.origin.xyz;
    let u = dot(rel, tp.axis_u.xyz) / tp.scale.x;
    let v = dot(rel, tp.axis_v.xyz) / tp.scale.y;
    let columns = f32(max(tp.sizes.x, 1u));
    let rows = f32(max(tp.sizes.y, 1u));
    let uv = vec2<f32>((u + 0.5) / columns, 1.0 - (v + 0.5) / rows);
    return vec3<f32>(uv, max(1.0 / (columns * tp.scale.x), 1.0 / (rows * tp.scale.y)));
}

// #else
// Without it: the terrain hook of texture.wgsl for a scene without terrains: never
// called (no ray hits a terrain); no terrain code or binding compiled.

fn terrain_texturing(k: u32, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(0.5, 0.5, 0.0);
}
// #endif
