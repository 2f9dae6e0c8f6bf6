// queue.wgsl — the state of Whitted's queue of secondary rays (a band's; in the words after the
// counters, fray_gpu::counters::QUEUE_*): the camera rays are level 0, slots [0, band_rays());
// each level's rays follow in `paths` as the level before spawned them, from slot band_rays().
// The queue passes (queue_forward.wgsl, queue_gather.wgsl) set the current level's range.

// The band's camera rays: the first slots of `paths`.
fn band_rays() -> u32 {
    return frame.width * frame.band_rows * frame.rays_per_pixel;
}

// The level being processed (0: the camera rays).
fn queue_depth() -> u32 {
    return atomicLoad(&counters[WORD_QUEUE_DEPTH]);
}

// The current dispatch's slots: (first, count).
fn queue_current() -> vec2<u32> {
    return vec2<u32>(atomicLoad(&counters[WORD_QUEUE_CURRENT_START]), atomicLoad(&counters[WORD_QUEUE_CURRENT_COUNT]));
}
