//! Density grids: `nx × ny × nz` f32 samples at cell centres over the unit cube, sampled
//! trilinearly in f64 (the CPU reference of a GPU 3D texture with linear filtering and clamped
//! edges), and their coarse max grids for empty-space skipping.

use crate::CloudsError;
use fray_core::MemoryBudget;

/// A grid of densities, x fastest, then y, then z; sample `(i, j, k)` sits at the centre of its
/// cell, `((i + ½)/nx, (j + ½)/ny, (k + ½)/nz)` in the unit cube.
#[derive(Clone, Debug, PartialEq)]
pub struct DensityGrid {
    size: [usize; 3],
    data: Vec<f32>,
}

impl DensityGrid {
    /// The grid whose sample `(i, j, k)` is `f(i, j, k)`, checked against `budget` before it is
    /// allocated.
    pub fn from_fn(
        size: [usize; 3],
        budget: &MemoryBudget,
        mut f: impl FnMut(usize, usize, usize) -> f32,
    ) -> Result<Self, CloudsError> {
        let count = budgeted_count(size, budget)?;
        let mut data = Vec::with_capacity(count as usize);
        for k in 0..size[2] {
            for j in 0..size[1] {
                for i in 0..size[0] {
                    data.push(f(i, j, k));
                }
            }
        }
        Ok(Self { size, data })
    }

    /// [`DensityGrid::from_fn`] filled z slice by z slice on rayon's threads (the same values:
    /// `f` is pure), calling `done(slices_done)` as each slice completes.
    pub fn from_fn_parallel(
        size: [usize; 3],
        budget: &MemoryBudget,
        f: impl Fn(usize, usize, usize) -> f32 + Sync,
        done: impl Fn(usize) + Sync,
    ) -> Result<Self, CloudsError> {
        use rayon::prelude::*;
        let count = budgeted_count(size, budget)?;
        let mut data = vec![0.0f32; count as usize];
        let finished = std::sync::atomic::AtomicUsize::new(0);
        let [nx, ny, _] = size;
        data.par_chunks_mut(nx * ny)
            .enumerate()
            .for_each(|(k, slice)| {
                for j in 0..ny {
                    for i in 0..nx {
                        slice[j * nx + i] = f(i, j, k);
                    }
                }
                done(finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1);
            });
        Ok(Self { size, data })
    }

    /// A grid of `data` (x fastest), which must hold `nx·ny·nz` values.
    pub fn from_data(size: [usize; 3], data: Vec<f32>) -> Result<Self, CloudsError> {
        let count = checked_count(size)?;
        if data.len() as u64 != count {
            return Err(CloudsError::BadSize(
                size[0] as u64,
                size[1] as u64,
                size[2] as u64,
            ));
        }
        Ok(Self { size, data })
    }

    /// `[nx, ny, nz]`.
    pub fn size(&self) -> [usize; 3] {
        self.size
    }

    /// The samples, x fastest.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Sample `(i, j, k)`, clamped to the grid.
    #[inline]
    pub fn get(&self, i: isize, j: isize, k: isize) -> f32 {
        let c = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
        let [nx, ny, nz] = self.size;
        self.data[(c(k, nz) * ny + c(j, ny)) * nx + c(i, nx)]
    }

    /// The trilinear interpolation at `p` in the unit cube (outside it: clamped to the edge
    /// samples, as a clamped 3D texture).
    pub fn sample(&self, p: [f64; 3]) -> f64 {
        let mut base = [0isize; 3];
        let mut frac = [0.0f64; 3];
        for a in 0..3 {
            let x = p[a] * self.size[a] as f64 - 0.5;
            let f = x.floor();
            base[a] = f as isize;
            frac[a] = x - f;
        }
        let [i, j, k] = base;
        let [fx, fy, fz] = frac;
        let g = |di: isize, dj: isize, dk: isize| f64::from(self.get(i + di, j + dj, k + dk));
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        lerp(
            fz,
            lerp(
                fy,
                lerp(fx, g(0, 0, 0), g(1, 0, 0)),
                lerp(fx, g(0, 1, 0), g(1, 1, 0)),
            ),
            lerp(
                fy,
                lerp(fx, g(0, 0, 1), g(1, 0, 1)),
                lerp(fx, g(0, 1, 1), g(1, 1, 1)),
            ),
        )
    }

    /// The coarse max grid over blocks of `block³` cells (`block ≥ 1`).
    pub fn max_grid(&self, block: usize) -> MaxGrid {
        let block = block.max(1);
        let blocks = self.size.map(|n| n.div_ceil(block));
        let mut max = Vec::with_capacity(blocks.iter().product());
        for bk in 0..blocks[2] {
            for bj in 0..blocks[1] {
                for bi in 0..blocks[0] {
                    // Trilinear samples anywhere in the block read the samples of its cells and
                    // of one cell more on each side.
                    let range = |b: usize| {
                        let lo = (b * block) as isize - 1;
                        lo..=lo + block as isize + 1
                    };
                    let mut m = f32::NEG_INFINITY;
                    for k in range(bk) {
                        for j in range(bj) {
                            for i in range(bi) {
                                m = m.max(self.get(i, j, k));
                            }
                        }
                    }
                    max.push(m);
                }
            }
        }
        MaxGrid {
            block,
            grid_size: self.size,
            blocks,
            max,
        }
    }
}

/// The cell count of a grid of `size`, its f32 samples checked against `budget`.
fn budgeted_count(size: [usize; 3], budget: &MemoryBudget) -> Result<u64, CloudsError> {
    let count = checked_count(size)?;
    budget.charge_elements(
        format!("a {} × {} × {} density grid", size[0], size[1], size[2]),
        count,
        4,
    )?;
    Ok(count)
}

fn checked_count(size: [usize; 3]) -> Result<u64, CloudsError> {
    let [a, b, c] = size.map(|n| n as u64);
    match a.checked_mul(b).and_then(|n| n.checked_mul(c)) {
        Some(n) if n > 0 => Ok(n),
        _ => Err(CloudsError::BadSize(a, b, c)),
    }
}

/// The largest density a trilinear sample can take in each block of a [`DensityGrid`]: a march
/// skips a block whose bound is zero (or below its threshold) without sampling it.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxGrid {
    block: usize,
    grid_size: [usize; 3],
    blocks: [usize; 3],
    max: Vec<f32>,
}

impl MaxGrid {
    /// Blocks per side.
    pub fn blocks(&self) -> [usize; 3] {
        self.blocks
    }

    /// The bound of the block holding `p` (unit-cube coordinates, clamped).
    pub fn bound_at(&self, p: [f64; 3]) -> f32 {
        self.block_at(p).0
    }

    /// The bound of the block holding `p` and the block's box in unit-cube coordinates (the
    /// first and last blocks reach out to ±∞ along each axis, as the clamp does).
    pub fn block_at(&self, p: [f64; 3]) -> (f32, [f64; 3], [f64; 3]) {
        let mut index = [0usize; 3];
        let (mut lo, mut hi) = ([0.0; 3], [0.0; 3]);
        for a in 0..3 {
            let n = self.grid_size[a] as f64;
            let cell = (p[a] * n).floor().clamp(0.0, n - 1.0) as usize;
            index[a] = (cell / self.block).min(self.blocks[a] - 1);
            lo[a] = if index[a] == 0 {
                f64::NEG_INFINITY
            } else {
                (index[a] * self.block) as f64 / n
            };
            hi[a] = if index[a] + 1 == self.blocks[a] {
                f64::INFINITY
            } else {
                ((index[a] + 1) * self.block) as f64 / n
            };
        }
        let [bx, by, _] = self.blocks;
        (self.max[(index[2] * by + index[1]) * bx + index[0]], lo, hi)
    }
}
