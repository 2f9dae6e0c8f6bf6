// no_whitted_media.wgsl — the media pass's hooks in a scene without Whitted's rays: the band's
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
