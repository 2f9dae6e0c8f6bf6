// queue_level.wgsl — one invocation before the media pass takes a level of Whitted's secondary
// rays (a scene with fog, a sky or clouds): the level being gathered (the queue's depth) becomes
// current, with the indirect dispatch over its rays in `queue_args`.
//
// #bindings frame, queue
// #include "queue.wgsl"
// #include "queue_dispatch.wgsl"

@compute @workgroup_size(1)
fn main() {
    let depth = queue_depth();
    let start = atomicLoad(&counters[WORD_LEVEL_START + depth]);
    let rays = atomicLoad(&counters[WORD_LEVEL_END + depth]) - start;
    atomicStore(&counters[WORD_QUEUE_CURRENT_START], start);
    atomicStore(&counters[WORD_QUEUE_CURRENT_COUNT], rays);
    write_dispatch(rays);
}
