//! Conservative ranges of `sin` and `cos` over an interval of angles (for the sphere surface).

use fray_core::Interval;
use std::f64::consts::{PI, TAU};

/// Slack added to both ends: covers the rounding of `sin`/`cos` and of the angle itself.
const SLACK: f64 = 1e-12;

/// A range that contains `cos θ` for every `θ ∈ a`.
pub(crate) fn cos_range(a: Interval) -> Interval {
    if !(a.lo.is_finite() && a.hi.is_finite()) || a.hi - a.lo >= TAU {
        return Interval::new(-1.0, 1.0);
    }
    let (c0, c1) = (a.lo.cos(), a.hi.cos());
    let mut lo = c0.min(c1);
    let mut hi = c0.max(c1);
    // Maxima at 2kπ, minima at (2k+1)π.
    if contains_multiple(a, 0.0) {
        hi = 1.0;
    }
    if contains_multiple(a, PI) {
        lo = -1.0;
    }
    Interval::new((lo - SLACK).max(-1.0), (hi + SLACK).min(1.0))
}

/// A range that contains `sin θ` for every `θ ∈ a`.
pub(crate) fn sin_range(a: Interval) -> Interval {
    cos_range(Interval::new(a.lo - 0.5 * PI, a.hi - 0.5 * PI))
}

/// Whether `[a.lo, a.hi]` (widened by the slack) holds a point `phase + 2kπ`.
fn contains_multiple(a: Interval, phase: f64) -> bool {
    let k = ((a.lo - SLACK - phase) / TAU).ceil();
    phase + k * TAU <= a.hi + SLACK
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_contain_dense_samples() {
        let mut seed = 12345u64;
        for _ in 0..2000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let a = ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 20.0;
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let w = (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0;
            let i = Interval::new(a, a + w);
            let (c, s) = (cos_range(i), sin_range(i));
            for k in 0..=64 {
                let t = a + w * f64::from(k) / 64.0;
                assert!(c.contains(t.cos()) && s.contains(t.sin()), "{i:?} at {t}");
            }
        }
    }
}
