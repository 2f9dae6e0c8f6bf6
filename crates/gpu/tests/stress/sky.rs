//! The sky under stress on the GPU (`SkyBatch`): Earth's atmosphere and variants (no Mie, no
//! ozone, 10× Rayleigh and Mie absorption), the ground at 0 or `±10^[−4, 4]`, suns from 27°
//! under the horizon to the zenith (irradiance 20, as the sky scenes'), the scenes' default
//! tables and march (16 steps); eyes on the ground (at it, 1 mm above, 1 m under: clamped),
//! inside, at the top (`±10^[−6, 0]` m), above it (`10^[5, 9]` m, and `10¹²`: clamped); per query
//! a direction exactly horizontal, grazing (`|d_y| = 10^[−16, −3]`), vertical, toward the sun's
//! azimuth at its elevation, or random; the ray from the eye or from a point `10^[0, 4]` m from it
//! (a secondary ray); ranges `0`, `10^[−3, 8]` m, `∞`.
//!
//! Per query: every answer a number, transmittances (aerial, to the sun, the table) in `[0, 1]`,
//! in-scatter, the sky-view table and the background `≥ 0`. Against the f64 adaptive-quadrature
//! reference (`fray_atmosphere::sky::reference`, as `tests/rays/sky.rs`), within that suite's
//! bounds: the aerial transmittance within `5·10⁻³` (one query in 8), the transmittance to the
//! sun within `10⁻³` (one in 8), the in-scatter within `5·10⁻²` of the brightest channel (one in
//! 64: the reference costs milliseconds). Where the f64 method itself (`Sky::aerial_perspective`,
//! `transmittance_to_sun`: the same march and table on the CPU) is already beyond a bound on a
//! query, the GPU may add at most the bound to the f64 method's error there; those queries are
//! counted. From eyes over `10⁸` m the aerial transmittance is held to `0.1` only (finding 10 of
//! `docs/stress.md`).

use crate::{cases, seed};
use fray_atmosphere::gpu_layout::{GpuSky, GpuSkyOptions};
use fray_atmosphere::sky::{Sky, SkyModel, SkySun, SkyTables, reference};
use fray_core::MemoryBudget;
use fray_gpu::GpuContext;
use fray_gpu::testing::{GpuSkyAnswer, GpuSkyQuery, SkyBatch, SkySeen, sky_query};
use fray_test_support::Rng;
use glam::DVec3;
use std::fmt;

pub const CASES: u32 = 24;
pub const QUERIES: usize = 4096;
/// The scenes' march (`default_sky_steps`), which the rays suite's bounds were measured at.
const STEPS: u32 = 16;
/// `tests/rays/sky.rs`'s bounds: aerial transmittance (absolute), in-scatter (relative to the
/// brightest channel, at least 10⁻³), transmittance to the sun (absolute).
const SKY_TRANSMITTANCE: f64 = 5e-3;
const SKY_IN_SCATTER: f64 = 5e-2;
const SKY_TO_SUN: f64 = 1e-3;
/// The aerial transmittance's bound from eyes over 10⁸ m (finding 10 of docs/stress.md:
/// measured 0.064).
const FAR_EYE_TRANSMITTANCE: f64 = 0.1;

const EYES: [&str; 4] = ["ground", "inside", "top", "above"];
const NAMES: [&str; 3] = ["transmittance", "in-scatter", "to the sun"];

/// What the sky's share found.
#[derive(Default)]
pub struct Summary {
    pub queries: u64,
    /// Reference comparisons made, per quantity.
    checked: [u64; 3],
    /// The GPU's worst error ÷ bound, per quantity, where the f64 method is within it.
    worst: [f64; 3],
    /// Queries where the f64 method itself is beyond the bound, per quantity and eye family,
    /// and the worst such error (÷ bound) of the f64 method and of the GPU.
    method: [[u64; 4]; 3],
    method_worst: [(f64, f64); 3],
    failures: Vec<String>,
    failed: u64,
    /// Eyes over 10⁸ m: transmittances checked, the GPU's and the f64 method's worst errors.
    far_eye: [f64; 3],
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "eyes over 10⁸ m: {} transmittances, GPU off ≤ {:.3e} (f64 method {:.3e}); ",
            self.far_eye[0], self.far_eye[1], self.far_eye[2]
        )?;
        for (q, name) in NAMES.iter().enumerate() {
            write!(
                f,
                "{name}: {} checked, worst {:.3e} of the bound; ",
                self.checked[q], self.worst[q]
            )?;
            let n: u64 = self.method[q].iter().sum();
            if n > 0 {
                write!(
                    f,
                    "the f64 method beyond it on {n} ({}), worst f64 {:.2} / GPU {:.2} of the bound; ",
                    EYES.iter()
                        .zip(self.method[q])
                        .filter(|e| e.1 > 0)
                        .map(|(e, k)| format!("{e} {k}"))
                        .collect::<Vec<_>>()
                        .join(", "),
                    self.method_worst[q].0,
                    self.method_worst[q].1
                )?;
            }
        }
        Ok(())
    }
}

/// Case `case`'s sky: the variant, the ground, the sun.
fn sky_case(rng: &mut Rng, case: u32) -> Sky {
    let mut model = SkyModel::earth();
    match case % 4 {
        0 => model.mie_scattering = 0.0,
        1 => model.ozone_absorption = DVec3::ZERO,
        2 => {
            model.rayleigh_scattering *= 10.0;
            model.mie_absorption *= 10.0;
        }
        _ => {}
    }
    if rng.unit() < 0.5 {
        let g = rng.range(-4.0, 4.0);
        model.ground_elevation = g.signum() * 10f64.powf(g.abs());
    }
    let elevation = rng.range(-0.3, 1.0) * std::f64::consts::FRAC_PI_2;
    let sun = SkySun::from_angles(elevation, rng.range(0.0, 6.3), DVec3::splat(20.0));
    Sky::new(model, sun, SkyTables::default(), &MemoryBudget::unlimited()).expect("a valid sky")
}

/// A query (eye-relative) and what it asks in f64: the ray's origin, direction, range and the
/// point the transmittance to the sun is asked at.
struct Query {
    origin: DVec3,
    dir: DVec3,
    t: f64,
    point: DVec3,
    table: (f64, f64),
}

fn query(rng: &mut Rng, i: usize, sun: DVec3, top: f64) -> Query {
    let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
    let a = rng.range(0.0, std::f64::consts::TAU);
    let dir = match i % 6 {
        0 => DVec3::new(a.cos(), 0.0, a.sin()),
        1 => DVec3::new(a.cos(), sign * rng.log_uniform(-16.0, -3.0), a.sin()).normalize(),
        2 => DVec3::Y * sign,
        // At the sun's azimuth, about its elevation (its glow, and under the horizon).
        3 => (sun + rng.direction() * rng.log_uniform(-4.0, -1.0)).normalize(),
        _ => rng.direction(),
    };
    let origin = if rng.unit() < 0.25 {
        rng.direction() * rng.log_uniform(0.0, 4.0)
    } else {
        DVec3::ZERO
    };
    let t = match rng.below(4) {
        0 => f64::INFINITY,
        1 => 0.0,
        _ => rng.log_uniform(-3.0, 8.0),
    };
    Query {
        origin,
        dir,
        t,
        point: origin + dir * t.min(1e4),
        table: (rng.range(-0.1, 1.1) * top, rng.range(-1.0, 1.0)),
    }
}

/// The sky's share: `CASES × QUERIES` queries.
pub fn skies(ctx: &GpuContext) -> Summary {
    let batch = SkyBatch::new(ctx).unwrap_or_else(|e| panic!("{e}"));
    let mut s = Summary::default();
    for case in 0..cases(CASES) {
        let mut rng = Rng(seed(0x5c1, case));
        let sky = sky_case(&mut rng, case);
        let m = *sky.model();
        let sun = sky.sun();
        let top = m.top_radius - m.ground_radius;
        let eye_kind = (case as usize / 4) % 4;
        let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        let altitude = match eye_kind {
            0 => [0.0, 1e-3, -1.0][rng.below(3)],
            1 => rng.range(0.0, top),
            2 => top + sign * rng.log_uniform(-6.0, 0.0),
            _ => [rng.log_uniform(5.0, 9.0), 1e12][usize::from(rng.unit() < 0.25)],
        };
        let eye = DVec3::new(
            rng.range(-1e5, 1e5),
            m.ground_elevation + altitude,
            rng.range(-1e5, 1e5),
        );
        let view = sky.view(eye);
        let options = GpuSkyOptions {
            sun_disc: rng.unit() < 0.5,
            aerial_perspective: true,
            steps: STEPS,
            sun_light: Some(0),
        };
        let block = GpuSky::new(&sky, eye.y, options);
        let queries: Vec<Query> = (0..QUERIES)
            .map(|i| query(&mut rng, i, sun.direction, top))
            .collect();
        let gpu_queries: Vec<GpuSkyQuery> = queries
            .iter()
            .map(|q| sky_query(q.origin, q.dir, q.t, q.point, q.table))
            .collect();
        let seen = SkySeen {
            block: &block,
            transmittance: sky.transmittance_table(),
            view: view.table(),
        };
        let answers = batch
            .answers(ctx, seen, &gpu_queries)
            .unwrap_or_else(|e| panic!("{e}"));
        for (i, (q, a)) in queries.iter().zip(&answers).enumerate() {
            s.queries += 1;
            check(&sky, eye, eye_kind, i, q, a, &mut s, case);
        }
    }
    assert!(
        s.failed == 0,
        "the sky on the GPU: {} queries failed ({s}), e.g.\n  {}",
        s.failed,
        s.failures.join("\n  ")
    );
    s
}

#[allow(clippy::too_many_arguments)]
fn check(
    sky: &Sky,
    eye: DVec3,
    eye_kind: usize,
    i: usize,
    q: &Query,
    a: &GpuSkyAnswer,
    s: &mut Summary,
    case: u32,
) {
    let m = sky.model();
    let rgb = |v: [f32; 3]| DVec3::from(v.map(f64::from));
    let (t_gpu, s_gpu, sun_gpu) = (rgb(a.transmittance), rgb(a.in_scatter), rgb(a.to_sun));
    let mut bad: Vec<String> = Vec::new();
    let unit = |v: DVec3| v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= 1.0;
    let positive = |v: DVec3| v.is_finite() && v.min_element() >= 0.0;
    if !(unit(t_gpu)
        && unit(sun_gpu)
        && unit(rgb(a.table))
        && positive(s_gpu)
        && positive(rgb(a.view))
        && positive(rgb(a.background)))
    {
        bad.push("nonsense".into());
    }
    let from = eye + q.origin;
    // Eyes over 10⁸ m: the GPU's aerial transmittance is bounded apart (finding 10).
    let far_eye = eye.y - m.ground_elevation > 1e8;
    if !bad.is_empty() {
        return report(s, sky, eye, eye_kind, q, a, case, bad);
    }
    // The rays suite's rule, with the f64 method's own error where it exceeds the bound.
    if i.is_multiple_of(8) {
        let cpu = sky.aerial_perspective(from, q.dir, q.t, STEPS);
        let (truth_t, truth_s) = if i.is_multiple_of(64) {
            let truth = reference::single_scattering(m, sky.sun(), from, q.dir, q.t);
            (truth.transmittance, Some(truth.in_scatter))
        } else {
            (reference::transmittance(m, from, q.dir, q.t), None)
        };
        let err = |v: DVec3| (v - truth_t).abs().max_element();
        if far_eye {
            s.far_eye[0] += 1.0;
            s.far_eye[1] = s.far_eye[1].max(err(t_gpu));
            s.far_eye[2] = s.far_eye[2].max(err(cpu.transmittance));
            if err(t_gpu) > FAR_EYE_TRANSMITTANCE {
                bad.push(format!(
                    "transmittance off by {:.3e} from an eye over 10⁸ m (bound {FAR_EYE_TRANSMITTANCE})",
                    err(t_gpu)
                ));
            }
        } else {
            compare(
                s,
                &mut bad,
                eye_kind,
                0,
                err(t_gpu),
                err(cpu.transmittance),
                SKY_TRANSMITTANCE,
            );
        }
        if let Some(truth) = truth_s {
            let bright = truth.max_element().max(1e-3);
            let err = |v: DVec3| (v - truth).abs().max_element() / bright;
            compare(
                s,
                &mut bad,
                eye_kind,
                1,
                err(s_gpu),
                err(cpu.in_scatter),
                SKY_IN_SCATTER,
            );
        }
        let p = eye + q.point;
        let truth = reference::transmittance_to_sun(m, sky.sun(), p, eye);
        let err = |v: DVec3| (v - truth).abs().max_element();
        compare(
            s,
            &mut bad,
            eye_kind,
            2,
            err(sun_gpu),
            err(sky.transmittance_to_sun(p, eye)),
            SKY_TO_SUN,
        );
    }
    report(s, sky, eye, eye_kind, q, a, case, bad);
}

/// The rays suite's rule for quantity `k`: the GPU's error `gpu` within `bound`, or, where the
/// f64 method's error `cpu` is already beyond it, within `cpu + bound`.
#[allow(clippy::too_many_arguments)]
fn compare(
    s: &mut Summary,
    bad: &mut Vec<String>,
    eye_kind: usize,
    k: usize,
    gpu: f64,
    cpu: f64,
    bound: f64,
) {
    s.checked[k] += 1;
    if cpu > bound {
        s.method[k][eye_kind] += 1;
        let w = &mut s.method_worst[k];
        *w = (w.0.max(cpu / bound), w.1.max(gpu / bound));
        if gpu > cpu + bound {
            bad.push(format!(
                "{} off by {gpu:.3e} where the f64 method is off by {cpu:.3e}",
                NAMES[k]
            ));
        }
    } else if gpu > bound {
        bad.push(format!(
            "{} off by {gpu:.3e} (bound {bound:e}; the f64 method {cpu:.3e})",
            NAMES[k]
        ));
    } else {
        s.worst[k] = s.worst[k].max(gpu / bound);
    }
}

/// Counts `bad` as failures of the query, keeping the first few described.
#[allow(clippy::too_many_arguments)]
fn report(
    s: &mut Summary,
    sky: &Sky,
    eye: DVec3,
    eye_kind: usize,
    q: &Query,
    a: &GpuSkyAnswer,
    case: u32,
    bad: Vec<String>,
) {
    for what in bad {
        s.failed += 1;
        if s.failures.len() < 8 {
            s.failures.push(format!(
                "case {case} ({} eye at {:?}, sun {:?}, ground {}): {what} for origin {:?} dir \
                 {:?} t {} point {:?} table {:?}: GPU {a:?}",
                EYES[eye_kind],
                eye,
                sky.sun().direction,
                sky.model().ground_elevation,
                q.origin,
                q.dir,
                q.t,
                q.point,
                q.table
            ));
        }
    }
}
