// mesh_shading.wgsl — the mesh hooks of the shade pass (a scene with meshes; mesh.wgsl): a mesh
// hit's surface as fray-trace's MeshPrimitive::surface makes it, and shadow rays any-hit
// against every instance (opaque: transmittance 0 or 1).
//
// #if meshes
struct MeshShading {
    // The outward normal to shade with (never turned to the viewer).
    normal: vec3<f32>,
    // The outward geometric normal (the face's).
    geometric: vec3<f32>,
    material: u32,
}

// The surface of the mesh hit the intersection pass left in `path` (instance in `index`,
// triangle slot in `part`, barycentrics in `hit.yzw`): the outward geometric normal — the
// inverse transpose of the mesh's face normal, outward whether or not the instance mirrors (as
// the CPU's winding normal turned round by the transform's sign) —; with
// MESH_FLAG_SMOOTH the interpolated vertex normal where it agrees in sign with that face
// normal, else (faceted, or a normal folded away from its face) the face's; the instance's
// material.
fn mesh_shading(path: GpuPath) -> MeshShading {
    var hit = mesh_no_hit();
    hit.t = path.hit.x;
    hit.instance = path.index;
    hit.slot = path.part;
    hit.barycentric = path.hit.yzw;
    let inst = load_mesh_instance(path.index);
    let s = mesh_surface(hit);
    var g = s.normal;
    // A sliver whose normal rounds to nothing faces the ray, as on the CPU.
    if dot(g, g) == 0.0 {
        g = -path.dir.xyz;
    }
    var out: MeshShading;
    out.normal = g;
    out.geometric = g;
    if (inst.flags & MESH_FLAG_SMOOTH) != 0u && dot(s.shading_normal, g) > 0.0 {
        out.normal = s.shading_normal;
    }
    out.material = inst.material;
    return out;
}

// Whether a shadow ray from `o` along `d` meets a mesh in (0, distance).
fn occluded_by_meshes(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    return mesh_any(o, d, 0.0, distance, mesh_info.x);
}

// Narrows `best` to the nearest mesh hit in (0, best) — (0, limit) before the first — of a ray
// leaving a surface, over every instance.
fn meshes_nearest(o: vec3<f32>, d: vec3<f32>, limit: f32, best: ptr<function, SurfaceHit>) {
    let hi = select(limit, (*best).t, (*best).t >= 0.0);
    let h = mesh_nearest(o, d, 0.0, hi, mesh_info.x);
    if h.instance != MESH_NO_HIT && ((*best).t < 0.0 || h.t < (*best).t) {
        *best = SurfaceHit(h.t, KIND_MESH, h.instance, h.slot, h.barycentric);
    }
}

// The material of instance k.
fn mesh_material(k: u32) -> u32 {
    return load_mesh_instance(k).material;
}

// #else
// Without it: the mesh hooks of a scene without meshes: nothing to hit, no mesh code or
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
// #endif
