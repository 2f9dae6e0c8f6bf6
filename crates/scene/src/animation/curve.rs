//! A keyframed curve of `N` numbers over time: linear or Catmull–Rom through its keys, eased,
//! optionally closed (a loop), with its tangent.

use crate::description::{Ease, Interpolation};

/// Values `values[i]` at strictly increasing `times[i]` (seconds).
///
/// Catmull–Rom here is the cubic Hermite spline whose tangent at a key is the slope between its
/// neighbours, `(p₊ − p₋) / (t₊ − t₋)`, so keys at any spacing in time give a continuous velocity;
/// an open curve's end keys take the slope of their one segment. Ease reshapes the track's time
/// between its first and last key (over one period for a loop) before the spline is evaluated.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve<const N: usize> {
    times: Vec<f64>,
    values: Vec<[f64; N]>,
    interpolation: Interpolation,
    ease: Ease,
    /// A closed curve's period: the last key runs on into the first at `times[0] + period`.
    period: Option<f64>,
}

/// Where a time falls: the segment's first key and the fraction `s ∈ [0, 1]` of it, with the
/// segment's length in time.
struct Place {
    i: usize,
    s: f64,
    h: f64,
}

impl<const N: usize> Curve<N> {
    /// A curve through `keys` (times strictly increasing, checked by the caller; at least one).
    /// A `period` closes it: every time must lie in `[times[0], times[0] + period)`.
    pub(crate) fn new(
        keys: Vec<(f64, [f64; N])>,
        interpolation: Interpolation,
        ease: Ease,
        period: Option<f64>,
    ) -> Self {
        let (times, values) = keys.into_iter().unzip();
        Self {
            times,
            values,
            interpolation,
            ease,
            period,
        }
    }

    fn len(&self) -> usize {
        self.times.len()
    }

    /// Key `i` of the curve extended periodically (a closed curve) or clamped (an open one):
    /// its time and value.
    fn key(&self, i: isize) -> (f64, [f64; N]) {
        let n = self.len() as isize;
        match self.period {
            Some(p) => {
                let wraps = i.div_euclid(n);
                let k = i.rem_euclid(n) as usize;
                (self.times[k] + wraps as f64 * p, self.values[k])
            }
            None => {
                let k = i.clamp(0, n - 1) as usize;
                (self.times[k], self.values[k])
            }
        }
    }

    /// The eased track time of `t`: within `[times[0], last]` for an open curve (held outside),
    /// within one period from `times[0]` for a closed one.
    fn eased(&self, t: f64) -> f64 {
        let t0 = self.times[0];
        let span = match self.period {
            Some(p) => p,
            None => self.times[self.len() - 1] - t0,
        };
        if span <= 0.0 {
            return t0;
        }
        let s = match self.period {
            Some(p) => (t - t0).rem_euclid(p) / p,
            None => ((t - t0) / span).clamp(0.0, 1.0),
        };
        t0 + ease(self.ease, s) * span
    }

    fn place(&self, u: f64) -> Place {
        let segments = match self.period {
            Some(_) => self.len(),
            None => self.len().saturating_sub(1),
        };
        if segments == 0 {
            return Place {
                i: 0,
                s: 0.0,
                h: 1.0,
            };
        }
        // The last key at or before `u` (the first segment before the first key).
        let i = self
            .times
            .partition_point(|&k| k <= u)
            .saturating_sub(1)
            .min(segments - 1);
        let (a, b) = (self.key(i as isize).0, self.key(i as isize + 1).0);
        let h = b - a;
        Place {
            i,
            s: ((u - a) / h).clamp(0.0, 1.0),
            h,
        }
    }

    /// The tangent (slope per second) the spline takes at key `i`.
    fn slope(&self, i: isize) -> [f64; N] {
        let n = self.len() as isize;
        let (lo, hi) = match self.period {
            Some(_) => (i - 1, i + 1),
            None => ((i - 1).max(0), (i + 1).min(n - 1)),
        };
        let ((ta, a), (tb, b)) = (self.key(lo), self.key(hi));
        std::array::from_fn(|c| (b[c] - a[c]) / (tb - ta))
    }

    /// The value at time `t` (seconds).
    pub fn at(&self, t: f64) -> [f64; N] {
        if self.len() == 1 {
            return self.values[0];
        }
        let Place { i, s, h } = self.place(self.eased(t));
        let i = i as isize;
        let ((_, p0), (_, p1)) = (self.key(i), self.key(i + 1));
        match self.interpolation {
            Interpolation::Linear => std::array::from_fn(|c| p0[c] + s * (p1[c] - p0[c])),
            Interpolation::CatmullRom => {
                let (m0, m1) = (self.slope(i), self.slope(i + 1));
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                std::array::from_fn(|c| {
                    h00 * p0[c] + h10 * h * m0[c] + h01 * p1[c] + h11 * h * m1[c]
                })
            }
        }
    }

    /// The spline's tangent at time `t`: its derivative with respect to the eased track time (the
    /// direction of travel; ease scales the speed, not the direction, and never stops it here).
    pub fn tangent(&self, t: f64) -> [f64; N] {
        if self.len() == 1 {
            return [0.0; N];
        }
        let Place { i, s, h } = self.place(self.eased(t));
        let i = i as isize;
        let ((_, p0), (_, p1)) = (self.key(i), self.key(i + 1));
        match self.interpolation {
            Interpolation::Linear => std::array::from_fn(|c| (p1[c] - p0[c]) / h),
            Interpolation::CatmullRom => {
                let (m0, m1) = (self.slope(i), self.slope(i + 1));
                let s2 = s * s;
                let d00 = 6.0 * s2 - 6.0 * s;
                let d10 = 3.0 * s2 - 4.0 * s + 1.0;
                let d01 = -6.0 * s2 + 6.0 * s;
                let d11 = 3.0 * s2 - 2.0 * s;
                std::array::from_fn(|c| (d00 * p0[c] + d01 * p1[c]) / h + d10 * m0[c] + d11 * m1[c])
            }
        }
    }

    /// The segment `t` falls in: its keys and the eased fraction along it (for what is
    /// interpolated per segment, as rotations are).
    pub(crate) fn segment(&self, t: f64) -> (usize, usize, f64) {
        if self.len() == 1 {
            return (0, 0, 0.0);
        }
        let Place { i, s, .. } = self.place(self.eased(t));
        (i, (i + 1) % self.len(), s)
    }
}

/// The eased fraction of `s ∈ [0, 1]`.
pub(crate) fn ease(ease: Ease, s: f64) -> f64 {
    match ease {
        Ease::Linear => s,
        Ease::In => s * s,
        Ease::Out => s * (2.0 - s),
        Ease::InOut => s * s * (3.0 - 2.0 * s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(keys: &[(f64, f64)], interpolation: Interpolation, period: Option<f64>) -> Curve<1> {
        Curve::new(
            keys.iter().map(|&(t, v)| (t, [v])).collect(),
            interpolation,
            Ease::Linear,
            period,
        )
    }

    /// Every spline passes through its keys exactly and holds its end values outside them.
    #[test]
    fn curves_pass_through_their_keys_and_hold_their_ends() {
        let keys = [(0.0, 1.0), (0.7, -2.0), (1.1, 4.0), (3.0, 0.5)];
        for interpolation in [Interpolation::Linear, Interpolation::CatmullRom] {
            let c = curve(&keys, interpolation, None);
            for &(t, v) in &keys {
                assert_eq!(c.at(t), [v], "{interpolation:?} at {t}");
            }
            assert_eq!(c.at(-5.0), [1.0]);
            assert_eq!(c.at(9.0), [0.5]);
        }
    }

    /// Against a known answer: on keys of a quadratic `f(t) = 3t² − 2t + 1` at even spacing the
    /// neighbours' slope is the exact derivative, so the interior segments of the Catmull–Rom
    /// spline (Hermite with exact values and slopes) reproduce the quadratic to rounding, and
    /// its tangent the derivative.
    #[test]
    fn catmull_rom_reproduces_a_quadratic_between_interior_keys() {
        let f = |t: f64| 3.0 * t * t - 2.0 * t + 1.0;
        let df = |t: f64| 6.0 * t - 2.0;
        let keys: Vec<(f64, f64)> = (0..6)
            .map(|k| (0.5 * k as f64, f(0.5 * k as f64)))
            .collect();
        let c = curve(&keys, Interpolation::CatmullRom, None);
        for k in 0..=300 {
            let t = 0.5 + 1.5 * k as f64 / 300.0; // keys 1 to 4: interior segments
            assert!((c.at(t)[0] - f(t)).abs() < 1e-12, "value at {t}");
            assert!((c.tangent(t)[0] - df(t)).abs() < 1e-11, "slope at {t}");
        }
    }

    /// The velocity is continuous across keys at uneven spacing (C¹), while linear
    /// interpolation's jumps: the one-sided difference quotients at a key agree to O(δ).
    #[test]
    fn catmull_rom_velocity_is_continuous_across_uneven_keys() {
        let keys = [(0.0, 0.0), (0.3, 2.0), (1.5, -1.0), (1.8, 3.0), (4.0, 0.0)];
        let c = curve(&keys, Interpolation::CatmullRom, None);
        let d = 1e-6;
        for &(t, _) in &keys[1..4] {
            let left = (c.at(t)[0] - c.at(t - d)[0]) / d;
            let right = (c.at(t + d)[0] - c.at(t)[0]) / d;
            assert!(
                (left - right).abs() < 1e-3 * (1.0 + left.abs()),
                "at {t}: {left} vs {right}"
            );
        }
        let l = curve(&keys, Interpolation::Linear, None);
        let t = 0.3;
        let jump = ((l.at(t + d)[0] - l.at(t)[0]) - (l.at(t)[0] - l.at(t - d)[0])) / d;
        assert!(jump.abs() > 1.0, "linear keeps its corner: {jump}");
    }

    /// A closed curve repeats with its period, passes from its last key into its first smoothly,
    /// and its value at the period's end is its first key's.
    #[test]
    fn a_closed_curve_is_periodic_and_smooth_at_the_wrap() {
        let keys = [(0.0, 1.0), (1.0, 3.0), (2.5, -1.0)];
        let c = curve(&keys, Interpolation::CatmullRom, Some(4.0));
        for k in 0..40 {
            let t = 0.1 * k as f64;
            assert!((c.at(t)[0] - c.at(t + 4.0)[0]).abs() < 1e-12, "{t}");
            assert!((c.at(t)[0] - c.at(t - 8.0)[0]).abs() < 1e-12, "{t}");
        }
        assert!((c.at(4.0)[0] - 1.0).abs() < 1e-12);
        let d = 1e-6;
        let left = (c.at(4.0)[0] - c.at(4.0 - d)[0]) / d;
        let right = (c.at(4.0 + d)[0] - c.at(4.0)[0]) / d;
        assert!(
            (left - right).abs() < 1e-3 * (1.0 + left.abs()),
            "{left} vs {right}"
        );
        // The slope at the wrap is the neighbours' across it: (3 − (−1)) / (1 − (2.5 − 4)).
        assert!((c.tangent(0.0)[0] - 4.0 / 2.5).abs() < 1e-12);
    }

    /// Ease keeps the ends and the middle of in-out, starts and stops with zero speed.
    #[test]
    fn ease_keeps_the_ends_and_slows_them() {
        for e in [Ease::Linear, Ease::In, Ease::Out, Ease::InOut] {
            assert_eq!(ease(e, 0.0), 0.0);
            assert_eq!(ease(e, 1.0), 1.0);
        }
        assert_eq!(ease(Ease::InOut, 0.5), 0.5);
        let d = 1e-6;
        assert!(ease(Ease::InOut, d) / d < 1e-5);
        assert!((1.0 - ease(Ease::InOut, 1.0 - d)) / d < 1e-5);
        assert!(ease(Ease::In, d) / d < 1e-5);
        assert!((1.0 - ease(Ease::Out, 1.0 - d)) / d < 1e-5);
    }
}
