//! Pixel samples for anti-aliasing: `N` stratified, jittered positions per pixel, the same on
//! every backend and every run (the jitter is a hash of the pixel and the sample index), with
//! box-filter weights equal to the strata's areas.
//!
//! The pixel is cut into `r = ⌊√N⌋` rows; row `i` holds `⌊N / r⌋` strata, the first `N mod r`
//! rows one more, so the strata tile the pixel exactly. Sample `s` lies at a uniformly
//! jittered point of its stratum and weighs the stratum's area: the weights sum to 1, and the
//! weighted sum is an unbiased box-filtered estimate of the pixel. One sample is the pixel
//! centre with weight 1, exactly the unsampled image.
//!
//! The hash is Jarzynski and Olano's PCG hash (2020) on `u32`s; offsets take its upper 24 bits,
//! which `f32` and `f64` both hold exactly, so the GPU twin (`shaders/raygen.wgsl`) computes
//! the very same offsets.

/// Samples per pixel must be in `1..=MAX_SAMPLES`.
pub const MAX_SAMPLES: u32 = 1024;

/// `N` samples per pixel, laid out as described in the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelSamples {
    count: u32,
    rows: u32,
}

/// One sample of a pixel: its offset inside the pixel (`[0, 1)²`, from the pixel's top-left
/// corner) and its weight in the box filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSample {
    pub dx: f64,
    pub dy: f64,
    pub weight: f64,
}

/// A sample count outside `1..=MAX_SAMPLES`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("samples per pixel must be in 1..={MAX_SAMPLES}, got {0}")]
pub struct SampleCountError(pub u32);

impl PixelSamples {
    /// One sample per pixel, at its centre.
    pub const ONE: Self = Self { count: 1, rows: 1 };

    pub fn new(count: u32) -> Result<Self, SampleCountError> {
        if !(1..=MAX_SAMPLES).contains(&count) {
            return Err(SampleCountError(count));
        }
        Ok(Self {
            count,
            rows: count.isqrt(),
        })
    }

    /// Samples per pixel.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Rows of strata.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// The row of sample `s` and that row's first sample and number of strata.
    pub fn row_of(&self, s: u32) -> (u32, u32, u32) {
        let (base, extra) = (self.count / self.rows, self.count % self.rows);
        // The first `extra` rows hold `base + 1` strata.
        let long = extra * (base + 1);
        if s < long {
            let row = s / (base + 1);
            (row, row * (base + 1), base + 1)
        } else {
            let row = extra + (s - long) / base;
            (row, long + (row - extra) * base, base)
        }
    }

    /// Sample `s` (`< count`) of pixel `(px, py)`.
    pub fn sample(&self, px: u32, py: u32, s: u32) -> PixelSample {
        if self.count == 1 {
            return PixelSample {
                dx: 0.5,
                dy: 0.5,
                weight: 1.0,
            };
        }
        let (row, first, strata) = self.row_of(s);
        let column = s - first;
        let (ux, uy) = jitter(px, py, s);
        let (n, r) = (f64::from(strata), f64::from(self.rows));
        PixelSample {
            dx: (f64::from(column) + ux) / n,
            dy: (f64::from(row) + uy) / r,
            weight: 1.0 / (n * r),
        }
    }
}

impl Default for PixelSamples {
    fn default() -> Self {
        Self::ONE
    }
}

/// The PCG hash of one `u32` (Jarzynski & Olano, "Hash Functions for GPU Rendering", 2020).
#[inline]
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Two uniform numbers in `[0, 1)` for sample `s` of pixel `(px, py)`: 24-bit fractions of
/// chained hashes, exact in `f32` and `f64`.
#[inline]
pub fn jitter(px: u32, py: u32, s: u32) -> (f64, f64) {
    let h = pcg_hash(px ^ pcg_hash(py ^ pcg_hash(s)));
    let g = pcg_hash(h);
    let unit = |x: u32| f64::from(x >> 8) * (1.0 / 16_777_216.0);
    (unit(h), unit(g))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_tile_the_pixel_and_weights_sum_to_one() {
        for n in [1u32, 2, 3, 4, 5, 7, 8, 9, 10, 16, 17, 33, 64, 1000] {
            let p = PixelSamples::new(n).unwrap();
            let mut weight = 0.0;
            let mut area = 0.0;
            let mut rows_seen = vec![0u32; p.rows() as usize];
            for s in 0..n {
                let (row, first, strata) = p.row_of(s);
                assert!(s >= first && s < first + strata, "n {n} s {s}");
                rows_seen[row as usize] += 1;
                let q = p.sample(3, 7, s);
                assert!((0.0..1.0).contains(&q.dx) && (0.0..1.0).contains(&q.dy));
                if n > 1 {
                    // Inside its own stratum.
                    let (col, r) = (f64::from(s - first), f64::from(p.rows()));
                    let w = 1.0 / f64::from(strata);
                    assert!(q.dx >= col * w && q.dx < (col + 1.0) * w, "n {n} s {s}");
                    assert!(q.dy >= f64::from(row) / r && q.dy < f64::from(row + 1) / r);
                }
                weight += q.weight;
                area += 1.0 / (f64::from(strata) * f64::from(p.rows()));
            }
            assert!((weight - 1.0).abs() < 1e-12, "n {n}: {weight}");
            assert!((area - 1.0).abs() < 1e-12);
            // Rows differ by at most one stratum.
            let (lo, hi) = (
                rows_seen.iter().min().unwrap(),
                rows_seen.iter().max().unwrap(),
            );
            assert!(hi - lo <= 1 && rows_seen.iter().sum::<u32>() == n);
        }
        assert_eq!(
            PixelSamples::ONE.sample(5, 5, 0),
            PixelSample {
                dx: 0.5,
                dy: 0.5,
                weight: 1.0
            }
        );
        assert!(PixelSamples::new(0).is_err() && PixelSamples::new(MAX_SAMPLES + 1).is_err());
    }

    #[test]
    fn jitter_is_deterministic_uniform_and_exact_in_f32() {
        // PCG hash of 0 and 1 as an independent evaluation of the paper's formula (Python,
        // arbitrary-precision integers masked to 32 bits) gives them.
        assert_eq!(pcg_hash(0), 129_708_002);
        assert_eq!(pcg_hash(1), 2_831_084_092);
        let mut sum = 0.0;
        let mut buckets = [0u32; 16];
        for k in 0..4096u32 {
            let (a, b) = jitter(k % 64, k / 64, 3);
            assert_eq!(a, f64::from(a as f32));
            assert_eq!(jitter(k % 64, k / 64, 3), (a, b));
            sum += a + b;
            buckets[(a * 16.0) as usize] += 1;
        }
        assert!((sum / 8192.0 - 0.5).abs() < 0.02, "{sum}");
        assert!(
            buckets.iter().all(|&c| (192..=320).contains(&c)),
            "{buckets:?}"
        );
    }
}
