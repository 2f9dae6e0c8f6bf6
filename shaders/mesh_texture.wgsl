// mesh_texture.wgsl — the mesh hook of texture.wgsl (a scene with meshes and textures): a mesh
// hit's texture coordinates as fray-trace takes them — the vertices' uvs interpolated by the
// hit's barycentrics (MeshPrimitive::surface), and the triangle's uv per world unit
// (fray_mesh::texture::triangle_uv_per_world over its world corners: the mesh-space edges
// through the inverse of the instance's world-to-mesh rows) — and the world geometric normal
// the footprint's cosine takes.
//
// #if meshes
struct MeshTexturing {
    uv: vec2<f32>,
    uv_per_world: f32,
    // Whether the mesh has texture coordinates (MESH_FLAG_UVS; else the image's mean).
    has_uv: bool,
    // The world geometric normal, outward by the winding (the ray's reverse for a sliver).
    normal: vec3<f32>,
}

// triangle_uv_per_world: the largest stretch of the affine map from the triangle's plane (world
// edges e1, e2) to uv (edges d1, d2); 0 for a degenerate triangle or a non-finite input.
fn texture_triangle_uv_per_world(e1: vec3<f32>, e2: vec3<f32>, d1: vec2<f32>, d2: vec2<f32>) -> f32 {
    let l1 = length(e1);
    if !(l1 > 0.0 && texture_finite(l1)) {
        return 0.0;
    }
    let a = e1 / l1;
    let side = e2 - a * dot(e2, a);
    let ls = length(side);
    if !(ls > 0.0 && texture_finite(ls)) {
        return 0.0;
    }
    let b = side / ls;
    let l = dot(e1, a);
    let p = dot(e2, a);
    let q = dot(e2, b);
    let det = l * q;
    if det == 0.0 || !texture_finite(det) {
        return 0.0;
    }
    let c0 = d1 / l;
    let c1 = (d2 - d1 * (p / l)) / q;
    let m00 = dot(c0, c0);
    let m01 = dot(c0, c1);
    let m11 = dot(c1, c1);
    let half = 0.5 * (m00 + m11);
    let disc = sqrt(0.25 * (m00 - m11) * (m00 - m11) + m01 * m01);
    let s = sqrt(max(half + disc, 0.0));
    return select(0.0, s, texture_finite(s));
}

// The mesh hit the intersection pass left in `path` (instance in `index`, triangle slot in
// `part`, barycentrics in `hit.yzw`).
fn mesh_texturing(path: GpuPath) -> MeshTexturing {
    var hit = mesh_no_hit();
    hit.t = path.hit.x;
    hit.instance = path.index;
    hit.slot = path.part;
    hit.barycentric = path.hit.yzw;
    let inst = load_mesh_instance(path.index);
    let s = mesh_surface(hit);
    var out: MeshTexturing;
    out.normal = s.normal;
    if dot(s.normal, s.normal) == 0.0 {
        out.normal = -path.dir.xyz;
    }
    out.has_uv = (inst.flags & MESH_FLAG_UVS) != 0u;
    out.uv = s.uv;
    // World edges: mesh = R · world + t with R's rows to_mesh_*, so world = R⁻¹ · mesh, R⁻¹'s
    // columns the rows' cross products over the determinant.
    let r0 = inst.to_mesh_x.xyz;
    let r1 = inst.to_mesh_y.xyz;
    let r2 = inst.to_mesh_z.xyz;
    let det = dot(r0, cross(r1, r2));
    let k0 = cross(r1, r2) / det;
    let k1 = cross(r2, r0) / det;
    let k2 = cross(r0, r1) / det;
    let tri = load_mesh_triangle(hit.slot);
    let m1 = tri.b.xyz - tri.a.xyz;
    let m2 = tri.c.xyz - tri.a.xyz;
    let e1 = k0 * m1.x + k1 * m1.y + k2 * m1.z;
    let e2 = k0 * m2.x + k1 * m2.y + k2 * m2.z;
    let ua = load_mesh_vertex(tri.v0).uv;
    let ub = load_mesh_vertex(tri.v1).uv;
    let uc = load_mesh_vertex(tri.v2).uv;
    out.uv_per_world = texture_triangle_uv_per_world(e1, e2, ub - ua, uc - ua);
    return out;
}

// #else
// Without it: the mesh hook of texture.wgsl for a scene without meshes: never called
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
// #endif
