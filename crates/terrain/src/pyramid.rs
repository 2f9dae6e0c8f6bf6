//! The max pyramid (and the optional min pyramid): per-cell bounds of the interpolated surface,
//! then level `k − 1` = the maximum (minimum) of each 2 × 2 block of level `k`, down to level 0,
//! the global bound.
//!
//! The finest level `n` holds one value per *cell* (the square between four samples), not per
//! sample: the bound of that cell's interpolant — the maximum of its 4 corners for bilinear
//! (exact), of its 16 B-spline control points for bicubic (convex hull: conservative). `n` is the
//! smallest with `2ⁿ ≥` the longer side in cells, so a level-`k` cell covers `2ⁿ⁻ᵏ × 2ⁿ⁻ᵏ`
//! finest cells (the footprint rule of docs/methods.md §4 needs that square), but the levels are
//! **rectangular**: level `k` has `⌈columns / 2ⁿ⁻ᵏ⌉ × ⌈rows / 2ⁿ⁻ᵏ⌉` values, only those that
//! cover part of the map. A 32768 × 2 map has 16 levels of one row each (≈ 2 × 32767 values),
//! not the `(4¹⁶ − 1) / 3` of a padded square. The last block of a row or column may reach past
//! the map: its missing cells count as `−∞` (no surface), like cells cut out by the threshold, so
//! the data stay exact and nothing beyond the map is ever hit. (In the min pyramid `−∞` means
//! "no proof of solid ground", see [`Pyramid::min_of`].)

use crate::Region;
use fray_core::{BudgetError, MemoryBudget};

/// The deepest pyramid: `n ≤ 15`, since a map has at most [`crate::MAX_SIDE`] − 1 = 2¹⁵ − 1
/// cells per side. (Levels 0 ..= 15: 16 of them; [`crate::gpu_layout`] sizes its table by it.)
pub const MAX_LEVELS: usize = 16;

/// A pyramid of `levels() + 1` rectangular levels, stored one after the other from level 0;
/// level `k` starts at [`Pyramid::offset`]`(k)` and is [`Pyramid::dims`]`(k)` values, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Pyramid {
    finest: u32,
    /// Each level's offset in `values` and its columns and rows, level 0 first, then the total
    /// (as the offset of a level past the finest, 0 × 0).
    levels: Vec<Level>,
    values: Vec<f32>,
}

/// Where a level starts and its size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Level {
    offset: usize,
    columns: usize,
    rows: usize,
}

/// `n` for `columns × rows` cells: the smallest with `2ⁿ ≥ max(columns, rows)`.
fn finest_level(columns: usize, rows: usize) -> u32 {
    columns
        .max(rows)
        .max(1)
        .next_power_of_two()
        .trailing_zeros()
}

/// `(columns, rows)` of level `level` of a pyramid over `columns × rows` cells with finest `n`.
#[inline]
fn level_dims(columns: usize, rows: usize, n: u32, level: u32) -> (usize, usize) {
    let shift = n - level;
    (
        columns.div_ceil(1usize << shift),
        rows.div_ceil(1usize << shift),
    )
}

impl Pyramid {
    /// The number of values a pyramid over `columns × rows` cells holds (all levels).
    pub fn len_for(columns: usize, rows: usize) -> usize {
        let n = finest_level(columns, rows);
        (0..=n)
            .map(|k| {
                let (c, r) = level_dims(columns, rows, n, k);
                c * r
            })
            .sum()
    }

    /// Checks that a pyramid over `columns × rows` cells (`4 ×` [`Pyramid::len_for`] bytes) fits
    /// `budget`; `what` names it in the error.
    pub fn check_budget(
        columns: usize,
        rows: usize,
        budget: &MemoryBudget,
        what: &str,
    ) -> Result<(), BudgetError> {
        budget.check_elements(
            format!("{what} over {columns} × {rows} cells"),
            Self::len_for(columns, rows) as u64,
            4,
        )
    }

    /// The max pyramid of `cells` (`columns × rows` per-cell upper bounds, row-major; `−∞` for
    /// no surface). Its size is [`Pyramid::len_for`]: at most `4/3 ·` the cells plus one row
    /// and column per level (check it with [`Pyramid::check_budget`] first where it matters).
    pub fn max_of(columns: usize, rows: usize, cells: &[f32]) -> Self {
        Self::build(columns, rows, cells, f32::max)
    }

    /// The min pyramid of per-cell lower bounds (`−∞` where a cell is not solid, so a block
    /// holding any non-solid cell, or reaching past the map, has minimum `−∞`: nothing is
    /// proven solid there).
    pub fn min_of(columns: usize, rows: usize, cells: &[f32]) -> Self {
        Self::build(columns, rows, cells, f32::min)
    }

    fn build(columns: usize, rows: usize, cells: &[f32], combine: fn(f32, f32) -> f32) -> Self {
        let finest = finest_level(columns, rows);
        let mut levels = Vec::with_capacity(finest as usize + 2);
        let mut total = 0;
        for k in 0..=finest {
            let (c, r) = level_dims(columns, rows, finest, k);
            levels.push(Level {
                offset: total,
                columns: c,
                rows: r,
            });
            total += c * r;
        }
        levels.push(Level {
            offset: total,
            columns: 0,
            rows: 0,
        });
        let mut values = vec![f32::NEG_INFINITY; total];
        let base = levels[finest as usize].offset;
        let count = columns * rows;
        values[base..base + count].copy_from_slice(&cells[..count]);
        let mut pyramid = Self {
            finest,
            levels,
            values,
        };
        let mut region = Region::all(columns, rows);
        for level in (0..finest as usize).rev() {
            region = region.halved();
            pyramid.combine_level(level, region, combine);
        }
        pyramid
    }

    /// Recomputes the cells of `level` in `blocks` (its own cells) from the 2 × 2 blocks of
    /// `level + 1` — the one rule for a full build and an update, so both give the same bits.
    fn combine_level(&mut self, level: usize, blocks: Region, combine: fn(f32, f32) -> f32) {
        let (below, here) = (self.levels[level + 1], self.levels[level]);
        let (src, dst) = (below.offset, here.offset);
        let (sc, sr) = (below.columns, below.rows);
        let dc = here.columns;
        let values = &mut self.values;
        for b in blocks.y0..blocks.y1 {
            for a in blocks.x0..blocks.x1 {
                // The 2 × 2 block below, less what lies past the last row or column.
                let mut v = f32::NEG_INFINITY;
                let mut first = true;
                for y in 2 * b..(2 * b + 2).min(sr) {
                    for x in 2 * a..(2 * a + 2).min(sc) {
                        let s = values[src + y * sc + x];
                        v = if first { s } else { combine(v, s) };
                        first = false;
                    }
                }
                // A block reaching past the map holds no-surface cells: −∞ in the min.
                let complete = 2 * a + 2 <= sc && 2 * b + 2 <= sr;
                if !complete {
                    v = combine(v, f32::NEG_INFINITY);
                }
                values[dst + b * dc + a] = v;
            }
        }
    }

    /// Updates a max pyramid after the finest cells in `changed` took new bounds: writes
    /// `cell(i, j)` for each cell of `changed` (clamped to the finest level), then recomputes,
    /// level by level, only the cells above it — at level `k − 1` the blocks holding a changed
    /// cell of level `k`, a rectangle half as wide. The result is bit for bit what
    /// [`Pyramid::max_of`] gives over the new cells (the same combination in the same order),
    /// for `changed.area() + O(levels + perimeter)` work instead of the whole map's.
    pub fn update_max(&mut self, changed: Region, cell: impl FnMut(usize, usize) -> f32) {
        self.update(changed, cell, f32::max);
    }

    /// [`Pyramid::update_max`] for a min pyramid ([`Pyramid::min_of`]).
    pub fn update_min(&mut self, changed: Region, cell: impl FnMut(usize, usize) -> f32) {
        self.update(changed, cell, f32::min);
    }

    fn update(
        &mut self,
        changed: Region,
        mut cell: impl FnMut(usize, usize) -> f32,
        combine: fn(f32, f32) -> f32,
    ) {
        let finest = self.levels[self.finest as usize];
        let mut region = changed.clamped(finest.columns, finest.rows);
        if region.is_empty() {
            return;
        }
        for j in region.y0..region.y1 {
            for i in region.x0..region.x1 {
                self.values[finest.offset + j * finest.columns + i] = cell(i, j);
            }
        }
        for level in (0..self.finest as usize).rev() {
            region = region.halved();
            self.combine_level(level, region, combine);
        }
    }

    /// Where level `k` starts in [`Pyramid::values`] (`k ≤ levels() + 1`; `levels() + 1` gives
    /// the total).
    #[inline]
    pub fn offset(&self, level: u32) -> usize {
        self.levels[level as usize].offset
    }

    /// `(columns, rows)` of level `k`: `(⌈columns / 2ⁿ⁻ᵏ⌉, ⌈rows / 2ⁿ⁻ᵏ⌉)` of the finest.
    #[inline]
    pub fn dims(&self, level: u32) -> (usize, usize) {
        let l = self.levels[level as usize];
        (l.columns, l.rows)
    }

    /// `n`: the finest level; a level-`k` cell covers `2ⁿ⁻ᵏ × 2ⁿ⁻ᵏ` finest cells.
    pub fn levels(&self) -> u32 {
        self.finest
    }

    /// All levels, level 0 first.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The value of cell `(a, b)` at `level` (`(a, b)` within [`Pyramid::dims`]`(level)`).
    #[inline]
    pub fn at(&self, level: u32, a: usize, b: usize) -> f32 {
        self.level(level).at(a, b)
    }

    /// Level `k` alone: its values and width, for loops over its cells.
    #[inline]
    pub fn level(&self, level: u32) -> PyramidLevel<'_> {
        let l = self.levels[level as usize];
        PyramidLevel {
            values: &self.values,
            offset: l.offset,
            columns: l.columns,
            rows: l.rows,
        }
    }

    /// Level 0: the bound over the whole map.
    pub fn global(&self) -> f32 {
        self.values[0]
    }
}

/// One level of a [`Pyramid`] ([`Pyramid::level`]).
#[derive(Clone, Copy, Debug)]
pub struct PyramidLevel<'a> {
    /// All levels' values (one bounds check per look-up, none to slice).
    values: &'a [f32],
    offset: usize,
    columns: usize,
    rows: usize,
}

impl PyramidLevel<'_> {
    /// `(columns, rows)` of this level.
    #[inline]
    pub fn dims(&self) -> (usize, usize) {
        (self.columns, self.rows)
    }

    /// The value of cell `(a, b)` (`a < columns`, `b < rows`).
    #[inline]
    pub fn at(&self, a: usize, b: usize) -> f32 {
        self.values[self.offset + b * self.columns + a]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_level_is_the_max_of_the_2x2_block_below_and_levels_are_rectangular() {
        // 3 × 2 cells: n = 2; level 2 is 3 × 2, level 1 is 2 × 1, level 0 is 1 × 1.
        let cells = [1.0, 5.0, 2.0, 3.0, 0.5, 7.0];
        let p = Pyramid::max_of(3, 2, &cells);
        assert_eq!(p.levels(), 2);
        assert_eq!((p.dims(2), p.dims(1), p.dims(0)), ((3, 2), (2, 1), (1, 1)));
        assert_eq!(p.values().len(), 1 + 2 + 6);
        assert_eq!(Pyramid::len_for(3, 2), 9);
        assert_eq!(
            (p.offset(0), p.offset(1), p.offset(2), p.offset(3)),
            (0, 1, 3, 9)
        );
        assert_eq!(p.at(2, 2, 1), 7.0);
        assert_eq!(p.at(1, 0, 0), 5.0);
        assert_eq!(p.at(1, 1, 0), 7.0);
        assert_eq!(p.global(), 7.0);
        let m = Pyramid::min_of(3, 2, &cells);
        assert_eq!(m.at(1, 0, 0), 0.5);
        assert_eq!(m.at(1, 1, 0), f32::NEG_INFINITY); // reaches past the map: nothing proven
        assert_eq!(m.global(), f32::NEG_INFINITY);
    }

    #[test]
    fn a_single_cell_is_level_zero() {
        let p = Pyramid::max_of(1, 1, &[2.5]);
        assert_eq!((p.levels(), p.global()), (0, 2.5));
    }

    #[test]
    fn a_long_thin_map_stays_small() {
        // 32767 × 1 cells (a 32768 × 2 map): n = 15, one row per level, ≈ 2 × 32767 values —
        // not the (4¹⁶ − 1) / 3 ≈ 1.4 × 10⁹ of a padded square.
        let cells: Vec<f32> = (0..32767).map(|k| (k % 1000) as f32).collect();
        assert_eq!(Pyramid::len_for(32767, 1), 65534);
        let p = Pyramid::max_of(32767, 1, &cells);
        assert_eq!(p.levels(), 15);
        assert_eq!(p.values().len(), 65534);
        assert_eq!(
            (p.dims(15), p.dims(3), p.dims(0)),
            ((32767, 1), (8, 1), (1, 1))
        );
        assert_eq!(p.global(), 999.0);
        assert_eq!(p.at(14, 16383, 0), cells[32766]); // the last block holds one cell
        let small = MemoryBudget::new(1 << 20);
        assert!(Pyramid::check_budget(32767, 1, &small, "the max pyramid").is_ok());
        let e = Pyramid::check_budget(32767, 32767, &small, "the max pyramid").unwrap_err();
        assert!(
            e.to_string()
                .contains("the max pyramid over 32767 × 32767 cells"),
            "{e}"
        );
    }
}
