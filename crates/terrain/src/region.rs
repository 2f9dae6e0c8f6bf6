//! A rectangle of a grid (samples or cells): what changed when a terrain's heights move.

/// The half-open rectangle `[x0, x1) × [y0, y1)` of columns and rows; empty when either side is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Region {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Region {
    /// Columns `x0..x1`, rows `y0..y1`.
    pub const fn new(x0: usize, y0: usize, x1: usize, y1: usize) -> Self {
        Self { x0, y0, x1, y1 }
    }

    /// The whole of a `columns × rows` grid.
    pub const fn all(columns: usize, rows: usize) -> Self {
        Self::new(0, 0, columns, rows)
    }

    pub fn is_empty(&self) -> bool {
        self.x0 >= self.x1 || self.y0 >= self.y1
    }

    /// Columns × rows inside (0 when empty).
    pub fn area(&self) -> usize {
        self.x1.saturating_sub(self.x0) * self.y1.saturating_sub(self.y0)
    }

    /// The part inside a `columns × rows` grid.
    pub fn clamped(&self, columns: usize, rows: usize) -> Self {
        Self::new(
            self.x0.min(columns),
            self.y0.min(rows),
            self.x1.min(columns),
            self.y1.min(rows),
        )
    }

    /// Grown by `before` columns and rows on the low side and `after` on the high side, clamped
    /// to a `columns × rows` grid.
    pub fn grown(&self, before: usize, after: usize, columns: usize, rows: usize) -> Self {
        Self::new(
            self.x0.saturating_sub(before),
            self.y0.saturating_sub(before),
            self.x1.saturating_add(after),
            self.y1.saturating_add(after),
        )
        .clamped(columns, rows)
    }

    /// The cells of a grid whose samples these are that touch a changed sample: cell `(i, j)`
    /// has corners `i..=i + 1`, so samples `x0..x1` touch cells `x0 − 1 .. x1` (`reach` more on
    /// each side for an interpolant reading `reach` samples further, as the B-spline's 4 × 4 does
    /// with 1). Clamped to the `columns × rows` cells.
    pub fn cells_touched(&self, reach: usize, columns: usize, rows: usize) -> Self {
        if self.is_empty() {
            return Self::default();
        }
        self.grown(1 + reach, reach, columns, rows)
    }

    /// The rectangle one pyramid level up (each 2 × 2 block is one cell): the blocks holding a
    /// cell of this one.
    pub fn halved(&self) -> Self {
        if self.is_empty() {
            return Self::default();
        }
        Self::new(
            self.x0 / 2,
            self.y0 / 2,
            self.x1.div_ceil(2),
            self.y1.div_ceil(2),
        )
    }

    /// The smallest rectangle holding both.
    pub fn union(&self, o: &Self) -> Self {
        if self.is_empty() {
            return *o;
        }
        if o.is_empty() {
            return *self;
        }
        Self::new(
            self.x0.min(o.x0),
            self.y0.min(o.y0),
            self.x1.max(o.x1),
            self.y1.max(o.y1),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_touched_by_samples_and_halving() {
        // Samples 3..5 of a 10-sample side (9 cells): cells 2..5 bilinear, 1..6 bicubic.
        let r = Region::new(3, 0, 5, 1);
        assert_eq!(r.cells_touched(0, 9, 9), Region::new(2, 0, 5, 1));
        assert_eq!(r.cells_touched(1, 9, 9), Region::new(1, 0, 6, 2));
        assert_eq!(
            Region::new(9, 9, 10, 10).cells_touched(0, 9, 9),
            Region::new(8, 8, 9, 9)
        );
        assert_eq!(Region::new(3, 2, 5, 7).halved(), Region::new(1, 1, 3, 4));
        assert!(Region::new(3, 3, 3, 5).halved().is_empty());
        assert_eq!(
            Region::new(3, 3, 3, 5).union(&Region::new(1, 1, 2, 2)),
            Region::new(1, 1, 2, 2)
        );
    }
}
