//! The interpolated surface at a map point: its height and its normals (the analytic normal
//! and the normal a hit is shaded with).

use super::Terrain;
use crate::interpolation::{BicubicCell, BilinearCell, Interpolation};
use fray_core::Ray;
use glam::DVec3;

impl Terrain {
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
    ///
    /// [`TerrainHit::levels_above_finest`]: super::TerrainHit::levels_above_finest
    /// [`TerrainHit::normal`]: super::TerrainHit::normal
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
}
