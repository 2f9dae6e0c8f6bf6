//! Conservative interval arithmetic on f64: every operation returns a range that contains the
//! exact result for all arguments in the input ranges.
//!
//! Rounding is not directed; instead the callers that need a proof (the free-form ray caster)
//! only use intervals to *discard* work, and confirm hits with point evaluations. Infinite
//! bounds are allowed (`-∞` encodes "outside" in CSG); operations never produce NaN from finite
//! or infinite inputs except the forbidden `∞ − ∞`, which [`Interval::add`] maps to the full line.

use std::ops::{Add, Mul, Neg, Sub};

/// A closed interval `[lo, hi]` with `lo ≤ hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// The whole real line.
    pub const EVERYTHING: Self = Self {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };
    /// No point at all (`lo > hi`): what a ray's part inside a box is when the ray misses it
    /// ([`crate::Aabb::slab_interval`]). Not an operand of the arithmetic below.
    pub const EMPTY: Self = Self {
        lo: f64::INFINITY,
        hi: f64::NEG_INFINITY,
    };
    /// The interval `{-∞}`: the value of a CSG operand that is absent (outside its box).
    pub const NEG_INFINITY: Self = Self {
        lo: f64::NEG_INFINITY,
        hi: f64::NEG_INFINITY,
    };

    /// `[lo, hi]`; the bounds are swapped if given in the wrong order.
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo <= hi {
            Self { lo, hi }
        } else {
            Self { lo: hi, hi: lo }
        }
    }

    /// The degenerate interval `[x, x]`.
    #[inline]
    pub const fn point(x: f64) -> Self {
        Self { lo: x, hi: x }
    }

    /// Width `hi - lo`.
    #[inline]
    pub fn width(self) -> f64 {
        self.hi - self.lo
    }

    /// Midpoint (finite bounds assumed).
    #[inline]
    pub fn mid(self) -> f64 {
        0.5 * (self.lo + self.hi)
    }

    /// Whether `x` lies in the interval.
    #[inline]
    pub fn contains(self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Whether the interval holds zero.
    #[inline]
    pub fn contains_zero(self) -> bool {
        self.lo <= 0.0 && 0.0 <= self.hi
    }

    /// The smallest interval holding both.
    #[inline]
    pub fn hull(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    /// The smallest interval holding `self` and `x`.
    #[inline]
    pub fn including(self, x: f64) -> Self {
        Self {
            lo: self.lo.min(x),
            hi: self.hi.max(x),
        }
    }

    /// `{x²}` — exact, tighter than `self * self` when the interval straddles zero.
    #[inline]
    pub fn square(self) -> Self {
        if self.lo >= 0.0 {
            Self::new(self.lo * self.lo, self.hi * self.hi)
        } else if self.hi <= 0.0 {
            Self::new(self.hi * self.hi, self.lo * self.lo)
        } else {
            Self::new(0.0, (self.lo * self.lo).max(self.hi * self.hi))
        }
    }

    /// `{x³}` — exact because the cube is monotone.
    #[inline]
    pub fn cube(self) -> Self {
        Self {
            lo: self.lo * self.lo * self.lo,
            hi: self.hi * self.hi * self.hi,
        }
    }

    /// `{max(x, 0)}`.
    #[inline]
    pub fn positive_part(self) -> Self {
        Self {
            lo: self.lo.max(0.0),
            hi: self.hi.max(0.0),
        }
    }

    /// `{max(x, y)}`.
    #[inline]
    pub fn max(self, other: Self) -> Self {
        Self {
            lo: self.lo.max(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    /// `{min(x, y)}`.
    #[inline]
    pub fn min(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.min(other.hi),
        }
    }

    /// `{k · x}` for a scalar `k`.
    #[inline]
    pub fn scale(self, k: f64) -> Self {
        if k >= 0.0 {
            Self {
                lo: self.lo * k,
                hi: self.hi * k,
            }
        } else {
            Self {
                lo: self.hi * k,
                hi: self.lo * k,
            }
        }
    }
}

impl Add for Interval {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        let lo = self.lo + o.lo;
        let hi = self.hi + o.hi;
        // -∞ + ∞ is NaN: the honest answer is "anything".
        Self {
            lo: if lo.is_nan() { f64::NEG_INFINITY } else { lo },
            hi: if hi.is_nan() { f64::INFINITY } else { hi },
        }
    }
}

impl Neg for Interval {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Sub for Interval {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl Mul for Interval {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let prod = |a: f64, b: f64| {
            let p = a * b;
            // 0 · ∞ is NaN; as a bound of a product of ranges it is 0.
            if p.is_nan() { 0.0 } else { p }
        };
        let (a, b, c, d) = (
            prod(self.lo, o.lo),
            prod(self.lo, o.hi),
            prod(self.hi, o.lo),
            prod(self.hi, o.hi),
        );
        Self {
            lo: a.min(b).min(c).min(d),
            hi: a.max(b).max(c).max(d),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn interval() -> impl Strategy<Value = Interval> {
        (-1e3f64..1e3, 0.0f64..1e3).prop_map(|(lo, w)| Interval::new(lo, lo + w))
    }

    proptest! {
        // Every operation must contain the exact image of sampled members (containment).
        #[test]
        fn operations_contain_pointwise_results(a in interval(), b in interval(), s in 0.0f64..=1.0, r in 0.0f64..=1.0, k in -10.0f64..10.0) {
            let x = a.lo + s * a.width();
            let y = b.lo + r * b.width();
            prop_assert!((a + b).contains(x + y));
            prop_assert!((a - b).contains(x - y));
            prop_assert!((a * b).contains(x * y) || ((a*b).lo - x*y).abs() < 1e-9 || ((a*b).hi - x*y).abs() < 1e-9);
            prop_assert!(a.square().contains(x * x) || (a.square().hi - x*x).abs() < 1e-9 || (a.square().lo - x*x).abs() < 1e-9);
            prop_assert!(a.cube().contains(x * x * x) || (a.cube().hi - x*x*x).abs() <= 1e-9 * x.abs().powi(3).max(1.0) || (a.cube().lo - x*x*x).abs() <= 1e-9 * x.abs().powi(3).max(1.0));
            prop_assert!(a.max(b).contains(x.max(y)));
            prop_assert!(a.min(b).contains(x.min(y)));
            prop_assert!(a.scale(k).contains(k * x) || (a.scale(k).lo - k*x).abs() < 1e-9 || (a.scale(k).hi - k*x).abs() < 1e-9);
            prop_assert!(a.positive_part().contains(x.max(0.0)));
        }
    }

    #[test]
    fn square_of_straddling_interval_starts_at_zero() {
        assert_eq!(Interval::new(-2.0, 3.0).square(), Interval::new(0.0, 9.0));
        assert_eq!(Interval::new(-3.0, -2.0).square(), Interval::new(4.0, 9.0));
    }

    #[test]
    fn infinities_never_make_nan() {
        let all = Interval::EVERYTHING;
        let s = all + Interval::NEG_INFINITY;
        assert!(!s.lo.is_nan() && !s.hi.is_nan());
        let p = Interval::new(0.0, 1.0) * all;
        assert!(!p.lo.is_nan() && !p.hi.is_nan());
        assert_eq!((-Interval::NEG_INFINITY).lo, f64::INFINITY);
    }
}
