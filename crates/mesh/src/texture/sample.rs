//! Lookups: nearest and bilinear at one level, trilinear between two, and the level of detail
//! from a footprint — `level = log₂(footprint in base texels)`, clamped to the chain.
//!
//! Texel coordinates (module [`crate::texture`]): at a level of `w × h` texels, uv `(u, v)` is
//! the point `x = u·w`, `y = (1 − v)·h` of the image (x right, y down from the top edge), and
//! texel `(i, j)` covers `[i, i+1] × [j, j+1]` with its centre at `(i + 0.5, j + 0.5)`.
//! Nearest reads the texel containing the point; bilinear blends the four texels whose centres
//! surround it, the wrap mode of each axis naming the texels past an edge.

use super::{Texture, Wrap};
use glam::{DVec2, Vec4};

/// How a lookup filters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The base level's texel under the point: a point sample (aliases when minified).
    Nearest,
    /// Bilinear at the base level (aliases when minified).
    Bilinear,
    /// Trilinear at the level of the footprint: the anti-aliased lookup.
    #[default]
    Trilinear,
}

/// Weights this close to 0 or 1 are snapped, so a texel centre reads its texel exactly however
/// its uv was rounded (2⁻³⁰ of a texel: far below any visible difference).
const SNAP: f64 = 1.0 / (1u64 << 30) as f64;

#[inline]
fn snap(f: f64) -> f64 {
    if f < SNAP {
        0.0
    } else if f > 1.0 - SNAP {
        1.0
    } else {
        f
    }
}

impl Texture {
    /// The texel of level `level` (clamped to the coarsest) under `uv`.
    pub fn nearest(&self, level: usize, uv: DVec2, wrap: Wrap) -> Vec4 {
        let l = self.level(level);
        let x = wrap.u.reduce(uv.x) * f64::from(l.width);
        let y = (1.0 - wrap.v.reduce(uv.y)) * f64::from(l.height);
        let i = wrap.u.index(x.floor() as i64, l.width);
        let j = wrap.v.index(y.floor() as i64, l.height);
        l.texel(i, j)
    }

    /// The bilinear blend at level `level` (clamped to the coarsest) of the four texels whose
    /// centres surround `uv`; at a texel centre, that texel exactly.
    pub fn bilinear(&self, level: usize, uv: DVec2, wrap: Wrap) -> Vec4 {
        let l = self.level(level);
        let x = wrap.u.reduce(uv.x) * f64::from(l.width) - 0.5;
        let y = (1.0 - wrap.v.reduce(uv.y)) * f64::from(l.height) - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (snap(x - x0), snap(y - y0));
        let (x0, y0) = (x0 as i64, y0 as i64);
        let (i0, i1) = (wrap.u.index(x0, l.width), wrap.u.index(x0 + 1, l.width));
        let (j0, j1) = (wrap.v.index(y0, l.height), wrap.v.index(y0 + 1, l.height));
        let mut sum = Vec4::ZERO;
        for (j, wy) in [(j0, 1.0 - fy), (j1, fy)] {
            for (i, wx) in [(i0, 1.0 - fx), (i1, fx)] {
                let w = wx * wy;
                if w > 0.0 {
                    sum += l.texel(i, j) * w as f32;
                }
            }
        }
        sum
    }

    /// Trilinear: the bilinear lookups at the two levels around `level_of_detail` (clamped to
    /// `[0, levels − 1]`; NaN reads the base), blended linearly.
    pub fn trilinear(&self, uv: DVec2, level_of_detail: f64, wrap: Wrap) -> Vec4 {
        let top = (self.levels.len() - 1) as f64;
        let lod = if level_of_detail.is_nan() {
            0.0
        } else {
            level_of_detail.clamp(0.0, top)
        };
        let k = lod.floor();
        let f = (lod - k) as f32;
        let k = k as usize;
        let a = self.bilinear(k, uv, wrap);
        if f == 0.0 {
            a
        } else {
            a.lerp(self.bilinear(k + 1, uv, wrap), f)
        }
    }

    /// The level for a footprint `footprint_texels` base texels wide: `log₂` of it, clamped to
    /// `[0, levels − 1]` (a footprint of at most one texel, or NaN, reads the base; an infinite
    /// one the 1 × 1 level).
    pub fn level_of_detail(&self, footprint_texels: f64) -> f64 {
        let top = (self.levels.len() - 1) as f64;
        if footprint_texels > 1.0 {
            footprint_texels.log2().min(top)
        } else {
            0.0
        }
    }

    /// Base texels per unit of uv along the texture's longer side: a uv width times this is the
    /// footprint in texels (the longer side errs toward blur on a non-square texture).
    pub fn texels_per_uv(&self) -> f64 {
        f64::from(self.width().max(self.height()))
    }

    /// The anti-aliased lookup: trilinear at the level of a footprint `uv_width` wide in uv
    /// units (from [`crate::texture::Footprint::uv_width`]).
    pub fn sample(&self, uv: DVec2, uv_width: f64, wrap: Wrap) -> Vec4 {
        self.filtered(uv, uv_width, wrap, Filter::Trilinear)
    }

    /// A lookup by `filter`: nearest or bilinear at the base level (`uv_width` unused), or
    /// trilinear at the footprint's level.
    pub fn filtered(&self, uv: DVec2, uv_width: f64, wrap: Wrap, filter: Filter) -> Vec4 {
        match filter {
            Filter::Nearest => self.nearest(0, uv, wrap),
            Filter::Bilinear => self.bilinear(0, uv, wrap),
            Filter::Trilinear => self.trilinear(
                uv,
                self.level_of_detail(uv_width * self.texels_per_uv()),
                wrap,
            ),
        }
    }
}
