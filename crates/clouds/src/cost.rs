//! What a cloud costs before it runs, and its caps: the density samples one view ray's march may
//! take (view steps across the region's diagonal, each sample with a sun ray) and the work of a
//! bake (cells × what one cell's density costs). Both are known from the description alone, so
//! a scene is refused at load, naming the cost and the cap, instead of running for hours.

use crate::bake::Region;
use crate::march::MarchSettings;
use crate::{CloudField, CloudsError};

/// The most density samples one view ray's march may take: its view steps (the region's
/// diagonal over the step) times one plus the sun steps of each. 9× the largest data scene's
/// (`clouds_ct_skull.ron`: 285 steps × 25 = 7 125). Measured (`fray render`, 640 × 480, 2
/// cores shared with other work): a unit box of noise seen whole from 3 units away renders in
/// 35–37 s at a step of 1.86e-4 (9 312 steps × 7 = 65 184 samples, just under the cap), 0.9 s at
/// the step of 0.01; its step of 1e-7 (17 M steps per ray) did not end.
pub const MAX_RAY_SAMPLES: u64 = 1 << 16;

/// The most work a bake may do, in units of one Perlin octave at one cell (see
/// [`CloudField::cell_cost`]): `2³⁰`, a 512³ grid of 7 octaves. Measured (`fray check`, 2 cores
/// shared with other work): that grid baked in 55 s, a 384³ one of 5 octaves with Worley
/// billows (0.95 of the cap) in 38 s. 34× the largest data scene's bake (`clouds_envelope.ron`:
/// 128 × 96 × 128 cells of 20 units); every 1024³ grid is past it.
pub const MAX_BAKE_WORK: u64 = 1 << 30;

/// What one Worley octave costs against one Perlin octave (F1 visits 27 cells' feature
/// points): measured 2.6–6× on 80³–96³ bakes (`examples/bake_cost.rs` in fray-scene; the spread
/// is the shared machine's). At 4, a Worley bake at 0.95 of [`MAX_BAKE_WORK`] took 38 s where a
/// Perlin one at the cap took 55 s.
pub const WORLEY_OCTAVE_COST: u64 = 4;

impl CloudField {
    /// The work per cell of a bake: one for the cell itself (its centre, the profile, the
    /// store), one per Perlin octave, [`WORLEY_OCTAVE_COST`] per Worley octave where billows are
    /// mixed in.
    pub fn cell_cost(&self) -> u64 {
        let worley = if self.worley > 0.0 {
            u64::from(self.noise.octaves.min(3)) * WORLEY_OCTAVE_COST
        } else {
            0
        };
        1 + u64::from(self.noise.octaves) + worley
    }
}

/// A bake's work: `cells × (field's cell cost + envelope_cost)`, refused past
/// [`MAX_BAKE_WORK`]. `envelope_cost` is what one depth query of the envelope costs in the same
/// units (0 for none).
pub fn check_bake(
    field: &CloudField,
    envelope_cost: u64,
    size: [usize; 3],
) -> Result<u64, CloudsError> {
    let [x, y, z] = size.map(|n| n as u64);
    let per_cell = field.cell_cost().saturating_add(envelope_cost);
    let work = x
        .checked_mul(y)
        .and_then(|n| n.checked_mul(z))
        .and_then(|n| n.checked_mul(per_cell));
    match work {
        Some(w) if w <= MAX_BAKE_WORK => Ok(w),
        _ => Err(CloudsError::BakeWork {
            size: [x, y, z],
            per_cell,
            work: (x as f64) * (y as f64) * (z as f64) * per_cell as f64,
            limit: MAX_BAKE_WORK,
        }),
    }
}

impl Region {
    /// The length of the box's diagonal (without overflow for huge boxes; ∞ for an infinite
    /// one).
    pub fn diagonal(&self) -> f64 {
        let e: [f64; 3] = std::array::from_fn(|a| self.max[a] - self.min[a]);
        e[0].hypot(e[1]).hypot(e[2])
    }
}

/// What a march across a region costs per view ray, at most.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MarchCost {
    /// View steps across the region's diagonal.
    pub view_steps: u64,
    /// Density samples: view steps × (1 + sun steps).
    pub samples: u64,
}

impl MarchSettings {
    /// The most a view ray's march through `region` costs with these settings (the clipped part
    /// of a ray is never longer than the diagonal), refused past [`MAX_RAY_SAMPLES`] — as is a
    /// step that is not a finite number > 0.
    pub fn cost(&self, region: &Region) -> Result<MarchCost, CloudsError> {
        let diagonal = region.diagonal();
        let view_steps = (diagonal / self.step).ceil().max(1.0);
        let samples = view_steps * (1.0 + f64::from(self.sun_steps));
        // Written so that a NaN step or diagonal is refused too.
        let within = self.step > 0.0 && samples <= MAX_RAY_SAMPLES as f64;
        if !within {
            return Err(CloudsError::MarchSamples {
                diagonal,
                step: self.step,
                view_steps,
                sun_steps: self.sun_steps,
                samples,
                limit: MAX_RAY_SAMPLES,
            });
        }
        Ok(MarchCost {
            view_steps: view_steps as u64,
            samples: samples as u64,
        })
    }
}

/// A count for a message: whole below 10¹⁵, else in scientific notation (`1e300` steps).
pub(crate) fn count(n: f64) -> String {
    if n.is_finite() && n.abs() < 1e15 {
        format!("{n:.0}")
    } else {
        format!("{n:.3e}")
    }
}

/// A length for a message: as written between 1e-4 and 10¹⁵, else in scientific notation.
pub(crate) fn length(x: f64) -> String {
    if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_lengths_read_plain_or_scientific() {
        assert_eq!(count(65536.0), "65536");
        assert_eq!(count(1.5e300), "1.500e300");
        assert_eq!(count(f64::INFINITY), "inf");
        assert_eq!(length(1.5), "1.5");
        assert_eq!(length(1e-7), "1.000e-7");
        assert_eq!(length(3.464_101_615e300), "3.464e300");
    }
}
