// freeform_batch.wgsl — freeform.wgsl on rays given by the caller (fray_gpu::testing::FreeFormBatch):
// each ray cast against every solid (all its leaves and its whole program), for the parity tests
// against fray-geometry's RayCaster.
//
// #bindings batch, free_forms
// #include "batch.wgsl"
// #include "freeform.wgsl"
//
// Batch: (ray count, solid count, bits of ε as f32, 0).
// Queries: two rows per ray, relative to the solids' reference point — (origin.xyz, t_lo),
// (unit dir.xyz, t_hi).
// Answers: two rows per ray — (t, outward normal.xyz), t < 0 for a miss; (solid, leaf, any hit
// over the same range 0/1, 0) as words.

const QUERY_ROWS: u32 = 2u;
const ANSWER_ROWS: u32 = 2u;

fn answer(k: u32) {
    let a = query(k, 0u);
    let b = query(k, 1u);
    let eps = bitcast<f32>(batch.z);
    var best = NO_HIT;
    var solid = 0u;
    for (var si = 0u; si < batch.y; si++) {
        var hi = b.w;
        if best >= 0.0 {
            hi = best;
        }
        let t = cast_solid(si, all_parts(si), a.xyz, b.xyz, a.w, hi, eps);
        if t >= 0.0 && (best < 0.0 || t < best) {
            best = t;
            solid = si;
        }
    }
    var normal = vec3<f32>(0.0);
    var leaf = 0u;
    if best >= 0.0 {
        let s = surface_at(solid, a.xyz + b.xyz * best, -b.xyz);
        normal = s.normal;
        leaf = s.leaf;
    }
    let any = occluded_by_solids(a.xyz, b.xyz, a.w, b.w, eps, batch.y);
    put(k, 0u, vec4<f32>(best, normal));
    put_words(k, 1u, vec4<u32>(solid, leaf, select(0u, 1u, any), 0u));
}
