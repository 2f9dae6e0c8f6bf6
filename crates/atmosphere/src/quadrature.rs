//! Globally adaptive Gauss–Kronrod (7/15-point) quadrature — the integrator of the f64
//! references, the fog's and the sky's (QUADPACK's QAG with the 15-point rule, RGB-valued;
//! [`integrate`] for scalar integrands).

use glam::DVec3;

/// Kronrod nodes on `[0, 1]` (the last is the centre); the odd-indexed ones are Gauss nodes.
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights for [`XGK`].
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
/// 7-point Gauss weights for `XGK[1]`, `XGK[3]`, `XGK[5]` and the centre.
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One panel: its ends, the 15-point value and the error estimate `|K15 − G7|` per channel.
#[derive(Clone, Copy, Debug)]
struct Panel {
    a: f64,
    b: f64,
    value: DVec3,
    error: DVec3,
}

/// The 15-point Kronrod value of `f` over `[a, b]` and QUADPACK's error estimate per channel:
/// `|K15 − G7|` scaled as `I_asc · min(1, (200 |K15 − G7| / I_asc)^{3/2})`, `I_asc` the
/// Kronrod integral of `|f − mean|` (so a smooth integrand, where the difference is far
/// larger than the Kronrod value's error, is not refined for nothing), and at least 50 ulps of
/// `∫|f|` (rounding).
fn gk15(f: &mut impl FnMut(f64) -> DVec3, a: f64, b: f64) -> Panel {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut values = [DVec3::ZERO; 15];
    values[14] = f(c);
    for (j, &x) in XGK.iter().take(7).enumerate() {
        values[2 * j] = f(c - h * x);
        values[2 * j + 1] = f(c + h * x);
    }
    let mut k = values[14] * WGK[7];
    let mut g = values[14] * WG[3];
    let mut abs = values[14].abs() * WGK[7];
    for (j, &w) in WGK.iter().take(7).enumerate() {
        let pair = values[2 * j] + values[2 * j + 1];
        k += pair * w;
        abs += (values[2 * j].abs() + values[2 * j + 1].abs()) * w;
        if j % 2 == 1 {
            g += pair * WG[j / 2];
        }
    }
    let mean = k * 0.5;
    let mut asc = (values[14] - mean).abs() * WGK[7];
    for (j, &w) in WGK.iter().take(7).enumerate() {
        asc += ((values[2 * j] - mean).abs() + (values[2 * j + 1] - mean).abs()) * w;
    }
    let h_abs = h.abs();
    let raw = ((k - g) * h).abs();
    let (asc, abs) = (asc * h_abs, abs * h_abs);
    let error = DVec3::from_array(std::array::from_fn(|i| {
        let mut e = raw[i];
        if asc[i] > 0.0 && e > 0.0 {
            e = asc[i] * (200.0 * e / asc[i]).powf(1.5).min(1.0);
        }
        e.max(50.0 * f64::EPSILON * abs[i])
    }));
    Panel {
        a,
        b,
        value: k * h,
        error,
    }
}

/// `∫ f` over `[breaks[0], breaks[last]]`, each piece between consecutive `breaks` (sorted;
/// duplicates allowed) first cut into `min_panels` equal panels, then the panel with the largest
/// error relative to the target bisected until every channel's summed estimate is at most
/// `max(rel · |∫ f|, floor)` (`rel` at least 100 ulps: no chasing rounding), or `max_panels`
/// is reached. Panels too narrow to split are accepted.
pub fn integrate_rgb(
    f: &mut impl FnMut(f64) -> DVec3,
    breaks: &[f64],
    rel: f64,
    floor: DVec3,
    min_panels: u32,
    max_panels: usize,
) -> DVec3 {
    let n = min_panels.max(1);
    let mut panels: Vec<Panel> = Vec::with_capacity(16);
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        for k in 0..n {
            let lo = a + (b - a) * f64::from(k) / f64::from(n);
            let hi = if k + 1 == n {
                b
            } else {
                a + (b - a) * f64::from(k + 1) / f64::from(n)
            };
            panels.push(gk15(f, lo, hi));
        }
    }
    loop {
        let (total, error) = panels.iter().fold((DVec3::ZERO, DVec3::ZERO), |(v, e), p| {
            (v + p.value, e + p.error)
        });
        let target = (total.abs() * rel.max(100.0 * f64::EPSILON))
            .max(floor)
            .max(DVec3::splat(1e-300));
        if error.cmple(target).all() || panels.len() >= max_panels {
            return total;
        }
        // The panel that contributes most to the worst channel's relative error.
        let mut worst = None;
        let mut worst_weight = 0.0;
        for (i, p) in panels.iter().enumerate() {
            let weight = (p.error / target).max_element();
            if weight > worst_weight {
                worst_weight = weight;
                worst = Some(i);
            }
        }
        let Some(i) = worst else {
            return total;
        };
        let p = panels[i];
        let mid = 0.5 * (p.a + p.b);
        if !(mid > p.a && mid < p.b) {
            // Too narrow to split in f64: accept it as it is.
            panels[i].error = DVec3::ZERO;
            continue;
        }
        panels[i] = gk15(f, p.a, mid);
        panels.push(gk15(f, mid, p.b));
    }
}

/// `∫ₐᵇ f` of a scalar integrand to relative tolerance `rel` ([`integrate_rgb`] on one channel).
pub fn integrate(mut f: impl FnMut(f64) -> f64, a: f64, b: f64, rel: f64) -> f64 {
    let mut g = |x: f64| DVec3::splat(f(x));
    integrate_rgb(&mut g, &[a, b], rel, DVec3::ZERO, 1, 20_000).x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_exact_for_polynomials() {
        // K15 is exact to degree 22, G7 to degree 13.
        for d in 0..=22 {
            let mut f = |x: f64| DVec3::splat(x.powi(d));
            let p = gk15(&mut f, -1.0, 1.0);
            let exact = if d % 2 == 0 {
                2.0 / f64::from(d + 1)
            } else {
                0.0
            };
            assert!((p.value.x - exact).abs() < 1e-15, "degree {d}");
            if d <= 13 {
                assert!(p.error.x < 1e-13, "degree {d}: G7 should be exact");
            }
        }
    }

    #[test]
    fn adaptive_meets_its_tolerance() {
        // A kink and a sharp peak.
        let mut f = |x: f64| DVec3::new(x.abs().sqrt(), 1.0 / (1e-4 + x * x), (-x).exp());
        let v = integrate_rgb(&mut f, &[-1.0, 1.0], 1e-12, DVec3::ZERO, 1, 10_000);
        let peak = 2.0 / 1e-2 * (1.0f64 / 1e-2).atan();
        assert!((v.x - 4.0 / 3.0).abs() < 1e-11);
        assert!((v.y - peak).abs() < 1e-12 * peak);
        assert!((v.z - (1f64.exp() - (-1f64).exp())).abs() < 1e-13);
        // The scalar form.
        let v = integrate(f64::exp, 0.0, 30.0, 1e-14);
        assert!((v / 30f64.exp_m1() - 1.0).abs() < 1e-13);
    }
}
