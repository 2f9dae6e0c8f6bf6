//! The max pyramid (and the optional min pyramid): per-cell bounds of the interpolated surface
//! on a `2ⁿ × 2ⁿ` grid of cells, then level `k − 1` = the maximum (minimum) of each 2 × 2 block
//! of level `k`, down to level 0, the global bound.
//!
//! The finest level holds one value per *cell* (the square between four samples), not per
//! sample: the bound of that cell's interpolant — the maximum of its 4 corners for bilinear
//! (exact), of its 16 B-spline control points for bicubic (convex hull: conservative). A map of
//! any size is **padded**, not resampled: cells beyond the map, and cells cut out by the
//! threshold, hold `−∞` (no surface) in both pyramids, so the data stay exact and a padded cell
//! is never hit. (In the min pyramid `−∞` means "no proof of solid ground", see
//! [`Pyramid::min_of`].)

/// A pyramid of `levels() + 1` square levels; level `k` has `2ᵏ × 2ᵏ` values, row-major, stored
/// one after the other from level 0 (offsets `(4ᵏ − 1) / 3`).
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    finest: u32,
    values: Vec<f32>,
}

impl Pyramid {
    /// The max pyramid of `cells` (`columns × rows` per-cell upper bounds, row-major; `−∞` for
    /// no surface), padded with `−∞` to the next `2ⁿ × 2ⁿ`.
    pub fn max_of(columns: usize, rows: usize, cells: &[f32]) -> Self {
        Self::build(columns, rows, cells, f32::max)
    }

    /// The min pyramid of per-cell lower bounds (`−∞` where a cell is not solid, so a block
    /// holding any non-solid or padded cell has minimum `−∞`: nothing is proven solid there).
    pub fn min_of(columns: usize, rows: usize, cells: &[f32]) -> Self {
        Self::build(columns, rows, cells, f32::min)
    }

    fn build(columns: usize, rows: usize, cells: &[f32], combine: fn(f32, f32) -> f32) -> Self {
        let side_needed = columns.max(rows).max(1);
        let finest = side_needed.next_power_of_two().trailing_zeros();
        let total = (4usize.pow(finest + 1) - 1) / 3;
        let mut values = vec![f32::NEG_INFINITY; total];
        let side = 1usize << finest;
        let base = Self::offset(finest);
        for j in 0..rows {
            let row = &cells[j * columns..(j + 1) * columns];
            values[base + j * side..base + j * side + columns].copy_from_slice(row);
        }
        for level in (0..finest).rev() {
            let (src, dst) = (Self::offset(level + 1), Self::offset(level));
            let n = 1usize << level;
            for b in 0..n {
                for a in 0..n {
                    let at = |x: usize, y: usize| values[src + y * 2 * n + x];
                    let v = combine(
                        combine(at(2 * a, 2 * b), at(2 * a + 1, 2 * b)),
                        combine(at(2 * a, 2 * b + 1), at(2 * a + 1, 2 * b + 1)),
                    );
                    values[dst + b * n + a] = v;
                }
            }
        }
        Self { finest, values }
    }

    /// Where level `k` starts in [`Pyramid::values`].
    #[inline]
    pub const fn offset(level: u32) -> usize {
        ((1usize << (2 * level)) - 1) / 3
    }

    /// `n`: the finest level, `2ⁿ` cells per side.
    pub fn levels(&self) -> u32 {
        self.finest
    }

    /// All levels, level 0 first.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The value of cell `(a, b)` at `level` (`a, b < 2^level`).
    #[inline]
    pub fn at(&self, level: u32, a: usize, b: usize) -> f32 {
        self.values[Self::offset(level) + (b << level) + a]
    }

    /// Level 0: the bound over the whole map.
    pub fn global(&self) -> f32 {
        self.values[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_level_is_the_max_of_the_2x2_block_below_and_padding_is_minus_infinity() {
        // 3 × 2 cells → padded to 4 × 4 (n = 2).
        let cells = [1.0, 5.0, 2.0, 3.0, 0.5, 7.0];
        let p = Pyramid::max_of(3, 2, &cells);
        assert_eq!(p.levels(), 2);
        assert_eq!(p.values().len(), 1 + 4 + 16);
        assert_eq!(p.at(2, 2, 1), 7.0);
        assert_eq!(p.at(2, 3, 0), f32::NEG_INFINITY);
        assert_eq!(p.at(1, 0, 0), 5.0);
        assert_eq!(p.at(1, 1, 0), 7.0);
        assert_eq!(p.at(1, 0, 1), f32::NEG_INFINITY);
        assert_eq!(p.global(), 7.0);
        let m = Pyramid::min_of(3, 2, &cells);
        assert_eq!(m.at(1, 0, 0), 0.5);
        assert_eq!(m.at(1, 1, 0), f32::NEG_INFINITY); // holds padding: nothing proven
    }

    #[test]
    fn a_single_cell_is_level_zero() {
        let p = Pyramid::max_of(1, 1, &[2.5]);
        assert_eq!((p.levels(), p.global()), (0, 2.5));
    }
}
