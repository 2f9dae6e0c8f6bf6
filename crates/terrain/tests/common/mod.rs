//! Shared by the terrain tests and benchmarks: a deterministic generator (SplitMix64) and
//! test maps.

#![allow(dead_code)] // each user needs a different subset

use fray_terrain::Heightmap;

pub use fray_test_support::Rng;

/// A rough random map: smooth hills plus per-sample noise, heights in about `[0, 20]`.
pub fn rough_map(width: usize, height: usize, seed: u64) -> Heightmap {
    let mut rng = Rng(seed);
    let noise: Vec<f32> = (0..width * height)
        .map(|_| rng.range(-2.0, 2.0) as f32)
        .collect();
    Heightmap::from_fn(width, height, |i, j| {
        let (x, z) = (i as f32 * 0.37, j as f32 * 0.29);
        10.0 + 6.0 * x.sin() * z.cos() + noise[j * width + i]
    })
    .expect("valid test map")
}
