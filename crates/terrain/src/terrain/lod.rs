//! Level of detail: the max-column tops a LOD search stops at, and the coarsest stop level
//! and column boxes the quadtree's cell test relies on.

use super::{HitKind, Terrain, TerrainHit, TerrainStats};
use crate::MapRay;
use crate::clip::{Clip, clip_within};
use fray_core::{Aabb, Ray};
use glam::DVec3;

/// The coarsest level a pixel-footprint search stops at (clamped to the pyramid's depth): 8 × 8
/// max columns over the whole map. A pixel wider than that sees the map as a few blocks anyway,
/// and the quadtree's cell test ([`Terrain::coarsest_stop_level`]) relies on the bound.
pub const PIXEL_LOD_COARSEST_LEVEL: u32 = 3;

impl Terrain {
    /// The coarsest pyramid level any search of this terrain stops at — exact (`n − lod_bias`) or
    /// pixel-footprint ([`PIXEL_LOD_COARSEST_LEVEL`] at most): every hit, LOD hits included, lies
    /// in one of this level's max columns ([`Terrain::column_bounds`]).
    pub fn coarsest_stop_level(&self) -> u32 {
        let n = self.max.levels();
        n.saturating_sub(self.options.lod_bias)
            .min(n.min(PIXEL_LOD_COARSEST_LEVEL))
    }

    /// The world box of the level-`level` max column `(a, b)`: the cell's map rectangle (clipped
    /// to the map) from the bottom to the column's maximum; `None` for an empty column or one
    /// past the map (levels are rectangular: [`Pyramid::dims`]).
    ///
    /// [`Pyramid::dims`]: crate::Pyramid::dims
    pub fn column_bounds(&self, level: u32, a: usize, b: usize) -> Option<Aabb> {
        let (columns, rows) = self.max.dims(level);
        if a >= columns || b >= rows {
            return None;
        }
        let m = self.max.at(level, a, b);
        if m == f32::NEG_INFINITY {
            return None;
        }
        let (cw, ch) = self.map.cells();
        let size = (1usize << (self.max.levels() - level)) as f64;
        let lo = DVec3::new(a as f64 * size, b as f64 * size, self.bottom);
        let hi = DVec3::new(
            ((a + 1) as f64 * size).min(cw as f64),
            ((b + 1) as f64 * size).min(ch as f64),
            f64::from(m),
        );
        let mut bx = Aabb::EMPTY;
        for k in 0..8 {
            let c = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let p = self.placement.to_world(c);
            bx = bx.union(&Aabb::new(p, p));
        }
        Some(bx)
    }

    /// LOD hit: the entry into the nearest max column `[cell] × [bottom, max]` at `level`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn column_hit(
        &self,
        m: &MapRay,
        ray: &Ray,
        clip: &Clip,
        (ta, tb): (f64, f64),
        level: u32,
        (a0, a1, b0, b1): (usize, usize, usize, usize),
        stats: &mut TerrainStats,
    ) -> Option<TerrainHit> {
        let (cw, ch) = self.map.cells();
        let size = (1usize << (self.max.levels() - level)) as f64;
        let grid = self.max.level(level);
        let mut best: Option<TerrainHit> = None;
        for b in b0..=b1 {
            for a in a0..=a1 {
                let top = grid.at(a, b);
                if top == f32::NEG_INFINITY {
                    continue;
                }
                stats.cells += 1;
                let lo = DVec3::new(a as f64 * size, b as f64 * size, self.bottom);
                let hi = DVec3::new(
                    ((a + 1) as f64 * size).min(cw as f64),
                    ((b + 1) as f64 * size).min(ch as f64),
                    f64::from(top),
                );
                let Some(c) = clip_within(m, lo, hi, clip) else {
                    continue;
                };
                let t = c.t0.max(ta);
                if t > c.t1.min(tb) || best.is_some_and(|h| h.t <= t) {
                    continue;
                }
                let (normal, kind) = match (t == c.t0, c.entry) {
                    (true, None) => (-ray.dir, HitKind::Start),
                    (true, Some((axis, sign))) if axis < 2 || sign < 0.0 => {
                        (self.placement.axis_normal(axis, sign), HitKind::Wall)
                    }
                    _ => (self.placement.axis_normal(2, 1.0), HitKind::Surface),
                };
                best = Some(TerrainHit {
                    t,
                    normal,
                    cell: [a as u32, b as u32],
                    kind,
                    levels_above_finest: self.max.levels() - level,
                });
            }
        }
        best
    }
}
