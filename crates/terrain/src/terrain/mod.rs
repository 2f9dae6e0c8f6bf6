//! The terrain: a height map placed in the world with its max pyramid, and its ray casting by
//! halving the ray segment in height-map space (docs/methods.md §4).
//!
//! The solid is `{ bottom ≤ r ≤ S(u, v) }` over the solid cells, `S` the interpolated surface
//! and `bottom = min(0, lowest surface bound)`: the base plane `r = 0` (or the lowest point if
//! the map goes below it) closes it, so a ray that enters through a threshold outline, the map
//! border or from below hits a vertical wall or the base, and a ray that starts inside the solid
//! hits at its start (like free forms: `F ≥ 0` is inside).
//!
//! The type, its construction and accessors are here; the search is in `search` (the
//! pyramid halving), `cell` (the finest cells' intersections, their roots in `roots`), `lod`
//! (max-column tops), `shadow` (`occluded`), `surface` (heights and shading normals) and
//! `reference` (the brute-force reference and the marching baseline).

mod cell;
mod lod;
mod reference;
mod roots;
mod search;
mod shadow;
mod surface;

pub use lod::PIXEL_LOD_COARSEST_LEVEL;
pub use reference::MAX_MARCH_STEPS;

use crate::interpolation::{BicubicCell, Interpolation};
use crate::{Heightmap, Placement, Pyramid, Region, TerrainError};
use fray_core::{Aabb, MemoryBudget};
use glam::DVec3;

/// How a terrain is searched and drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TerrainOptions {
    pub interpolation: Interpolation,
    /// Levels above the finest at which the search stops and hits the max columns' tops:
    /// 0 = exact surface; larger = faster and coarser (clamped to the pyramid's depth).
    pub lod_bias: u32,
    /// Also build the min pyramid: shadow rays ([`Terrain::occluded`]) stop as soon as a
    /// segment end is proven under the ground at a coarse level.
    pub min_pyramid: bool,
}

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitKind {
    /// The interpolated surface (or, with a LOD bias, the top of a max column).
    Surface,
    /// A vertical wall (threshold outline, map border) or the base, entered from outside.
    Wall,
    /// The ray starts inside the solid (the hit is at its start).
    Start,
}

/// The nearest hit on a terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TerrainHit {
    /// World distance along the ray.
    pub t: f64,
    /// Outward world unit normal (analytic, from the interpolant, for surface hits; `−dir` for
    /// [`HitKind::Start`]).
    pub normal: DVec3,
    /// The cell `(column, row)` hit (at the stop level's resolution for LOD hits).
    pub cell: [u32; 2],
    pub kind: HitKind,
    /// 0 for a hit on the exact surface, its walls or its base; `k > 0` for a hit on a
    /// level-`(n − k)` max column (a LOD hit: its normal is the column face's, see
    /// [`Terrain::shading_normal`] for the surface's beneath).
    pub levels_above_finest: u32,
}

/// Work counters of terrain casts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TerrainStats {
    /// Segments popped by the halving search.
    pub segments: u64,
    /// Finest cells (or stop-level columns) intersected.
    pub cells: u64,
    /// Segments that reached their stop level and were intersected there.
    pub stops: u64,
    /// Sum over those stops of their level's distance above the finest (`n − level`): divided by
    /// `stops`, the mean level of detail actually used (0 = exact everywhere).
    pub stop_levels_above_finest: u64,
}

impl std::ops::AddAssign for TerrainStats {
    fn add_assign(&mut self, o: Self) {
        self.segments += o.segments;
        self.cells += o.cells;
        self.stops += o.stops;
        self.stop_levels_above_finest += o.stop_levels_above_finest;
    }
}

/// The lower and upper bound of cell `(i, j)`'s interpolant (its corners for bilinear, exact;
/// its 16 control points for bicubic, the convex hull's), `None` for a cell that is not solid.
fn cell_bounds(
    map: &Heightmap,
    interpolation: Interpolation,
    i: usize,
    j: usize,
) -> Option<(f32, f32)> {
    if !map.cell_is_solid(i, j) {
        return None;
    }
    Some(match interpolation {
        Interpolation::Bilinear => {
            let c = [
                map.at(i, j),
                map.at(i + 1, j),
                map.at(i, j + 1),
                map.at(i + 1, j + 1),
            ];
            (
                c.iter().copied().fold(f32::INFINITY, f32::min),
                c.iter().copied().fold(f32::NEG_INFINITY, f32::max),
            )
        }
        Interpolation::Bicubic => {
            let p = BicubicCell::control_points(map, i, j);
            let flat = p.iter().flatten().copied();
            (
                flat.clone().fold(f32::INFINITY, f32::min),
                flat.fold(f32::NEG_INFINITY, f32::max),
            )
        }
    })
}

/// How many samples past a cell's own corners its interpolant reads (the B-spline's 4 × 4
/// reaches one further on each side).
fn reach(interpolation: Interpolation) -> usize {
    match interpolation {
        Interpolation::Bilinear => 0,
        Interpolation::Bicubic => 1,
    }
}

/// A height map placed in the world, with its pyramid(s): ready to ray-cast.
#[derive(Clone, Debug)]
pub struct Terrain {
    map: Heightmap,
    placement: Placement,
    options: TerrainOptions,
    max: Pyramid,
    min: Option<Pyramid>,
    bottom: f64,
    top: f64,
}

impl Terrain {
    /// Builds the pyramid(s) of `map` for `options.interpolation`, within the default memory
    /// budget ([`MemoryBudget::default`]). Fails when no cell is solid.
    pub fn new(
        map: Heightmap,
        placement: Placement,
        options: TerrainOptions,
    ) -> Result<Self, TerrainError> {
        Self::new_within(map, placement, options, &MemoryBudget::default())
    }

    /// [`Terrain::new`] within `budget`: the pyramid(s) and the per-cell bounds they are built
    /// from (alive together: `4 · (cells + Pyramid::len_for(cells))` bytes per pyramid) are
    /// refused over it ([`TerrainError::Budget`]) before anything is allocated.
    pub fn new_within(
        map: Heightmap,
        placement: Placement,
        options: TerrainOptions,
        budget: &MemoryBudget,
    ) -> Result<Self, TerrainError> {
        let (cw, ch) = map.cells();
        let per_pyramid = ((cw * ch) as u64).saturating_add(Pyramid::len_for(cw, ch) as u64) * 4;
        let (count, what) = if options.min_pyramid {
            (2, "max and min pyramids")
        } else {
            (1, "max pyramid")
        };
        budget
            .check(
                format!(
                    "the terrain's {what} over {cw} × {ch} cells (with the per-cell bounds they \
                     are built from)"
                ),
                per_pyramid.saturating_mul(count),
            )
            .map_err(|source| TerrainError::Budget { path: None, source })?;
        // The pyramids stay with the terrain; the per-cell bounds go when it is built.
        budget
            .charge(
                "terrains' pyramids",
                (Pyramid::len_for(cw, ch) as u64)
                    .saturating_mul(4)
                    .saturating_mul(count),
            )
            .map_err(|source| TerrainError::Budget { path: None, source })?;
        let mut hi = vec![f32::NEG_INFINITY; cw * ch];
        let mut lo = if options.min_pyramid {
            vec![f32::NEG_INFINITY; cw * ch]
        } else {
            Vec::new()
        };
        let mut lowest = f32::INFINITY;
        for j in 0..ch {
            for i in 0..cw {
                let Some((a, b)) = cell_bounds(&map, options.interpolation, i, j) else {
                    continue;
                };
                if let Some(l) = lo.get_mut(j * cw + i) {
                    *l = a;
                }
                hi[j * cw + i] = b;
                lowest = lowest.min(a);
            }
        }
        let max = Pyramid::max_of(cw, ch, &hi);
        drop(hi);
        if max.global() == f32::NEG_INFINITY {
            return Err(TerrainError::NoSurface {
                threshold: f64::from(map.threshold()),
            });
        }
        let min = options.min_pyramid.then(|| Pyramid::min_of(cw, ch, &lo));
        Ok(Self {
            bottom: f64::from(lowest).min(0.0),
            top: f64::from(max.global()),
            map,
            placement,
            options,
            max,
            min,
        })
    }

    /// This terrain with new heights `map` (the same size; its threshold is used) that differ
    /// from the current ones only in the samples of `changed`: the pyramid(s) are updated only
    /// above the cells those samples touch ([`Pyramid::update_max`]), not rebuilt, and the result
    /// is bit for bit what [`Terrain::new`] builds from `map` with the same placement and
    /// options. The caller charges the copy ([`Terrain::heap_bytes`]) to its budget first.
    /// Fails when the size differs or no cell is solid any more.
    pub fn with_heights(&self, map: Heightmap, changed: Region) -> Result<Self, TerrainError> {
        if (map.width(), map.height()) != (self.map.width(), self.map.height()) {
            return Err(TerrainError::Parameter {
                name: "heights",
                message: format!(
                    "a {} × {} map cannot replace the terrain's {} × {}",
                    map.width(),
                    map.height(),
                    self.map.width(),
                    self.map.height()
                ),
            });
        }
        let (cw, ch) = map.cells();
        let interpolation = self.options.interpolation;
        // A new threshold changes which cells are solid anywhere: every cell is touched.
        let cells = if map.threshold().to_bits() == self.map.threshold().to_bits() {
            changed.cells_touched(reach(interpolation), cw, ch)
        } else {
            Region::all(cw, ch)
        };
        let mut max = self.max.clone();
        let mut lowest = f32::INFINITY;
        max.update_max(cells, |i, j| match cell_bounds(&map, interpolation, i, j) {
            Some((lo, hi)) => {
                lowest = lowest.min(lo);
                hi
            }
            None => f32::NEG_INFINITY,
        });
        if max.global() == f32::NEG_INFINITY {
            return Err(TerrainError::NoSurface {
                threshold: f64::from(map.threshold()),
            });
        }
        let min = self.min.as_ref().map(|m| {
            let mut m = m.clone();
            m.update_min(cells, |i, j| {
                cell_bounds(&map, interpolation, i, j).map_or(f32::NEG_INFINITY, |(lo, _)| lo)
            });
            m
        });
        // The base: `min(0, lowest bound)`. When it was 0 every cell outside `cells` (unchanged)
        // was at or above 0, so the changed cells decide; otherwise the lowest may have moved
        // out of them: scan every cell, as a build does.
        let lowest = if self.bottom == 0.0 {
            lowest
        } else {
            let mut all = f32::INFINITY;
            for j in 0..ch {
                for i in 0..cw {
                    if let Some((lo, _)) = cell_bounds(&map, interpolation, i, j) {
                        all = all.min(lo);
                    }
                }
            }
            all
        };
        Ok(Self {
            bottom: f64::from(lowest).min(0.0),
            top: f64::from(max.global()),
            map,
            placement: self.placement,
            options: self.options,
            max,
            min,
        })
    }

    /// The bytes this terrain's heights and pyramid(s) hold (what a copy with new heights
    /// allocates).
    pub fn heap_bytes(&self) -> u64 {
        let pyramids = self.max.values().len() + self.min.as_ref().map_or(0, |m| m.values().len());
        4 * (self.map.samples().len() + pyramids) as u64
    }

    pub fn map(&self) -> &Heightmap {
        &self.map
    }

    pub fn placement(&self) -> &Placement {
        &self.placement
    }

    pub fn options(&self) -> &TerrainOptions {
        &self.options
    }

    pub fn max_pyramid(&self) -> &Pyramid {
        &self.max
    }

    pub fn min_pyramid(&self) -> Option<&Pyramid> {
        self.min.as_ref()
    }

    /// The raw-height range `[bottom, top]` of the solid.
    pub fn height_range(&self) -> (f64, f64) {
        (self.bottom, self.top)
    }

    /// The box of the solid in map space `(u, v, r)`.
    pub fn map_box(&self) -> (DVec3, DVec3) {
        let (cw, ch) = self.map.cells();
        (
            DVec3::new(0.0, 0.0, self.bottom),
            DVec3::new(cw as f64, ch as f64, self.top),
        )
    }

    /// The world box around the solid (its eight map-box corners, placed).
    pub fn bounds(&self) -> Aabb {
        let (lo, hi) = self.map_box();
        let mut b = Aabb::EMPTY;
        for k in 0..8 {
            let c = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let p = self.placement.to_world(c);
            b = b.union(&Aabb::new(p, p));
        }
        b
    }
}
