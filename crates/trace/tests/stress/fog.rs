//! The fog layer under stress: layers `10^[−3, 6]` m thick, homogeneous or falling off with a
//! scale height from `10⁻³` to `10³` thicknesses, extinction `10^[−9, 2]` per thickness, their
//! base at `0` or `±10⁵`; rays exactly horizontal, nearly so (`|d_y| = 10^[−16, −6]`),
//! vertical, from `10⁵` away, from inside, over bounded, unbounded and split ranges —
//! `FogLayer::optical_depth` and `transmittance`.
//!
//! The reference is the layer's definition, not its closed form: the part of the range inside
//! the layer (`[base, top]` crossed by the ray, computed here) of length `L`, and the extinction
//! at its two ends' heights, `B_lo ≤ B ≤ B_hi` (monotone in height). Per ray:
//! - **no nonsense**: `τ ≥ 0` and a number; `τ = ∞` only for a horizontal ray inside a foggy
//!   layer over an unbounded range; `T ∈ [0, 1]`;
//! - **bracket**: `B_lo L (1 − r) − a ≤ τ ≤ B_hi L (1 + r) + a`, `r = 1e-9`, `a = B_hi · 8u (|o_y|
//!   + |base| + |top|) / |d_y| + 10⁻³⁰⁰` (the rounding of the crossing's two ends; subnormals);
//! - **additive**: `τ[lo, hi] = τ[lo, m] + τ[m, hi]` within `r τ + 2a` at a point `m` inside.

use super::runner::{self, Family, Tally};
use fray_atmosphere::{FogLayer, Phase};
use fray_core::{Interval, Ray};
use fray_test_support::Rng;
use glam::DVec3;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const U: f64 = f64::EPSILON / 2.0;
const FAMILIES: [&str; 7] = [
    "random",
    "horizontal",
    "near horizontal",
    "vertical",
    "far camera",
    "inside",
    "split/unbounded",
];
const RAYS_PER_CASE: usize = 8192;
const REL: f64 = 1e-9;

fn layer() -> impl Strategy<Value = (FogLayer, u64)> {
    (
        -3.0..6.0f64,
        0..3u8,
        -9.0..2.0f64,
        prop::option::of(-3.0..3.0f64),
        any::<u64>(),
    )
        .prop_map(|(h, at, b, falloff, seed)| {
            let thickness = 10f64.powf(h);
            let base = match at {
                0 => 1e5,
                1 => -1e5,
                _ => 0.0,
            };
            (
                FogLayer {
                    base,
                    top: base + thickness,
                    extinction: 10f64.powf(b) / thickness,
                    albedo: DVec3::splat(0.9),
                    falloff: falloff.map(|f| thickness * 10f64.powf(f)),
                    phase: Phase::Isotropic,
                },
                seed,
            )
        })
}

/// The part of `range` inside the layer, computed from the definition.
fn inside(fog: &FogLayer, ray: &Ray, range: Interval) -> Option<(f64, f64)> {
    let (y, dy) = (ray.origin.y, ray.dir.y);
    let (a, b) = if dy == 0.0 {
        if y < fog.base || y > fog.top {
            return None;
        }
        (range.lo, range.hi)
    } else {
        let (t0, t1) = ((fog.base - y) / dy, (fog.top - y) / dy);
        (range.lo.max(t0.min(t1)), range.hi.min(t0.max(t1)))
    };
    (a <= b).then_some((a, b))
}

fn run_case(fog: &FogLayer, seed: u64, tally: &Tally) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let h = fog.thickness();
    let mut families = [Family::default(); FAMILIES.len()];
    for i in 0..RAYS_PER_CASE {
        let k = i % FAMILIES.len();
        let y_in = fog.base + h * rng.unit();
        let horizontal = |rng: &mut Rng| {
            let a = rng.range(0.0, std::f64::consts::TAU);
            DVec3::new(a.cos(), 0.0, a.sin())
        };
        let (o, d) = match k {
            1 => (DVec3::new(0.0, y_in, 0.0), horizontal(&mut rng)),
            2 => {
                let dy = rng.log_uniform(-16.0, -6.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                (
                    DVec3::new(0.0, y_in, 0.0),
                    (horizontal(&mut rng) + DVec3::Y * dy).normalize(),
                )
            }
            3 => {
                let up = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
                (
                    DVec3::new(0.0, fog.base + h * rng.range(-2.0, 3.0), 0.0),
                    DVec3::Y * up,
                )
            }
            4 => {
                let d = rng.direction();
                (
                    DVec3::new(0.0, y_in, 0.0) - d * 1e5 * rng.range(1.0, 3.0),
                    d,
                )
            }
            5 => (DVec3::new(rng.range(-1e3, 1e3), y_in, 0.0), rng.direction()),
            _ => (
                DVec3::new(0.0, fog.base + h * rng.range(-3.0, 4.0), 0.0),
                rng.direction(),
            ),
        };
        let ray = Ray::new(o, d).expect("a unit direction");
        let lo = if rng.unit() < 0.3 {
            0.0
        } else {
            h * rng.log_uniform(-3.0, 1.0)
        };
        let hi = if k == 6 || rng.unit() < 0.3 {
            f64::INFINITY
        } else {
            lo + h * rng.log_uniform(-3.0, 3.0)
        };
        let range = Interval::new(lo, hi);
        let tau = fog.optical_depth(&ray, range);
        let t = fog.transmittance(&ray, range);
        let fail = |what: String| {
            TestCaseError::fail(format!(
                "{} ray through {fog:?}: {what} for {ray:?} over {range:?}",
                FAMILIES[k]
            ))
        };
        if tau.is_nan() || tau < 0.0 || !(0.0..=1.0).contains(&t) {
            return Err(fail(format!("τ = {tau}, T = {t}")));
        }
        let span = inside(fog, &ray, range);
        let (b_lo, b_hi, len) = span.map_or((0.0, 0.0, 0.0), |(a, b)| {
            let (ya, yb) = (
                ray.at(a).y,
                if b.is_finite() {
                    ray.at(b).y
                } else {
                    ray.origin.y
                },
            );
            let dens = |y: f64| fog.density(y.clamp(fog.base, fog.top));
            let (da, db) = (dens(ya), dens(yb));
            (da.min(db), da.max(db), b - a)
        });
        if tau == f64::INFINITY {
            if !(d.y == 0.0 && hi == f64::INFINITY && span.is_some() && b_hi > 0.0) {
                return Err(fail("τ = ∞ on a ray that leaves the layer".into()));
            }
        } else {
            let a = b_hi * 8.0 * U * (o.y.abs() + fog.base.abs() + fog.top.abs())
                / d.y.abs().max(f64::MIN_POSITIVE);
            // Plus 1e-300: a subnormal τ keeps no relative precision.
            let a = if d.y == 0.0 { 0.0 } else { a } + 1e-300;
            // No fog at all (the density underflowed) over an unbounded span is none.
            let times = |b: f64| if b == 0.0 { 0.0 } else { b * len };
            let (low, high) = (times(b_lo) * (1.0 - REL) - a, times(b_hi) * (1.0 + REL) + a);
            if !(tau >= low && tau <= high) {
                return Err(fail(format!(
                    "τ = {tau:e} outside [{low:e}, {high:e}] (L = {len:e})"
                )));
            }
            families[k].worst = families[k].worst.max(
                ((tau - times(b_lo)).min(0.0).abs() + (tau - times(b_hi)).max(0.0))
                    / tau.max(1e-300),
            );
            if hi.is_finite() {
                let m = lo + (hi - lo) * rng.unit();
                let parts = fog.optical_depth(&ray, Interval::new(lo, m))
                    + fog.optical_depth(&ray, Interval::new(m, hi));
                if (parts - tau).abs() > REL * tau + 2.0 * a + f64::MIN_POSITIVE {
                    return Err(fail(format!(
                        "τ = {tau:e} but its two parts at {m} sum to {parts:e}"
                    )));
                }
            }
        }
        families[k].count(tau > 0.0);
    }
    tally.add(&families);
    Ok(())
}

#[test]
fn fog_layers() {
    let name = "fog";
    let cases = 400;
    let tally = Tally::new(name, &FAMILIES, "τ outside [B_lo L, B_hi L], relative");
    runner::run(name, cases, layer(), |(fog, seed)| {
        run_case(&fog, seed, &tally)
    });
    let total = tally.report();
    let planned = runner::cases(cases) * RAYS_PER_CASE as u64;
    assert!(total >= planned, "{name}: {total} rays, planned {planned}");
}
