// mesh.wgsl — triangle meshes (docs/methods.md §7), the f32 twin of fray_mesh's MeshBvh::nearest_hit /
// any_hit and Instance, over the arrays fray_mesh::gpu_layout flattens: every mesh's BVH nodes,
// triangles (leaf order, corners relative to the mesh's anchor) and vertex attributes
// concatenated, one GpuMeshInstance block per placed mesh (its root node and the affine rows
// from reference-relative world positions to anchor-relative mesh positions). No bindings of its
// own: the module that includes it binds the meshes group (fray_gpu::bindings::MESHES, or
// TERRAINS_MESHES): `mesh_data`, one texture of 16-byte texels holding every array —
// instances, then nodes, triangles and vertices, each element its struct's words in field order
// (fray_gpu::mesh_pass::MeshBuffers) — and `mesh_info`, (instance count, first texel of the
// nodes, of the triangles, of the vertices). The load_mesh_* functions read one element.
//
// - mesh_instance_nearest(k, origin, dir, lo, hi, &best): narrows `best` (a MeshHit, start from
//   mesh_no_hit()) by instance k's triangles with t in the open range (lo, hi); ties on equal t
//   go to the smaller (instance, triangle) pair, so the result does not depend on the order the
//   BVH visits them in. A caller narrowing over instances in increasing order keeps the earlier
//   instance's hit on a tie.
// - mesh_instance_any(k, origin, dir, lo, hi): whether instance k has a hit in (lo, hi) (shadow
//   rays; stops at the first).
// - mesh_nearest(origin, dir, lo, hi, count) / mesh_any(…): the same over instances 0..count.
// - mesh_surface(hit): the hit's world geometric normal (unit, outward by the triangle's
//   counter-clockwise winding, through the inverse transpose — never turned to the viewer),
//   its interpolated shading normal and uv.
// `origin` is camera-relative (minus the reference point the instance blocks were written for),
// `dir` any non-zero vector (t is in its units, as on the CPU: instance rays are not
// renormalised); `lo` ≥ 0 and `hi` ≤ BIG.
//
// Per instance: the ray moved into the mesh's space (the instance rows), then the BVH nearest
// child first with a fixed private stack of MESH_STACK entries (the CPU refuses a BVH deeper
// than MESH_STACK − 1: fray_mesh::gpu_layout), each box by a slab test whose far end is widened
// by MESH_SLAB_WIDEN of itself (and of `hi`), so f32 rounding never drops a box the ray enters
// (Ize 2013; the boxes themselves are rounded outward around the f32 corners), and each triangle
// by the watertight test of Woop, Benthin and Wald (2013) in f32 as fray_mesh::triangle does it
// in f64: the axis permutation by the ray's largest component and the shear, per-vertex sheared
// positions (the same bits for a vertex in every triangle that shares it), and edge functions
// whose **signs** come from comparing their two rounded products — exactly antisymmetric across
// a shared edge even where a compiler fuses a product into the subtraction (an FMA would break
// `u(P→Q) = −u(Q→P)` of the differences), so a ray through an edge or a vertex can never pass
// between the triangles that share it.

// The slab test's far end and `hi` are widened by 2⁻²¹ of themselves: past the relative error
// of `(b − o) · (1/d)` in f32 (two roundings and a reciprocal within 2.5 ulp, ≤ 2⁻²² for
// both ends together).
const MESH_SLAB_WIDEN: f32 = 4.76837158e-7;
// A box entry meaning "missed".
const MESH_MISS: f32 = 3.0e38;

// Texel i of the mesh texture (MESH_TEXTURE_WIDTH per row).
fn mesh_texel(i: u32) -> vec4<u32> {
    return textureLoad(mesh_data, vec2<u32>(i % MESH_TEXTURE_WIDTH, i / MESH_TEXTURE_WIDTH), 0);
}

fn load_mesh_instance(k: u32) -> GpuMeshInstance {
    let at = 4u * k;
    let d = mesh_texel(at + 3u);
    var m: GpuMeshInstance;
    m.to_mesh_x = bitcast<vec4<f32>>(mesh_texel(at));
    m.to_mesh_y = bitcast<vec4<f32>>(mesh_texel(at + 1u));
    m.to_mesh_z = bitcast<vec4<f32>>(mesh_texel(at + 2u));
    m.root = d.x;
    m.mesh = d.y;
    m.material = d.z;
    m.flags = d.w;
    return m;
}

fn load_mesh_node(i: u32) -> GpuMeshNode {
    let at = mesh_info.y + 2u * i;
    let a = mesh_texel(at);
    let b = mesh_texel(at + 1u);
    var n: GpuMeshNode;
    n.min_x = bitcast<f32>(a.x);
    n.min_y = bitcast<f32>(a.y);
    n.min_z = bitcast<f32>(a.z);
    n.first = a.w;
    n.max_x = bitcast<f32>(b.x);
    n.max_y = bitcast<f32>(b.y);
    n.max_z = bitcast<f32>(b.z);
    n.count = b.w;
    return n;
}

fn load_mesh_triangle(slot: u32) -> GpuMeshTriangle {
    let at = mesh_info.z + 4u * slot;
    let d = mesh_texel(at + 3u);
    var t: GpuMeshTriangle;
    t.a = bitcast<vec4<f32>>(mesh_texel(at));
    t.b = bitcast<vec4<f32>>(mesh_texel(at + 1u));
    t.c = bitcast<vec4<f32>>(mesh_texel(at + 2u));
    t.index = d.x;
    t.v0 = d.y;
    t.v1 = d.z;
    t.v2 = d.w;
    return t;
}

fn load_mesh_vertex(v: u32) -> GpuMeshVertex {
    let at = mesh_info.w + 2u * v;
    let b = bitcast<vec4<f32>>(mesh_texel(at + 1u));
    var m: GpuMeshVertex;
    m.normal = bitcast<vec4<f32>>(mesh_texel(at));
    m.uv = b.xy;
    m.pad = b.zw;
    return m;
}

struct MeshHit {
    // Distance along the ray (in units of `dir`); −1 for a miss.
    t: f32,
    // The instance hit, MESH_NO_HIT for a miss.
    instance: u32,
    // The mesh's own index of the triangle (fray_mesh::MeshHit::triangle).
    triangle: u32,
    // Its slot in the triangle array (for mesh_surface).
    slot: u32,
    // The barycentric weights of the triangle's corners a, b, c at the hit.
    barycentric: vec3<f32>,
}

fn mesh_no_hit() -> MeshHit {
    var h: MeshHit;
    h.t = -1.0;
    h.instance = MESH_NO_HIT;
    h.triangle = MESH_NO_HIT;
    h.slot = 0u;
    return h;
}

// A ray in a mesh's space (anchor-relative) with its watertight frame (fray_mesh's RayFrame).
struct MeshRay {
    origin: vec3<f32>,
    dir: vec3<f32>,
    // 1/dir, 0 on the axes where dir is 0 (`flat`).
    inv: vec3<f32>,
    flat: vec3<bool>,
    kx: u32,
    ky: u32,
    kz: u32,
    // (d[kx]/d[kz], d[ky]/d[kz], 1/d[kz]).
    shear: vec3<f32>,
    // False for a zero direction (nothing is hit).
    valid: bool,
}

fn mesh_ray(inst: GpuMeshInstance, origin: vec3<f32>, dir: vec3<f32>) -> MeshRay {
    var r: MeshRay;
    r.origin = vec3<f32>(
        dot(inst.to_mesh_x.xyz, origin) + inst.to_mesh_x.w,
        dot(inst.to_mesh_y.xyz, origin) + inst.to_mesh_y.w,
        dot(inst.to_mesh_z.xyz, origin) + inst.to_mesh_z.w,
    );
    let d = vec3<f32>(
        dot(inst.to_mesh_x.xyz, dir),
        dot(inst.to_mesh_y.xyz, dir),
        dot(inst.to_mesh_z.xyz, dir),
    );
    r.dir = d;
    r.flat = abs(d) < vec3<f32>(1.0e-30);
    r.inv = select(vec3<f32>(1.0) / d, vec3<f32>(0.0), r.flat);
    let a = abs(d);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kz + 2u) % 3u;
    // Keep the winding: a negative major axis mirrors the frame, so swap the others.
    if d[kz] < 0.0 {
        let s = kx;
        kx = ky;
        ky = s;
    }
    r.kx = kx;
    r.ky = ky;
    r.kz = kz;
    r.valid = a[kz] > 0.0;
    let dz = select(1.0, d[kz], r.valid);
    r.shear = vec3<f32>(d[kx] / dz, d[ky] / dz, 1.0 / dz);
    return r;
}

// The entry distance of the ray into node `n`'s box within [lo, hi], or MESH_MISS. Axes along
// which the ray does not move count as inside the slab when the origin is (closed), as on the
// CPU (its NaN rule).
fn mesh_box_entry(n: GpuMeshNode, r: MeshRay, lo: f32, hi: f32) -> f32 {
    let bmin = vec3<f32>(n.min_x, n.min_y, n.min_z);
    let bmax = vec3<f32>(n.max_x, n.max_y, n.max_z);
    let t0 = (bmin - r.origin) * r.inv;
    let t1 = (bmax - r.origin) * r.inv;
    let inside = (bmin <= r.origin) & (r.origin <= bmax);
    let near = select(min(t0, t1), select(vec3<f32>(MESH_MISS), vec3<f32>(-MESH_MISS), inside), r.flat);
    var far = select(max(t0, t1), select(vec3<f32>(-MESH_MISS), vec3<f32>(MESH_MISS), inside), r.flat);
    far = far + abs(far) * MESH_SLAB_WIDEN;
    let enter = max(lo, max(near.x, max(near.y, near.z)));
    let leave = min(hi + abs(hi) * MESH_SLAB_WIDEN, min(far.x, min(far.y, far.z)));
    return select(MESH_MISS, enter, enter <= leave);
}

// A corner relative to the ray's origin in the sheared frame: (x, y) in the ray's plane, z along
// it scaled by 1/d[kz]. A function of the vertex and the ray alone.
fn mesh_shear(r: MeshRay, corner: vec4<f32>) -> vec3<f32> {
    let p = corner.xyz - r.origin;
    return vec3<f32>(p[r.kx] - r.shear.x * p[r.kz], p[r.ky] - r.shear.y * p[r.kz], r.shear.z * p[r.kz]);
}

// (t, barycentric a, b, c) of the ray's hit on `tri` with t > lo, either side facing; t = −1
// with weights 0 for none (a miss, a degenerate triangle, a ray in its plane).
fn mesh_triangle(r: MeshRay, tri: GpuMeshTriangle, lo: f32) -> vec4<f32> {
    let a = mesh_shear(r, tri.a);
    let b = mesh_shear(r, tri.b);
    let c = mesh_shear(r, tri.c);
    // Edge P → Q as Qx·Py − Qy·Px; its sign from the comparison of the two rounded products.
    let u1 = c.x * b.y;
    let u2 = c.y * b.x; // edge b → c: a's weight
    let v1 = a.x * c.y;
    let v2 = a.y * c.x; // edge c → a: b's weight
    let w1 = b.x * a.y;
    let w2 = b.y * a.x; // edge a → b: c's weight
    let negative = u1 < u2 || v1 < v2 || w1 < w2;
    let positive = u1 > u2 || v1 > v2 || w1 > w2;
    let none = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    if negative && positive {
        return none;
    }
    let u = select(u1 - u2, 0.0, u1 == u2);
    let v = select(v1 - v2, 0.0, v1 == v2);
    let w = select(w1 - w2, 0.0, w1 == w2);
    let det = u + v + w;
    if det == 0.0 {
        return none;
    }
    let t = (u * a.z + v * b.z + w * c.z) / det;
    // NaN (an overflow) fails the test too.
    if !(t > lo) {
        return none;
    }
    return vec4<f32>(t, vec3<f32>(u, v, w) / det);
}

// Whether a hit at `t` on (instance, triangle) replaces `best`: nearer, or as near with a
// smaller (instance, triangle).
fn mesh_better(t: f32, instance: u32, triangle: u32, best: MeshHit) -> bool {
    if best.instance == MESH_NO_HIT || t < best.t {
        return true;
    }
    return t == best.t && (instance < best.instance || (instance == best.instance && triangle < best.triangle));
}

fn mesh_instance_nearest(k: u32, origin: vec3<f32>, dir: vec3<f32>, lo: f32, hi: f32, best: ptr<function, MeshHit>) {
    let inst = load_mesh_instance(k);
    if inst.root == MESH_NO_NODE {
        return;
    }
    let r = mesh_ray(inst, origin, dir);
    if !r.valid {
        return;
    }
    var bound = hi;
    if (*best).instance != MESH_NO_HIT {
        bound = min(hi, (*best).t);
    }
    let root_t = mesh_box_entry(load_mesh_node(inst.root), r, lo, bound);
    if root_t == MESH_MISS {
        return;
    }
    var stack_node: array<u32, MESH_STACK>;
    var stack_t: array<f32, MESH_STACK>;
    stack_node[0] = inst.root;
    stack_t[0] = root_t;
    var top = 1u;
    while top > 0u {
        top -= 1u;
        if (*best).instance != MESH_NO_HIT {
            bound = min(hi, (*best).t);
        }
        // A box entered only past the best hit so far (widened as the slab test is).
        if stack_t[top] > bound + abs(bound) * MESH_SLAB_WIDEN {
            continue;
        }
        let node = load_mesh_node(stack_node[top]);
        if node.count > 0u {
            for (var j = 0u; j < node.count; j++) {
                let slot = node.first + j;
                let tri = load_mesh_triangle(slot);
                let h = mesh_triangle(r, tri, lo);
                if h.x > lo && h.x < hi && mesh_better(h.x, k, tri.index, *best) {
                    (*best).t = h.x;
                    (*best).instance = k;
                    (*best).triangle = tri.index;
                    (*best).slot = slot;
                    (*best).barycentric = h.yzw;
                }
            }
            continue;
        }
        if (*best).instance != MESH_NO_HIT {
            bound = min(hi, (*best).t);
        }
        let left = node.first;
        let right = node.first + 1u;
        let tl = mesh_box_entry(load_mesh_node(left), r, lo, bound);
        let tr = mesh_box_entry(load_mesh_node(right), r, lo, bound);
        // The nearer child is pushed last, so it is popped first. The stack never overflows:
        // the CPU refuses a BVH deeper than MESH_STACK − 1 (the guard only keeps indices in
        // bounds).
        var first_node = right;
        var first_t = tr;
        var second_node = left;
        var second_t = tl;
        if tr < tl {
            first_node = left;
            first_t = tl;
            second_node = right;
            second_t = tr;
        }
        if first_t != MESH_MISS && top < MESH_STACK {
            stack_node[top] = first_node;
            stack_t[top] = first_t;
            top += 1u;
        }
        if second_t != MESH_MISS && top < MESH_STACK {
            stack_node[top] = second_node;
            stack_t[top] = second_t;
            top += 1u;
        }
    }
}

fn mesh_instance_any(k: u32, origin: vec3<f32>, dir: vec3<f32>, lo: f32, hi: f32) -> bool {
    let inst = load_mesh_instance(k);
    if inst.root == MESH_NO_NODE {
        return false;
    }
    let r = mesh_ray(inst, origin, dir);
    if !r.valid || mesh_box_entry(load_mesh_node(inst.root), r, lo, hi) == MESH_MISS {
        return false;
    }
    var stack_node: array<u32, MESH_STACK>;
    stack_node[0] = inst.root;
    var top = 1u;
    while top > 0u {
        top -= 1u;
        let node = load_mesh_node(stack_node[top]);
        if node.count > 0u {
            for (var j = 0u; j < node.count; j++) {
                let h = mesh_triangle(r, load_mesh_triangle(node.first + j), lo);
                if h.x > lo && h.x < hi {
                    return true;
                }
            }
            continue;
        }
        for (var c = 0u; c < 2u; c++) {
            let child = node.first + c;
            if mesh_box_entry(load_mesh_node(child), r, lo, hi) != MESH_MISS && top < MESH_STACK {
                stack_node[top] = child;
                top += 1u;
            }
        }
    }
    return false;
}

// The nearest hit over instances 0..count.
fn mesh_nearest(origin: vec3<f32>, dir: vec3<f32>, lo: f32, hi: f32, count: u32) -> MeshHit {
    var best = mesh_no_hit();
    for (var k = 0u; k < count; k++) {
        mesh_instance_nearest(k, origin, dir, lo, hi, &best);
    }
    return best;
}

// Whether any of instances 0..count is hit in (lo, hi).
fn mesh_any(origin: vec3<f32>, dir: vec3<f32>, lo: f32, hi: f32, count: u32) -> bool {
    for (var k = 0u; k < count; k++) {
        if mesh_instance_any(k, origin, dir, lo, hi) {
            return true;
        }
    }
    return false;
}

struct MeshSurface {
    // World geometric normal, unit, outward by the counter-clockwise winding (never flipped).
    normal: vec3<f32>,
    // World shading normal: the vertices' normals interpolated, unit.
    shading_normal: vec3<f32>,
    // Interpolated texture coordinates (0 without them: MESH_FLAG_UVS).
    uv: vec2<f32>,
}

// A mesh-space normal in the world: the inverse transpose, Σᵢ n[i] · to_mesh_i.xyz, unit.
fn mesh_world_normal(inst: GpuMeshInstance, n: vec3<f32>) -> vec3<f32> {
    let w = n.x * inst.to_mesh_x.xyz + n.y * inst.to_mesh_y.xyz + n.z * inst.to_mesh_z.xyz;
    let len = length(w);
    return select(n, w / len, len > 0.0);
}

// The surface at `hit` (a hit, not a miss).
fn mesh_surface(hit: MeshHit) -> MeshSurface {
    let inst = load_mesh_instance(hit.instance);
    let tri = load_mesh_triangle(hit.slot);
    let g = cross(tri.b.xyz - tri.a.xyz, tri.c.xyz - tri.a.xyz);
    let va = load_mesh_vertex(tri.v0);
    let vb = load_mesh_vertex(tri.v1);
    let vc = load_mesh_vertex(tri.v2);
    let w = hit.barycentric;
    var s: MeshSurface;
    s.normal = mesh_world_normal(inst, g);
    s.shading_normal = mesh_world_normal(inst, w.x * va.normal.xyz + w.y * vb.normal.xyz + w.z * vc.normal.xyz);
    s.uv = w.x * va.uv + w.y * vb.uv + w.z * vc.uv;
    return s;
}
