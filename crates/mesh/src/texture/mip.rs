//! The mip chain: level `k + 1` is level `k` box-filtered to `⌈w/2⌉ × ⌈h/2⌉` texels, down to
//! 1 × 1; sizes, level count and bytes are known from the base size before anything is allocated.
//!
//! **The filter.** Every level spans the same uv square, so a coarse texel covers a rectangle of
//! the finer level `w/⌈w/2⌉` texels wide (2 when `w` is even, `2w/(w+1) < 2` when it is odd)
//! and as high likewise. The coarse texel is the exact **area average** of the finer level —
//! read as piecewise constant over its texels — over that rectangle: separable weights, each
//! the overlap of the coarse texel's interval with a fine texel's, over the coarse width. For
//! even sides that is the usual 2 × 2 average; for odd ones up to 3 fine texels per axis
//! contribute, the shared middle one split between two coarse texels (side 3: weights
//! `2/3, 1/3` and `1/3, 2/3`). A side of 1 is kept. Because the coarse texels partition the
//! square into equal areas, each level's mean is the finer level's mean (up to rounding), so
//! every level has the base level's mean, and the texture does not darken or brighten with
//! distance. The weights are exact rationals of the two sides; sums run in f64. Every channel is
//! filtered alike, alpha included (straight, not premultiplied: a cut-out texture's transparent
//! texels' colours reach its coarse levels).

use glam::Vec4;

/// One level of a mip chain: `width × height` texels of `channels` linear `f32` values each,
/// row-major, row 0 the image's top row.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) channels: usize,
    pub(crate) data: Vec<f32>,
}

impl MipLevel {
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major from the top row, `channels` values each.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Texel `(x, y)` (column, row from the top) as RGBA: grey is replicated, a missing alpha is
    /// 1. Indices past the level read its last column or row.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec4 {
        let (x, y) = (x.min(self.width - 1), y.min(self.height - 1));
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        let t = &self.data[i..i + self.channels];
        match self.channels {
            1 => Vec4::new(t[0], t[0], t[0], 1.0),
            2 => Vec4::new(t[0], t[0], t[0], t[1]),
            3 => Vec4::new(t[0], t[1], t[2], 1.0),
            _ => Vec4::new(t[0], t[1], t[2], t[3]),
        }
    }

    /// The mean of every texel's channels (RGBA as [`MipLevel::texel`] reads them), in f64.
    pub fn mean(&self) -> [f64; 4] {
        let mut sum = [0f64; 4];
        for y in 0..self.height {
            for x in 0..self.width {
                let t = self.texel(x, y);
                for (s, v) in sum.iter_mut().zip(t.to_array()) {
                    *s += f64::from(v);
                }
            }
        }
        let n = f64::from(self.width) * f64::from(self.height);
        sum.map(|s| s / n)
    }
}

/// The sizes of every level of the chain of a `width × height` base (both at least 1), base
/// first, each `⌈w/2⌉ × ⌈h/2⌉` of the one before, the last 1 × 1.
pub fn level_sizes(width: u32, height: u32) -> Vec<(u32, u32)> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let mut sizes = vec![(w, h)];
    while w > 1 || h > 1 {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        sizes.push((w, h));
    }
    sizes
}

/// The number of levels: `1 + ⌈log₂ max(width, height)⌉`.
pub fn level_count(width: u32, height: u32) -> usize {
    let side = width.max(height).max(1);
    1 + (u32::BITS - (side - 1).leading_zeros()) as usize
}

/// The texels of the whole chain (every level, base included), counted before allocation.
pub fn chain_texels(width: u32, height: u32) -> u64 {
    level_sizes(width, height)
        .iter()
        .map(|&(w, h)| u64::from(w) * u64::from(h))
        .sum()
}

/// The weights of one axis: for each coarse index, the first fine index and up to three
/// weights (exact overlaps over the coarse width).
fn axis_weights(fine: u32, coarse: u32) -> Vec<(u32, [f64; 3])> {
    // In units of 1/(fine·coarse): fine texel j covers [j·coarse, (j+1)·coarse], coarse texel i
    // covers [i·fine, (i+1)·fine]. Overlaps are integers, weights overlap / fine.
    let (f, c) = (u64::from(fine), u64::from(coarse));
    (0..c)
        .map(|i| {
            let (lo, hi) = (i * f, (i + 1) * f);
            let first = lo / c;
            let mut w = [0f64; 3];
            for (k, slot) in w.iter_mut().enumerate() {
                let j = first + k as u64;
                if j >= f {
                    break;
                }
                let overlap = hi.min((j + 1) * c).saturating_sub(lo.max(j * c));
                *slot = overlap as f64 / f as f64;
            }
            (first as u32, w)
        })
        .collect()
}

/// Level `k + 1` from level `k` by the area-average box filter (module documentation).
pub(crate) fn downsample(fine: &MipLevel) -> MipLevel {
    let (w, h) = (fine.width.div_ceil(2), fine.height.div_ceil(2));
    let (wx, wy) = (axis_weights(fine.width, w), axis_weights(fine.height, h));
    let ch = fine.channels;
    let mut data = Vec::with_capacity(w as usize * h as usize * ch);
    for &(y0, ky) in &wy {
        for &(x0, kx) in &wx {
            let mut sum = [0f64; 4];
            for (dy, &a) in ky.iter().enumerate() {
                if a == 0.0 {
                    continue;
                }
                let row = (y0 as usize + dy) * fine.width as usize;
                for (dx, &b) in kx.iter().enumerate() {
                    if b == 0.0 {
                        continue;
                    }
                    let i = (row + x0 as usize + dx) * ch;
                    for (s, &v) in sum.iter_mut().zip(&fine.data[i..i + ch]) {
                        *s += a * b * f64::from(v);
                    }
                }
            }
            data.extend(sum[..ch].iter().map(|&s| s as f32));
        }
    }
    MipLevel {
        width: w,
        height: h,
        channels: ch,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sizes halve with rounding up to 1 × 1; the count formula agrees with the list.
    #[test]
    fn sizes_and_counts() {
        assert_eq!(level_sizes(4, 4), vec![(4, 4), (2, 2), (1, 1)]);
        assert_eq!(level_sizes(5, 3), vec![(5, 3), (3, 2), (2, 1), (1, 1)]);
        assert_eq!(level_sizes(1, 1), vec![(1, 1)]);
        assert_eq!(level_sizes(1, 6), vec![(1, 6), (1, 3), (1, 2), (1, 1)]);
        for (w, h) in [
            (1, 1),
            (2, 1),
            (3, 7),
            (451, 300),
            (512, 512),
            (513, 2),
            (65536, 1),
        ] {
            assert_eq!(level_count(w, h), level_sizes(w, h).len(), "{w} × {h}");
        }
        assert_eq!(chain_texels(4, 4), 16 + 4 + 1);
    }

    /// Every coarse texel's weights sum to 1, and every fine texel's weights over the coarse
    /// texels sum to `coarse / fine` (each fine texel counts by its area: the mean is kept).
    #[test]
    fn weights_partition_both_grids() {
        for fine in 1..40u32 {
            let coarse = fine.div_ceil(2);
            let wts = axis_weights(fine, coarse);
            let mut per_fine = vec![0f64; fine as usize];
            for &(first, w) in &wts {
                assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15, "{fine}");
                for (k, &v) in w.iter().enumerate() {
                    if v > 0.0 {
                        per_fine[(first as usize) + k] += v;
                    }
                }
            }
            for v in per_fine {
                assert!(
                    (v - f64::from(coarse) / f64::from(fine)).abs() < 1e-15,
                    "{fine}"
                );
            }
        }
        assert_eq!(
            axis_weights(3, 2),
            vec![
                (0, [2.0 / 3.0, 1.0 / 3.0, 0.0]),
                (1, [1.0 / 3.0, 2.0 / 3.0, 0.0])
            ]
        );
    }
}
