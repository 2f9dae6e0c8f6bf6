// queue_forward.wgsl — one invocation before each level of Whitted's secondary rays: the next
// level becomes current — the rays the level before spawned, from the end of that level to the
// queue's top — its range is recorded per level for the gather, and the indirect dispatch of
// the level's passes (64 rays a workgroup, folded into 2D past the per-dimension limit) is
// written to `queue_args`. The first call records the camera rays as level 0.
//
// #bindings frame, queue
// #include "queue.wgsl"
// #include "queue_dispatch.wgsl"

@compute @workgroup_size(1)
fn main() {
    let depth = queue_depth() + 1u;
    if depth == 1u {
        atomicStore(&counters[WORD_LEVEL_START], 0u);
        atomicStore(&counters[WORD_LEVEL_END], band_rays());
    }
    let start = atomicLoad(&counters[WORD_LEVEL_END + depth - 1u]);
    let end = band_rays() + atomicLoad(&counters[WORD_QUEUE_TOP]);
    atomicStore(&counters[WORD_QUEUE_DEPTH], depth);
    atomicStore(&counters[WORD_LEVEL_START + depth], start);
    atomicStore(&counters[WORD_LEVEL_END + depth], end);
    atomicStore(&counters[WORD_QUEUE_CURRENT_START], start);
    atomicStore(&counters[WORD_QUEUE_CURRENT_COUNT], end - start);
    write_dispatch(end - start);
}
