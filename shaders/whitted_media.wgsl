// whitted_media.wgsl — the media pass's hooks in a Whitted scene: the band's camera rays (level
// 0), or the queue's current level of secondary rays (queue_level.wgsl made it current), which
// belong to no pixel.
//
// #if whitted
// #include "queue.wgsl"

fn media_range() -> vec2<u32> {
    if queue_depth() == 0u {
        return vec2<u32>(0u, band_rays());
    }
    return queue_current();
}

fn media_colour_ray(slot: u32) -> bool {
    return queue_depth() > 0u || frame.rays_per_pixel == 1u || slot % frame.rays_per_pixel != 0u;
}

fn media_pixel_ray(slot: u32) -> u32 {
    return select(slot, NO_PIXEL, queue_depth() > 0u);
}

// #else
// Without it: the media pass's hooks in a scene without Whitted's rays: the band's
// camera rays, each its pixel's.

fn media_range() -> vec2<u32> {
    return vec2<u32>(0u, frame.width * frame.band_rows * frame.rays_per_pixel);
}

// Whether the ray's colour is read: not a centre ray's with anti-aliasing.
fn media_colour_ray(slot: u32) -> bool {
    return frame.rays_per_pixel == 1u || slot % frame.rays_per_pixel != 0u;
}

fn media_pixel_ray(slot: u32) -> u32 {
    return slot;
}
// #endif
