//! Linear RGB colour, tone mapping and the sRGB transfer function used when writing 8/16-bit images.

/// Linear RGB radiance (or reflectance), `f32` per channel.
pub type Rgb = glam::Vec3;

/// How linear radiance is squeezed into `[0, 1]` before sRGB encoding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ToneMap {
    /// `exposure · L`, clamped to `[0, 1]`: radiance 1 is white.
    #[default]
    Clamp,
    /// Reinhard on each channel: `x / (1 + x)` after exposure.
    Reinhard,
}

impl ToneMap {
    /// The display value in `[0, 1]` (still linear) of radiance `value` at `exposure`.
    #[inline]
    pub fn apply(self, value: f32, exposure: f32) -> f32 {
        let x = (value * exposure).max(0.0);
        let y = match self {
            ToneMap::Clamp => x,
            ToneMap::Reinhard => x / (1.0 + x),
        };
        if y.is_nan() { 0.0 } else { y.min(1.0) }
    }
}

/// The sRGB opto-electronic transfer function (IEC 61966-2-1) for `x` in `[0, 1]`.
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`linear_to_srgb`].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_and_hits_known_values() {
        // Published anchor: linear 0.5 encodes to ≈ 0.7354.
        assert!((linear_to_srgb(0.5) - 0.735_356_7).abs() < 1e-6);
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-5);
        }
    }

    #[test]
    fn tone_maps_stay_in_range_and_never_nan() {
        for tm in [ToneMap::Clamp, ToneMap::Reinhard] {
            for v in [-1.0, 0.0, 0.5, 1.0, 1e30, f32::INFINITY, f32::NAN] {
                let y = tm.apply(v, 1.0);
                assert!((0.0..=1.0).contains(&y), "{tm:?} {v} -> {y}");
            }
        }
    }
}
