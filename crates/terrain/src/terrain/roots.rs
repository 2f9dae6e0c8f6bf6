//! The roots along a ray within one cell: the first root of the bilinear quadratic and the
//! bicubic halving with slope bounds, finished by Illinois.

use glam::DVec2;

/// The smallest root of `a τ² + b τ + c` in `[lo, hi]` (the quadratic is `> 0` at `lo`).
#[inline]
pub(super) fn first_root(a: f64, b: f64, c: f64, lo: f64, hi: f64) -> Option<f64> {
    let in_range = |t: f64| (t >= lo && t <= hi).then_some(t);
    if a == 0.0 {
        return if b < 0.0 { in_range(-c / b) } else { None };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (mut r1, mut r2) = (q / a, if q != 0.0 { c / q } else { q / a });
    if r1 > r2 {
        std::mem::swap(&mut r1, &mut r2);
    }
    in_range(r1).or_else(|| in_range(r2))
}

/// The floor of the bicubic root tolerance, relative to `|lo| + |hi|` of the piece searched:
/// `8 ε_f64 = 2⁻⁴⁹` (the GPU twin uses `8 ε_f32 = 2⁻²⁰`, the same rule in its precision). It
/// bounds the halving's depth: see [`BICUBIC_STACK`].
const BICUBIC_EPS_FLOOR: f64 = 8.0 * f64::EPSILON;

/// Pending pieces of [`bicubic_root`]'s halving, sized by a proof: a piece is split only while
/// wider than `eps ≥ 2⁻⁴⁹ (|lo| + |hi|) ≥ 2⁻⁴⁹ (hi − lo)` (`lo ≥ 0`: pieces start at or after
/// the cell's entry), and a piece at depth `d` is `(hi − lo) / 2ᵈ` wide, so only pieces at
/// depth `d ≤ 48` are split; depth-first, splitting a depth-`d` piece leaves `d + 2` pending.
/// 50 would do; 56 leaves room for the midpoints' rounding. A full stack (reachable only when
/// the tolerance underflows, for pieces within a few subnormals of 0) settles the piece as one
/// narrower than `eps`: the same rule, never a dropped bracket.
const BICUBIC_STACK: usize = 56;

/// Illinois steps at most (it stops at `eps` long before).
const ILLINOIS_STEPS: usize = 100;

/// The first root of `f` (value, derivative, slope) in `[lo, hi]` with `f(lo) = f_lo > 0`:
/// halving nearer-first with tolerance `eps` (raised to [`BICUBIC_EPS_FLOOR`] `· (|lo| + |hi|)`).
/// For each piece `[a, b]` (`f(a) > 0`), `m` its midpoint and `h` half its width:
/// - `f(b) ≤ 0` (a bracket): when monotone (`|f'(m)| > k2 · h`: exactly one root) or no wider
///   than `eps`, Illinois finds the root to `eps`; else the piece is split;
/// - `f(b) > 0`: dropped when `f(m) − k1 · h > 0` (the slope bound keeps `f > 0` on it) or when
///   monotone (no root between two positive ends); a piece no wider than `eps` with `f(m) ≤ 0`
///   brackets a root in `[a, m]` (Illinois); one with `f(m) > 0` is dropped (a graze thinner
///   than `eps`); else split.
#[inline]
pub(super) fn bicubic_root(
    f: &impl Fn(f64) -> (f64, f64, DVec2),
    k1: f64,
    k2: f64,
    lo: f64,
    hi: f64,
    f_lo: f64,
    eps: f64,
) -> Option<f64> {
    let eps = eps.max(BICUBIC_EPS_FLOOR * (lo.abs() + hi.abs()));
    let mut stack = [(0.0f64, 0.0f64, 0.0f64, 0.0f64); BICUBIC_STACK];
    stack[0] = (lo, hi, f_lo, f(hi).0);
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let (a, b, fa, fb) = stack[len];
        let mid = 0.5 * (a + b);
        let half = 0.5 * (b - a);
        let (fm, dm, _) = f(mid);
        let monotone = dm.abs() > k2 * half;
        // No wider than the tolerance (or, never at a normal tolerance, out of stack).
        let small = b - a <= eps || len + 2 > BICUBIC_STACK;
        if fb <= 0.0 {
            if monotone || small {
                return Some(illinois(f, a, b, fa, fb, eps));
            }
        } else if fm - k1 * half > 0.0 || monotone {
            continue;
        } else if small {
            if fm <= 0.0 {
                return Some(illinois(f, a, mid, fa, fm, eps));
            }
            continue;
        }
        stack[len] = (mid, b, fm, fb);
        stack[len + 1] = (a, mid, fa, fm);
        len += 2;
    }
    None
}

/// Illinois (modified regula falsi) on a bracket `f(a) > 0 ≥ f(b)`, to `|b − a| ≤ eps`.
#[inline]
fn illinois(
    f: &impl Fn(f64) -> (f64, f64, DVec2),
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    eps: f64,
) -> f64 {
    let mut side = 0i8;
    for _ in 0..ILLINOIS_STEPS {
        if b - a <= eps || fb == 0.0 {
            break;
        }
        let mut t = (a * fb - b * fa) / (fb - fa);
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let ft = f(t).0;
        if ft > 0.0 {
            a = t;
            fa = ft;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = t;
            fb = ft;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_root_is_stable_for_tiny_leading_terms() {
        // (τ − 1)(1e-12 τ − 1) > 0 at 0 → first root 1.
        let (a, b, c) = (1e-12, -(1.0 + 1e-12), 1.0);
        let r = first_root(a, b, c, 0.0, 10.0).unwrap();
        assert!((r - 1.0).abs() < 1e-15);
        assert_eq!(first_root(0.0, -2.0, 1.0, 0.0, 1.0), Some(0.5));
        assert_eq!(first_root(1.0, 0.0, 1.0, 0.0, 1.0), None);
    }
}
