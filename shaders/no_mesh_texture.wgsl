// no_mesh_texture.wgsl — the mesh hook of texture.wgsl for a scene without meshes: never called
// (no ray hits a mesh); no mesh code or binding compiled.

struct MeshTexturing {
    uv: vec2<f32>,
    uv_per_world: f32,
    has_uv: bool,
    normal: vec3<f32>,
}

fn mesh_texturing(path: GpuPath) -> MeshTexturing {
    var out: MeshTexturing;
    out.uv = vec2<f32>(0.5);
    out.uv_per_world = 0.0;
    out.has_uv = false;
    out.normal = -path.dir.xyz;
    return out;
}
