//! Root finishing on a sign bracket: the Illinois variant of regula falsi, shared by the model
//! crates' ray casters (free forms, terrain) so they converge — and stop — the same way.

/// A point `t ≥ root` with `t − root ≤ eps` and `f(t) ≥ 0`, for a bracket with
/// `f(a) < 0 ≤ f(b)` (`fa = f(a)`, `fb = f(b)`) on which `f` changes sign once.
///
/// Regula falsi, with the stale end's value halved when the same end moves twice (Illinois),
/// and a bisection whenever four steps would not otherwise have halved the bracket, so it never
/// stalls (≤ 4 log₂(width/ε) steps); a secant
/// point outside the open bracket is replaced by the midpoint, and the iteration stops when no
/// float lies strictly between the ends. At most 200 evaluations of `f`.
pub fn illinois(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    eps: f64,
) -> f64 {
    let mut last_side = 0i8;
    let mut width_before = b - a;
    for iteration in 0..200 {
        if b - a <= eps || fb == 0.0 {
            break;
        }
        let mut c = b - fb * (b - a) / (fb - fa);
        // Windows of four steps: if the first three did not halve the bracket, the fourth
        // bisects, so the bracket at least halves every four steps (a triple root, where the
        // secant crawls, still converges); always stay strictly inside.
        if iteration % 4 == 0 {
            width_before = b - a;
        } else if iteration % 4 == 3 && b - a > 0.5 * width_before {
            c = a + 0.5 * (b - a);
        }
        if !(c > a && c < b) {
            c = a + 0.5 * (b - a);
            if !(c > a && c < b) {
                break; // no float between a and b
            }
        }
        let fc = f(c);
        if fc >= 0.0 {
            b = c;
            fb = fc;
            if last_side == 1 {
                fa *= 0.5;
            }
            last_side = 1;
        } else {
            a = c;
            fa = fc;
            if last_side == -1 {
                fb *= 0.5;
            }
            last_side = -1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against closed forms: a line, a steep cubic, and a function that is −∞ before its root
    /// (a clipping face): within ε, never before the root, with `f ≥ 0` at the answer.
    #[test]
    fn converges_to_the_root_from_above_within_eps() {
        let eps = 1e-12;
        /// A function, its bracket `[a, b]`, and its root.
        type Case = (fn(f64) -> f64, f64, f64, f64);
        let cases: [Case; 3] = [
            (|t| t - 0.3, 0.0, 1.0, 0.3),
            (|t| (t - 0.7).powi(3) * 1e6, 0.0, 1.0, 0.7),
            (
                |t| if t < 0.25 { f64::NEG_INFINITY } else { 1.0 },
                0.0,
                1.0,
                0.25,
            ),
        ];
        for (f, a, b, root) in cases {
            let t = illinois(f, (a, f(a)), (b, f(b)), eps);
            assert!(t >= root && t - root <= eps, "{t} vs root {root}");
            assert!(f(t) >= 0.0);
        }
    }

    /// The evaluation budget holds even when `f` never reaches the bracket's precision.
    #[test]
    fn stops_without_a_float_between_the_ends() {
        let mut calls = 0;
        let t = illinois(
            |t| {
                calls += 1;
                if t >= 1.0 { 1.0 } else { -1.0 }
            },
            (0.5, -1.0),
            (1.0, 1.0),
            0.0,
        );
        assert_eq!(t, 1.0);
        assert!(calls <= 200);
    }
}
