// The viewer's blit: one full-window triangle drawing the frame's texture, nearest texel, as
// the picture itself (sRGB bytes), its depth (grey) or its normals.

struct Blit {
    surface: vec2<f32>,
    source: vec2<f32>,
    // 0: the picture (sRGB-encoded colour); 1: depth in .w; 2: normals in .xyz, hit flag in .w.
    mode: u32,
    // 1 when the surface encodes sRGB itself (its format is *Srgb): decode first.
    srgb_surface: u32,
    // Depths map to grey as exp(-depth / depth_scale).
    depth_scale: f32,
    pad: f32,
}

@group(0) @binding(0) var<uniform> blit: Blit;
@group(0) @binding(1) var source: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

@fragment
fn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let size = vec2<i32>(blit.source);
    let texel = clamp(vec2<i32>(floor(p.xy / blit.surface * blit.source)), vec2<i32>(0), size - 1);
    let t = textureLoad(source, texel, 0);
    var c = t.rgb;
    if blit.mode == 1u {
        // Misses are negative (GPU) or infinite (CPU): black.
        let hit = t.w >= 0.0 && t.w < 3.0e38;
        c = select(vec3<f32>(0.0), vec3<f32>(exp(-t.w / blit.depth_scale)), hit);
    } else if blit.mode == 2u {
        c = select(vec3<f32>(0.0), t.xyz * 0.5 + 0.5, t.w > 0.5);
    }
    if blit.srgb_surface == 1u {
        c = srgb_to_linear(c);
    }
    return vec4<f32>(c, 1.0);
}
