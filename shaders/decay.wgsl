// decay.wgsl — the mean of e^{−s} over [0, x], (1 − e^{−x}) / x, in f32 without cancellation:
// what an exponential attenuation integrates to over a step (the fog's closed forms, the sky's
// march). No bindings.

// (1 − e^{−x}) / x for x ≥ 0 (the Rust's `-(-x).exp_m1() / x`). WGSL has no expm1, and
// 1 − exp(−x) in f32 cancels: at x = 1e−4 it keeps about three digits. Below 1 the Taylor
// series Σ (−x)ⁿ/(n + 1)! to n = 10 instead — its remainder is under x¹¹/12! ≈ 2e−9, far below
// f32's 6e−8, and no term cancels another by more than the sum's size; from 1 on, e^{−x} ≤ 0.37
// and the subtraction loses under 2 bits. Straight-line: both are computed, one is selected.
fn mean_decay(x: f32) -> f32 {
    var s = -1.0 / 39916800.0;
    s = 1.0 / 3628800.0 + x * s;
    s = -1.0 / 362880.0 + x * s;
    s = 1.0 / 40320.0 + x * s;
    s = -1.0 / 5040.0 + x * s;
    s = 1.0 / 720.0 + x * s;
    s = -1.0 / 120.0 + x * s;
    s = 1.0 / 24.0 + x * s;
    s = -1.0 / 6.0 + x * s;
    s = 0.5 + x * s;
    let series = 1.0 - x * s;
    // (The divisor only matters where the direct form is selected, x ≥ 1.)
    let direct = (1.0 - exp(-x)) / max(x, 1.0);
    return select(direct, series, x < 1.0);
}

// mean_decay per channel.
fn mean_decay3(x: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(mean_decay(x.x), mean_decay(x.y), mean_decay(x.z));
}
