// no_mesh.wgsl — the mesh hooks of a scene without meshes: nothing to hit, no mesh code or
// binding compiled.

struct MeshShading {
    normal: vec3<f32>,
    geometric: vec3<f32>,
    material: u32,
}

fn mesh_shading(path: GpuPath) -> MeshShading {
    var out: MeshShading;
    out.normal = -path.dir.xyz;
    out.geometric = out.normal;
    out.material = 0u;
    return out;
}

fn meshes_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, best: ptr<function, SurfaceHit>) {}

fn mesh_material(k: u32) -> u32 {
    return 0u;
}

fn occluded_by_meshes(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    return false;
}
