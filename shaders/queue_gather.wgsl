// queue_gather.wgsl — one invocation before each gather of Whitted's secondary rays, deepest
// level first: the level above the current one becomes current (its rays are the parents whose
// children's radiance the gather adds), with the indirect dispatch over them in `queue_args` —
// none when the level below spawned no ray.
//
// #bindings frame, queue
// #include "queue.wgsl"
// #include "queue_dispatch.wgsl"

@compute @workgroup_size(1)
fn main() {
    let depth = queue_depth();
    var rays = 0u;
    var start = 0u;
    if depth > 0u {
        let children = atomicLoad(&counters[WORD_LEVEL_END + depth]) - atomicLoad(&counters[WORD_LEVEL_START + depth]);
        start = atomicLoad(&counters[WORD_LEVEL_START + depth - 1u]);
        if children > 0u {
            rays = atomicLoad(&counters[WORD_LEVEL_END + depth - 1u]) - start;
        }
        atomicStore(&counters[WORD_QUEUE_DEPTH], depth - 1u);
    }
    atomicStore(&counters[WORD_QUEUE_CURRENT_START], start);
    atomicStore(&counters[WORD_QUEUE_CURRENT_COUNT], rays);
    write_dispatch(rays);
}
