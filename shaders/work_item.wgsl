// work_item.wgsl — what an invocation of a work item's workgroup covers: one pixel of the item's
// tile (TILE_THREADS² invocations per item) and that pixel's camera rays in `paths`.

// The range [x, y) of `paths` holding the camera rays of the pixel invocation `local` covers in
// `item`'s tile; empty for an invocation past the tile's edge.
fn item_rays(item: WorkItem, local: vec3<u32>) -> vec2<u32> {
    let px = item.x0 + local.x;
    let py = item.y0 + local.y;
    if px >= item.x1 || py >= item.y1 {
        return vec2<u32>(0u, 0u);
    }
    let first = ((py - frame.band_y0) * frame.width + px) * frame.rays_per_pixel;
    return vec2<u32>(first, first + frame.rays_per_pixel);
}
