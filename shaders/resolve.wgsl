// resolve.wgsl — the band's pixels from their camera rays: colour the box-filtered radiance of
// the samples (the background where one hits nothing; without anti-aliasing the centre ray's),
// depth and normal from the centre ray — into the frame's storage textures: linear colour and
// depth, normal and hit flag, and the tone-mapped sRGB display image (fray_core's ToneMap and
// linear_to_srgb, in f32). Counts the pixels whose centre ray hit. With media (HAS_MEDIA: the
// media pass ran) every ray's radiance is its own, a miss's too — the background through the
// fog; without, a miss is the background, as before media existed.
//
// #bindings frame, targets
// #include "ray.wgsl"
// #include "counters.wgsl"

override HAS_MEDIA: bool = false;

// Whether a ray's radiance is its colour: it hit, or it missed and the media pass lit it.
fn has_radiance(path: GpuPath) -> bool {
    return path.origin.w >= 0.0 && (HAS_MEDIA || path.hit.x >= 0.0);
}

fn tone_map(value: f32) -> f32 {
    let x = max(value * frame.exposure, 0.0);
    var y = x;
    if frame.tone_map == TONE_MAP_REINHARD {
        y = x / (1.0 + x);
    }
    // NaN compares false: it maps to 0, as on the CPU.
    if !(y >= 0.0) {
        return 0.0;
    }
    return min(y, 1.0);
}

fn linear_to_srgb(v: f32) -> f32 {
    let x = clamp(v, 0.0, 1.0);
    if x <= 0.0031308 {
        return 12.92 * x;
    }
    return 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

@compute @workgroup_size(8, 8)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) local_index: u32,
) {
    zero_counts(local_index);
    workgroupBarrier();
    let px = id.x;
    let row = id.y;
    if px < frame.width && row < frame.band_rows {
        let per_pixel = frame.rays_per_pixel;
        let first = (row * frame.width + px) * per_pixel;
        let centre = paths[first];
        let background = frame.background.xyz;
        var colour = background;
        if per_pixel == 1u {
            if has_radiance(centre) {
                colour = centre.radiance.xyz;
            }
        } else {
            colour = vec3<f32>(0.0);
            for (var r = first + 1u; r < first + per_pixel; r++) {
                let path = paths[r];
                var c = background;
                if has_radiance(path) {
                    c = path.radiance.xyz;
                }
                colour += path.dir.w * c;
            }
        }
        let hit = centre.origin.w >= 0.0 && centre.hit.x >= 0.0;
        let at = vec2<u32>(px, frame.band_y0 + row);
        var depth = -1.0;
        var normal = vec4<f32>(0.0);
        if hit {
            depth = centre.hit.x;
            normal = vec4<f32>(centre.hit.yzw, 1.0);
            count(COUNT_HITS, 1u);
        }
        textureStore(colour_depth, at, vec4<f32>(colour, depth));
        textureStore(normals, at, normal);
        let display = vec3<f32>(
            linear_to_srgb(tone_map(colour.x)),
            linear_to_srgb(tone_map(colour.y)),
            linear_to_srgb(tone_map(colour.z)),
        );
        textureStore(display_image, at, vec4<f32>(display, 1.0));
    }
    workgroupBarrier();
    flush_counts(local_index);
}
