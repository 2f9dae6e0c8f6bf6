// rebase.wgsl — moves resident, anchor-relative scene data to the camera: every vec4 slot of an
// array of GPU structs is copied bit for bit, except the slots that hold positions, which become
// `(x − hi) − lo` (the camera's offset from the anchor as a hi/lo pair), and box corners, which
// are moved outward by the rounding of that subtraction so that boxes still hold what they held.
// With a zero offset it is an exact copy. The CPU twin is fray_gpu::passes::rebase::rebase_words.
//
// #bindings rebase

// The slack that keeps a moved box corner conservative: the subtraction's rounding is at most
// an ulp of |x| + |hi| (2⁻²³ relative); twice that is taken. Zero where the offset is.
fn slack(x: vec3<f32>) -> vec3<f32> {
    let offset_axes = (rebase.hi.xyz != vec3<f32>(0.0)) | (rebase.lo.xyz != vec3<f32>(0.0));
    return select(vec3<f32>(0.0), (abs(x) + abs(rebase.hi.xyz)) * (1.0 / 4194304.0), offset_axes);
}

fn shift(x: vec3<f32>) -> vec3<f32> {
    return (x - rebase.hi.xyz) - rebase.lo.xyz;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= rebase.words {
        return;
    }
    let bit = 1u << (i % rebase.stride);
    let v = source[i];
    let x = bitcast<vec3<f32>>(v.xyz);
    if (rebase.points & bit) != 0u {
        moved[i] = vec4<u32>(bitcast<vec3<u32>>(shift(x)), v.w);
    } else if (rebase.box_mins & bit) != 0u {
        moved[i] = vec4<u32>(bitcast<vec3<u32>>(shift(x) - slack(x)), v.w);
    } else if (rebase.box_maxs & bit) != 0u {
        moved[i] = vec4<u32>(bitcast<vec3<u32>>(shift(x) + slack(x)), v.w);
    } else {
        moved[i] = v;
    }
}
