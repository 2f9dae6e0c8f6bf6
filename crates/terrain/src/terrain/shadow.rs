//! Shadow rays: `occluded`, which with the min pyramid stops as soon as a segment end is
//! proven under the ground.

use super::search::{Footprint, STACK, level_for, rounding};
use super::{Terrain, TerrainStats};
use crate::clip::clip_box;
use fray_core::{Interval, Ray};
use glam::DVec3;

impl Terrain {
    /// Whether anything of the terrain lies on `ray` within `range` (shadow rays). With the min
    /// pyramid, stops as soon as a segment end is proven inside the solid.
    pub fn occluded(&self, ray: &Ray, range: Interval, eps: f64) -> bool {
        let Some(min) = &self.min else {
            return self.cast(ray, range, eps).is_some();
        };
        let m = self.placement.map_ray(ray);
        let (lo, hi) = self.map_box();
        let Some(clip) = clip_box(&m, lo, hi, range.lo, range.hi) else {
            return false;
        };
        let err = rounding(&m, &clip);
        let n = self.max.levels();
        let stop = n.saturating_sub(self.options.lod_bias);
        let mut stack = [(0.0f64, 0.0f64); STACK];
        stack[0] = (clip.t0, clip.t1);
        let mut len = 1;
        let mut stats = TerrainStats::default();
        while len > 0 {
            len -= 1;
            let (ta, tb) = stack[len];
            let (pa, pb) = (m.at(ta), m.at(tb));
            let fp = Footprint::of(pa, pb, err);
            let tm = 0.5 * (ta + tb);
            let splittable = ta < tm && tm < tb && len + 2 <= STACK;
            let mut level = level_for(fp.extent(), n).min(stop);
            if !splittable {
                level = stop;
            }
            let grid = self.max.level(level);
            let Some((a0, a1, b0, b1)) = fp.cells(level, n, grid.dims()) else {
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
            // A segment end strictly under the minimum of the level cell it lies in is inside
            // the solid: something on the ray is hit.
            for p in [pa, pb] {
                if let Some((a, b)) = point_cell(p, err, level, n, min.dims(level))
                    && p.z + err.z < f64::from(min.at(level, a, b))
                {
                    return true;
                }
            }
            if level == stop {
                let cells = (a0, a1, b0, b1);
                let hit = if stop == n {
                    self.finest_hit(&m, ray, &clip, (ta, tb), cells, fp.r_min, eps, &mut stats)
                } else {
                    self.column_hit(&m, ray, &clip, (ta, tb), level, cells, &mut stats)
                };
                if hit.is_some() {
                    return true;
                }
                continue;
            }
            stack[len] = (tm, tb);
            stack[len + 1] = (ta, tm);
            len += 2;
        }
        false
    }
}

/// The level-`level` cell holding map point `p` when that is unambiguous under rounding.
#[inline]
fn point_cell(
    p: DVec3,
    err: DVec3,
    level: u32,
    n: u32,
    dims: (usize, usize),
) -> Option<(usize, usize)> {
    let fp = Footprint::of(p, p, err);
    match fp.cells(level, n, dims)? {
        (a0, a1, b0, b1) if a0 == a1 && b0 == b1 => Some((a0, b0)),
        _ => None,
    }
}
