// batch.wgsl — the scaffold of every batch kernel (fray_gpu::testing::BatchPass): invocation k
// answers query k with `answer(k)`, which the including module defines (terrain_batch.wgsl,
// fog_batch.wgsl, …) together with its QUERY_ROWS and ANSWER_ROWS: it reads its query's rows with
// `query(k, row)` and writes its answer's rows with `put` (floats, as their bits) or `put_words`.
// The parity tests compare the answers with the CPU's, ray by ray.
//
// Batch: (query count, three parameters of the kernel's own).

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let k = id.x + id.y * groups.x * 64u;
    if k >= batch.x {
        return;
    }
    answer(k);
}

fn query(k: u32, row: u32) -> vec4<f32> {
    return queries[QUERY_ROWS * k + row];
}

fn put(k: u32, row: u32, v: vec4<f32>) {
    answers[ANSWER_ROWS * k + row] = bitcast<vec4<u32>>(v);
}

fn put_words(k: u32, row: u32, v: vec4<u32>) {
    answers[ANSWER_ROWS * k + row] = v;
}
