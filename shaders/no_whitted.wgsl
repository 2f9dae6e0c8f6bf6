// no_whitted.wgsl — the Whitted hooks of the shade pass in a scene whose materials neither
// reflect nor transmit: it shades the band's camera rays, spawns nothing, and shadow rays stop at
// the first surface (no Whitted code or binding compiled).

fn shade_range() -> vec2<u32> {
    return vec2<u32>(0u, frame.width * frame.band_rows * frame.rays_per_pixel);
}

fn whitted_begin(slot: u32) {}

// The path's length from the camera to a hit at `t` along the ray of `slot`: t.
fn whitted_path_length(slot: u32, t: f32) -> f32 {
    return t;
}

fn whitted_miss(slot: u32) {}

fn whitted_spawn(slot: u32, p: vec3<f32>, d: vec3<f32>, geometric: vec3<f32>, shading: vec3<f32>, m: GpuMaterial, t: f32) {}

fn whitted_transmits() -> bool {
    return false;
}

fn whitted_transmittance(o: vec3<f32>, d: vec3<f32>, distance: f32, eps: f32) -> vec3<f32> {
    return vec3<f32>(1.0);
}
