//! The references the pyramid search is checked and measured against: the brute-force exact
//! hit over every solid cell and a fixed-step ray march.

use super::{Terrain, TerrainHit};
use crate::TerrainError;
use crate::clip::clip_box;
use fray_core::{Interval, Ray};

/// The most steps [`Terrain::march`] takes along one ray: 11× the finest march the benches
/// time (0.03 cells) across the largest map ([`crate::MAX_SIDE`]² cells, a diagonal of 46 341
/// cells: 1.5 M steps); past it a march is a mistake in its step, not a baseline.
pub const MAX_MARCH_STEPS: u64 = 1 << 24;

impl Terrain {
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

    /// A plain fixed-step ray march (the baseline the pyramid is measured against): samples
    /// every `step` world units from the box entry and returns the first sample under the
    /// surface, refined by one secant step between it and the sample before. A march of more
    /// than [`MAX_MARCH_STEPS`] steps over the ray's part in the box is refused
    /// ([`TerrainError::MarchSteps`]); `Ok(None)` for a miss or a step that is not > 0.
    pub fn march(
        &self,
        ray: &Ray,
        range: Interval,
        step: f64,
    ) -> Result<Option<f64>, TerrainError> {
        let m = self.placement.map_ray(ray);
        let (lo, hi) = self.map_box();
        let Some(clip) = clip_box(&m, lo, hi, range.lo, range.hi) else {
            return Ok(None);
        };
        if step.is_nan() || step <= 0.0 {
            return Ok(None);
        }
        let length = clip.t1 - clip.t0;
        let steps = (length / step).ceil();
        // An infinite or NaN length is refused too.
        if steps.is_nan() || steps > MAX_MARCH_STEPS as f64 {
            return Err(TerrainError::MarchSteps {
                length,
                step,
                steps,
            });
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
                    return Ok(Some(match prev {
                        Some((tp, fp)) if fp > 0.0 => tp + (t - tp) * fp / (fp - f),
                        _ => t,
                    }));
                }
                prev = Some((t, f));
            } else {
                prev = None;
            }
            if t >= clip.t1 {
                return Ok(None);
            }
            k += 1;
        }
    }
}
