// texture.wgsl — a material's colour C from its image texture or colour ramp in the shade pass
// (a scene with textures; the `#else` below holds its identity without): the f32 twin of fray-trace's
// `surface_colour` over `fray_mesh::texture` — the lookup's coordinates (the projected
// mapping's, camera-relative; else the hit's kind's, `kinds_texturing`: a mesh's interpolated uv
// or a terrain's drape), its width by the footprint rule (the camera pixel's width at
// the path length, stretched by 1/|cos θ| up to TEXTURE_MAX_ANISOTROPY, times the uv per world
// unit), nearest, bilinear or trilinear by hand over `textureLoad` with the CPU's texel-centre
// convention, level rule and wrap modes, and the ramp by world height and slope. Everything is
// read from `texture_data` (crate::textures: mapping blocks, material records, level records,
// texels, ramp stops, 16-byte texels TEXTURE_DATA_WIDTH a row) where `texture_info` says.
//
// #if textures
// #include "kinds.wgsl"

// fray_mesh::texture::Footprint::DEFAULT_MAX_ANISOTROPY (a Rust test checks it).
const TEXTURE_MAX_ANISOTROPY: f32 = 8.0;
// Bilinear weights this close to 0 or 1 are snapped (fray_mesh's SNAP, 2⁻³⁰).
const TEXTURE_SNAP: f32 = 9.313225746154785e-10;
const TEXTURE_TAU: f32 = 6.283185307179586;
const TEXTURE_F32_MAX: f32 = 3.4028234663852886e38;

fn texture_word(i: u32) -> vec4<u32> {
    return textureLoad(texture_data, vec2<u32>(i % TEXTURE_DATA_WIDTH, i / TEXTURE_DATA_WIDTH), 0);
}

fn texture_vec(i: u32) -> vec4<f32> {
    return bitcast<vec4<f32>>(texture_word(i));
}

// Whether `x` is finite (by its bits: no fast-math assumption can fold it away).
fn texture_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn texture_finite_or_zero(x: f32) -> f32 {
    return select(0.0, x, texture_finite(x));
}

// The record of material `m` (fields in GpuTextureMaterial's order; a Rust test checks it).
fn load_texture_material(m: u32) -> GpuTextureMaterial {
    let at = texture_info.sections.x + 3u * m;
    let w0 = texture_word(at);
    let w1 = texture_word(at + 1u);
    let w2 = texture_word(at + 2u);
    var r: GpuTextureMaterial;
    r.flags = w0.x;
    r.mapping = w0.y;
    r.filter_mode = w0.z;
    r.first_level = w0.w;
    r.level_count = w1.x;
    r.wrap_u = w1.y;
    r.wrap_v = w1.z;
    r.texels_per_uv = bitcast<f32>(w1.w);
    r.height_first = w2.x;
    r.height_count = w2.y;
    r.slope_first = w2.z;
    r.slope_count = w2.w;
    return r;
}

// Level `k` of material record `r`'s image, clamped to the coarsest (Texture::level).
fn load_texture_level(r: GpuTextureMaterial, k: u32) -> GpuTextureLevel {
    let w0 = texture_word(texture_info.sections.y + r.first_level + min(k, r.level_count - 1u));
    var l: GpuTextureLevel;
    l.first = w0.x;
    l.width = w0.y;
    l.height = w0.z;
    l.pad = w0.w;
    return l;
}

// Material `m`'s mapping block (camera-relative).
fn load_texture_mapping(m: u32) -> GpuMapping {
    let at = 5u * m;
    var g: GpuMapping;
    g.origin = texture_vec(at);
    g.a = texture_vec(at + 1u);
    g.b = texture_vec(at + 2u);
    g.c = texture_vec(at + 3u);
    g.params = texture_vec(at + 4u);
    return g;
}

// Texel (x, y) of level `l` (MipLevel::texel: past the level its last column or row).
fn texture_texel(l: GpuTextureLevel, x: u32, y: u32) -> vec4<f32> {
    let i = min(x, l.width - 1u);
    let j = min(y, l.height - 1u);
    return texture_vec(l.first + j * l.width + i);
}

// WrapMode::reduce.
fn texture_reduce(mode: u32, x: f32) -> f32 {
    if !texture_finite(x) {
        return 0.0;
    }
    if mode == TEXTURE_WRAP_REPEAT {
        return x - floor(x);
    }
    if mode == TEXTURE_WRAP_MIRROR {
        return x - 2.0 * floor(0.5 * x);
    }
    return clamp(x, 0.0, 1.0);
}

// WrapMode::index: the texel integer index `i` of an `n`-texel axis reads.
fn texture_index(mode: u32, i: i32, n: u32) -> u32 {
    let m = i32(n);
    if i >= 0 && i < m {
        return u32(i);
    }
    if mode == TEXTURE_WRAP_REPEAT {
        return u32(((i % m) + m) % m);
    }
    if mode == TEXTURE_WRAP_CLAMP {
        return u32(clamp(i, 0, m - 1));
    }
    let p = 2 * m;
    let k = ((i % p) + p) % p;
    if k < m {
        return u32(k);
    }
    return u32(p - 1 - k);
}

fn texture_snap(f: f32) -> f32 {
    if f < TEXTURE_SNAP {
        return 0.0;
    }
    if f > 1.0 - TEXTURE_SNAP {
        return 1.0;
    }
    return f;
}

// Texture::nearest.
fn texture_nearest(r: GpuTextureMaterial, k: u32, uv: vec2<f32>) -> vec4<f32> {
    let l = load_texture_level(r, k);
    let x = texture_reduce(r.wrap_u, uv.x) * f32(l.width);
    let y = (1.0 - texture_reduce(r.wrap_v, uv.y)) * f32(l.height);
    let i = texture_index(r.wrap_u, i32(floor(x)), l.width);
    let j = texture_index(r.wrap_v, i32(floor(y)), l.height);
    return texture_texel(l, i, j);
}

// Texture::bilinear: the four texels whose centres surround uv, weights snapped.
fn texture_bilinear(r: GpuTextureMaterial, k: u32, uv: vec2<f32>) -> vec4<f32> {
    let l = load_texture_level(r, k);
    let x = texture_reduce(r.wrap_u, uv.x) * f32(l.width) - 0.5;
    let y = (1.0 - texture_reduce(r.wrap_v, uv.y)) * f32(l.height) - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = texture_snap(x - x0);
    let fy = texture_snap(y - y0);
    let i0 = texture_index(r.wrap_u, i32(x0), l.width);
    let i1 = texture_index(r.wrap_u, i32(x0) + 1, l.width);
    let j0 = texture_index(r.wrap_v, i32(y0), l.height);
    let j1 = texture_index(r.wrap_v, i32(y0) + 1, l.height);
    var sum = vec4<f32>(0.0);
    let w00 = (1.0 - fx) * (1.0 - fy);
    let w10 = fx * (1.0 - fy);
    let w01 = (1.0 - fx) * fy;
    let w11 = fx * fy;
    if w00 > 0.0 {
        sum += texture_texel(l, i0, j0) * w00;
    }
    if w10 > 0.0 {
        sum += texture_texel(l, i1, j0) * w10;
    }
    if w01 > 0.0 {
        sum += texture_texel(l, i0, j1) * w01;
    }
    if w11 > 0.0 {
        sum += texture_texel(l, i1, j1) * w11;
    }
    return sum;
}

// Texture::trilinear at `lod` (clamped to the chain; NaN reads the base).
fn texture_trilinear(r: GpuTextureMaterial, uv: vec2<f32>, lod_in: f32) -> vec4<f32> {
    let top = f32(r.level_count - 1u);
    var lod = 0.0;
    if lod_in == lod_in && texture_finite(lod_in) {
        lod = clamp(lod_in, 0.0, top);
    } else if lod_in > 0.0 {
        lod = top;
    }
    let k = floor(lod);
    let f = lod - k;
    let a = texture_bilinear(r, u32(k), uv);
    if f == 0.0 {
        return a;
    }
    return mix(a, texture_bilinear(r, u32(k) + 1u, uv), f);
}

// Texture::level_of_detail of a footprint `texels` base texels wide.
fn texture_level_of_detail(r: GpuTextureMaterial, texels: f32) -> f32 {
    let top = f32(r.level_count - 1u);
    if texels > 1.0 {
        return min(log2(texels), top);
    }
    return 0.0;
}

// Texture::filtered.
fn texture_filtered(r: GpuTextureMaterial, uv: vec2<f32>, uv_width: f32) -> vec4<f32> {
    if r.filter_mode == TEXTURE_FILTER_NEAREST {
        return texture_nearest(r, 0u, uv);
    }
    if r.filter_mode == TEXTURE_FILTER_BILINEAR {
        return texture_bilinear(r, 0u, uv);
    }
    let texels = min(uv_width * r.texels_per_uv, TEXTURE_F32_MAX);
    return texture_trilinear(r, uv, texture_level_of_detail(r, texels));
}

// A surface without coordinates: the image's mean (its 1 × 1 level; fray-trace's trilinear
// lookup at an infinite footprint).
fn texture_mean(r: GpuTextureMaterial) -> vec4<f32> {
    return texture_texel(load_texture_level(r, r.level_count - 1u), 0u, 0u);
}

// Footprint::uv_width: the pixel's width × the capped stretch 1/|cos θ| × the uv per world.
fn texture_uv_width(pixel: f32, cos_theta: f32, uv_per_world: f32) -> f32 {
    let c = abs(cos_theta);
    var stretch = TEXTURE_MAX_ANISOTROPY;
    if c * TEXTURE_MAX_ANISOTROPY > 1.0 {
        stretch = 1.0 / c;
    }
    let w = pixel * stretch * uv_per_world;
    if w > 0.0 {
        return min(w, TEXTURE_F32_MAX);
    }
    return 0.0;
}

// Mapping::project's scale, finite (NaN: the largest).
fn texture_scale(s: f32) -> f32 {
    if s != s {
        return TEXTURE_F32_MAX;
    }
    return clamp(s, 0.0, TEXTURE_F32_MAX);
}

// The angle of (x, y) in [0, 2π) (0 where both are 0).
fn texture_angle(x: f32, y: f32, ring: f32) -> f32 {
    var phi = 0.0;
    if ring > 0.0 {
        phi = atan2(y, x);
    }
    if phi < 0.0 {
        phi += TEXTURE_TAU;
    }
    return phi;
}

// |n|^s with powf's 0⁰ = 1 (x in [0, 1]).
fn texture_pow(x: f32, s: f32) -> f32 {
    if s == 0.0 || x == 1.0 {
        return 1.0;
    }
    if x == 0.0 {
        return 0.0;
    }
    return pow(x, s);
}

// A projected lookup (fray_mesh's Projected): up to three (uv, weight) pairs and the scale.
struct TextureProjected {
    uv: array<vec2<f32>, 3>,
    weight: vec3<f32>,
    uv_per_world: f32,
}

fn texture_single(uv: vec2<f32>, scale: f32) -> TextureProjected {
    var out: TextureProjected;
    out.uv[0] = vec2<f32>(texture_finite_or_zero(uv.x), texture_finite_or_zero(uv.y));
    out.weight = vec3<f32>(1.0, 0.0, 0.0);
    out.uv_per_world = texture_scale(scale);
    return out;
}

// Mapping::project at camera-relative `p` with outward `normal`.
fn texture_project(kind: u32, g: GpuMapping, p: vec3<f32>, normal: vec3<f32>) -> TextureProjected {
    let d = p - g.origin.xyz;
    if kind == MAPPING_PLANAR {
        return texture_single(vec2<f32>(dot(d, g.a.xyz), dot(d, g.b.xyz)), g.params.x);
    }
    if kind == MAPPING_SPHERICAL {
        let r = length(d);
        if !(r > 0.0 && texture_finite(r)) {
            return texture_single(vec2<f32>(0.0, 0.5 * g.params.y), TEXTURE_F32_MAX);
        }
        let x = dot(d, g.a.xyz);
        let y = dot(d, g.b.xyz);
        let z = dot(d, g.c.xyz);
        let ring = length(vec2<f32>(x, y));
        let theta = atan2(ring, z);
        let phi = texture_angle(x, y, ring);
        let uv = vec2<f32>(g.params.x * phi / TEXTURE_TAU, g.params.y * (1.0 - theta / PI));
        let scale = max(g.params.y / (PI * r), g.params.x / (TEXTURE_TAU * ring));
        return texture_single(uv, scale);
    }
    if kind == MAPPING_CYLINDRICAL {
        let x = dot(d, g.a.xyz);
        let y = dot(d, g.b.xyz);
        let h = dot(d, g.c.xyz);
        let rho = length(vec2<f32>(x, y));
        let phi = texture_angle(x, y, rho);
        let uv = vec2<f32>(g.params.x * phi / TEXTURE_TAU, g.params.y * h);
        return texture_single(uv, max(g.params.y, g.params.x / (TEXTURE_TAU * rho)));
    }
    // Triplanar.
    let s = d * g.params.x;
    let side = select(vec3<f32>(1.0), vec3<f32>(-1.0), normal < vec3<f32>(0.0));
    var out: TextureProjected;
    out.uv[0] = vec2<f32>(-side.x * s.z, s.y);
    out.uv[1] = vec2<f32>(s.x, -side.y * s.z);
    out.uv[2] = vec2<f32>(side.z * s.x, s.y);
    for (var k = 0; k < 3; k++) {
        out.uv[k] = vec2<f32>(texture_finite_or_zero(out.uv[k].x), texture_finite_or_zero(out.uv[k].y));
    }
    let a = abs(normal);
    let m = max(a.x, max(a.y, a.z));
    if !(m > 0.0 && texture_finite(m)) {
        out.weight = vec3<f32>(1.0 / 3.0);
    } else {
        let sharp = g.params.y;
        let w = vec3<f32>(texture_pow(a.x / m, sharp), texture_pow(a.y / m, sharp), texture_pow(a.z / m, sharp));
        out.weight = w / (w.x + w.y + w.z);
    }
    out.uv_per_world = g.params.x;
    return out;
}

// Ramp::at over `count` stops from texel `first`: linear between the stops around x, the end
// stops' colours past the ends, the later one at a step; NaN reads the first.
fn texture_ramp_at(first: u32, count: u32, x: f32) -> vec4<f32> {
    var k = 0u;
    while k < count && texture_vec(first + 2u * k).x <= x {
        k++;
    }
    if k == 0u {
        return texture_vec(first + 1u);
    }
    if k == count {
        return texture_vec(first + 2u * k - 1u);
    }
    let a = texture_vec(first + 2u * (k - 1u)).x;
    let b = texture_vec(first + 2u * k).x;
    let f = (x - a) / (b - a);
    return mix(texture_vec(first + 2u * k - 1u), texture_vec(first + 2u * k + 1u), f);
}

// TerrainRamp::colour at world `height` with outward `normal` (Y up).
fn texture_ramp_colour(r: GpuTextureMaterial, height: f32, normal: vec3<f32>) -> vec3<f32> {
    let base = texture_ramp_at(r.height_first, r.height_count, height).xyz;
    if r.slope_count == 0u {
        return base;
    }
    var slope = atan2(length(vec2<f32>(normal.x, normal.z)), normal.y);
    if !texture_finite(slope) {
        slope = 0.0;
    }
    let c = texture_ramp_at(r.slope_first, r.slope_count, slope);
    return mix(base, c.xyz, clamp(c.w, 0.0, 1.0));
}

// The colour C (fray-trace's surface_colour) of material `material` at the hit of `path`:
// camera-relative point `p`, outward shading `normal` (the cut face's where the picture
// surface cuts the object), seen after a path of `distance` from the camera (the footprint
// grows with it).
fn surface_colour(r: GpuTextureMaterial, material: u32, path: GpuPath, p: vec3<f32>, normal: vec3<f32>, distance: f32) -> vec3<f32> {
    var colour = vec3<f32>(1.0);
    if (r.flags & TEXTURE_FLAG_IMAGE) != 0u {
        let dir = path.dir.xyz;
        let cut = path.hit.x <= path.origin.w;
        var geometric = normal;
        var uv = vec2<f32>(0.5);
        var uv_per_world = 0.0;
        var coordinates = false;
        if path.kind != KIND_FREE_FORM {
            let k = kinds_texturing(path, p, normal);
            if !cut {
                geometric = k.geometric;
            }
            uv = k.uv;
            uv_per_world = k.uv_per_world;
            coordinates = k.has_uv;
        }
        let pixel = frame.footprint.x + frame.footprint.y * max(distance, 0.0);
        let cos_theta = abs(dot(dir, geometric));
        var c = vec4<f32>(0.0);
        if r.mapping != MAPPING_NONE {
            var projected = texture_project(r.mapping, load_texture_mapping(material), p, normal);
            let width = texture_uv_width(pixel, cos_theta, projected.uv_per_world);
            for (var k = 0; k < 3; k++) {
                if projected.weight[k] > 0.0 {
                    c += texture_filtered(r, projected.uv[k], width) * projected.weight[k];
                }
            }
        } else if coordinates {
            c = texture_filtered(r, uv, texture_uv_width(pixel, cos_theta, uv_per_world));
        } else {
            c = texture_mean(r);
        }
        colour *= c.xyz;
    }
    if (r.flags & TEXTURE_FLAG_RAMP) != 0u {
        // The world height: camera-relative plus the camera's (an f32 pair).
        let height = (p.y + texture_info.reference.y) + texture_info.reference.x;
        colour *= texture_ramp_colour(r, height, normal);
    }
    return colour;
}

// Material `m` (index `material`) with its colour C multiplying its ambient and diffuse terms
// (Whitted's ka·C and kd·C) at the hit of `path` (see surface_colour); untextured materials
// are returned as they are.
fn textured(m: GpuMaterial, material: u32, path: GpuPath, p: vec3<f32>, normal: vec3<f32>, distance: f32) -> GpuMaterial {
    let r = load_texture_material(material);
    if r.flags == 0u {
        return m;
    }
    let c = surface_colour(r, material, path, p, normal, distance);
    var out = m;
    out.ambient = vec4<f32>(m.ambient.xyz * c, m.ambient.w);
    out.diffuse = vec4<f32>(m.diffuse.xyz * c, m.diffuse.w);
    return out;
}

// #else
// Without it: the textures' hook in shade.wgsl for a scene without image textures or
// colour ramps: every material as it is (C = 1 exactly, so the radiance is bit for bit what it
// was before textures reached the GPU); no texture code, uniform or data texture is compiled.

fn textured(m: GpuMaterial, material: u32, path: GpuPath, p: vec3<f32>, normal: vec3<f32>, distance: f32) -> GpuMaterial {
    return m;
}
// #endif
