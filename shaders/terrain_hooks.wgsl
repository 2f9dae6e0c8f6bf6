// terrain_hooks.wgsl — the terrain kind's hooks (terrain.wgsl), called by the generated dispatch
// of the scene's kinds (fray_gpu::shader's kinds.wgsl) for the shade and Whitted passes: a
// terrain hit's surface (the shading normal its intersection pass left in `hit.yzw`, the
// terrain's material), shadow rays against every terrain exactly (no level of detail, as
// fray-trace's TerrainPrimitive::transmittance), the nearest hit of a ray leaving a surface,
// and — with textures — the drape's uv at camera-relative point `p` on the terrain: its map
// point (u, v) = (column, row) from the camera-relative placement,
// `((u + ½)/columns, 1 − (v + ½)/rows)` (fray-trace's drape_uv: texel centres on the samples,
// the image's top row on the map's row 0), and the drape's uv per world unit, the larger of
// the two axes' (drape_uv_per_world). The geometric normal the footprint takes is the shading
// normal (a terrain's surface has no other).

// The surface of the terrain hit in `path` (terrain `index`).
fn terrain_shading(path: GpuPath) -> KindShading {
    var out: KindShading;
    out.normal = path.hit.yzw;
    out.geometric = out.normal;
    out.material = terrain_material(path.index);
    return out;
}

// Whether a shadow ray from `o` along `d` meets a terrain in [0, distance].
fn terrain_occludes(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
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
fn terrain_nearest_from_surface(
    o: vec3<f32>,
    d: vec3<f32>,
    limit: f32,
    eps: f32,
    best: ptr<function, SurfaceHit>,
) {
    for (var k = 0u; k < frame.terrains; k++) {
        let hi = select(limit, (*best).t, (*best).t >= 0.0);
        let h = cast_terrain(k, o, d, 0.0, hi, eps, false);
        if h.t >= 0.0 && ((*best).t < 0.0 || h.t < (*best).t) {
            *best = SurfaceHit(h.t, KIND_TERRAIN, k, h.levels_above, terrain_shading_normal(k, o, d, h));
        }
    }
}

// #if textures
fn terrain_texturing(path: GpuPath, p: vec3<f32>, normal: vec3<f32>) -> KindTexturing {
    let tp = terrains[path.index];
    let rel = p - tp.origin.xyz;
    let u = dot(rel, tp.axis_u.xyz) / tp.scale.x;
    let v = dot(rel, tp.axis_v.xyz) / tp.scale.y;
    let columns = f32(max(tp.sizes.x, 1u));
    let rows = f32(max(tp.sizes.y, 1u));
    var out: KindTexturing;
    out.uv = vec2<f32>((u + 0.5) / columns, 1.0 - (v + 0.5) / rows);
    out.uv_per_world = max(1.0 / (columns * tp.scale.x), 1.0 / (rows * tp.scale.y));
    out.has_uv = true;
    out.geometric = normal;
    return out;
}
// #endif
