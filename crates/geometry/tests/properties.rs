//! Property tests of the ray caster on perturbed free forms and CSG trees, against dense sampling.
//!
//! Objects: an ellipsoid base (random centre, radii, rotation) with 1–8 random ellipsoid
//! perturbations of either sign; and CSG trees of depth ≤ 3 of such objects (union, intersection,
//! difference). Rays: random, grazing the surface (offset `±δ` along the normal, `δ ∈ [1e-6,
//! 1e-3]`), and exactly tangent to a perturbation's support boundary `Q = 0`. 600 + 600 cases ×
//! 100 rays = 1.2 × 10⁵ rays.
//!
//! Reference: `solid.eval(ray.at(t))` sampled at `N = 1000` equal steps `h` over the cast range
//! (the ray's part inside the solid's box). Properties, with `ε = 1e-10 × max(diagonal, 1)`:
//! - **never a later root:** if a sample `t_k` is inside by more than `TOL` (`eval ≥ TOL`), the
//!   cast hits at `t ≤ t_k + ε`;
//! - **a real surface:** if the cast hits at `t`, then `max eval` over `[t − ε, t + ε]` (9 points)
//!   is `≥ −TOL`; `t` is not NaN, `t ≥ range.lo ≥ 0` (never behind the ray's origin);
//! - **deterministic:** casting the same ray twice gives the same bits.
//!
//! `TOL = 1e-9`: values here are O(1) (the base is `1 − Σ(xᵢ/rᵢ)²`, perturbations `f Q³` with
//! `|f| ≤ 1.5`, `Q ≤ 1`), the cast evaluates the ray-restricted polynomials and `eval` the world
//! point, so the two agree to ~1e-14; `TOL` also keeps a sample that is inside only by rounding
//! (at a tangency) from counting as a surface the cast must find. The slope of `F′` is at most
//! ~10², so over `ε` it changes by < 1e-7 · ε — the 9-point window absorbs it.

use fray_core::{Interval, Ray};
use fray_geometry::{
    CastMethod, CastStats, FreeForm, Perturbation, Quadric, RayCaster, Shape, Solid,
};
use glam::{DAffine3, DQuat, DVec3, EulerRot};
use proptest::prelude::*;

const SAMPLES: usize = 1000;
const RAYS_PER_CASE: usize = 100;
const TOL: f64 = 1e-9;

mod common;
use common::rng::Rng;

fn vec3(lo: f64, hi: f64) -> impl Strategy<Value = DVec3> {
    (lo..hi, lo..hi, lo..hi).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// A solid ellipsoid `1 − Σ(xᵢ/rᵢ)²` with a random centre, radii and orientation.
fn ellipsoid(centre: (f64, f64), radii: (f64, f64)) -> impl Strategy<Value = Quadric> {
    (
        vec3(centre.0, centre.1),
        vec3(radii.0, radii.1),
        vec3(-3.2, 3.2),
    )
        .prop_map(|(c, r, a)| {
            let t = DAffine3::from_rotation_translation(
                DQuat::from_euler(EulerRot::XYZ, a.x, a.y, a.z),
                c,
            );
            Quadric::ellipsoid(DVec3::ZERO, r)
                .transformed(&t)
                .expect("rotation is invertible")
        })
}

fn perturbation() -> impl Strategy<Value = Perturbation> {
    (
        prop_oneof![-1.5..-0.05, 0.05..1.5f64],
        ellipsoid((-1.6, 1.6), (0.15, 0.8)),
    )
        .prop_map(|(f, q)| Perturbation::new(f, q))
}

fn free_form() -> impl Strategy<Value = FreeForm> {
    (
        ellipsoid((-0.5, 0.5), (0.5, 1.5)),
        prop::collection::vec(perturbation(), 1..=8),
    )
        .prop_map(|(base, perts)| FreeForm::new(base, perts, None).expect("ellipsoids are bounded"))
}

/// A plain ellipsoid (no perturbation), half the time clipped by a box that may cut it, so its
/// faces are surface too.
fn plain_free_form() -> impl Strategy<Value = FreeForm> {
    (
        ellipsoid((-0.5, 0.5), (0.5, 1.5)),
        vec3(-0.8, 0.8),
        vec3(0.3, 1.6),
        any::<bool>(),
    )
        .prop_map(|(base, centre, half, clip)| {
            let bounds = clip.then(|| fray_core::Aabb::from_center_half(centre, half));
            FreeForm::new(base, vec![], bounds).expect("ellipsoids are bounded")
        })
}

/// CSG trees of depth ≤ 3 over free forms.
fn shape() -> impl Strategy<Value = Shape> {
    tree_of(free_form())
}

/// CSG trees of depth ≤ 3 over `leaf`.
fn tree_of(leaf: impl Strategy<Value = FreeForm> + 'static) -> impl Strategy<Value = Shape> {
    leaf.prop_map(Shape::FreeForm)
        .prop_recursive(3, 12, 3, |inner| {
            prop_oneof![
                prop::collection::vec(inner.clone(), 2..=3).prop_map(Shape::Union),
                prop::collection::vec(inner.clone(), 2..=3).prop_map(Shape::Intersection),
                (inner.clone(), inner)
                    .prop_map(|(a, b)| Shape::Difference(Box::new(a), Box::new(b))),
            ]
        })
}

/// Why a ray was cast (for failure messages and the tally).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Random = 0,
    Grazing = 1,
    SupportTangent = 2,
}

/// Checks the three properties for one ray; returns whether it hit.
fn check(
    solid: &Solid,
    caster: &mut RayCaster,
    ray: &Ray,
    kind: Kind,
    tally: &mut Tally,
) -> Result<(), TestCaseError> {
    let eps = 1e-10 * solid.bounds().diagonal().max(1.0);
    let full = Interval::new(0.0, f64::INFINITY);
    let mut stats = CastStats::default();
    let hit = caster.cast(solid, ray, full, eps, &mut stats);
    tally.stats += stats;
    let again = caster.cast(solid, ray, full, eps, &mut stats);
    // The any-hit query (shadow rays) answers yes wherever the first-hit search hits; it may
    // also say yes where the search stepped over a span shorter than ε (checked below against
    // the dense reference: only where no sample is clearly inside).
    let mut any_stats = CastStats::default();
    let occludes = caster.occludes(solid, ray, full, eps, None, &mut any_stats);
    tally.any_stats += any_stats;
    if hit.is_some() {
        prop_assert!(
            occludes,
            "any-hit missed the hit at {:?} ({:?}) for {:?}",
            hit,
            kind,
            ray
        );
    }
    tally.rays[kind as usize] += 1;
    tally.hits[kind as usize] += usize::from(hit.is_some());
    prop_assert_eq!(
        hit.map(f64::to_bits),
        again.map(f64::to_bits),
        "not deterministic ({:?}) for {:?}",
        kind,
        ray
    );

    let range = solid.bounds().clip_ray(ray, full);
    let Some(range) = range else {
        prop_assert!(
            hit.is_none(),
            "hit {:?} outside the solid's box ({:?})",
            hit,
            kind
        );
        return Ok(());
    };
    if let Some(t) = hit {
        prop_assert!(!t.is_nan(), "NaN depth ({:?}) for {:?}", kind, ray);
        prop_assert!(
            t >= range.lo && t >= 0.0,
            "t = {} before the range start {} ({:?})",
            t,
            range.lo,
            kind
        );
        prop_assert!(
            t <= range.hi,
            "t = {} after the range end {} ({:?})",
            t,
            range.hi,
            kind
        );
        let near = (-4..=4)
            .map(|j| solid.eval(ray.at(t + f64::from(j) * 0.25 * eps)))
            .fold(f64::NEG_INFINITY, f64::max);
        prop_assert!(
            near >= -TOL,
            "hit at t = {} is not on a surface: max F′ near it = {:e} ({:?}) for {:?}",
            t,
            near,
            kind,
            ray
        );
    }
    // Dense reference: the first clearly-inside sample.
    let h = (range.hi - range.lo) / SAMPLES as f64;
    let first_inside = (0..=SAMPLES)
        .map(|i| range.lo + h * i as f64)
        .find(|&t| solid.eval(ray.at(t)) >= TOL);
    if occludes && hit.is_none() {
        tally.any_only += 1;
        prop_assert!(
            first_inside.is_none(),
            "any-hit says blocked, the first-hit search missed a sample inside ({:?}) for {:?}",
            kind,
            ray
        );
    }
    if let Some(tk) = first_inside {
        tally.reference_hits += 1;
        match hit {
            Some(t) => prop_assert!(
                t <= tk + eps,
                "later root: cast {} but the sample at {} is inside (F′ = {:e}) ({:?}) for {:?}",
                t,
                tk,
                solid.eval(ray.at(tk)),
                kind,
                ray
            ),
            None => prop_assert!(
                false,
                "missed: the sample at {} is inside (F′ = {:e}) ({:?}) for {:?}",
                tk,
                solid.eval(ray.at(tk)),
                kind,
                ray
            ),
        }
    }
    Ok(())
}

/// Casts `RAYS_PER_CASE` rays at `solid`: 60 % random, 25 % grazing its surface, 15 % tangent to
/// a perturbation's support boundary (when it has perturbations on any leaf).
fn cast_many(
    solid: &Solid,
    seed: u64,
    tally: &mut Tally,
    method: CastMethod,
) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let mut caster = RayCaster::with_method(method);
    let supports: Vec<Quadric> = solid
        .leaves()
        .iter()
        .flat_map(|l| l.perturbations().iter().map(|p| p.quadric))
        .collect();
    let b = solid.bounds();
    let (box_min, box_max) = if b.is_empty() {
        (DVec3::splat(-2.0), DVec3::splat(2.0))
    } else {
        (b.min - 0.1 * (b.max - b.min), b.max + 0.1 * (b.max - b.min))
    };
    let mut done = 0;
    let mut failed_attempts = 0;
    while done < RAYS_PER_CASE {
        // 12 in 20 random, 5 in 20 grazing, 3 in 20 support-tangent; a kind that cannot be
        // built (an empty solid, no perturbations) falls back to random after 200 tries.
        let wanted = match done % 20 {
            0..12 => Kind::Random,
            12..17 => Kind::Grazing,
            _ => Kind::SupportTangent,
        };
        let origin = rng.direction() * rng.range(4.0, 8.0);
        let target = DVec3::new(
            rng.range(box_min.x, box_max.x),
            rng.range(box_min.y, box_max.y),
            rng.range(box_min.z, box_max.z),
        );
        let random = Ray::new(origin, target - origin).expect("distinct points");
        let (ray, kind) = if wanted == Kind::Random || failed_attempts > 200 {
            (random, Kind::Random)
        } else if wanted == Kind::Grazing {
            failed_attempts += 1;
            // Grazing: through a surface point found by a first cast, along a tangent.
            let Some(t) = solid.cast(&random, Interval::new(0.0, f64::INFINITY), 1e-12) else {
                continue;
            };
            let p = random.at(t);
            let (n, _) = solid.surface_at(p, -random.dir);
            let w = rng.direction();
            let Some(d) = (w - n * w.dot(n)).try_normalize() else {
                continue;
            };
            let delta = 10f64.powf(rng.range(-6.0, -3.0));
            let side = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
            let Some(ray) = Ray::new(p - n * (side * delta) - d * 6.0, d) else {
                continue;
            };
            (ray, Kind::Grazing)
        } else {
            // Exactly tangent to a support ellipsoid Q = 0 (up to rounding).
            failed_attempts += 1;
            if supports.is_empty() {
                continue;
            }
            let q = supports[(rng.next_u64() % supports.len() as u64) as usize];
            let u = rng.direction();
            let Some(axis) = Ray::new(q.origin, u) else {
                continue;
            };
            let a = q.on_ray(&axis).a; // Q(origin + s u) = a s² + 1 (centred ellipsoid)
            if a >= 0.0 {
                continue;
            }
            let p = q.origin + u * (-1.0 / a).sqrt();
            let g = q.gradient(p);
            let w = rng.direction();
            let Some(d) = (w - g * (w.dot(g) / g.length_squared())).try_normalize() else {
                continue;
            };
            let Some(ray) = Ray::new(p - d * rng.range(3.0, 6.0), d) else {
                continue;
            };
            (ray, Kind::SupportTangent)
        };
        check(solid, &mut caster, &ray, kind, tally)?;
        failed_attempts = 0;
        done += 1;
    }
    Ok(())
}

/// `cases` cases from a fixed seed, so every run checks the same objects (set
/// `PROPTEST_RNG_SEED` to explore others); no failure files are written.
fn config(cases: u32) -> ProptestConfig {
    let mut config = ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    };
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        config.rng_seed = proptest::test_runner::RngSeed::Fixed(0x0F4A_7C15);
    }
    config
}

/// Rays cast and hits, by kind, plus the caster's work (summed over a run).
#[derive(Debug, Default)]
struct Tally {
    rays: [usize; 3],
    hits: [usize; 3],
    reference_hits: usize,
    stats: CastStats,
    /// The any-hit queries' work, and how often they alone said blocked (a span shorter than ε).
    any_stats: CastStats,
    any_only: usize,
}

/// Runs `cases` proptest cases of `strategy`, each casting `RAYS_PER_CASE` rays, and prints the
/// tally (run with `--nocapture` to see it).
fn run<S: Strategy>(
    name: &str,
    method: CastMethod,
    cases: u32,
    strategy: S,
    to_solid: impl Fn(S::Value) -> Solid,
) {
    let mut runner = proptest::test_runner::TestRunner::new(config(cases));
    let tally = std::cell::RefCell::new(Tally::default());
    let result = runner.run(&(strategy, any::<u64>()), |(value, seed)| {
        let solid = to_solid(value);
        let mut local = Tally::default();
        cast_many(&solid, seed, &mut local, method)?;
        let mut t = tally.borrow_mut();
        for k in 0..3 {
            t.rays[k] += local.rays[k];
            t.hits[k] += local.hits[k];
        }
        t.reference_hits += local.reference_hits;
        t.stats += local.stats;
        t.any_stats += local.any_stats;
        t.any_only += local.any_only;
        Ok(())
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    let t = tally.into_inner();
    let total: usize = t.rays.iter().sum();
    eprintln!(
        "{name} ({method:?}): {total} rays (random {}, grazing {}, support-tangent {}), hits {:?}, reference (sampled) hits {}, \
         mean {:.1} bound + {:.1} point evaluations per cast; any-hit {:.1} + {:.1}, blocked where the search missed {}",
        t.rays[0],
        t.rays[1],
        t.rays[2],
        t.hits,
        t.reference_hits,
        t.stats.bound_evaluations as f64 / total as f64,
        t.stats.point_evaluations as f64 / total as f64,
        t.any_stats.bound_evaluations as f64 / total as f64,
        t.any_stats.point_evaluations as f64 / total as f64,
        t.any_only,
    );
    assert!(total >= cases as usize * RAYS_PER_CASE);
}

/// Perturbed ellipsoids: 600 cases × 100 rays (rays that miss every support are answered in
/// closed form, the rest by the search).
#[test]
fn perturbed_free_forms_find_the_first_surface() {
    run(
        "perturbed free forms",
        CastMethod::ClosedForm,
        600,
        free_form(),
        Solid::from_free_form,
    );
}

/// CSG trees of depth ≤ 3 of perturbed ellipsoids: 600 cases × 100 rays, searched and with
/// the closed form where a ray meets only plain leaves.
#[test]
fn csg_trees_find_the_first_surface() {
    for method in [CastMethod::Halving, CastMethod::ClosedForm] {
        run("CSG trees", method, 600, shape(), |s| {
            Solid::new(s).expect("operand counts are valid")
        });
    }
}

/// CSG trees of depth ≤ 3 of plain, partly box-clipped ellipsoids: 600 cases × 100 rays, by the
/// search and by the closed form (which answers every ray here that its sets can hold).
#[test]
fn plain_csg_trees_find_the_first_surface() {
    for method in [CastMethod::Halving, CastMethod::ClosedForm] {
        run(
            "plain CSG trees",
            method,
            600,
            tree_of(plain_free_form()),
            |s| Solid::new(s).expect("operand counts are valid"),
        );
    }
}

/// A fixed, hand-made case that touches the support boundary tangentially along an axis: the
/// perturbation's support is the unit ball around (2, 0, 0) and the ray runs along y at x = 1 —
/// `Q = 0` exactly at one point, where the base ellipsoid is also entered.
#[test]
fn ray_tangent_to_a_support_boundary_is_stable() {
    let base = Quadric::ellipsoid(DVec3::ZERO, DVec3::new(1.5, 1.0, 1.0));
    for f in [-1.0, -1e-3, 1e-3, 1.0] {
        let bump = Perturbation::new(f, Quadric::sphere(DVec3::new(2.0, 0.0, 0.0), 1.0));
        let solid = Solid::from_free_form(FreeForm::new(base, vec![bump], None).unwrap());
        let mut caster = RayCaster::new();
        for z in [0.0, 1e-9, 1e-5, 0.3] {
            let ray = Ray::new(DVec3::new(1.0, -4.0, z), DVec3::Y).unwrap();
            check(
                &solid,
                &mut caster,
                &ray,
                Kind::SupportTangent,
                &mut Tally::default(),
            )
            .unwrap();
        }
    }
}

/// The segment bound is conservative: for perturbed free forms, random rays and random
/// sub-segments, every sampled value `F′(ray.at(t))` lies in the value range and every difference
/// quotient between samples (an average of the derivative, by the mean value theorem) lies in the
/// derivative range — up to rounding, `1e-9 × (1 + |bound|)` (values are O(1)). 300 cases × 20
/// rays × 64 samples.
#[test]
fn segment_bounds_contain_the_sampled_values_and_slopes() {
    let mut runner = proptest::test_runner::TestRunner::new(config(300));
    let full = Interval::new(0.0, f64::INFINITY);
    let result = runner.run(&(free_form(), any::<u64>()), |(ff, seed)| {
        let solid = Solid::from_free_form(ff.clone());
        let mut rng = Rng(seed);
        let mut caster = RayCaster::new();
        let b = solid.bounds();
        for _ in 0..20 {
            let origin = rng.direction() * 6.0;
            let target = b.min + (b.max - b.min) * DVec3::new(rng.unit(), rng.unit(), rng.unit());
            let ray = Ray::new(origin, target - origin).expect("distinct points");
            let Some(range) = caster.prepare_ray(&solid, &ray, full) else {
                continue;
            };
            let (x, y) = (rng.range(range.lo, range.hi), rng.range(range.lo, range.hi));
            let seg = Interval::new(x.min(y), x.max(y));
            let (value, slope) = caster.segment_bound(&solid, seg);
            let n = 64;
            let ts: Vec<f64> = (0..=n)
                .map(|i| seg.lo + seg.width() * i as f64 / n as f64)
                .collect();
            let fs: Vec<f64> = ts.iter().map(|&t| ff.eval_unclipped(ray.at(t))).collect();
            let vtol = 1e-9 * (1.0 + value.lo.abs().max(value.hi.abs()));
            for (&t, &f) in ts.iter().zip(&fs) {
                prop_assert!(
                    f >= value.lo - vtol && f <= value.hi + vtol,
                    "F′({}) = {} outside {:?}",
                    t,
                    f,
                    value
                );
            }
            let stol = 1e-9 * (1.0 + slope.lo.abs().max(slope.hi.abs()));
            for i in 0..n {
                let dt = ts[i + 1] - ts[i];
                if dt <= 1e-6 {
                    continue; // the quotient is rounding noise
                }
                let q = (fs[i + 1] - fs[i]) / dt;
                prop_assert!(
                    q >= slope.lo - stol && q <= slope.hi + stol,
                    "slope {} outside {:?} on {:?}",
                    q,
                    slope,
                    seg
                );
            }
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}
