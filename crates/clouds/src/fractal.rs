//! Fractal sums of improved noise: `Σᵢ gainⁱ · noise(lacunarityⁱ · p)` over a number of octaves
//! (fractional Brownian motion), the shape cloud densities are built from.

use crate::perlin::noise;

/// The parameters of a fractal sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fractal {
    /// Octaves summed, `≥ 1`.
    pub octaves: u32,
    /// The frequency factor between octaves (2 doubles it).
    pub lacunarity: f64,
    /// The amplitude factor between octaves (0.5 halves it).
    pub gain: f64,
}

impl Default for Fractal {
    fn default() -> Self {
        Self {
            octaves: 5,
            lacunarity: 2.0,
            gain: 0.5,
        }
    }
}

impl Fractal {
    /// The sum at `(x, y, z)`.
    pub fn eval(&self, x: f64, y: f64, z: f64) -> f64 {
        let (mut sum, mut frequency, mut amplitude) = (0.0, 1.0, 1.0);
        for _ in 0..self.octaves {
            sum += amplitude * noise(x * frequency, y * frequency, z * frequency);
            frequency *= self.lacunarity;
            amplitude *= self.gain;
        }
        sum
    }

    /// The largest `|eval|` can be: `Σ |gain|ⁱ` (improved noise stays within ±1), to normalise
    /// a sum into `[−1, 1]`.
    pub fn amplitude_bound(&self) -> f64 {
        (0..self.octaves)
            .map(|i| self.gain.abs().powi(i as i32))
            .sum()
    }
}
