//! Reference root finding along a ray in f64: bisection of a sign change and the inside spans
//! of a function sampled at given points — what the ray-by-ray suites measure backends against.

/// The first point of `[a, b]` on `f`'s inside (`f ≥ 0`) side of its sign change (`f` changes
/// sign between the ends), to 1e-12 relative.
pub fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let inside_a = f(a) >= 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b || (b - a) <= 1e-12 * b.abs().max(1.0) {
            break;
        }
        if (f(m) >= 0.0) == inside_a {
            a = m;
        } else {
            b = m;
        }
    }
    // The first inside point of the pair.
    if inside_a { a } else { b }
}

/// `n + 1` evenly spaced samples of `[lo, hi]`, the last exactly `hi` (`n ≥ 1`).
pub fn samples(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let h = (hi - lo) / n as f64;
    (0..=n)
        .map(|k| if k == n { hi } else { lo + h * k as f64 })
        .collect()
}

/// The spans where `f ≥ 0` over the increasing samples `ts` (at least one), each sign change
/// between neighbours bisected; a span still open at the last sample ends there.
pub fn inside_spans(f: &impl Fn(f64) -> f64, ts: &[f64]) -> Vec<(f64, f64)> {
    let mut spans = Vec::new();
    let mut prev = (ts[0], f(ts[0]));
    let mut entry = (prev.1 >= 0.0).then_some(ts[0]);
    for &t in &ts[1..] {
        let v = f(t);
        if (v >= 0.0) != (prev.1 >= 0.0) {
            let edge = bisect(f, prev.0, t);
            match entry.take() {
                Some(a) => spans.push((a, edge)),
                None => entry = Some(edge),
            }
        }
        prev = (t, v);
    }
    if let Some(a) = entry {
        spans.push((a, ts[ts.len() - 1]));
    }
    spans
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit ball's chord along x, `1 − x²` sampled coarsely: the span is `[-1, 1]` to the
    /// bisection's tolerance (closed form, not the same search).
    #[test]
    fn a_chord_of_the_unit_ball() {
        let spans = inside_spans(&|x: f64| 1.0 - x * x, &samples(-3.0, 3.0, 7));
        assert_eq!(spans.len(), 1);
        assert!((spans[0].0 + 1.0).abs() < 1e-11 && (spans[0].1 - 1.0).abs() < 1e-11);
        // Inside at the last sample: the span ends there.
        let open = inside_spans(&|x: f64| x, &[-1.0, 0.5, 2.0]);
        assert_eq!(open.len(), 1);
        assert!(open[0].0.abs() < 1e-11 && open[0].1 == 2.0, "{open:?}");
    }
}
