//! The height map: a grid of samples in raw height units, row-major, any size from 2 × 2 up to
//! [`MAX_SIDE`] per side; the threshold that cuts parts of it out.
//!
//! Sample `(column i, row j)` lies at height-map coordinates `(u, v) = (i, j)`; with the default
//! placement `u` runs along world `+x` and `v` along world `+z` (row 0 of a north-up DEM is the
//! north edge when `+z` is south, as Y-up right-handed axes with `+x` east make it). Samples are
//! stored as `f32`: exact for 16-bit PNG, `<i2`/`<u2` and `f32` data; `f64` `.npy` data is
//! rounded to the nearest `f32`. All arithmetic on them is `f64`.

use crate::{Region, TerrainError};
use fray_core::MemoryBudget;

/// The largest accepted number of samples along either side.
pub const MAX_SIDE: usize = 32768;
/// The largest accepted number of samples in all (2²⁶ = 8192², 256 MiB of `f32`).
pub const MAX_SAMPLES: usize = 1 << 26;

/// A checked height map: `width × height` finite samples (row-major, row `j` at `v = j`) and a
/// threshold — samples below it are *no surface*, so a map can have holes and any outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Heightmap {
    width: usize,
    height: usize,
    samples: Vec<f32>,
    threshold: f32,
}

impl Heightmap {
    /// A height map from row-major samples (`samples[j * width + i]` is column `i`, row `j`).
    /// Rejects sizes below 2 × 2 or above the limits, a wrong length and non-finite samples.
    pub fn from_samples(
        width: usize,
        height: usize,
        samples: Vec<f32>,
    ) -> Result<Self, TerrainError> {
        check_size(width, height)?;
        let expected = width * height;
        if samples.len() != expected {
            return Err(TerrainError::WrongLength {
                width,
                height,
                expected,
                got: samples.len(),
            });
        }
        if let Some(k) = samples.iter().position(|s| !s.is_finite()) {
            return Err(TerrainError::NonFinite {
                column: k % width,
                row: k / width,
                value: f64::from(samples[k]),
            });
        }
        Ok(Self {
            width,
            height,
            samples,
            threshold: f32::NEG_INFINITY,
        })
    }

    /// A height map of `width × height` samples from a function of `(column, row)`, within the
    /// default memory budget ([`MemoryBudget::default`]).
    pub fn from_fn(
        width: usize,
        height: usize,
        f: impl Fn(usize, usize) -> f32,
    ) -> Result<Self, TerrainError> {
        Self::from_fn_within(width, height, &MemoryBudget::default(), f)
    }

    /// [`Heightmap::from_fn`] refusing samples (`4 · width · height` bytes) over `budget`.
    pub fn from_fn_within(
        width: usize,
        height: usize,
        budget: &MemoryBudget,
        f: impl Fn(usize, usize) -> f32,
    ) -> Result<Self, TerrainError> {
        check_size(width, height)?;
        budget
            .charge_elements(
                format!("the {width} × {height} height map's f32 samples"),
                (width * height) as u64,
                4,
            )
            .map_err(|source| TerrainError::Budget { path: None, source })?;
        let samples = (0..height)
            .flat_map(|j| (0..width).map(move |i| (i, j)))
            .map(|(i, j)| f(i, j))
            .collect();
        Self::from_samples(width, height, samples)
    }

    /// The same map where samples below `threshold` are no surface (a cell is solid only when
    /// all four of its corner samples are `≥ threshold`). `−∞` (the default) keeps everything.
    /// NaN is rejected.
    pub fn with_threshold(mut self, threshold: f32) -> Result<Self, TerrainError> {
        if threshold.is_nan() {
            return Err(TerrainError::Parameter {
                name: "threshold",
                message: "must be a number, got NaN".into(),
            });
        }
        self.threshold = threshold;
        Ok(self)
    }

    /// A copy whose samples in `region` (clamped to the map) are `f(column, row, old sample)`,
    /// the others and the threshold kept: the heights of a terrain at a time. A non-finite new
    /// sample is refused ([`TerrainError::NonFinite`]). The copy is `4 · width · height` bytes:
    /// the caller charges it first.
    pub fn with_region(
        &self,
        region: Region,
        mut f: impl FnMut(usize, usize, f32) -> f32,
    ) -> Result<Self, TerrainError> {
        let r = region.clamped(self.width, self.height);
        let mut samples = self.samples.clone();
        for j in r.y0..r.y1 {
            for i in r.x0..r.x1 {
                let s = &mut samples[j * self.width + i];
                let v = f(i, j, *s);
                if !v.is_finite() {
                    return Err(TerrainError::NonFinite {
                        column: i,
                        row: j,
                        value: f64::from(v),
                    });
                }
                *s = v;
            }
        }
        Ok(Self { samples, ..*self })
    }

    /// Samples along `u` (columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Samples along `v` (rows).
    pub fn height(&self) -> usize {
        self.height
    }

    pub fn threshold(&self) -> f32 {
        self.threshold
    }

    /// All samples, row-major.
    pub fn samples(&self) -> &[f32] {
        &self.samples
    }

    /// The sample at column `i`, row `j` (both in range).
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> f32 {
        self.samples[j * self.width + i]
    }

    /// Whether sample `(i, j)` is surface (not below the threshold).
    #[inline]
    pub fn is_surface(&self, i: usize, j: usize) -> bool {
        self.at(i, j) >= self.threshold
    }

    /// Whether cell `(i, j)` (between samples `i..=i+1`, `j..=j+1`) is solid: all four corners
    /// are surface. `i < width − 1`, `j < height − 1`.
    #[inline]
    pub fn cell_is_solid(&self, i: usize, j: usize) -> bool {
        self.is_surface(i, j)
            && self.is_surface(i + 1, j)
            && self.is_surface(i, j + 1)
            && self.is_surface(i + 1, j + 1)
    }

    /// Cells along `u` and `v`: one fewer than samples.
    pub fn cells(&self) -> (usize, usize) {
        (self.width - 1, self.height - 1)
    }
}

pub(crate) fn check_size(width: usize, height: usize) -> Result<(), TerrainError> {
    if width < 2 || height < 2 {
        return Err(TerrainError::TooSmall { width, height });
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_SAMPLES {
        return Err(TerrainError::TooLarge { width, height });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_small_large_wrong_length_and_non_finite() {
        assert!(matches!(
            Heightmap::from_samples(1, 5, vec![0.0; 5]),
            Err(TerrainError::TooSmall { .. })
        ));
        assert!(matches!(
            Heightmap::from_samples(MAX_SIDE + 1, 2, vec![]),
            Err(TerrainError::TooLarge { .. })
        ));
        assert!(matches!(
            Heightmap::from_samples(3, 3, vec![0.0; 8]),
            Err(TerrainError::WrongLength { got: 8, .. })
        ));
        let mut s = vec![0.0; 9];
        s[5] = f32::NAN;
        let e = Heightmap::from_samples(3, 3, s).unwrap_err();
        assert_eq!(e.to_string(), "sample (2, 1) is not finite: NaN");
    }

    #[test]
    fn a_cell_is_solid_only_when_all_four_corners_reach_the_threshold() {
        let m = Heightmap::from_fn(3, 2, |i, _| i as f32)
            .unwrap()
            .with_threshold(1.0)
            .unwrap();
        assert!(!m.cell_is_solid(0, 0)); // column 0 is below
        assert!(m.cell_is_solid(1, 0));
    }
}
