//! The halving search: split the segment nearer half first, drop a half whose value range is
//! negative, finish a half whose slope range proves one sign change ([`super::finish`]). Its
//! any-hit form (`ANY`, for shadow rays) stops at the first point it proves non-negative: it also
//! tests each split's midpoint, and a monotone segment whose end is non-negative needs no finish.

use super::finish::finish;
use super::program::RayFunction;
use fray_core::Interval;

/// The halving search (module docs) over `range`; `segments` is scratch space. `#[inline]` so
/// that each instantiation may be inlined into its caller's code unit, as when this lived there.
/// With `ANY` the answer is some point of `range` where the function is non-negative (not
/// necessarily the first), found wherever the first search finds one — and also in spans
/// shorter than ε that the first search may step over.
#[inline]
pub(super) fn search<F: RayFunction, const ANY: bool>(
    mut f: F,
    segments: &mut Vec<(f64, f64)>,
    range: Interval,
    eps: f64,
) -> Option<f64> {
    segments.clear();
    segments.push((range.lo, range.hi));
    // The last point evaluated: a halved segment's right half starts where the left half's
    // test ended, so its start value is often known already.
    let mut known = (f64::NAN, f64::NAN);
    let mut first = true;
    let mut hit = None;
    while let Some((a, b)) = segments.pop() {
        let bound = f.bound(Interval { lo: a, hi: b });
        if bound.value.hi < 0.0 {
            continue; // proven empty (most misses end here, after one bound)
        }
        if first {
            // The range may start inside the solid (the picture surface cuts it): then the
            // answer is its start, exactly.
            first = false;
            let fa = f.value(a);
            if fa >= 0.0 {
                hit = Some(a);
                break;
            }
            known = (a, fa);
        }
        if bound.value.lo >= 0.0 {
            hit = Some(a); // everything before `a` was proven or tested negative
            break;
        }
        if bound.slope.lo > 0.0 {
            // Increasing: a root exists iff F′(b) ≥ 0, and it is unique.
            let fb = f.value(b);
            if fb < 0.0 {
                known = (b, fb);
                continue;
            }
            if ANY {
                hit = Some(b);
                break;
            }
            let fa = value_at(&mut f, a, known);
            if fa >= 0.0 {
                hit = Some(a);
            } else {
                hit = Some(finish(&mut f, (a, fa), (b, fb), eps));
            }
            break;
        }
        if bound.slope.hi < 0.0 {
            // Decreasing: the maximum is at `a`.
            if value_at(&mut f, a, known) >= 0.0 {
                hit = Some(a);
                break;
            }
            continue;
        }
        let m = a + 0.5 * (b - a);
        if b - a <= eps || m <= a || m >= b {
            // Shorter than ε (or than the float spacing): test it directly.
            if f.value(m) >= 0.0 {
                hit = Some(m);
                break;
            }
            let fb = f.value(b);
            if fb >= 0.0 {
                hit = Some(b);
                break;
            }
            known = (b, fb);
            continue;
        }
        if ANY {
            // Any point inside ends the search: a ray through a thick solid stops at the first
            // split instead of descending to its surface.
            let fm = f.value(m);
            if fm >= 0.0 {
                hit = Some(m);
                break;
            }
            known = (m, fm);
        }
        segments.push((m, b));
        segments.push((a, m));
    }
    hit
}

/// `F′(t)`, reusing `known = (t, F′(t))` when it is that point.
#[inline]
fn value_at<F: RayFunction>(f: &mut F, t: f64, known: (f64, f64)) -> f64 {
    if known.0 == t { known.1 } else { f.value(t) }
}
