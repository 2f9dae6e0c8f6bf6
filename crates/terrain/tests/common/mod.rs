//! Shared by the terrain tests and benchmarks: a deterministic generator (SplitMix64) and
//! test maps.

#![allow(dead_code)] // each user needs a different subset

use fray_terrain::Heightmap;

/// SplitMix64: the same numbers on every machine, no dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

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
