// mesh_hooks.wgsl — the mesh kind's hooks (mesh.wgsl), called by the generated dispatch of the
// scene's kinds (fray_gpu::shader's kinds.wgsl) for the shade and Whitted passes: a mesh hit's
// surface as fray-trace's MeshPrimitive::surface makes it, shadow rays any-hit against every
// instance (opaque: transmittance 0 or 1), the nearest hit of a ray leaving a surface, an
// instance's material and — with textures — a hit's texture coordinates as fray-trace takes
// them: the vertices' uvs interpolated by the hit's barycentrics, and the triangle's uv per
// world unit (fray_mesh::texture::triangle_uv_per_world over its world corners: the mesh-space
// edges through the inverse of the instance's world-to-mesh rows).

// The mesh hit the intersection pass left in `path` (instance in `index`, triangle slot in
// `part`, barycentrics in `hit.yzw`).
fn mesh_hit_of(path: GpuPath) -> MeshHit {
    var hit = mesh_no_hit();
    hit.t = path.hit.x;
    hit.instance = path.index;
    hit.slot = path.part;
    hit.barycentric = path.hit.yzw;
    return hit;
}

// The surface of the mesh hit the intersection pass left in `path` (instance in `index`,
// triangle slot in `part`, barycentrics in `hit.yzw`): the outward geometric normal — the
// inverse transpose of the mesh's face normal, outward whether or not the instance mirrors (as
// the CPU's winding normal turned round by the transform's sign) —; with
// MESH_FLAG_SMOOTH the interpolated vertex normal where it agrees in sign with that face
// normal, else (faceted, or a normal folded away from its face) the face's; the instance's
// material.
fn mesh_shading(path: GpuPath) -> KindShading {
    let hit = mesh_hit_of(path);
    let inst = load_mesh_instance(path.index);
    let s = mesh_surface(hit);
    var g = s.normal;
    // A sliver whose normal rounds to nothing faces the ray, as on the CPU.
    if dot(g, g) == 0.0 {
        g = -path.dir.xyz;
    }
    var out: KindShading;
    out.normal = g;
    out.geometric = g;
    if (inst.flags & MESH_FLAG_SMOOTH) != 0u && dot(s.shading_normal, g) > 0.0 {
        out.normal = s.shading_normal;
    }
    out.material = inst.material;
    return out;
}

// Whether a shadow ray from `o` along `d` meets a mesh in (0, distance).
fn mesh_occludes(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> bool {
    return mesh_any(o, d, 0.0, distance, mesh_info.x);
}

// Narrows `best` to the nearest mesh hit in (0, best) — (0, limit) before the first — of a ray
// leaving a surface, over every instance.
fn mesh_nearest_from_surface(
    o: vec3<f32>,
    d: vec3<f32>,
    limit: f32,
    eps: f32,
    best: ptr<function, SurfaceHit>,
) {
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

// #if textures
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

// The texture coordinates of the mesh hit the intersection pass left in `path` (instance in
// `index`, triangle slot in `part`, barycentrics in `hit.yzw`), and its world geometric normal
// (outward by the winding; the ray's reverse for a sliver).
fn mesh_texturing(path: GpuPath, p: vec3<f32>, normal: vec3<f32>) -> KindTexturing {
    let hit = mesh_hit_of(path);
    let inst = load_mesh_instance(path.index);
    let s = mesh_surface(hit);
    var out: KindTexturing;
    out.geometric = s.normal;
    if dot(s.normal, s.normal) == 0.0 {
        out.geometric = -path.dir.xyz;
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
// #endif
