// queue_gather.wgsl — one invocation before each gather of Whitted's secondary rays, deepest
// level first: the level above the current one becomes current (its rays are the parents whose
// children's radiance the gather adds), with the indirect dispatch over them in `queue_args` —
// none when the level below spawned no ray.
//
// #bindings frame, queue
// #include "queue.wgsl"

const MAX_GROUPS_PER_DIMENSION: u32 = 65535u;

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
    let groups = (rays + 63u) / 64u;
    let x = min(groups, MAX_GROUPS_PER_DIMENSION);
    var y = 0u;
    if x > 0u {
        y = (groups + x - 1u) / x;
    }
    queue_args[0] = x;
    queue_args[1] = y;
    queue_args[2] = 1u;
}
