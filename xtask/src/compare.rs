//! Image comparison for regression tests: RMSE, max channel difference, the fraction of
//! "bad" pixels, and a visible diff image.

use fray_core::Image;

/// A pixel is *bad* when one of its channels differs by more than this (0–255 scale).
pub const BAD_PIXEL_DIFFERENCE: u8 = 8;

/// How much two 8-bit RGB images differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Root mean square difference over all channels of all pixels, 0–255 scale.
    pub rmse: f64,
    /// The largest absolute difference of any channel of any pixel.
    pub max_abs: u8,
    /// Fraction of pixels whose largest channel difference exceeds [`BAD_PIXEL_DIFFERENCE`].
    pub bad_fraction: f64,
}

/// The images' sizes differ, so they cannot be compared pixel by pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SizeMismatch {
    pub expected: (u32, u32),
    pub actual: (u32, u32),
}

impl std::fmt::Display for SizeMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "size differs: expected {}×{}, got {}×{}",
            self.expected.0, self.expected.1, self.actual.0, self.actual.1
        )
    }
}

fn same_size(expected: &Image<[u8; 3]>, actual: &Image<[u8; 3]>) -> Result<(), SizeMismatch> {
    let e = (expected.width(), expected.height());
    let a = (actual.width(), actual.height());
    if e == a {
        Ok(())
    } else {
        Err(SizeMismatch {
            expected: e,
            actual: a,
        })
    }
}

/// Compares `actual` with `expected`. Empty images compare as identical.
pub fn compare(
    expected: &Image<[u8; 3]>,
    actual: &Image<[u8; 3]>,
) -> Result<Metrics, SizeMismatch> {
    same_size(expected, actual)?;
    let mut sum_sq = 0u64;
    let mut max_abs = 0u8;
    let mut bad = 0usize;
    for (e, a) in expected.pixels().iter().zip(actual.pixels()) {
        let mut pixel_max = 0u8;
        for (x, y) in e.iter().zip(a) {
            let d = x.abs_diff(*y);
            sum_sq += u64::from(d) * u64::from(d);
            pixel_max = pixel_max.max(d);
        }
        max_abs = max_abs.max(pixel_max);
        if pixel_max > BAD_PIXEL_DIFFERENCE {
            bad += 1;
        }
    }
    let pixels = expected.pixels().len();
    let (rmse, bad_fraction) = if pixels == 0 {
        (0.0, 0.0)
    } else {
        (
            (sum_sq as f64 / (3 * pixels) as f64).sqrt(),
            bad as f64 / pixels as f64,
        )
    };
    Ok(Metrics {
        rmse,
        max_abs,
        bad_fraction,
    })
}

/// A visible diff: the absolute difference of each channel, amplified ×8 and saturated.
pub fn diff_image(
    expected: &Image<[u8; 3]>,
    actual: &Image<[u8; 3]>,
) -> Result<Image<[u8; 3]>, SizeMismatch> {
    same_size(expected, actual)?;
    let pixels = expected
        .pixels()
        .iter()
        .zip(actual.pixels())
        .map(|(e, a)| std::array::from_fn(|c| e[c].abs_diff(a[c]).saturating_mul(8)))
        .collect();
    Image::from_pixels(expected.width(), expected.height(), pixels).ok_or(SizeMismatch {
        expected: (expected.width(), expected.height()),
        actual: (actual.width(), actual.height()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32) -> Image<[u8; 3]> {
        let pixels = (0..w * h)
            .map(|i| [(i % 256) as u8, (i * 7 % 256) as u8, 200])
            .collect();
        Image::from_pixels(w, h, pixels).unwrap()
    }

    #[test]
    fn identical_images_have_zero_metrics_and_a_black_diff() {
        let a = gradient(10, 10);
        let m = compare(&a, &a.clone()).unwrap();
        assert_eq!(
            m,
            Metrics {
                rmse: 0.0,
                max_abs: 0,
                bad_fraction: 0.0
            }
        );
        let d = diff_image(&a, &a).unwrap();
        assert!(d.pixels().iter().all(|p| *p == [0, 0, 0]));
    }

    #[test]
    fn a_single_pixel_difference_gives_the_known_metrics() {
        let a = gradient(10, 10);
        let mut b = a.clone();
        let p = *b.get(3, 4);
        b.set(3, 4, [p[0], p[1], p[2] - 30]);
        let m = compare(&a, &b).unwrap();
        // 30² summed once, over 100 pixels × 3 channels: √(900 / 300) = √3.
        assert!((m.rmse - 3f64.sqrt()).abs() < 1e-12, "{m:?}");
        assert_eq!(m.max_abs, 30);
        assert_eq!(m.bad_fraction, 0.01);
        // Symmetric.
        assert_eq!(compare(&b, &a).unwrap(), m);

        let d = diff_image(&a, &b).unwrap();
        assert_eq!(*d.get(3, 4), [0, 0, 240]);
        assert_eq!(d.pixels().iter().filter(|p| **p != [0, 0, 0]).count(), 1);
    }

    #[test]
    fn a_difference_of_exactly_the_limit_is_not_bad_and_diffs_saturate() {
        let a = Image::filled(2, 2, [100u8, 100, 100]);
        let mut b = a.clone();
        b.set(0, 0, [108, 92, 100]); // 8: not bad
        b.set(1, 1, [100, 100, 0]); // 100: bad; ×8 saturates
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.max_abs, 100);
        assert_eq!(m.bad_fraction, 0.25);
        let d = diff_image(&a, &b).unwrap();
        assert_eq!(*d.get(0, 0), [64, 64, 0]);
        assert_eq!(*d.get(1, 1), [0, 0, 255]);
    }

    #[test]
    fn different_sizes_are_reported() {
        let err = compare(&gradient(4, 3), &gradient(3, 4)).unwrap_err();
        assert_eq!(err.expected, (4, 3));
        assert_eq!(err.actual, (3, 4));
        assert!(err.to_string().contains("4×3"));
        assert!(diff_image(&gradient(4, 3), &gradient(3, 4)).is_err());
    }
}
