//! A small seeded random stream for tests (splitmix64): the same numbers on every machine, no
//! dependency, fast enough for millions of rays.

use glam::DVec3;

/// splitmix64: every seed gives a full-period stream of well-mixed 64-bit words.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform on the unit sphere (a normalised point of the cube's inscribed ball).
    pub fn direction(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let n = v.length_squared();
            if n > 1e-6 && n <= 1.0 {
                return v / n.sqrt();
            }
        }
    }

    /// Uniform in the box `[min, max]`.
    pub fn in_box(&mut self, min: DVec3, max: DVec3) -> DVec3 {
        DVec3::new(
            self.range(min.x, max.x),
            self.range(min.y, max.y),
            self.range(min.z, max.z),
        )
    }

    /// `10^U(lo_exp, hi_exp)`: log-uniform, for scales over decades.
    pub fn log_uniform(&mut self, lo_exp: f64, hi_exp: f64) -> f64 {
        10f64.powf(self.range(lo_exp, hi_exp))
    }

    /// Uniform in `0..n` (`n > 0`; the modulo's bias is below 2⁻⁴⁰ for test sizes).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stream_is_splitmix64() {
        // splitmix64's published first output for seed 0.
        assert_eq!(Rng(0).next_u64(), 0xE220_A839_7B1D_CDAF);
    }

    #[test]
    fn units_and_directions_stay_in_range() {
        let mut rng = Rng(7);
        for _ in 0..10_000 {
            let u = rng.unit();
            assert!((0.0..1.0).contains(&u));
            let d = rng.direction();
            assert!((d.length() - 1.0).abs() < 1e-12);
        }
    }
}
