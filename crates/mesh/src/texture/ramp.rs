//! Colour ramps for terrain: piecewise-linear colour by height and by slope, and the drape —
//! an image laid over the height map, read at the terrain's map coordinates.
//!
//! A [`Ramp`] maps a number to an RGBA colour through sorted stops, linear between them and
//! constant past the ends; two stops at the same key make a step. A [`TerrainRamp`] colours by
//! height, then lays the slope ramp's colour over it by its alpha (coverage): e.g. rock from 30°
//! to 45° with alpha 0 → 1.
//!
//! **The drape.** An image draped over a height map of `columns × rows` samples is just a
//! [`Texture`](super::Texture) looked up at [`Drape::uv`] with [`Wrap::CLAMP`]: the image
//! covers the map's extent with its pixels as areas, as the map's own samples are — sample
//! `(i, j)` (column, row) at the centre of the image's texel `(i, j)` when the image has the
//! map's size, and the same extent `[−½, columns − ½] × [−½, rows − ½]` at any other size.
//! Row 0 of the image lies on row 0 of the map, as both are read from their files, so a height
//! map and its photograph line up without a flip. The footprint: a lookup `L` map units wide is
//! `L · Drape::uv_per_map_unit()` wide in uv (the terrain's placement converts world units to
//! map units).

use super::{TextureError, Wrap};
use glam::{DVec2, DVec3, Vec3, Vec4};

/// Piecewise-linear RGBA stops (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    keys: Vec<f64>,
    colours: Vec<Vec4>,
}

impl Ramp {
    /// A ramp of `(key, colour)` stops: at least one; keys finite and non-decreasing (equal keys
    /// make a step); colours finite.
    pub fn new(stops: Vec<(f64, Vec4)>) -> Result<Self, TextureError> {
        let bad = |message: String| TextureError::Parameter {
            name: "ramp",
            message,
        };
        if stops.is_empty() {
            return Err(bad("needs at least one stop".into()));
        }
        for (i, (k, c)) in stops.iter().enumerate() {
            if !k.is_finite() {
                return Err(bad(format!("stop {i}: the key {k} is not finite")));
            }
            if !c.is_finite() {
                return Err(bad(format!("stop {i}: the colour {c} is not finite")));
            }
            if i > 0 && *k < stops[i - 1].0 {
                return Err(bad(format!(
                    "stop {i}: the key {k} is below stop {}'s {} (stops must be sorted)",
                    i - 1,
                    stops[i - 1].0
                )));
            }
        }
        let (keys, colours) = stops.into_iter().unzip();
        Ok(Self { keys, colours })
    }

    /// The stops, in order.
    pub fn stops(&self) -> impl Iterator<Item = (f64, Vec4)> + '_ {
        self.keys.iter().copied().zip(self.colours.iter().copied())
    }

    /// The colour at `x`: linear between the stops around it, the end stops' colours past the
    /// ends; at a step the later stop's colour; NaN reads the first stop.
    pub fn at(&self, x: f64) -> Vec4 {
        // The first stop with a key above x.
        let k = self.keys.partition_point(|&key| key <= x);
        if k == 0 {
            return self.colours[0];
        }
        if k == self.keys.len() {
            return self.colours[k - 1];
        }
        let (a, b) = (self.keys[k - 1], self.keys[k]);
        let f = ((x - a) / (b - a)) as f32;
        self.colours[k - 1].lerp(self.colours[k], f)
    }
}

/// Terrain colour by height and slope (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainRamp {
    /// Colour by height (world units, or whatever the caller passes).
    pub height: Ramp,
    /// Colour by slope in radians (0 flat, π/2 vertical), laid over the height colour by its
    /// alpha; none: the height colour alone.
    pub slope: Option<Ramp>,
}

impl TerrainRamp {
    /// The slope of a surface with `normal` under `up` (+y in world space): the angle between
    /// them in `[0, π]` (a zero or non-finite normal reads 0).
    pub fn slope_of(normal: DVec3, up: DVec3) -> f64 {
        let a = normal.cross(up).length().atan2(normal.dot(up));
        if a.is_finite() { a } else { 0.0 }
    }

    /// The linear RGB colour at `height` on a surface with `normal` (Y up): the height colour,
    /// then the slope ramp's over it by its alpha (clamped to `[0, 1]`).
    pub fn colour(&self, height: f64, normal: DVec3) -> Vec3 {
        let base = self.height.at(height).truncate();
        match &self.slope {
            None => base,
            Some(s) => {
                let c = s.at(Self::slope_of(normal, DVec3::Y));
                base.lerp(c.truncate(), c.w.clamp(0.0, 1.0))
            }
        }
    }
}

/// An image draped over a `columns × rows` height map (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Drape {
    columns: u32,
    rows: u32,
}

impl Drape {
    /// The wrap a drape is read with: clamp (the image ends where the map does).
    pub const WRAP: Wrap = Wrap::CLAMP;

    /// A drape over a map of `columns × rows` samples (both ≥ 1).
    pub fn new(columns: u32, rows: u32) -> Result<Self, TextureError> {
        if columns == 0 || rows == 0 {
            return Err(TextureError::Parameter {
                name: "drape",
                message: format!("a height map of {columns} × {rows} samples has none"),
            });
        }
        Ok(Self { columns, rows })
    }

    /// The uv of map point `(u, v)` = (column, row): `((u + ½)/columns, 1 − (v + ½)/rows)`.
    pub fn uv(&self, map_u: f64, map_v: f64) -> DVec2 {
        DVec2::new(
            (map_u + 0.5) / f64::from(self.columns),
            1.0 - (map_v + 0.5) / f64::from(self.rows),
        )
    }

    /// The uv per map unit along the map's shorter side (the larger of the two axes' scales).
    pub fn uv_per_map_unit(&self) -> f64 {
        1.0 / f64::from(self.columns.min(self.rows))
    }
}
