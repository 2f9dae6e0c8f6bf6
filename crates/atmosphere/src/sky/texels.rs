//! Texel storage shared by the sky's tables: `[f32; 4]` row-major (RGB, the fourth channel 1),
//! filled in parallel rows from an f64 function, read back with bilinear filtering.

use glam::DVec3;
use std::sync::Mutex;

/// Converts an f64 RGB value to a texel.
pub(crate) fn texel(v: DVec3) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, 1.0]
}

/// Fills `texels` (rows of `width`) with `f(column, row)`. Rows are handed out to up to
/// `available_parallelism` scoped threads; each texel depends only on its own indices, so the
/// bytes are the same whatever the thread count (a thread that cannot be spawned just leaves
/// its rows to the others).
pub(crate) fn fill_rows(
    texels: &mut [[f32; 4]],
    width: usize,
    f: impl Fn(usize, usize) -> DVec3 + Sync,
) {
    if width == 0 {
        return;
    }
    let rows = texels.len() / width;
    let threads = std::thread::available_parallelism()
        .map_or(1, usize::from)
        .min(rows)
        .max(1);
    let queue = Mutex::new(texels.chunks_mut(width).enumerate());
    let work = || {
        loop {
            let next = match queue.lock() {
                Ok(mut q) => q.next(),
                Err(poisoned) => poisoned.into_inner().next(),
            };
            let Some((j, row)) = next else { break };
            for (i, t) in row.iter_mut().enumerate() {
                *t = texel(f(i, j));
            }
        }
    };
    std::thread::scope(|s| {
        for _ in 1..threads {
            // A failed spawn only means fewer workers.
            let _ = std::thread::Builder::new().spawn_scoped(s, work);
        }
        work();
    });
}

/// Bilinear interpolation at continuous texel coordinates `(x, y)` (texel centres at integers),
/// `x` clamped to `[0, width − 1]` and `y` to the rows `[row_lo, row_hi]`.
pub(crate) fn bilinear(
    texels: &[[f32; 4]],
    width: usize,
    x: f64,
    y: f64,
    row_lo: usize,
    row_hi: usize,
) -> DVec3 {
    let at = |i: usize, j: usize| {
        texels.get(j * width + i).map_or(DVec3::ZERO, |t| {
            DVec3::new(t[0].into(), t[1].into(), t[2].into())
        })
    };
    let x_max = width.saturating_sub(1) as f64;
    // NaN coordinates fall to the first texel (`clamp` keeps NaN; `max` does not).
    let x = x.max(0.0).min(x_max);
    let y = y.max(row_lo as f64).min(row_hi as f64);
    let i0 = (x.floor() as usize).min(width.saturating_sub(1));
    let j0 = (y.floor() as usize).clamp(row_lo, row_hi);
    let i1 = (i0 + 1).min(width.saturating_sub(1));
    let j1 = (j0 + 1).min(row_hi);
    let (fx, fy) = (x - i0 as f64, y - j0 as f64);
    let top = at(i0, j0) * (1.0 - fx) + at(i1, j0) * fx;
    let bottom = at(i0, j1) * (1.0 - fx) + at(i1, j1) * fx;
    top * (1.0 - fy) + bottom * fy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_and_interpolate() {
        let (w, h) = (5, 4);
        let mut t = vec![[0.0f32; 4]; w * h];
        fill_rows(&mut t, w, |i, j| {
            DVec3::new(i as f64, j as f64, (i * j) as f64)
        });
        assert_eq!(t[2 * w + 3], [3.0, 2.0, 6.0, 1.0]);
        let v = bilinear(&t, w, 1.5, 2.25, 0, h - 1);
        assert!((v - DVec3::new(1.5, 2.25, 1.5 * 2.25)).abs().max_element() < 1e-12);
        // Clamped to the rows given (a half table) and to the edges.
        let v = bilinear(&t, w, 9.0, 3.0, 0, 1);
        assert_eq!(v, DVec3::new(4.0, 1.0, 4.0));
        let v = bilinear(&t, w, f64::NAN, f64::NAN, 2, 3);
        assert_eq!(v, DVec3::new(0.0, 2.0, 0.0));
    }
}
