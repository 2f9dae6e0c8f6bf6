// counters.wgsl — the frame's work counters: each invocation adds to its workgroup's sums
// (`count`), and one invocation per workgroup adds the sums to the frame's counter buffer
// (`flush_counts`), 64-bit pairs carried by hand. The slots and words (COUNT_*, WORD_*,
// COUNTER_WORD, COUNTER_WIDE) are generated from one Rust table (fray_gpu::counters). On a real
// GPU, atomics from every invocation to the same few words serialise and cost more than the work.

var<workgroup> group_counts: array<atomic<u32>, GROUP_COUNTERS>;

// The invocation of a queue kernel (shade, media, Whitted's intersection): one ray slot per
// invocation, 64 a workgroup, the workgroups in a 2D grid.
struct QueueInvocation {
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local_index: u32,
}

// Opens a queue kernel: zeroes the workgroup's sums before any invocation adds to them, and
// returns the invocation's index in the dispatch. Call first, in uniform control flow.
fn begin_queue_kernel(at: QueueInvocation) -> u32 {
    zero_counts(at.local_index);
    workgroupBarrier();
    return at.id.x + at.id.y * at.groups.x * 64u;
}

// Closes a queue kernel: the workgroup's sums go to the frame's counters once every invocation
// has added to them. Call last, in uniform control flow.
fn end_queue_kernel(at: QueueInvocation) {
    workgroupBarrier();
    flush_counts(at.local_index);
}

// Zeroes the workgroup's sums (the pipelines skip wgpu's workgroup zero-fill); call with the
// local index before the first barrier.
fn zero_counts(local_index: u32) {
    if local_index < GROUP_COUNTERS {
        atomicStore(&group_counts[local_index], 0u);
    }
}

fn count(slot: u32, value: u32) {
    if value > 0u {
        atomicAdd(&group_counts[slot], value);
    }
}

fn add_wide(lo: u32, value: u32) {
    if value == 0u {
        return;
    }
    let old = atomicAdd(&counters[lo], value);
    if old + value < old {
        atomicAdd(&counters[lo + 1u], 1u);
    }
}

// Adds the workgroup's sums to the frame's counters; call with the local index after a barrier
// that every invocation reaches.
fn flush_counts(local_index: u32) {
    if local_index != 0u {
        return;
    }
    for (var slot = 0u; slot < GROUP_COUNTERS; slot++) {
        let value = atomicLoad(&group_counts[slot]);
        if value == 0u {
            continue;
        }
        if COUNTER_WIDE[slot] {
            add_wide(COUNTER_WORD[slot], value);
        } else {
            atomicAdd(&counters[COUNTER_WORD[slot]], value);
        }
    }
}
