//! The surface between samples: bilinear (exact reference; ray/patch is a quadratic per cell)
//! or bicubic as a **uniform cubic B-spline** over the 4 × 4 neighbouring samples (C², smooth,
//! approximating rather than interpolating — it passes within the samples' local range, not
//! through them). The B-spline is chosen for its convex-hull property: a cell's surface lies
//! between the min and max of its 16 control points, and its slopes between the min and max of
//! neighbouring differences — exact, cheap, conservative bounds for the pyramid and for the
//! per-cell halving.
//!
//! Control points come from the samples; where a neighbour is off the map or below the
//! threshold it is replaced by the nearest corner of the cell itself (all four corners of a
//! solid cell are surface). So the bicubic surface is C² where the 4 × 4 neighbourhood is
//! complete; along the map border and threshold outlines adjacent cells may not meet exactly
//! (sub-cell steps where the data end anyway).

use crate::Heightmap;
use glam::DVec2;

/// How the surface is interpolated between samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// Bilinear patches: the cell's 4 corner samples. Exact ray intersection (a quadratic).
    #[default]
    Bilinear,
    /// Uniform cubic B-spline over the 4 × 4 neighbouring samples (see the module docs).
    Bicubic,
}

/// The bilinear patch of one cell in local coordinates `(s, w) ∈ [0, 1]²`:
/// `S = h00 + a s + b w + k s w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearCell {
    pub h00: f64,
    pub a: f64,
    pub b: f64,
    pub k: f64,
}

impl BilinearCell {
    pub fn new(map: &Heightmap, i: usize, j: usize) -> Self {
        let h00 = f64::from(map.at(i, j));
        let h10 = f64::from(map.at(i + 1, j));
        let h01 = f64::from(map.at(i, j + 1));
        let h11 = f64::from(map.at(i + 1, j + 1));
        Self {
            h00,
            a: h10 - h00,
            b: h01 - h00,
            k: h00 - h10 - h01 + h11,
        }
    }

    #[inline]
    pub fn eval(&self, s: f64, w: f64) -> f64 {
        self.h00 + self.a * s + self.b * w + self.k * s * w
    }

    /// `(∂S/∂s, ∂S/∂w)`.
    #[inline]
    pub fn slope(&self, s: f64, w: f64) -> DVec2 {
        DVec2::new(self.a + self.k * w, self.b + self.k * s)
    }
}

/// The B-spline patch of one cell: 16 control points `p[m][l]` (row `j − 1 + m`, column
/// `i − 1 + l`) and bounds derived from them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BicubicCell {
    pub p: [[f64; 4]; 4],
    /// Bounds of the surface over the cell (convex hull).
    pub min: f64,
    pub max: f64,
    /// Bounds of `|∂S/∂s|`, `|∂S/∂w|` (first differences) and of `|∂²S/∂s²|`, `|∂²S/∂s∂w|`,
    /// `|∂²S/∂w²|` (second differences) over the cell.
    pub d1: DVec2,
    pub d2: [f64; 3],
}

/// Cubic B-spline basis at `s` and its derivative.
#[inline]
fn basis(s: f64) -> ([f64; 4], [f64; 4]) {
    let t = 1.0 - s;
    let s2 = s * s;
    let s3 = s2 * s;
    (
        [
            t * t * t / 6.0,
            (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0,
            (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0,
            s3 / 6.0,
        ],
        [
            -t * t / 2.0,
            (3.0 * s2 - 4.0 * s) / 2.0,
            (-3.0 * s2 + 2.0 * s + 1.0) / 2.0,
            s2 / 2.0,
        ],
    )
}

impl BicubicCell {
    /// The control points of solid cell `(i, j)` (see the module docs for the replacement rule).
    pub fn control_points(map: &Heightmap, i: usize, j: usize) -> [[f32; 4]; 4] {
        let (w, h) = (map.width() as isize, map.height() as isize);
        let mut p = [[0f32; 4]; 4];
        for (m, row) in p.iter_mut().enumerate() {
            for (l, out) in row.iter_mut().enumerate() {
                let x = i as isize - 1 + l as isize;
                let y = j as isize - 1 + m as isize;
                let inside = x >= 0 && y >= 0 && x < w && y < h;
                *out = if inside && map.is_surface(x as usize, y as usize) {
                    map.at(x as usize, y as usize)
                } else {
                    let cx = x.clamp(i as isize, i as isize + 1) as usize;
                    let cy = y.clamp(j as isize, j as isize + 1) as usize;
                    map.at(cx, cy)
                };
            }
        }
        p
    }

    // Differences along rows and columns index `p` both ways round; ranges read clearest.
    #[allow(clippy::needless_range_loop)]
    pub fn new(map: &Heightmap, i: usize, j: usize) -> Self {
        let c = Self::control_points(map, i, j);
        let mut p = [[0.0; 4]; 4];
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        for (row, src) in p.iter_mut().zip(&c) {
            for (out, &v) in row.iter_mut().zip(src) {
                *out = f64::from(v);
                min = min.min(*out);
                max = max.max(*out);
            }
        }
        let mut d1 = DVec2::ZERO;
        let mut d2 = [0.0f64; 3];
        for m in 0..4 {
            for l in 0..3 {
                d1.x = d1.x.max((p[m][l + 1] - p[m][l]).abs());
                d1.y = d1.y.max((p[l + 1][m] - p[l][m]).abs());
            }
            for l in 0..2 {
                d2[0] = d2[0].max((p[m][l + 2] - 2.0 * p[m][l + 1] + p[m][l]).abs());
                d2[2] = d2[2].max((p[l + 2][m] - 2.0 * p[l + 1][m] + p[l][m]).abs());
            }
        }
        for m in 0..3 {
            for l in 0..3 {
                let mixed = p[m + 1][l + 1] - p[m + 1][l] - p[m][l + 1] + p[m][l];
                d2[1] = d2[1].max(mixed.abs());
            }
        }
        Self {
            p,
            min,
            max,
            d1,
            d2,
        }
    }

    /// The surface and its slopes `(∂S/∂s, ∂S/∂w)` at `(s, w)`.
    #[inline]
    pub fn eval_with_slope(&self, s: f64, w: f64) -> (f64, DVec2) {
        let (bs, ds) = basis(s);
        let (bw, dw) = basis(w);
        let (mut v, mut vs, mut vw) = (0.0, 0.0, 0.0);
        for m in 0..4 {
            let row = &self.p[m];
            let r = bs[0] * row[0] + bs[1] * row[1] + bs[2] * row[2] + bs[3] * row[3];
            let rd = ds[0] * row[0] + ds[1] * row[1] + ds[2] * row[2] + ds[3] * row[3];
            v += bw[m] * r;
            vs += bw[m] * rd;
            vw += dw[m] * r;
        }
        (v, DVec2::new(vs, vw))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bspline_reproduces_planes_and_its_slope_matches_finite_differences() {
        // A plane is reproduced exactly by a uniform B-spline (linear precision).
        let map = Heightmap::from_fn(6, 6, |i, j| 2.0 * i as f32 - 3.0 * j as f32 + 1.0).unwrap();
        let c = BicubicCell::new(&map, 2, 2);
        let (v, g) = c.eval_with_slope(0.25, 0.75);
        assert!((v - (2.0 * 2.25 - 3.0 * 2.75 + 1.0)).abs() < 1e-12);
        assert!((g - DVec2::new(2.0, -3.0)).length() < 1e-12);
        let map = Heightmap::from_fn(6, 6, |i, j| ((i * 7 + j * 3) % 5) as f32).unwrap();
        let c = BicubicCell::new(&map, 1, 2);
        let h = 1e-6;
        let (_, g) = c.eval_with_slope(0.3, 0.6);
        let fd_s =
            (c.eval_with_slope(0.3 + h, 0.6).0 - c.eval_with_slope(0.3 - h, 0.6).0) / (2.0 * h);
        let fd_w =
            (c.eval_with_slope(0.3, 0.6 + h).0 - c.eval_with_slope(0.3, 0.6 - h).0) / (2.0 * h);
        assert!((g.x - fd_s).abs() < 1e-7 && (g.y - fd_w).abs() < 1e-7);
        // Convex hull and slope bounds hold on a grid of points.
        for a in 0..=10 {
            for b in 0..=10 {
                let (v, g) = c.eval_with_slope(a as f64 / 10.0, b as f64 / 10.0);
                assert!(v >= c.min - 1e-12 && v <= c.max + 1e-12);
                assert!(g.x.abs() <= c.d1.x + 1e-12 && g.y.abs() <= c.d1.y + 1e-12);
            }
        }
    }

    #[test]
    fn bilinear_slope_is_the_derivative() {
        let map = Heightmap::from_samples(2, 2, vec![1.0, 4.0, 2.0, -3.0]).unwrap();
        let c = BilinearCell::new(&map, 0, 0);
        assert_eq!(c.eval(0.0, 0.0), 1.0);
        assert_eq!(c.eval(1.0, 1.0), -3.0);
        let g = c.slope(0.5, 0.5);
        let h = 1e-7;
        assert!((g.x - (c.eval(0.5 + h, 0.5) - c.eval(0.5 - h, 0.5)) / (2.0 * h)).abs() < 1e-6);
    }
}
