//! The shape of a cloud layer's density: fractal noise (Perlin's, optionally mixed with Worley
//! billows) cut by coverage and a threshold, shaped
//! by a height-distribution profile (flat bases, rounded or towering tops) and bounded by an
//! envelope — any shape that answers "inside, and how deep" (the scene supplies free forms; this
//! crate does not depend on them).

use crate::fractal::Fractal;

/// A shape that bounds a cloud: `depth(p) > 0` inside, how deep (world units); `≤ 0` outside.
pub trait Envelope: Sync {
    fn depth(&self, p: [f64; 3]) -> f64;
    /// What one [`Envelope::depth`] costs in a bake's work units (one Perlin octave each; see
    /// [`crate::cost::check_bake`]).
    fn cost(&self) -> u64;
}

/// No envelope: everywhere is deep inside.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Unbounded;

impl Envelope for Unbounded {
    fn depth(&self, _: [f64; 3]) -> f64 {
        f64::INFINITY
    }

    fn cost(&self) -> u64 {
        0
    }
}

/// How density is distributed over the layer's height `h ∈ [0, 1]` (0 the base, 1 the top):
/// zero at the base rising to full over `base_ramp`, full up to `top_start`, falling to zero at
/// the top — smoothsteps, so bases are flat and tops rounded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightProfile {
    pub base_ramp: f64,
    pub top_start: f64,
}

impl HeightProfile {
    /// Fair-weather cumulus: a flat base (the density is full 8 % above it), rounded tops from
    /// 40 % of the layer up.
    pub const CUMULUS: Self = Self {
        base_ramp: 0.08,
        top_start: 0.4,
    };
    /// Stratus: a flat sheet, full from 10 % to 30 % of the layer, thinning out above.
    pub const STRATUS: Self = Self {
        base_ramp: 0.1,
        top_start: 0.3,
    };
    /// Towering cumulonimbus: a flat base, full almost to the top.
    pub const CUMULONIMBUS: Self = Self {
        base_ramp: 0.05,
        top_start: 0.85,
    };

    /// The profile at height `h` (0 outside `[0, 1]`).
    pub fn at(&self, h: f64) -> f64 {
        if !(0.0..=1.0).contains(&h) {
            return 0.0;
        }
        smoothstep(0.0, self.base_ramp, h) * (1.0 - smoothstep(self.top_start, 1.0, h))
    }
}

/// `3t² − 2t³` of `t = (x − a)/(b − a)` clamped to `[0, 1]` (1 past `b`; `a == b` is a step).
fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    if b <= a {
        return if x >= b { 1.0 } else { 0.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A cloud layer's density field (world space, Y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CloudField {
    /// The layer: base and top heights.
    pub base: f64,
    pub top: f64,
    /// Noise cells per world unit.
    pub frequency: f64,
    pub noise: Fractal,
    /// Which noise: the domain is shifted by a hash of the seed (deterministic).
    pub seed: u32,
    /// The sky fraction covered, in `[0, 1]`: the normalised noise is kept above `1 − coverage`.
    pub coverage: f64,
    /// Shaped densities below this (in `[0, 1]`) are cut to zero: no wisps.
    pub threshold: f64,
    /// Extinction (1/m) of the densest cloud.
    pub density_scale: f64,
    pub profile: HeightProfile,
    /// The envelope's depth (world units) over which density fades in from its surface.
    pub envelope_fade: f64,
    /// How much of the noise is Worley billows (`1 − F1`, up to 3 octaves of the same
    /// frequency, lacunarity and gain) instead of Perlin's sum, in `[0, 1]`: puffier tops.
    pub worley: f64,
}

impl Default for CloudField {
    fn default() -> Self {
        Self {
            base: 1500.0,
            top: 3500.0,
            frequency: 1.0 / 2000.0,
            noise: Fractal::default(),
            seed: 0,
            coverage: 0.5,
            threshold: 0.05,
            density_scale: 0.02,
            profile: HeightProfile::CUMULUS,
            envelope_fade: 100.0,
            worley: 0.0,
        }
    }
}

impl CloudField {
    /// The domain offset of the seed: three coordinates from a 32-bit mix, in `[0, 256)` (the
    /// noise's period), so different seeds give unrelated clouds.
    fn offset(&self) -> [f64; 3] {
        let mut h = self.seed.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
        let mut next = || {
            h ^= h >> 16;
            h = h.wrapping_mul(0x7FEB_352D);
            h ^= h >> 15;
            h = h.wrapping_mul(0x846C_A68B);
            h ^= h >> 16;
            f64::from(h) / f64::from(u32::MAX) * 256.0
        };
        [next(), next(), next()]
    }

    /// The extinction at world point `p` inside `envelope`.
    pub fn density(&self, p: [f64; 3], envelope: &dyn Envelope) -> f64 {
        let h = (p[1] - self.base) / (self.top - self.base);
        let profile = self.profile.at(h);
        if profile == 0.0 {
            return 0.0;
        }
        let depth = envelope.depth(p);
        if depth <= 0.0 {
            return 0.0;
        }
        let o = self.offset();
        let f = self.frequency;
        let n = self
            .noise
            .eval(p[0] * f + o[0], p[1] * f + o[1], p[2] * f + o[2]);
        // Into [0, 1] by the sum's bound, then kept above 1 − coverage and stretched back.
        let mut n = 0.5 + 0.5 * n / self.noise.amplitude_bound();
        if self.worley > 0.0 {
            let w = self.worley.min(1.0);
            let (x, y, z) = (p[0] * f + o[0], p[1] * f + o[1], p[2] * f + o[2]);
            let octaves = self.noise.octaves.min(3);
            let b =
                crate::worley::billows(x, y, z, octaves, self.noise.lacunarity, self.noise.gain);
            n = (1.0 - w) * n + w * b;
        }
        let cut = 1.0 - self.coverage.clamp(0.0, 1.0);
        let shaped = if self.coverage > 0.0 {
            ((n * profile - cut) / self.coverage).max(0.0)
        } else {
            0.0
        };
        if shaped < self.threshold || shaped == 0.0 {
            return 0.0;
        }
        let fade = if self.envelope_fade > 0.0 {
            smoothstep(0.0, self.envelope_fade, depth)
        } else {
            1.0
        };
        self.density_scale * shaped.min(1.0) * fade
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_have_flat_bases_and_fall_to_zero_at_the_top() {
        for p in [
            HeightProfile::CUMULUS,
            HeightProfile::STRATUS,
            HeightProfile::CUMULONIMBUS,
        ] {
            assert_eq!(p.at(0.0), 0.0);
            assert_eq!(p.at(1.0), 0.0);
            assert_eq!(p.at(-0.1), 0.0);
            assert_eq!(p.at(p.base_ramp), 1.0);
            assert_eq!(p.at(0.5 * (p.base_ramp + p.top_start)), 1.0);
            // Monotone up to the top start, down after it.
            let mut last = 0.0;
            for k in 0..=100 {
                let h = p.top_start * f64::from(k) / 100.0;
                assert!(p.at(h) >= last);
                last = p.at(h);
            }
        }
        assert!(HeightProfile::CUMULONIMBUS.at(0.8) > HeightProfile::CUMULUS.at(0.8));
    }
}
