//! A quadric restricted to a ray: the quadratic `a t² + b t + c`, with exact ranges over a
//! parameter interval and the closed-form first entry (in f64, unwidened; the accuracy tests'
//! reference is double-double, docs/accuracy.md).

use fray_core::Interval;

/// `f(t) = a t² + b t + c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuadratic {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

impl RayQuadratic {
    #[inline]
    pub fn eval(&self, t: f64) -> f64 {
        (self.a * t + self.b) * t + self.c
    }

    #[inline]
    pub fn derivative(&self, t: f64) -> f64 {
        2.0 * self.a * t + self.b
    }

    /// The exact range of `f` over `[t.lo, t.hi]` (endpoints and, if inside, the vertex).
    #[inline]
    pub fn range(&self, t: Interval) -> Interval {
        let f0 = self.eval(t.lo);
        let f1 = self.eval(t.hi);
        let mut r = Interval::new(f0.min(f1), f0.max(f1));
        if self.a != 0.0 {
            let v = -self.b / (2.0 * self.a);
            if v > t.lo && v < t.hi {
                r = r.including(self.eval(v));
            }
        }
        r
    }

    /// The exact range of `f'` over `t` (linear, so its endpoints).
    #[inline]
    pub fn derivative_range(&self, t: Interval) -> Interval {
        Interval::new(self.derivative(t.lo), self.derivative(t.hi))
    }

    /// The first `t` in `range` with `f(t) ≥ 0`, by the closed form; `None` if there is none.
    /// Roots are found with the cancellation-free formulas (`q = −½(b + sign(b)√Δ)`, roots `q/a`
    /// and `c/q`), and degenerate (linear, constant) cases are handled.
    pub fn first_nonnegative(&self, range: Interval) -> Option<f64> {
        // An empty or NaN range has no first point.
        if range.lo > range.hi || range.lo.is_nan() || range.hi.is_nan() {
            return None;
        }
        if self.eval(range.lo) >= 0.0 {
            return Some(range.lo);
        }
        let mut roots = [f64::NAN; 2];
        let scale = self.a.abs().max(self.b.abs()).max(self.c.abs());
        if self.a.abs() <= 1e-300 * scale.max(1e-300) || self.a == 0.0 {
            if self.b != 0.0 {
                roots[0] = -self.c / self.b;
            }
        } else {
            let disc = self.b * self.b - 4.0 * self.a * self.c;
            if disc < 0.0 {
                return None;
            }
            let q = -0.5 * (self.b + self.b.signum() * disc.sqrt());
            if q == 0.0 {
                // b = 0 and Δ = 0: a double root at 0.
                roots[0] = 0.0;
            } else {
                roots = [q / self.a, self.c / q];
            }
        }
        let mut first: Option<f64> = None;
        for r in roots {
            if r.is_finite() && r >= range.lo && r <= range.hi {
                first = Some(first.map_or(r, |f: f64| f.min(r)));
            }
        }
        first
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_includes_vertex() {
        let q = RayQuadratic {
            a: -1.0,
            b: 2.0,
            c: 0.0,
        }; // max 1 at t = 1
        let r = q.range(Interval::new(0.0, 3.0));
        assert_eq!((r.lo, r.hi), (-3.0, 1.0));
    }

    #[test]
    fn first_nonnegative_handles_all_cases() {
        // Entering a sphere-like bump between 1 and 3.
        let q = RayQuadratic {
            a: -1.0,
            b: 4.0,
            c: -3.0,
        };
        assert_eq!(q.first_nonnegative(Interval::new(0.0, 10.0)), Some(1.0));
        assert_eq!(q.first_nonnegative(Interval::new(2.0, 10.0)), Some(2.0));
        assert_eq!(q.first_nonnegative(Interval::new(3.5, 10.0)), None);
        // Linear.
        let l = RayQuadratic {
            a: 0.0,
            b: 1.0,
            c: -2.0,
        };
        assert_eq!(l.first_nonnegative(Interval::new(0.0, 10.0)), Some(2.0));
        // Negative everywhere.
        let n = RayQuadratic {
            a: -1.0,
            b: 0.0,
            c: -1.0,
        };
        assert_eq!(n.first_nonnegative(Interval::new(0.0, 10.0)), None);
        // Upward parabola starting inside its negative part: exit root.
        let u = RayQuadratic {
            a: 1.0,
            b: -4.0,
            c: 3.0,
        };
        assert_eq!(u.first_nonnegative(Interval::new(2.0, 10.0)), Some(3.0));
    }
}
