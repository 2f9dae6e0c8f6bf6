//! The terrain: a height map placed in the world with its max pyramid, and its ray casting by
//! halving the ray segment in height-map space (DESIGN.md §4).
//!
//! The solid is `{ bottom ≤ r ≤ S(u, v) }` over the solid cells, `S` the interpolated surface
//! and `bottom = min(0, lowest surface bound)`: the base plane `r = 0` (or the lowest point if
//! the map goes below it) closes it, so a ray that enters through a threshold outline, the map
//! border or from below hits a vertical wall or the base, and a ray that starts inside the solid
//! hits at its start (like free forms: `F ≥ 0` is inside).
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

use crate::clip::{Clip, clip_box, clip_within};
use crate::interpolation::{BicubicCell, BilinearCell, Interpolation};
use crate::{Heightmap, MapRay, Placement, Pyramid, TerrainError};
use fray_core::{Aabb, Interval, MemoryBudget, PixelFootprint, Ray};
use glam::{DVec2, DVec3};

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

/// The coarsest level a pixel-footprint search stops at (clamped to the pyramid's depth): 8 × 8
/// max columns over the whole map. A pixel wider than that sees the map as a few blocks anyway,
/// and the quadtree's cell test ([`Terrain::coarsest_stop_level`]) relies on the bound.
pub const PIXEL_LOD_COARSEST_LEVEL: u32 = 3;

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

const STACK: usize = 96;

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
        let mut hi = vec![f32::NEG_INFINITY; cw * ch];
        let mut lo = if options.min_pyramid {
            vec![f32::NEG_INFINITY; cw * ch]
        } else {
            Vec::new()
        };
        let mut lowest = f32::INFINITY;
        for j in 0..ch {
            for i in 0..cw {
                if !map.cell_is_solid(i, j) {
                    continue;
                }
                let (a, b) = match options.interpolation {
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
                        let p = BicubicCell::control_points(&map, i, j);
                        let flat = p.iter().flatten().copied();
                        (
                            flat.clone().fold(f32::INFINITY, f32::min),
                            flat.fold(f32::NEG_INFINITY, f32::max),
                        )
                    }
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

    /// The nearest hit over the finest cells `a0..=a1 × b0..=b1` within `[ta, tb]`.
    #[allow(clippy::too_many_arguments)]
    fn finest_hit(
        &self,
        m: &MapRay,
        ray: &Ray,
        clip: &Clip,
        seg: (f64, f64),
        (a0, a1, b0, b1): (usize, usize, usize, usize),
        r_min: f64,
        eps: f64,
        stats: &mut TerrainStats,
    ) -> Option<TerrainHit> {
        let finest = self.max.level(self.max.levels());
        let mut best: Option<TerrainHit> = None;
        for b in b0..=b1 {
            for a in a0..=a1 {
                if r_min > f64::from(finest.at(a, b)) {
                    continue; // also skips padded and cut-out cells (−∞)
                }
                stats.cells += 1;
                let seg = (seg.0, best.map_or(seg.1, |h| h.t));
                if let Some(h) = self.cell_hit(m, ray, clip, a, b, seg, eps) {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The first hit on solid cell `(i, j)` within `seg`, parametrised from the cell's own entry
    /// into the whole clipped range `clip`, so the same cell gives the same numbers whatever the
    /// segment (the brute-force reference uses this function too).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn cell_hit(
        &self,
        m: &MapRay,
        ray: &Ray,
        clip: &Clip,
        i: usize,
        j: usize,
        seg: (f64, f64),
        eps: f64,
    ) -> Option<TerrainHit> {
        let cmin = DVec3::new(i as f64, j as f64, self.bottom);
        let cmax = DVec3::new(i as f64 + 1.0, j as f64 + 1.0, self.top);
        let c = clip_within(m, cmin, cmax, clip)?;
        let (lo, hi) = (c.t0.max(seg.0), c.t1.min(seg.1));
        if lo > hi {
            return None;
        }
        let start = m.at(c.t0);
        let (s0, w0, r0) = (start.x - i as f64, start.y - j as f64, start.z);
        let (ds, dw, dr) = (m.dir.x, m.dir.y, m.dir.z);
        let (tau_lo, tau_hi) = (lo - c.t0, hi - c.t0);
        let (tau, slope) = match self.options.interpolation {
            Interpolation::Bilinear => {
                let p = BilinearCell::new(&self.map, i, j);
                let qa = -p.k * ds * dw;
                let qb = dr - (p.a * ds + p.b * dw + p.k * (s0 * dw + w0 * ds));
                let qc = r0 - p.eval(s0, w0);
                let f_lo = (qa * tau_lo + qb) * tau_lo + qc;
                if f_lo <= 0.0 {
                    return Some(self.entry_hit(m, ray, &c, lo, i, j, |s, w| p.slope(s, w)));
                }
                let tau = first_root(qa, qb, qc, tau_lo, tau_hi)?;
                let (s, w) = (
                    (s0 + tau * ds).clamp(0.0, 1.0),
                    (w0 + tau * dw).clamp(0.0, 1.0),
                );
                (tau, p.slope(s, w))
            }
            Interpolation::Bicubic => {
                let p = BicubicCell::new(&self.map, i, j);
                let f = |tau: f64| {
                    let (s, w) = (s0 + tau * ds, w0 + tau * dw);
                    let (v, g) = p.eval_with_slope(s, w);
                    (r0 + tau * dr - v, dr - (g.x * ds + g.y * dw), g)
                };
                let f_lo = f(tau_lo).0;
                if f_lo <= 0.0 {
                    return Some(
                        self.entry_hit(m, ray, &c, lo, i, j, |s, w| p.eval_with_slope(s, w).1),
                    );
                }
                let k1 = dr.abs() + p.d1.x * ds.abs() + p.d1.y * dw.abs();
                let k2 = p.d2[0] * ds * ds + 2.0 * p.d2[1] * (ds * dw).abs() + p.d2[2] * dw * dw;
                let tau = bicubic_root(&f, k1, k2, tau_lo, tau_hi, f_lo, eps)?;
                (tau, f(tau).2)
            }
        };
        Some(TerrainHit {
            t: c.t0 + tau,
            normal: self.placement.surface_normal(slope),
            cell: [i as u32, j as u32],
            kind: HitKind::Surface,
            levels_above_finest: 0,
        })
    }

    /// A hit where the ray is already inside the cell's solid at `t` (the start of the part of
    /// the cell examined): a wall or the base when the ray entered the cell there from outside
    /// the solid, the ray's start when it starts inside, else (rounding at a shared edge with
    /// a solid neighbour, or a segment start) the surface.
    #[allow(clippy::too_many_arguments)]
    fn entry_hit(
        &self,
        m: &MapRay,
        ray: &Ray,
        c: &Clip,
        t: f64,
        i: usize,
        j: usize,
        slope: impl Fn(f64, f64) -> DVec2,
    ) -> TerrainHit {
        let cell = [i as u32, j as u32];
        let surface = |this: &Self| {
            let p = m.at(t);
            let (s, w) = (
                (p.x - i as f64).clamp(0.0, 1.0),
                (p.y - j as f64).clamp(0.0, 1.0),
            );
            TerrainHit {
                t,
                normal: this.placement.surface_normal(slope(s, w)),
                cell,
                kind: HitKind::Surface,
                levels_above_finest: 0,
            }
        };
        if t != c.t0 {
            return surface(self);
        }
        match c.entry {
            None => TerrainHit {
                t,
                normal: -ray.dir,
                cell,
                kind: HitKind::Start,
                levels_above_finest: 0,
            },
            Some((2, sign)) if sign > 0.0 => surface(self),
            Some((axis, sign)) => {
                if axis < 2 && self.neighbour_is_solid(i, j, axis, sign) {
                    return surface(self);
                }
                TerrainHit {
                    t,
                    normal: self.placement.axis_normal(axis, sign),
                    cell,
                    kind: HitKind::Wall,
                    levels_above_finest: 0,
                }
            }
        }
    }

    fn neighbour_is_solid(&self, i: usize, j: usize, axis: usize, sign: f64) -> bool {
        let (cw, ch) = self.map.cells();
        let (di, dj) = match (axis, sign > 0.0) {
            (0, true) => (1, 0),
            (0, false) => (-1, 0),
            (_, true) => (0, 1),
            (_, false) => (0, -1),
        };
        let (x, y) = (i as isize + di, j as isize + dj);
        x >= 0
            && y >= 0
            && (x as usize) < cw
            && (y as usize) < ch
            && self.map.cell_is_solid(x as usize, y as usize)
    }

    /// LOD hit: the entry into the nearest max column `[cell] × [bottom, max]` at `level`.
    #[allow(clippy::too_many_arguments)]
    fn column_hit(
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

    /// The exact first hit by brute force: every solid cell, no pyramid (for tests and error
    /// measurements; cost grows with the map).
    pub fn cast_brute_force(&self, ray: &Ray, range: Interval, eps: f64) -> Option<TerrainHit> {
        let m = self.placement.map_ray(ray);
        let (lo, hi) = self.map_box();
        let clip = clip_box(&m, lo, hi, range.lo, range.hi)?;
        let (cw, ch) = self.map.cells();
        let mut best: Option<TerrainHit> = None;
        for j in 0..ch {
            for i in 0..cw {
                if !self.map.cell_is_solid(i, j) {
                    continue;
                }
                let seg = (clip.t0, best.map_or(clip.t1, |h| h.t));
                if let Some(h) = self.cell_hit(&m, ray, &clip, i, j, seg, eps)
                    && best.is_none_or(|b| h.t < b.t)
                {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The world unit normal of the interpolated surface under the world point `p` (the
    /// analytic normal at its map position `(u, v)`, the height ignored); `None` off the map or
    /// on a cut-out cell. (Renderers shade LOD hits with [`Terrain::shading_normal`], which
    /// picks the cell inside a column's wall.)
    pub fn surface_normal_at(&self, p: DVec3) -> Option<DVec3> {
        let q = self.placement.to_map(p);
        let (i, j, s, w) = self.solid_cell_at(q.x, q.y)?;
        let slope = match self.options.interpolation {
            Interpolation::Bilinear => BilinearCell::new(&self.map, i, j).slope(s, w),
            Interpolation::Bicubic => BicubicCell::new(&self.map, i, j).eval_with_slope(s, w).1,
        };
        Some(self.placement.surface_normal(slope))
    }

    /// The normal to shade a hit of `ray` at `t` with, given its level above the finest and its
    /// normal ([`TerrainHit::levels_above_finest`], [`TerrainHit::normal`]): its own normal on
    /// the exact surface; a LOD hit (on a flat max-column face) is shaded with the interpolant's
    /// normal beneath it, so relief shading survives a coarse level. The cell beneath is the
    /// finest cell under the hit point, except on a column's side wall (a normal along the map's
    /// `u` or `v` axis): the wall lies on a cell line, where the point alone (and its rounding)
    /// would pick either neighbour, so the cell is the one **inside** the wall, opposite its
    /// outward normal. Falls back to `normal` where that cell is cut out.
    pub fn shading_normal(
        &self,
        ray: &Ray,
        t: f64,
        levels_above_finest: u32,
        normal: DVec3,
    ) -> DVec3 {
        if levels_above_finest == 0 {
            return normal;
        }
        let (cw, ch) = self.map.cells();
        let q = self.placement.map_ray(ray).at(t);
        // The face: rotation⁻¹ · normal in the map's frame (x = u, z = v).
        let local = self.placement.rotation().transpose() * normal;
        let cell = |x: f64, cells: usize| {
            if x.is_nan() {
                return 0;
            }
            (x.floor().max(0.0) as usize).min(cells - 1)
        };
        let inside = |x: f64, outward: f64, cells: usize| {
            // The wall's line, and the cell on the side opposite the outward normal.
            let line = x.round().max(0.0) as usize;
            let i = if outward < 0.0 {
                line
            } else {
                line.saturating_sub(1)
            };
            i.min(cells - 1)
        };
        let (i, j) = if local.x.abs() > 0.5 {
            (inside(q.x, local.x, cw), cell(q.y, ch))
        } else if local.z.abs() > 0.5 {
            (cell(q.x, cw), inside(q.y, local.z, ch))
        } else {
            (cell(q.x, cw), cell(q.y, ch))
        };
        if !self.map.cell_is_solid(i, j) {
            return normal;
        }
        let (s, w) = (
            (q.x - i as f64).clamp(0.0, 1.0),
            (q.y - j as f64).clamp(0.0, 1.0),
        );
        let slope = match self.options.interpolation {
            Interpolation::Bilinear => BilinearCell::new(&self.map, i, j).slope(s, w),
            Interpolation::Bicubic => BicubicCell::new(&self.map, i, j).eval_with_slope(s, w).1,
        };
        self.placement.surface_normal(slope)
    }

    /// The solid cell `(i, j)` holding map point `(u, v)` (the far edges belong to the last
    /// cell) and the point's position `(s, w)` in it; `None` off the map or on a cut-out cell.
    fn solid_cell_at(&self, u: f64, v: f64) -> Option<(usize, usize, f64, f64)> {
        let (cw, ch) = self.map.cells();
        if !(u >= 0.0 && v >= 0.0 && u <= cw as f64 && v <= ch as f64) {
            return None;
        }
        let (i, j) = (
            (u.floor() as usize).min(cw - 1),
            (v.floor() as usize).min(ch - 1),
        );
        self.map
            .cell_is_solid(i, j)
            .then_some((i, j, u - i as f64, v - j as f64))
    }

    /// The interpolated surface height (raw units) at map point `(u, v)`; `None` off the map or
    /// on a cut-out cell.
    pub fn surface(&self, u: f64, v: f64) -> Option<f64> {
        let (i, j, s, w) = self.solid_cell_at(u, v)?;
        Some(match self.options.interpolation {
            Interpolation::Bilinear => BilinearCell::new(&self.map, i, j).eval(s, w),
            Interpolation::Bicubic => BicubicCell::new(&self.map, i, j).eval_with_slope(s, w).0,
        })
    }

    /// A plain fixed-step ray march (the baseline the pyramid is measured against): samples
    /// every `step` world units from the box entry and returns the first sample under the
    /// surface, refined by one secant step between it and the sample before.
    pub fn march(&self, ray: &Ray, range: Interval, step: f64) -> Option<f64> {
        let m = self.placement.map_ray(ray);
        let (lo, hi) = self.map_box();
        let clip = clip_box(&m, lo, hi, range.lo, range.hi)?;
        if step.is_nan() || step <= 0.0 {
            return None;
        }
        let below = |t: f64| {
            let p = m.at(t);
            self.surface(p.x, p.y).map(|s| p.z - s)
        };
        let mut prev: Option<(f64, f64)> = None;
        let mut k = 0u64;
        loop {
            let t = (clip.t0 + k as f64 * step).min(clip.t1);
            if let Some(f) = below(t) {
                if f <= 0.0 {
                    return Some(match prev {
                        Some((tp, fp)) if fp > 0.0 => tp + (t - tp) * fp / (fp - f),
                        _ => t,
                    });
                }
                prev = Some((t, f));
            } else {
                prev = None;
            }
            if t >= clip.t1 {
                return None;
            }
            k += 1;
        }
    }
}

/// A bound on the absolute rounding error of `o + t·d` per map axis over the clipped range.
fn rounding(m: &MapRay, clip: &Clip) -> DVec3 {
    let t = clip.t0.abs().max(clip.t1.abs());
    (m.origin.abs() + m.dir.abs() * t) * (4.0 * f64::EPSILON) + DVec3::splat(f64::MIN_POSITIVE)
}

/// A segment's map-space footprint, widened by the rounding bound.
struct Footprint {
    u: (f64, f64),
    v: (f64, f64),
    r_min: f64,
}

impl Footprint {
    #[inline]
    fn of(pa: DVec3, pb: DVec3, err: DVec3) -> Self {
        Self {
            u: (pa.x.min(pb.x) - err.x, pa.x.max(pb.x) + err.x),
            v: (pa.y.min(pb.y) - err.y, pa.y.max(pb.y) + err.y),
            r_min: pa.z.min(pb.z) - err.z,
        }
    }

    #[inline]
    fn extent(&self) -> f64 {
        (self.u.1 - self.u.0).max(self.v.1 - self.v.0)
    }

    /// The level-`level` cells whose closed squares meet the footprint, clamped to the level's
    /// grid of `dims` cells (levels are rectangular: cells past it cover no part of the map);
    /// `None` if it lies off the grid.
    #[inline]
    fn cells(
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

/// The level-`level` cell holding map point `p` when that is unambiguous under rounding.
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

/// The pyramid level for a footprint of `extent` finest cells: `k` with
/// `2^(n−k−1) < extent ≤ 2^(n−k)` (that is `2^-(k+1) < Lp ≤ 2^-k` for `Lp = extent / 2ⁿ`),
/// clamped to `0..=n`.
#[inline]
fn level_for(extent: f64, n: u32) -> u32 {
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

/// The smallest root of `a τ² + b τ + c` in `[lo, hi]` (the quadratic is `> 0` at `lo`).
#[inline]
fn first_root(a: f64, b: f64, c: f64, lo: f64, hi: f64) -> Option<f64> {
    let in_range = |t: f64| (t >= lo && t <= hi).then_some(t);
    if a == 0.0 {
        return if b < 0.0 { in_range(-c / b) } else { None };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (mut r1, mut r2) = (q / a, if q != 0.0 { c / q } else { q / a });
    if r1 > r2 {
        std::mem::swap(&mut r1, &mut r2);
    }
    in_range(r1).or_else(|| in_range(r2))
}

/// The floor of the bicubic root tolerance, relative to `|lo| + |hi|` of the piece searched:
/// `8 ε_f64 = 2⁻⁴⁹` (the GPU twin uses `8 ε_f32 = 2⁻²⁰`, the same rule in its precision). It
/// bounds the halving's depth: see [`BICUBIC_STACK`].
const BICUBIC_EPS_FLOOR: f64 = 8.0 * f64::EPSILON;

/// Pending pieces of [`bicubic_root`]'s halving, sized by a proof: a piece is split only while
/// wider than `eps ≥ 2⁻⁴⁹ (|lo| + |hi|) ≥ 2⁻⁴⁹ (hi − lo)` (`lo ≥ 0`: pieces start at or after
/// the cell's entry), and a piece at depth `d` is `(hi − lo) / 2ᵈ` wide, so only pieces at
/// depth `d ≤ 48` are split; depth-first, splitting a depth-`d` piece leaves `d + 2` pending.
/// 50 would do; 56 leaves room for the midpoints' rounding. A full stack (reachable only when
/// the tolerance underflows, for pieces within a few subnormals of 0) settles the piece as one
/// narrower than `eps`: the same rule, never a dropped bracket.
const BICUBIC_STACK: usize = 56;

/// Illinois steps at most (it stops at `eps` long before).
const ILLINOIS_STEPS: usize = 100;

/// The first root of `f` (value, derivative, slope) in `[lo, hi]` with `f(lo) = f_lo > 0`:
/// halving nearer-first with tolerance `eps` (raised to [`BICUBIC_EPS_FLOOR`] `· (|lo| + |hi|)`).
/// For each piece `[a, b]` (`f(a) > 0`), `m` its midpoint and `h` half its width:
/// - `f(b) ≤ 0` (a bracket): when monotone (`|f'(m)| > k2 · h`: exactly one root) or no wider
///   than `eps`, Illinois finds the root to `eps`; else the piece is split;
/// - `f(b) > 0`: dropped when `f(m) − k1 · h > 0` (the slope bound keeps `f > 0` on it) or when
///   monotone (no root between two positive ends); a piece no wider than `eps` with `f(m) ≤ 0`
///   brackets a root in `[a, m]` (Illinois); one with `f(m) > 0` is dropped (a graze thinner
///   than `eps`); else split.
fn bicubic_root(
    f: &impl Fn(f64) -> (f64, f64, DVec2),
    k1: f64,
    k2: f64,
    lo: f64,
    hi: f64,
    f_lo: f64,
    eps: f64,
) -> Option<f64> {
    let eps = eps.max(BICUBIC_EPS_FLOOR * (lo.abs() + hi.abs()));
    let mut stack = [(0.0f64, 0.0f64, 0.0f64, 0.0f64); BICUBIC_STACK];
    stack[0] = (lo, hi, f_lo, f(hi).0);
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let (a, b, fa, fb) = stack[len];
        let mid = 0.5 * (a + b);
        let half = 0.5 * (b - a);
        let (fm, dm, _) = f(mid);
        let monotone = dm.abs() > k2 * half;
        // No wider than the tolerance (or, never at a normal tolerance, out of stack).
        let small = b - a <= eps || len + 2 > BICUBIC_STACK;
        if fb <= 0.0 {
            if monotone || small {
                return Some(illinois(f, a, b, fa, fb, eps));
            }
        } else if fm - k1 * half > 0.0 || monotone {
            continue;
        } else if small {
            if fm <= 0.0 {
                return Some(illinois(f, a, mid, fa, fm, eps));
            }
            continue;
        }
        stack[len] = (mid, b, fm, fb);
        stack[len + 1] = (a, mid, fa, fm);
        len += 2;
    }
    None
}

/// Illinois (modified regula falsi) on a bracket `f(a) > 0 ≥ f(b)`, to `|b − a| ≤ eps`.
fn illinois(
    f: &impl Fn(f64) -> (f64, f64, DVec2),
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    eps: f64,
) -> f64 {
    let mut side = 0i8;
    for _ in 0..ILLINOIS_STEPS {
        if b - a <= eps || fb == 0.0 {
            break;
        }
        let mut t = (a * fb - b * fa) / (fb - fa);
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let ft = f(t).0;
        if ft > 0.0 {
            a = t;
            fa = ft;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = t;
            fb = ft;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    b
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

    #[test]
    fn first_root_is_stable_for_tiny_leading_terms() {
        // (τ − 1)(1e-12 τ − 1) > 0 at 0 → first root 1.
        let (a, b, c) = (1e-12, -(1.0 + 1e-12), 1.0);
        let r = first_root(a, b, c, 0.0, 10.0).unwrap();
        assert!((r - 1.0).abs() < 1e-15);
        assert_eq!(first_root(0.0, -2.0, 1.0, 0.0, 1.0), Some(0.5));
        assert_eq!(first_root(1.0, 0.0, 1.0, 0.0, 1.0), None);
    }
}
