//! Clouds under stress: density grids `2..12` cells a side — homogeneous, random, sparse blobs
//! in empty space —, over boxes `10^[−3, 6]` m a side (aspect up to 100 : 1), a third of them
//! `10⁵` from the origin, extinction `10^[−9, 2]` per box size; march steps of `1/4 .. 1/256`
//! diagonal, any jitter, with and without the early exit; rays from outside, from inside, exactly
//! horizontal, grazing a face (`10^[−15, −3]` off it), along the axes, from `10⁵` away, over
//! ranges `0..∞` and segments — `march::march` (with and without the max grid's skipping) and
//! `march::optical_depth`.
//!
//! The reference is the volume's definition: the part of the range inside the box (its slabs,
//! computed here) of length `L`, and the trilinear density's range `[min, max]` of the samples
//! times the scale. Per ray:
//! - **no nonsense**: `T ∈ [0, 1]`, in-scatter finite and `≥ 0`, no more samples than
//!   `⌈L / step⌉`;
//! - **skipping is lossless**: the march with the max grid equals the one without, bit for bit
//!   (`docs/clouds.md`);
//! - **bracket**: `τ` (`optical_depth`, and `−ln T` of a march without the early exit) in
//!   `[σ_min L, σ_max L]` — every midpoint lies in the box —, relative `1e-9` plus the
//!   clip's rounding (and `T`'s, a product of a factor per sample: `(2n + 8) u` of `τ`); with the early exit, `T` no lower than `e^{−σ_max L}`;
//! - **additive**: over a split, the parts' `τ` are in their brackets, and on a homogeneous
//!   grid they sum to the whole within `1e-12` relative.

use super::runner::{self, Family, Tally};
use fray_clouds::DensityGrid;
use fray_clouds::bake::Region;
use fray_clouds::march::{self, CloudLight, DualLobe, GridVolume, MarchSettings};
use fray_core::MemoryBudget;
use fray_test_support::Rng;
use glam::DVec3;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const U: f64 = f64::EPSILON / 2.0;
const FAMILIES: [&str; 7] = [
    "outside",
    "inside",
    "horizontal",
    "grazing",
    "axes",
    "far camera",
    "segment",
];
const RAYS_PER_CASE: usize = 2048;
const REL: f64 = 1e-9;

/// One volume: its grid's kind and size, the box, the extinction scale, the march and a seed.
#[derive(Clone, Debug)]
pub struct CloudCase {
    kind: u8,
    size: [usize; 3],
    extent: DVec3,
    far: bool,
    extinction: f64,
    steps_per_diagonal: f64,
    early_exit: bool,
    seed: u64,
}

fn cloud_case() -> impl Strategy<Value = CloudCase> {
    (
        (0..3u8, [2..13usize, 2..13usize, 2..13usize]),
        (
            -3.0..6.0f64,
            [-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64],
            0..3u8,
        ),
        (-9.0..2.0f64, 0.6..2.4f64, any::<bool>(), any::<u64>()),
    )
        .prop_map(
            |((kind, size), (e, aspect, far), (x, s, early_exit, seed))| {
                let base = 10f64.powf(e);
                CloudCase {
                    kind,
                    size,
                    extent: DVec3::from_array(aspect.map(|a| base * 10f64.powf(a))),
                    far: far == 0,
                    extinction: 10f64.powf(x),
                    steps_per_diagonal: 10f64.powf(s),
                    early_exit,
                    seed,
                }
            },
        )
}

/// The part of `[lo, hi]` of `o + t d` inside `[min, max]`, independent of the crate's clip.
fn slab(min: DVec3, max: DVec3, o: DVec3, d: DVec3, lo: f64, hi: f64) -> Option<(f64, f64)> {
    let (mut a, mut b) = (lo, hi);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < min[k] || o[k] > max[k] {
                return None;
            }
        } else {
            let (p, q) = ((min[k] - o[k]) / d[k], (max[k] - o[k]) / d[k]);
            a = a.max(p.min(q));
            b = b.min(p.max(q));
        }
    }
    (a <= b).then_some((a, b))
}

#[allow(clippy::too_many_lines)]
fn run_case(case: &CloudCase, tally: &Tally) -> Result<(), TestCaseError> {
    let mut rng = Rng(case.seed);
    let centre = if case.far {
        rng.direction() * 1e5
    } else {
        DVec3::ZERO
    };
    let (min, max) = (centre - 0.5 * case.extent, centre + 0.5 * case.extent);
    let region = Region {
        min: min.to_array(),
        max: max.to_array(),
    };
    let blobs: Vec<DVec3> = (0..3)
        .map(|_| rng.in_box(DVec3::ZERO, DVec3::ONE))
        .collect();
    let homogeneous = rng.unit();
    let size = case.size;
    let grid = DensityGrid::from_fn(size, &MemoryBudget::unlimited(), |i, j, k| {
        let p = DVec3::new(i as f64, j as f64, k as f64)
            / DVec3::new(size[0] as f64, size[1] as f64, size[2] as f64);
        match case.kind {
            0 => homogeneous as f32,
            1 => ((p.x * 7.3 + p.y * 3.1 + p.z * 5.7).sin() * 0.5 + 0.5) as f32,
            _ => blobs
                .iter()
                .map(|b| (1.0 - 3.0 * (p - *b).length()).max(0.0))
                .fold(0.0, f64::max) as f32,
        }
    })
    .expect("a small grid");
    let (g_min, g_max) = grid
        .data()
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| {
            (a.min(f64::from(v)), b.max(f64::from(v)))
        });
    let diag = case.extent.length();
    let scale = case.extinction / diag;
    let skip = grid.max_grid(2);
    let plain = GridVolume {
        grid,
        region,
        scale,
        skip: None,
    };
    let skipping = GridVolume {
        skip: Some(skip),
        ..plain.clone()
    };
    let (s_min, s_max) = (scale * g_min, scale * g_max);
    let step = diag / case.steps_per_diagonal;
    let light = CloudLight {
        sun_direction: rng.direction().to_array(),
        sun_irradiance: [3.0, 2.0, 1.0],
        ambient: [0.1, 0.2, 0.3],
        albedo: 0.9,
        phase: DualLobe {
            g1: 0.8,
            g2: -0.3,
            weight: 0.2,
        },
    };
    let mut families = [Family::default(); FAMILIES.len()];
    for i in 0..RAYS_PER_CASE {
        let k = i % FAMILIES.len();
        let settings = MarchSettings {
            step,
            sun_steps: 1 + rng.below(8) as u32,
            jitter: rng.unit(),
            min_transmittance: if case.early_exit { 1e-3 } else { 0.0 },
        };
        let inside = rng.in_box(min, max);
        let dist = diag * rng.range(0.6, 3.0);
        let full = (0.0, f64::INFINITY);
        let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        let (o, d, range) = match k {
            1 => (inside, rng.direction(), full),
            2 => {
                let a = rng.range(0.0, std::f64::consts::TAU);
                let d = DVec3::new(a.cos(), 0.0, a.sin());
                (inside - d * dist, d, full)
            }
            3 => {
                // In a face's plane, a hair inside or outside, tilted a hair.
                let axis = rng.below(3);
                let mut p = inside;
                p[axis] = if rng.unit() < 0.5 {
                    min[axis]
                } else {
                    max[axis]
                } + sign * case.extent[axis] * rng.log_uniform(-15.0, -3.0);
                let mut d = rng.direction();
                d[axis] = sign * rng.log_uniform(-15.0, -3.0);
                let d = d.normalize();
                (p - d * dist, d, full)
            }
            4 => {
                let mut d = DVec3::ZERO;
                d[rng.below(3)] = sign;
                (inside - d * dist, d, full)
            }
            5 => {
                let d = rng.direction();
                (inside - d * rng.range(1e5, 3e5), d, full)
            }
            6 => {
                let d = rng.direction();
                let lo = dist + diag * rng.range(-0.5, 0.5);
                (
                    inside - d * dist,
                    d,
                    (lo.max(0.0), lo.max(0.0) + diag * rng.log_uniform(-6.0, 0.0)),
                )
            }
            _ => {
                let d = rng.direction();
                (inside - d * dist, d, full)
            }
        };
        let (oa, da) = (o.to_array(), d.to_array());
        let fail = |what: String| {
            TestCaseError::fail(format!(
                "{} ray through {case:?}: {what} for o {o:?}, d {d:?} over {range:?}",
                FAMILIES[k]
            ))
        };
        let m = march::march(&plain, oa, da, range, &settings, &light);
        let ms = march::march(&skipping, oa, da, range, &settings, &light);
        // (The samples taken differ: that is what skipping saves.)
        if (m.transmittance, m.in_scatter) != (ms.transmittance, ms.in_scatter) {
            return Err(fail(format!("skipping changed the march: {m:?} vs {ms:?}")));
        }
        let t = m.transmittance;
        if !((0.0..=1.0).contains(&t) && m.in_scatter.iter().all(|c| c.is_finite() && *c >= 0.0)) {
            return Err(fail(format!("{m:?}")));
        }
        let span = slab(min, max, o, d, range.0, range.1);
        let len = span.map_or(0.0, |(a, b)| b - a);
        // The clip's rounding: the ends move by a few ulps of the coordinates over |d| per axis.
        let a = s_max * 8.0 * U * (o.abs().max_element() + max.abs().max_element()) * 3.0
            / d.abs().max_element()
            + 1e-300;
        let bracket = |tau: f64, len: f64, extra: f64, what: &str| -> Result<f64, TestCaseError> {
            let a = a + extra;
            let (low, high) = (s_min * len * (1.0 - REL) - a, s_max * len * (1.0 + REL) + a);
            if !(tau >= low && tau <= high) {
                return Err(fail(format!(
                    "{what} τ = {tau:e} outside [{low:e}, {high:e}] (L = {len:e})"
                )));
            }
            Ok((tau - s_max * len).max(s_min * len - tau).max(0.0) / tau.max(a).max(1e-300))
        };
        if f64::from(m.samples) > (len / step).ceil() + 1.0 {
            return Err(fail(format!("{} samples over L = {len:e}", m.samples)));
        }
        if t > 0.0 {
            let tau = -t.ln();
            if case.early_exit {
                if tau > s_max * len * (1.0 + REL) + a + f64::from(2 * m.samples + 8) * U {
                    return Err(fail(format!("T = {t:e} below e^(−σ_max L), L = {len:e}")));
                }
            } else {
                families[k].worst = families[k].worst.max(bracket(
                    tau,
                    len,
                    f64::from(2 * m.samples + 8) * U,
                    "the march's",
                )?);
            }
        }
        let tau = march::optical_depth(&plain, oa, da, range, step);
        bracket(tau, len, 0.0, "optical_depth's")?;
        if let Some((lo, hi)) = span.filter(|s| s.1.is_finite() && s.1 > s.0) {
            let mid = lo + (hi - lo) * rng.unit();
            let (p1, p2) = (
                march::optical_depth(&plain, oa, da, (range.0, mid), step),
                march::optical_depth(&plain, oa, da, (mid, range.1), step),
            );
            bracket(p1, mid - lo, 0.0, "the first part's")?;
            bracket(p2, hi - mid, 0.0, "the second part's")?;
            if case.kind == 0 && ((p1 + p2) - tau).abs() > 1e-12 * tau + 2.0 * a {
                return Err(fail(format!(
                    "homogeneous τ = {tau:e}, its parts at {mid} sum to {:e}",
                    p1 + p2
                )));
            }
        }
        families[k].count(len > 0.0);
    }
    tally.add(&families);
    Ok(())
}

#[test]
fn clouds() {
    let name = "clouds";
    let cases = 150;
    let tally = Tally::new(
        name,
        &FAMILIES,
        "the march's τ outside [σ_min L, σ_max L], relative",
    );
    runner::run(name, cases, cloud_case(), |case| run_case(&case, &tally));
    let total = tally.report();
    let planned = runner::cases(cases) * RAYS_PER_CASE as u64;
    assert!(total >= planned, "{name}: {total} rays, planned {planned}");
}
