//! The pyramid halving search: `cast`, `cast_lod` and `cast_footprint`, the footprint level
//! rule and the stop levels.
//!
//! The search: the ray, clipped to the terrain's box, is mapped to `(u, v, r)` and split in
//! halves, nearer half first. For each segment the level is chosen from its footprint `Lp`
//! (the larger of its `u` and `v` extents as a fraction of the pyramid's side `2ⁿ` cells): the
//! level `k` with `2^-(k+1) < Lp ≤ 2^-k`, so the footprint spans at most 2 × 2 cells of that
//! level (3 × 3 when it ends exactly on cell lines); a segment whose lowest `r` is above the
//! maximum over those cells is dropped. At the stop level `n − lod_bias` the surface is
//! intersected: with bias 0, each finest cell exactly (bilinear: a quadratic; bicubic:
//! halving with the B-spline's slope bounds, monotone pieces finished by Illinois); with a bias
//! `b > 0`, the tops of the level-`(n − b)` max columns (early and blocky — the LOD knob).
//! Footprints and heights are widened by a bound on the rounding of `o + t·d`, so rounding
//! never drops a segment that holds a hit.

use super::{PIXEL_LOD_COARSEST_LEVEL, Terrain, TerrainHit, TerrainStats};
use crate::MapRay;
use crate::clip::{Clip, clip_box};
use fray_core::{Interval, PixelFootprint, Ray};
use glam::DVec3;

pub(super) const STACK: usize = 96;

impl Terrain {
    /// The nearest hit in `range` (world distances along `ray`); `eps` is the root tolerance of
    /// the bicubic search (world units; the bilinear hit is exact to rounding).
    pub fn cast(&self, ray: &Ray, range: Interval, eps: f64) -> Option<TerrainHit> {
        self.cast_with_stats(ray, range, eps, 0.0, &mut TerrainStats::default())
    }

    /// [`Terrain::cast`] with a pixel-footprint level of detail: `footprint` is the world size of
    /// a pixel per unit of distance (≈ the pixel's angle). A segment starting at distance `t`
    /// stops at the level whose cells are at least `footprint · t` wide (and hits that level's
    /// max column tops), so the work follows the screen, not the map size; `0` is exact.
    pub fn cast_lod(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        footprint: f64,
    ) -> Option<TerrainHit> {
        self.cast_with_stats(ray, range, eps, footprint, &mut TerrainStats::default())
    }

    /// [`Terrain::cast_lod`], counting work into `stats`.
    pub fn cast_with_stats(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        footprint: f64,
        stats: &mut TerrainStats,
    ) -> Option<TerrainHit> {
        let footprint = PixelFootprint {
            size: 0.0,
            angle: footprint,
        };
        self.cast_footprint(ray, range, eps, footprint, stats)
    }

    /// The pixel-footprint search for any projector: a segment starting at distance `t` stops at
    /// the level whose cells are at least `footprint.at(t)` wide (never coarser than
    /// [`PIXEL_LOD_COARSEST_LEVEL`], never finer than the LOD bias allows) and hits that level's
    /// max-column tops — never later than the exact hit, never missing one.
    /// [`PixelFootprint::ZERO`] is [`Terrain::cast`]. Counts work into `stats`.
    pub fn cast_footprint(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        footprint: PixelFootprint,
        stats: &mut TerrainStats,
    ) -> Option<TerrainHit> {
        let m = self.placement.map_ray(ray);
        let (lo, hi) = self.map_box();
        let clip = clip_box(&m, lo, hi, range.lo, range.hi)?;
        let err = rounding(&m, &clip);
        let n = self.max.levels();
        let stop_bias = n.saturating_sub(self.options.lod_bias);
        let floor = n.min(PIXEL_LOD_COARSEST_LEVEL);
        // Finest cells per pixel (0: no pixel LOD).
        let cell = self.placement.spacing().min_element();
        let pixel = !footprint.is_zero()
            && footprint.size.is_finite()
            && footprint.angle.is_finite()
            && footprint.size >= 0.0
            && footprint.angle >= 0.0;
        let mut stack = [(0.0f64, 0.0f64); STACK];
        stack[0] = (clip.t0, clip.t1);
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (ta, tb) = stack[len];
            stats.segments += 1;
            let stop = if pixel {
                stop_bias.min(level_for(footprint.at(ta) / cell, n).max(floor))
            } else {
                stop_bias
            };
            let (pa, pb) = (m.at(ta), m.at(tb));
            let fp = Footprint::of(pa, pb, err);
            let tm = 0.5 * (ta + tb);
            let splittable = ta < tm && tm < tb && len + 2 <= STACK;
            let mut level = level_for(fp.extent(), n).min(stop);
            if !splittable {
                level = stop;
            }
            let grid = self.max.level(level);
            let cells = fp.cells(level, n, grid.dims());
            let Some((a0, a1, b0, b1)) = cells else {
                continue;
            };
            let mut top = f32::NEG_INFINITY;
            for b in b0..=b1 {
                for a in a0..=a1 {
                    top = top.max(grid.at(a, b));
                }
            }
            if fp.r_min > f64::from(top) {
                continue;
            }
            if level == stop {
                stats.stops += 1;
                stats.stop_levels_above_finest += u64::from(n - stop);
                let hit = if stop == n {
                    self.finest_hit(
                        &m,
                        ray,
                        &clip,
                        (ta, tb),
                        (a0, a1, b0, b1),
                        fp.r_min,
                        eps,
                        stats,
                    )
                } else {
                    self.column_hit(&m, ray, &clip, (ta, tb), level, (a0, a1, b0, b1), stats)
                };
                if hit.is_some() {
                    return hit;
                }
                continue;
            }
            stack[len] = (tm, tb);
            stack[len + 1] = (ta, tm);
            len += 2;
        }
        None
    }
}

/// A bound on the absolute rounding error of `o + t·d` per map axis over the clipped range.
pub(super) fn rounding(m: &MapRay, clip: &Clip) -> DVec3 {
    let t = clip.t0.abs().max(clip.t1.abs());
    (m.origin.abs() + m.dir.abs() * t) * (4.0 * f64::EPSILON) + DVec3::splat(f64::MIN_POSITIVE)
}

/// A segment's map-space footprint, widened by the rounding bound.
pub(super) struct Footprint {
    u: (f64, f64),
    v: (f64, f64),
    pub(super) r_min: f64,
}

impl Footprint {
    #[inline]
    pub(super) fn of(pa: DVec3, pb: DVec3, err: DVec3) -> Self {
        Self {
            u: (pa.x.min(pb.x) - err.x, pa.x.max(pb.x) + err.x),
            v: (pa.y.min(pb.y) - err.y, pa.y.max(pb.y) + err.y),
            r_min: pa.z.min(pb.z) - err.z,
        }
    }

    #[inline]
    pub(super) fn extent(&self) -> f64 {
        (self.u.1 - self.u.0).max(self.v.1 - self.v.0)
    }

    /// The level-`level` cells whose closed squares meet the footprint, clamped to the level's
    /// grid of `dims` cells (levels are rectangular: cells past it cover no part of the map);
    /// `None` if it lies off the grid.
    #[inline]
    pub(super) fn cells(
        &self,
        level: u32,
        n: u32,
        (columns, rows): (usize, usize),
    ) -> Option<(usize, usize, usize, usize)> {
        let scale = 1.0 / (1u64 << (n - level)) as f64;
        let range = |(lo, hi): (f64, f64), last: f64| {
            let a = first_cell(lo * scale);
            let b = last_cell(hi * scale).min(last);
            (a <= b).then_some((a as usize, b as usize))
        };
        let (a0, a1) = range(self.u, (columns - 1) as f64)?;
        let (b0, b1) = range(self.v, (rows - 1) as f64)?;
        Some((a0, a1, b0, b1))
    }
}

/// `max(⌈x⌉ − 1, 0)`: the first cell whose closed square reaches `x` (in cell units) — without
/// the libm call `f64::ceil` compiles to on baseline x86-64 (no SSE4.1), where it was a tenth of
/// a terrain frame's instructions: for `1 < x < 2⁵³` the truncation is the floor. Exact for
/// every input (NaN, ±∞ and huge values take `ceil`).
#[inline]
fn first_cell(x: f64) -> f64 {
    if x <= 1.0 {
        return 0.0;
    }
    if x >= 9.0e15 || x.is_nan() {
        return (x.ceil() - 1.0).max(0.0);
    }
    let t = x as i64 as f64;
    if x > t { t } else { t - 1.0 }
}

/// `⌊x⌋` where it can be a cell index, any negative value where `x < 0` (no cell): the last
/// cell whose closed square reaches `x`, as [`first_cell`] without the libm call.
#[inline]
fn last_cell(x: f64) -> f64 {
    if x < 0.0 {
        return -1.0;
    }
    if x >= 9.0e15 || x.is_nan() {
        return x.floor();
    }
    x as i64 as f64
}

/// The pyramid level for a footprint of `extent` finest cells: `k` with
/// `2^(n−k−1) < extent ≤ 2^(n−k)` (that is `2^-(k+1) < Lp ≤ 2^-k` for `Lp = extent / 2ⁿ`),
/// clamped to `0..=n`.
#[inline]
pub(super) fn level_for(extent: f64, n: u32) -> u32 {
    if extent.is_nan() || extent <= 1.0 {
        return n;
    }
    // ceil(log2(extent)) from the exponent bits: exact for powers of two.
    let bits = extent.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mantissa = bits & ((1u64 << 52) - 1);
    let ceil_log2 = if mantissa == 0 { exp } else { exp + 1 };
    (n as i64 - ceil_log2).clamp(0, n as i64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_follows_the_footprint_inequality() {
        // n = 10: extent in finest cells; 2^(n−k−1) < extent ≤ 2^(n−k).
        assert_eq!(level_for(0.0, 10), 10);
        assert_eq!(level_for(1.0, 10), 10);
        assert_eq!(level_for(1.5, 10), 9);
        assert_eq!(level_for(2.0, 10), 9);
        assert_eq!(level_for(2.0001, 10), 8);
        assert_eq!(level_for(1024.0, 10), 0);
        assert_eq!(level_for(5000.0, 10), 0);
    }

    #[test]
    fn cell_bounds_without_libm_are_ceil_and_floor() {
        let xs = [
            -1e300,
            -3.5,
            -1.0,
            -0.5,
            -0.0,
            0.0,
            0.25,
            1.0,
            1.0 + f64::EPSILON,
            1.5,
            2.0,
            2.0 - f64::EPSILON,
            7.999999,
            1e9 + 0.5,
            8.9e15,
            9.1e15,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for x in xs {
            assert_eq!(first_cell(x), (x.ceil() - 1.0).max(0.0), "{x}");
            if x >= 0.0 {
                assert_eq!(last_cell(x), x.floor(), "{x}");
            } else {
                assert!(last_cell(x) < 0.0, "{x}");
            }
        }
        assert_eq!(first_cell(f64::NAN), 0.0);
        assert!(last_cell(f64::NAN).is_nan());
    }
}
