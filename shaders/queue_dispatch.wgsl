// queue_dispatch.wgsl — the queue passes' indirect dispatch: `rays` rays, 64 a workgroup, folded
// into 2D past WebGPU's least maximum of workgroups per dimension (the passes fold it back:
// `id.x + id.y · groups.x · 64`).

const MAX_GROUPS_PER_DIMENSION: u32 = 65535u;

fn write_dispatch(rays: u32) {
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
