// raygen.wgsl — ray generation: the camera rays of one band of rows, one invocation per ray —
// per pixel its centre and, with anti-aliasing, its samples (samples.wgsl) — written to `paths`
// with no hit yet. The CPU twin is fray_core's Projector::ray and PixelSamples.
//
// #bindings frame
// #include "ray.wgsl"
// #include "camera.wgsl"
// #include "samples.wgsl"

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    let per_pixel = frame.rays_per_pixel;
    if k >= frame.width * frame.band_rows * per_pixel {
        return;
    }
    let pixel = k / per_pixel;
    let s = k % per_pixel;
    let px = pixel % frame.width;
    let py = frame.band_y0 + pixel / frame.width;
    // Ray 0 is the pixel centre (depth, normal; the colour too without anti-aliasing); rays
    // 1… are the samples.
    var offset = vec3<f32>(0.5, 0.5, 1.0);
    if s > 0u {
        offset = pixel_sample(px, py, s - 1u, frame.samples, frame.sample_rows);
    }
    let ray = camera_ray(f32(px) + offset.x, f32(py) + offset.y);
    var path: GpuPath;
    path.origin = vec4<f32>(ray.origin, select(-1.0, ray.t_near, ray.ok));
    path.dir = vec4<f32>(ray.dir, offset.z);
    path.hit = vec4<f32>(NO_HIT, 0.0, 0.0, 0.0);
    paths[k] = path;
}
