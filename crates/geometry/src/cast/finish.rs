//! Finishing a bracket on which `F′` changes sign once: the deciding leaf predicts the root —
//! its quadratic's closed-form root, or the clipping-box face the ray enters through — and two
//! point evaluations certify it (`F′(r) ≥ 0 > F′(r − ε)`); otherwise [`illinois`]
//! (`fray_core::root`, the one Illinois iteration the model crates share) finishes the bracket.

use super::on_ray::LeafOnRay;
use super::program::RayFunction;
use fray_core::Interval;
use fray_core::root::illinois;

/// The root of a monotone bracket `f(a) < 0 ≤ f(b)`, to within `eps` (the contract of
/// [`illinois`]). When the program is one leaf that is a plain quadric over the
/// bracket, its closed-form root is the prediction, and two point evaluations certify it:
/// `f(r) ≥ 0` and `f(r − ε) < 0` put the root in `(r − ε, r]`. A prediction that rounding
/// put on the wrong side only narrows the bracket for the Illinois iteration.
#[inline]
pub(super) fn finish<F: RayFunction>(
    f: &mut F,
    (a, fa): (f64, f64),
    (b, fb): (f64, f64),
    eps: f64,
) -> f64 {
    if let Some(r) = f.predict(a, b) {
        let fr = f.value(r);
        if fr < 0.0 {
            return illinois(|t| f.value(t), (r, fr), (b, fb), eps);
        }
        let before = r - eps;
        if before <= a {
            return r;
        }
        let f_before = f.value(before);
        if f_before < 0.0 {
            return r;
        }
        return illinois(|t| f.value(t), (a, fa), (before, f_before), eps);
    }
    illinois(|t| f.value(t), (a, fa), (b, fb), eps)
}

/// A prediction of the root in `(a, b)` when the leaf decides `F′` there: the clipping-box face
/// where the ray enters the box with the leaf already `≥ 0` (`F′` jumps from `−∞`), or else, for
/// a plain leaf (`plain`: no perturbation), the closed-form root of its quadratic past the face.
#[inline]
pub(super) fn predict_leaf(leaf: &LeafOnRay, plain: bool, a: f64, b: f64) -> Option<f64> {
    let present = leaf.present?;
    let mut lo = a;
    if present.lo > a {
        if present.lo >= b {
            return None;
        }
        if leaf.clips && (!plain || leaf.base.eval(present.lo) >= 0.0) {
            return Some(present.lo);
        }
        lo = present.lo;
    }
    if !plain || b > present.hi {
        return None;
    }
    leaf.base
        .first_nonnegative(Interval { lo, hi: b })
        .filter(|&r| r > a && r < b)
}
