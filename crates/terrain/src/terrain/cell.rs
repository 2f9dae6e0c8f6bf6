//! The intersection of a ray with the finest cells: the exact bilinear quadratic, the bicubic
//! halving (its root finders are in `roots`), and the entry, wall and start hits.

use super::roots::{bicubic_root, first_root};
use super::{HitKind, Terrain, TerrainHit, TerrainStats};
use crate::MapRay;
use crate::clip::{Clip, clip_within};
use crate::interpolation::{BicubicCell, BilinearCell, Interpolation};
use fray_core::Ray;
use glam::{DVec2, DVec3};

impl Terrain {
    /// The nearest hit over the finest cells `a0..=a1 × b0..=b1` within `[ta, tb]`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn finest_hit(
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
}
