// samples.wgsl — anti-aliasing sample positions: fray_core::samples, the same strata, the same
// PCG hash and the same 24-bit jitter, so both backends sample the very same points.

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Sample `s` of pixel (px, py) for `count` samples in `rows` rows of strata: its offset inside
// the pixel (xy, in [0, 1)) and its box-filter weight (z): PixelSamples::sample.
fn pixel_sample(px: u32, py: u32, s: u32, count: u32, rows: u32) -> vec3<f32> {
    if count == 1u {
        return vec3<f32>(0.5, 0.5, 1.0);
    }
    let base = count / rows;
    let extra = count % rows;
    let long = extra * (base + 1u);
    var row: u32;
    var first: u32;
    var strata: u32;
    if s < long {
        row = s / (base + 1u);
        first = row * (base + 1u);
        strata = base + 1u;
    } else {
        row = extra + (s - long) / base;
        first = long + (row - extra) * base;
        strata = base;
    }
    let h = pcg_hash(px ^ pcg_hash(py ^ pcg_hash(s)));
    let g = pcg_hash(h);
    let ux = f32(h >> 8u) * (1.0 / 16777216.0);
    let uy = f32(g >> 8u) * (1.0 / 16777216.0);
    let n = f32(strata);
    let r = f32(rows);
    return vec3<f32>((f32(s - first) + ux) / n, (f32(row) + uy) / r, 1.0 / (n * r));
}
