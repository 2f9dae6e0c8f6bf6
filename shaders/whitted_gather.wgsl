// whitted_gather.wgsl — Whitted's gather: one invocation per ray of the current level (set by
// queue_gather.wgsl, deepest level first), its radiance plus each child's weighted by the child's
// `kr` or `kt` — the `kr · I_r + kt · I_t` of fray-trace's Integrator::whitted, summed in the
// same order (reflected, then refracted). Children are final before their parents are gathered.
//
// #bindings frame, shading
// #include "queue.wgsl"

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    let level = queue_current();
    if k >= level.y {
        return;
    }
    let slot = level.x + k;
    let record = secondaries[slot];
    if record.children == 0u {
        return;
    }
    var total = vec3<f32>(0.0);
    for (var c = record.first_child; c < record.first_child + record.children; c++) {
        total += secondaries[c].weight.xyz * paths[c].radiance.xyz;
    }
    paths[slot].radiance = vec4<f32>(paths[slot].radiance.xyz + total, 0.0);
}
