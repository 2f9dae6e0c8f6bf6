//! The GPU's share of the numerical stress suite (issue 27; the CPU's is
//! `crates/trace/tests/stress/`, `docs/stress.md`): ~2·10⁶ adversarial rays through the batch
//! kernels of `fray_gpu::testing`, seeded (the same rays every run; `FRAY_STRESS_SEED` changes
//! them, `FRAY_STRESS_SCALE` multiplies the cases), each answer checked for nonsense and against
//! an f64 reference within the bounds the rays suite (`tests/rays/`) states for the GPU. One
//! trial per kind or medium, each in its module, each printing its ray count, time and worst
//! figures:
//! - [`terrains`] (`TerrainBatch`), [`meshes`] (`MeshBatch`), [`fog`] (`FogBatch`);
//! - [`free_forms`] (`FreeFormBatch`): perturbed ellipsoids, CSG trees, degenerate quadrics
//!   clipped by boxes and extreme form factors, scaled `10^[−3, 6]`, a third `10⁵` from the
//!   origin; cameras near, inside, `10²`–`10⁴` diagonals and `10⁵` away; grazing, tangent, axis,
//!   seam and support rays — against `F` sampled and bisected in f64;
//! - [`sky`] (`SkyBatch`): eyes from the ground to `10⁹` m, suns from under the horizon to the
//!   zenith, grazing directions, ranges `0` to unbounded — against the adaptive-quadrature
//!   reference;
//! - [`clouds`] (`CloudsBatch`): rays from inside, along the base and top planes, grazing the
//!   box, from far away — against the optical depth at a 64th of the step.
//!
//! Uses the libtest-mimic harness: ignored without an adapter, a failure under
//! `FRAY_REQUIRE_GPU=1`.

#[path = "../common/mod.rs"]
mod common;

mod clouds;
mod fog;
mod free_forms;
mod meshes;
mod sky;
mod terrains;

use fray_core::{Interval, Ray};
use fray_gpu::GpuContext;
use fray_gpu::testing::GpuRay;
use fray_test_support::Rng;
use glam::DVec3;
use std::time::{Duration, Instant};

/// `cases × FRAY_STRESS_SCALE`.
pub fn cases(n: u32) -> u32 {
    let scale = std::env::var("FRAY_STRESS_SCALE")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0);
    (f64::from(n) * scale).ceil() as u32
}

/// The seed of case `k` of test `salt`.
pub fn seed(salt: u64, k: u32) -> u64 {
    let extra = std::env::var("FRAY_STRESS_SEED")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(0);
    Rng(salt ^ extra.rotate_left(17) ^ u64::from(k).wrapping_mul(0x9E37_79B9_7F4A_7C15)).next_u64()
}

/// `rays` as the batches take them: f32, relative to `reference`, `t_hi` at most 1e30.
pub fn relative(rays: &[(Ray, Interval)], reference: DVec3) -> Vec<GpuRay> {
    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
    rays.iter()
        .map(|(r, range)| {
            let (o, d) = (f(r.origin - reference), f(r.dir));
            [
                [o[0], o[1], o[2], range.lo as f32],
                [d[0], d[1], d[2], range.hi.min(1e30) as f32],
            ]
        })
        .collect()
}

/// A ray's range: a fifth of them a segment starting between half the distance to the target
/// and the target, up to a diagonal long; the others `[0, ∞)`.
pub fn case_range(rng: &mut Rng, to_target: f64, diag: f64) -> Interval {
    if rng.unit() < 0.2 {
        let lo = to_target * rng.range(0.5, 1.0);
        Interval::new(lo, lo + diag * rng.log_uniform(-3.0, 0.0))
    } else {
        Interval::new(0.0, f64::INFINITY)
    }
}

/// Runs one module's share on a fresh GPU context and prints its ray count and time.
fn trial(name: &str, run: impl FnOnce(&GpuContext) -> (u64, String)) -> (u64, Duration) {
    let renderer = common::gpu(&format!("stress {name}"));
    let clock = Instant::now();
    let (rays, detail) = run(renderer.context());
    let time = clock.elapsed();
    println!("gpu stress: {name}: {rays} rays in {time:.1?} ({detail})");
    (rays, time)
}

/// Fails unless `rays` reached the planned `cases × per_case`.
fn planned(name: &str, rays: u64, cases: u32, per_case: usize) {
    let planned = u64::from(cases) * per_case as u64;
    assert!(rays >= planned, "{name}: {rays} rays, planned {planned}");
}

fn terrains_trial() {
    let (rays, _) = trial("terrains", |ctx| {
        let (rays, worst, base_slivers) = terrains::terrains(ctx);
        (
            rays,
            format!(
                "worst |Δt| cos θ ÷ depth bound {worst:.3e}; {base_slivers} base slivers thinner \
                 than the bound stepped over"
            ),
        )
    });
    planned("terrains", rays, cases(48), terrains::TERRAIN_RAYS);
}

fn meshes_trial() {
    let (rays, _) = trial("meshes", |ctx| {
        let (rays, worst, excused) = meshes::meshes(ctx);
        (
            rays,
            format!("worst depth ÷ bound {worst:.3e}; {excused} excused at edges or grazed faces"),
        )
    });
    planned("meshes", rays, cases(24), meshes::MESH_RAYS);
}

fn fog_trial() {
    let (rays, _) = trial("fog", |ctx| {
        let (rays, worst) = fog::fogs(ctx);
        (rays, format!("worst |ΔT| ÷ bound {worst:.3e}"))
    });
    planned("fog", rays, cases(40), fog::FOG_RAYS);
}

fn free_forms_trial() {
    let (rays, _) = trial("free forms", |ctx| {
        let s = free_forms::free_forms(ctx);
        (s.rays, s.to_string())
    });
    planned(
        "free forms",
        rays,
        cases(free_forms::CASES),
        free_forms::RAYS,
    );
}

fn sky_trial() {
    let (rays, _) = trial("sky", |ctx| {
        let s = sky::skies(ctx);
        (s.queries, s.to_string())
    });
    planned("sky", rays, cases(sky::CASES), sky::QUERIES);
}

fn clouds_trial() {
    let (rays, _) = trial("clouds", |ctx| {
        let s = clouds::clouds(ctx);
        (s.rays, s.to_string())
    });
    planned("clouds", rays, cases(clouds::CASES), clouds::RAYS);
}

fn main() {
    common::run(
        &[
            ("terrains", terrains_trial),
            ("meshes", meshes_trial),
            ("fog", fog_trial),
            ("free_forms", free_forms_trial),
            ("sky", sky_trial),
            ("clouds", clouds_trial),
        ],
        &[],
    );
}
