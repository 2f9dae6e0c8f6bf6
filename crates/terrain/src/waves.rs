//! Waves on a terrain: heights that change with time, a sum of travelling sine waves added to a
//! rectangle of the map (or raising it to a wavy water level) — the procedural displacement of an
//! animated terrain.

use crate::{Heightmap, Placement, Region, TerrainError};
use glam::DVec2;

/// One travelling wave, in world units: `amplitude · sin(2π/wavelength · (direction · p −
/// speed · t))`, `p` a sample's world offset `(column · spacing.x, row · spacing.y)` from the
/// map's origin along its axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wave {
    pub amplitude: f64,
    /// `> 0`.
    pub wavelength: f64,
    /// A unit vector along the map's columns (`x`) and rows (`y`).
    pub direction: DVec2,
    /// Along `direction`, world units per second (negative runs backwards).
    pub speed: f64,
}

/// A sum of waves over a region of a height map.
#[derive(Clone, Debug, PartialEq)]
pub struct Waves {
    pub waves: Vec<Wave>,
    /// `Some(level)`: the water's mean height (world units above the base plane): a sample of
    /// the region becomes `max(ground, level + Σ waves)` — a lake whose shore is where the
    /// ground rises out of it. `None`: the waves are added to the ground.
    pub level: Option<f64>,
    /// The samples that move (clamped to the map); `None`: all of them.
    pub region: Option<Region>,
}

impl Waves {
    /// The displacement (world units) at world offset `p` and time `t`.
    pub fn displacement(&self, p: DVec2, t: f64) -> f64 {
        self.waves
            .iter()
            .map(|w| {
                let k = std::f64::consts::TAU / w.wavelength;
                w.amplitude * (k * (w.direction.dot(p) - w.speed * t)).sin()
            })
            .sum()
    }

    /// The samples that move on a `width × height` map.
    pub fn region(&self, width: usize, height: usize) -> Region {
        self.region
            .unwrap_or(Region::all(width, height))
            .clamped(width, height)
    }

    /// The heights of `base` (placed by `placement`) at time `t`: a copy with the region
    /// displaced (`4 · width · height` bytes: the caller charges them first). The changed
    /// samples are [`Waves::region`]. Non-finite results (a zero wavelength, an infinite
    /// amplitude) are refused ([`TerrainError::NonFinite`]).
    pub fn heights_at(
        &self,
        base: &Heightmap,
        placement: &Placement,
        t: f64,
    ) -> Result<Heightmap, TerrainError> {
        let spacing = placement.spacing();
        let scale = placement.vertical_scale();
        let region = self.region(base.width(), base.height());
        base.with_region(region, |i, j, ground| {
            let p = DVec2::new(i as f64 * spacing.x, j as f64 * spacing.y);
            let d = self.displacement(p, t);
            let ground = f64::from(ground);
            let h = match self.level {
                Some(level) => ground.max((level + d) / scale),
                None => ground + d / scale,
            };
            h as f32
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn waves_move_only_their_region_and_travel_at_their_speed() {
        let base = Heightmap::from_fn(8, 6, |i, j| (i + j) as f32).unwrap();
        let placement = Placement::new(DVec3::ZERO, DVec2::new(2.0, 1.0), 0.5).unwrap();
        let waves = Waves {
            waves: vec![Wave {
                amplitude: 1.0,
                wavelength: 8.0,
                direction: DVec2::X,
                speed: 4.0,
            }],
            level: None,
            region: Some(Region::new(2, 1, 6, 4)),
        };
        let at = |t| waves.heights_at(&base, &placement, t).unwrap();
        let (a, b) = (at(0.0), at(0.5));
        for j in 0..6 {
            for i in 0..8 {
                let inside = (2..6).contains(&i) && (1..4).contains(&j);
                // Outside the region nothing moves; inside, world x = 2i and amplitude 1 world
                // unit = 2 raw units; half a second later the crest has moved 2 m = one column.
                let expect = |t: f64| {
                    let phase = std::f64::consts::TAU / 8.0 * (2.0 * i as f64 - 4.0 * t);
                    ((i + j) as f64 + 2.0 * phase.sin()) as f32
                };
                let (ea, eb) = if inside {
                    (expect(0.0), expect(0.5))
                } else {
                    ((i + j) as f32, (i + j) as f32)
                };
                assert_eq!((a.at(i, j), b.at(i, j)), (ea, eb), "({i}, {j})");
            }
        }
        let lake = Waves {
            level: Some(3.0),
            ..waves.clone()
        };
        let h = lake.heights_at(&base, &placement, 0.0).unwrap();
        // Ground 2 raw = 1 m is under the water (level 3 m = 6 raw, crest at x = 4 m: +2 raw).
        assert_eq!(h.at(2, 0), 2.0);
        assert_eq!(
            h.at(2, 1),
            (6.0 + 2.0 * (std::f64::consts::TAU / 8.0 * 4.0).sin()) as f32
        );
        let bad = Waves {
            waves: vec![Wave {
                wavelength: 0.0,
                ..waves.waves[0]
            }],
            ..waves
        };
        assert!(matches!(
            bad.heights_at(&base, &placement, 0.3),
            Err(TerrainError::NonFinite { .. })
        ));
    }
}
