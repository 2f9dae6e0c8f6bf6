//! Accuracy of the ray caster against a high-precision reference (docs/accuracy.md), for both
//! ways it answers plain rays ([`CastMethod`]) and through every entry point (`cast`, `cast_with`
//! with the whole and a culled [`ActiveSet`], `cast_planned`, which must agree bit for bit).
//!
//! The reference (`common::reference`) works in double-double from the f64 inputs taken as
//! exact: the quadrics restricted to the ray, their roots, the boxes' parameter intervals, and
//! CSG as sets of `t` — never the caster's f64 formulas. For perturbed solids it samples the
//! exact value densely and bisects where it turns non-negative.
//!
//! The contract checked on every ray (ε the cast's accuracy, `t*` the true first hit):
//! - `t` is a number, `range.lo ≤ t ≤ range.hi`;
//! - `t` lies in the **loose** set: the solid with every leaf widened by `Δ + δ(t)` — `Δ` the
//!   widening the caster applies (its stated rounding bound, `K u Φ(‖o − origin‖₁ + T)`),
//!   `δ(t) = K u S(t)` the rounding of one evaluation at `t` — so `t ≥ t* − ρ⁻`, where
//!   `ρ⁻ = t* − (first loose point)`, to first order `(Δ + δ)/|F′′(t*)|` with `F′′` the slope;
//! - if the exact set has a span at least ε long in the range, starting at `t₁`: a hit, and
//!   `t ≤ t₁ + ε + ρ⁺`, `ρ⁺ = 4u·t₁` (the f64 rounding of the reference root). So no span at least
//!   ε long is ever missed, grazing or not, and `t − t* ≤ ε + ρ⁺` where the first span is one.
//!
//! Ray classes: random, grazing (offsets down to the rounding of the coordinates, so that rays
//! within rounding of tangency are many), along axes and in coordinate planes, from a common
//! origin (a pinhole camera, which exercises the plan's cached origin terms), objects and
//! camera 10⁴–10⁶ m from the world origin, the camera 10²–10⁴ diagonals away, and scenes
//! scaled by 10⁻³ and 10³. Run with `--nocapture` for the figures (max `(t − t*)/ε`, max
//! `ρ⁻/ε`, hits the reference calls thin or absent).

use fray_core::{Aabb, Interval, Ray};
use fray_geometry::{
    ActiveSet, CastMethod, CastPlan, CastStats, FreeForm, Perturbation, Quadric, RayCaster, Shape,
    Sheets, Solid,
};
use glam::{DAffine3, DQuat, DVec3, EulerRot};

mod common;
use common::dd::Dd;
use common::reference::{self as reference, Truth, U};
use common::rng::Rng;

/// Every test runs with both ways of answering plain rays.
const METHODS: [CastMethod; 2] = [CastMethod::Halving, CastMethod::ClosedForm];
/// The renderer's default ε, relative to the scene diagonal.
const EPS_REL: f64 = 1e-10;

fn full_range() -> Interval {
    Interval::new(0.0, f64::INFINITY)
}

/// The figures of one class of rays.
#[derive(Default)]
struct Tally {
    rays: usize,
    hits: usize,
    /// Rays the reference says enter the solid, and those whose first span is at least ε.
    entering: usize,
    long: usize,
    /// Largest `(t − t*)/ε` over hits whose first span is at least ε long, and `(t* − t)/ε`
    /// over all hits where `t*` exists.
    late: f64,
    early: f64,
    /// Largest `ρ⁻/ε` (`t*` minus the first loose point).
    rho: f64,
    /// Largest `−F′(t) / Δ` over hits (`Δ` the largest leaf widening): how much of the rounding
    /// allowance a hit outside the exact solid uses (at most about 2).
    allowance: f64,
    /// Hits where the reference has no inside point (within rounding of tangency), and rays
    /// the reference enters only on spans shorter than ε that the caster did not hit.
    phantom: usize,
    thin_missed: usize,
    stats: CastStats,
}

impl Tally {
    fn add(&mut self, o: &Tally) {
        self.rays += o.rays;
        self.hits += o.hits;
        self.entering += o.entering;
        self.long += o.long;
        self.late = self.late.max(o.late);
        self.early = self.early.max(o.early);
        self.rho = self.rho.max(o.rho);
        self.allowance = self.allowance.max(o.allowance);
        self.phantom += o.phantom;
        self.thin_missed += o.thin_missed;
        self.stats += o.stats;
    }

    fn report(&self, name: &str) {
        eprintln!(
            "{name:>40}: {:>6} rays, {:>6} hits ({} enter, {} on spans ≥ ε); max (t − t*)/ε = {:.3}, \
             max (t* − t)/ε = {:.2e}, max ρ⁻/ε = {:.2e}, max −F′(t)/Δ = {:.2}; {} tangent-zone hits, \
             {} thin spans missed; {:.1} bound + {:.1} point evals per ray",
            self.rays,
            self.hits,
            self.entering,
            self.long,
            self.late,
            self.early,
            self.rho,
            self.allowance,
            self.phantom,
            self.thin_missed,
            self.stats.bound_evaluations as f64 / self.rays.max(1) as f64,
            self.stats.point_evaluations as f64 / self.rays.max(1) as f64,
        );
    }
}

/// A solid with what casting it every way needs: its whole active set and a plan kept across
/// rays (so rays that share an origin reuse the plan's origin terms).
struct Target<'a> {
    solid: &'a Solid,
    all: &'a ActiveSet,
    plan: CastPlan<'a>,
    caster: RayCaster,
}

impl<'a> Target<'a> {
    fn new(solid: &'a Solid, all: &'a ActiveSet, method: CastMethod) -> Self {
        Self {
            solid,
            all,
            plan: CastPlan::new(solid, None),
            caster: RayCaster::with_method(method),
        }
    }

    /// [`Target::cast`] over the full range, checked against the double-double truth
    /// ([`check`], tallied in `tally`).
    fn cast_checked(&mut self, name: &str, ray: &Ray, eps: f64, tally: &mut Tally) -> Option<f64> {
        let range = full_range();
        let hit = self.cast(ray, range, eps, &mut tally.stats);
        let truth = plain_truth(self.solid, ray, range, eps);
        check(name, self.solid, ray, range, eps, hit, &truth, tally);
        hit
    }

    /// The hit of `cast`, after checking that `cast_with` (whole and culled to the ray) and
    /// `cast_planned` (fresh and kept plans, whole and with the active sets) give the same bits.
    fn cast(&mut self, ray: &Ray, range: Interval, eps: f64, stats: &mut CastStats) -> Option<f64> {
        let bits = |t: Option<f64>| t.map(f64::to_bits);
        let c = &mut self.caster;
        let hit = c.cast(self.solid, ray, range, eps, stats);
        let mut ignore = CastStats::default();
        let with = c.cast_with(self.solid, ray, range, eps, self.all, &mut ignore);
        assert_eq!(bits(hit), bits(with), "cast_with(all) ≠ cast for {ray:?}");
        let (mut leaves, mut perts) = (Vec::new(), Vec::new());
        self.solid.active_parts(
            |b| {
                b.expanded(1e-9 * b.diagonal())
                    .clip_ray(ray, range)
                    .is_some()
            },
            &mut leaves,
            &mut perts,
        );
        let mut subset = ActiveSet::new();
        subset.set(self.solid, &leaves, &perts);
        let culled = c.cast_with(self.solid, ray, range, eps, &subset, &mut ignore);
        assert_eq!(
            bits(hit),
            bits(culled),
            "cast_with(culled) ≠ cast for {ray:?}"
        );
        let kept = c.cast_planned(&mut self.plan, ray, range, eps, &mut ignore);
        assert_eq!(
            bits(hit),
            bits(kept),
            "cast_planned(kept plan) ≠ cast for {ray:?}"
        );
        for active in [Some(self.all), Some(&subset)] {
            let mut plan = CastPlan::new(self.solid, active);
            let planned = c.cast_planned(&mut plan, ray, range, eps, &mut ignore);
            assert_eq!(bits(hit), bits(planned), "cast_planned ≠ cast for {ray:?}");
        }
        hit
    }
}

/// Checks the contract (module docs) for one cast; updates `tally`.
#[allow(clippy::too_many_arguments)]
fn check(
    name: &str,
    solid: &Solid,
    ray: &Ray,
    range: Interval,
    eps: f64,
    hit: Option<f64>,
    truth: &Truth,
    tally: &mut Tally,
) {
    tally.rays += 1;
    tally.entering += usize::from(truth.first.is_some());
    tally.long += usize::from(truth.first_long.is_some());
    let widenings = reference::widenings(solid, ray, range);
    if let Some(t) = hit {
        tally.hits += 1;
        assert!(!t.is_nan(), "{name}: NaN for {ray:?}");
        assert!(
            t >= range.lo && t <= range.hi,
            "{name}: t = {t} outside the range {range:?} for {ray:?}"
        );
        let value = reference::exact_value(solid, ray, t);
        assert!(
            reference::loose_at(solid, ray, &widenings, t),
            "{name}: hit at t = {t} is outside the solid by more than its rounding \
             (exact value {value:e}, widenings {widenings:?}; truth {truth:?}) for {ray:?}"
        );
        let widest = widenings.iter().fold(0.0f64, |m, &w| m.max(w));
        if value < 0.0 && value.is_finite() {
            tally.allowance = tally.allowance.max(-value / widest);
        }
        match truth.first {
            Some(ts) => {
                if truth.first_long == Some(ts) {
                    tally.late = tally.late.max((t - ts) / eps);
                }
                tally.early = tally.early.max((ts - t) / eps);
                if let Some(tl) = truth.loose_first {
                    assert!(
                        t >= tl - 4.0 * U * tl.abs(),
                        "{name}: t = {t} before the first loose point {tl} for {ray:?}"
                    );
                    tally.rho = tally.rho.max((ts - tl) / eps);
                }
            }
            None => tally.phantom += 1,
        }
    }
    if let Some(t1) = truth.first_long {
        let Some(t) = hit else {
            panic!(
                "{name}: missed a span at least ε long starting at {t1} (truth {truth:?}) for {ray:?}"
            );
        };
        assert!(
            t <= t1 + eps + 4.0 * U * t1.abs(),
            "{name}: t = {t} passes the first span (from {t1}) by {:e} > ε = {eps:e} for {ray:?}",
            t - t1
        );
    } else if truth.first.is_some() && hit.is_none() {
        tally.thin_missed += 1;
    }
}

/// The truth for a solid of plain leaves, from the reference's sets.
fn plain_truth(solid: &Solid, ray: &Ray, range: Interval, eps: f64) -> Truth {
    reference::truth_from_sets(&reference::solid_sets(solid, ray, range), range, eps)
}

fn cube(centre: DVec3, half: f64) -> Aabb {
    Aabb::from_center_half(centre, DVec3::splat(half))
}

/// The quadric kinds, centred `offset + (0.3, −0.2, 0.7)·size` and scaled by `size`: name,
/// free form, and the length scale of its surface.
fn kinds(offset: DVec3, size: f64) -> Vec<(&'static str, FreeForm)> {
    let c = offset + DVec3::new(0.3, -0.2, 0.7) * size;
    let rot = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3);
    let axis = rot * DVec3::Y;
    let radii = DVec3::new(2.0, 1.0, 0.5) * size;
    let rotated = Quadric::ellipsoid(DVec3::ZERO, radii)
        .transformed(&DAffine3::from_rotation_translation(rot, DVec3::ZERO))
        .unwrap()
        .translated(c);
    // x ↦ F(x / size) for the general quadric.
    let g = [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -3.0];
    let s2 = 1.0 / (size * size);
    let general = Quadric::new(
        c,
        [
            g[0] * s2,
            g[1] * s2,
            g[2] * s2,
            g[3] * s2,
            g[4] * s2,
            g[5] * s2,
            g[6] / size,
            g[7] / size,
            g[8] / size,
            g[9],
        ],
    );
    let free = |q: Quadric| FreeForm::new(q, vec![], None).unwrap();
    let clipped = |q: Quadric| FreeForm::new(q, vec![], Some(cube(c, 2.0 * size))).unwrap();
    vec![
        ("sphere", free(Quadric::sphere(c, size))),
        ("ellipsoid", free(Quadric::ellipsoid(c, radii))),
        ("rotated ellipsoid", free(rotated)),
        ("cylinder", clipped(Quadric::cylinder(c, axis, size))),
        ("cone", clipped(Quadric::cone(c, axis, 0.5))),
        (
            "half-space",
            clipped(Quadric::half_space(c, DVec3::new(0.3, 1.0, -0.2))),
        ),
        (
            "paraboloid",
            clipped(Quadric::paraboloid(c, axis, 0.5 * size)),
        ),
        (
            "hyperboloid (1 sheet)",
            clipped(Quadric::hyperboloid(
                c,
                axis,
                0.8 * size,
                1.2 * size,
                Sheets::One,
            )),
        ),
        (
            "hyperboloid (2 sheets)",
            clipped(Quadric::hyperboloid(
                c,
                axis,
                0.8 * size,
                1.2 * size,
                Sheets::Two,
            )),
        ),
        ("general quadric", clipped(general)),
    ]
}

/// A ray through a surface point of `ff` (found by a probe ray from `camera`, or a random one
/// around the box), along a random tangent, moved off the surface along the normal by
/// `±10^U(lo, hi)` times `scale` — down to below the coordinates' rounding, so that many rays
/// lie within rounding of tangency.
fn grazing_ray(
    ff: &FreeForm,
    rng: &mut Rng,
    camera: Option<DVec3>,
    (lo, hi): (f64, f64),
) -> Option<Ray> {
    let b = ff.bounds();
    let diag = b.diagonal();
    let centre = b.center();
    let origin = camera.unwrap_or_else(|| centre + rng.direction() * diag * rng.range(0.6, 2.0));
    let probe = Ray::new(origin, rng.in_box(b.min, b.max) - origin)?;
    let t = ff.closed_form_hit(&probe, full_range())?;
    let p = probe.at(t);
    // Skip hits on the clipping box's faces and at singular points (a cone's apex).
    if !b.expanded(-1e-6 * diag).contains(p) {
        return None;
    }
    let g = ff.base().gradient(p);
    if !g.is_finite() || g.length() <= 1e-9 * ff.base().eval(centre).abs().max(1.0) / diag {
        return None;
    }
    let n_in = g.normalize(); // F increases inward
    let w = rng.direction();
    let d = (w - n_in * w.dot(n_in)).try_normalize()?;
    let offset = rng.log_uniform(lo, hi) * if rng.unit() < 0.5 { 1.0 } else { -1.0 };
    let q = p + n_in * (offset * diag);
    let start = match camera {
        Some(camera) => q - d * (camera - q).length(),
        None => q - d * diag * rng.range(0.6, 2.0),
    };
    Ray::new(start, d)
}

/// Directions along the axes and in the coordinate planes (exact zero components).
fn axis_directions() -> Vec<DVec3> {
    let mut dirs = Vec::new();
    for axis in 0..3 {
        for sign in [1.0, -1.0] {
            let mut d = DVec3::ZERO;
            d[axis] = sign;
            dirs.push(d);
            let mut e = d;
            e[(axis + 1) % 3] = 0.7 * sign;
            dirs.push(e);
        }
    }
    dirs
}

/// The ray classes of one plain quadric (see the module docs): `n` rays per class.
fn plain_classes(
    kind: &str,
    ff: &FreeForm,
    method: CastMethod,
    n: usize,
    seed: u64,
    classes: &mut Vec<(String, Tally)>,
) {
    let solid = Solid::from_free_form(ff.clone());
    let all = ActiveSet::all(&solid);
    let mut target = Target::new(&solid, &all, method);
    let b = ff.bounds();
    let diag = b.diagonal();
    let centre = b.center();
    let eps = EPS_REL * diag;
    let mut rng = Rng(seed);
    let dirs = axis_directions();
    let pinhole = centre + DVec3::new(0.9, 0.5, -1.3) * diag;
    type Gen<'g> = Box<dyn FnMut(&mut Rng, usize) -> Option<Ray> + 'g>;
    let gens: Vec<(&str, Gen)> = vec![
        (
            "random",
            Box::new(|rng: &mut Rng, _| {
                let origin = centre + rng.direction() * diag * rng.range(0.3, 3.0);
                Ray::new(origin, rng.in_box(b.min, b.max) - origin)
            }),
        ),
        (
            "grazing",
            Box::new(|rng: &mut Rng, _| grazing_ray(ff, rng, None, (-17.0, -3.0))),
        ),
        (
            "axes",
            Box::new(|rng: &mut Rng, i| {
                let d = dirs[i % dirs.len()];
                // One in eight through the object's origin or on a box face plane.
                let mut target = rng.in_box(b.min, b.max);
                if i % 8 == 0 {
                    target[(i / 8) % 3] = ff.base().origin[(i / 8) % 3];
                } else if i % 8 == 1 {
                    target[(i / 8) % 3] = b.min[(i / 8) % 3];
                }
                Ray::new(target - d * diag * rng.range(0.0, 2.0), d)
            }),
        ),
        (
            "pinhole",
            Box::new(|rng: &mut Rng, i| {
                if i % 4 == 0 {
                    grazing_ray(ff, rng, Some(pinhole), (-17.0, -5.0))
                } else {
                    Ray::new(pinhole, rng.in_box(b.min, b.max) - pinhole)
                }
            }),
        ),
        (
            "camera 1e2–1e4 diagonals away",
            Box::new(|rng: &mut Rng, i| {
                let camera = centre + rng.direction() * diag * rng.log_uniform(2.0, 4.0);
                if i % 4 == 0 {
                    grazing_ray(ff, rng, Some(camera), (-17.0, -5.0))
                } else {
                    Ray::new(camera, rng.in_box(b.min, b.max) - camera)
                }
            }),
        ),
    ];
    for (class, mut gen_ray) in gens {
        let mut tally = Tally::default();
        let mut i = 0;
        while tally.rays < n {
            i += 1;
            let Some(ray) = gen_ray(&mut rng, i) else {
                continue;
            };
            target.cast_checked(
                &format!("{kind} {class} ({method:?})"),
                &ray,
                eps,
                &mut tally,
            );
        }
        match classes.iter_mut().find(|c| c.0 == class) {
            Some(c) => c.1.add(&tally),
            None => classes.push((class.to_string(), tally)),
        }
    }
}

fn run_plain(title: &str, offset: DVec3, size: f64, n: usize) {
    for method in METHODS {
        let mut classes = Vec::new();
        for (i, (name, ff)) in kinds(offset, size).into_iter().enumerate() {
            let mut per_kind = Vec::new();
            plain_classes(name, &ff, method, n, 0xF4A7 + i as u64, &mut per_kind);
            let mut total = Tally::default();
            for (_, t) in &per_kind {
                total.add(t);
            }
            total.report(&format!("{title} {name} ({method:?})"));
            for (class, t) in per_kind {
                match classes
                    .iter_mut()
                    .find(|c: &&mut (String, Tally)| c.0 == class)
                {
                    Some(c) => c.1.add(&t),
                    None => classes.push((class, t)),
                }
            }
        }
        for (class, t) in &classes {
            t.report(&format!("{title}, all kinds: {class} ({method:?})"));
            assert!(
                t.long * 10 >= t.rays,
                "{class}: too few hits to measure anything"
            );
        }
    }
}

/// Ten quadric kinds at the origin, unit size: every class.
#[test]
fn plain_quadrics_keep_the_contract() {
    run_plain("unit", DVec3::ZERO, 1.0, 4_000);
}

/// Objects and camera 10⁴, 10⁵ and 10⁶ m from the world origin (the quadrics' own origins
/// keep the coefficients small: the rounding stays that of the camera's distance to them).
#[test]
fn far_from_the_world_origin_keeps_the_contract() {
    for (k, distance) in [1e4, 1e5, 1e6].into_iter().enumerate() {
        let offset = DVec3::new(0.6, 0.48, -0.64) * distance * (1.0 + 0.1 * k as f64);
        run_plain(&format!("at {distance:.0e} m"), offset, 1.0, 1_000);
    }
}

/// Scenes scaled by 10⁻³ and 10³ (the bounds are relative, so they hold unchanged).
#[test]
fn scaled_scenes_keep_the_contract() {
    for size in [1e-3, 1e3] {
        run_plain(&format!("scale {size:e}"), DVec3::ZERO, size, 1_000);
    }
}

/// CSG of plain quadrics (unions, intersections, differences, nested, with clipping boxes):
/// the reference combines the leaves' double-double roots as sets.
#[test]
fn plain_csg_keeps_the_contract() {
    let ball = |c: DVec3, r: f64| {
        Shape::FreeForm(FreeForm::new(Quadric::sphere(c, r), vec![], None).unwrap())
    };
    let rot = DAffine3::from_rotation_translation(
        DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3),
        DVec3::new(0.1, 0.2, -0.1),
    );
    let ell = Shape::FreeForm(
        FreeForm::new(
            Quadric::ellipsoid(DVec3::ZERO, DVec3::new(1.5, 0.8, 0.6))
                .transformed(&rot)
                .unwrap(),
            vec![],
            None,
        )
        .unwrap(),
    );
    let cyl = |axis: DVec3, r: f64, half: f64| {
        Shape::FreeForm(
            FreeForm::new(
                Quadric::cylinder(DVec3::ZERO, axis, r),
                vec![],
                Some(cube(DVec3::ZERO, half)),
            )
            .unwrap(),
        )
    };
    let slab = Shape::FreeForm(
        FreeForm::new(
            Quadric::half_space(DVec3::new(0.0, 0.3, 0.0), DVec3::new(0.2, 1.0, 0.1)),
            vec![],
            Some(cube(DVec3::ZERO, 1.2)),
        )
        .unwrap(),
    );
    let solids = [
        (
            "union",
            Shape::Union(vec![
                ball(DVec3::ZERO, 1.0),
                ball(DVec3::new(1.2, 0.3, 0.0), 0.8),
            ]),
        ),
        (
            "intersection",
            Shape::Intersection(vec![ell.clone(), ball(DVec3::new(0.5, 0.0, 0.0), 1.0)]),
        ),
        (
            "difference",
            Shape::Difference(
                Box::new(ell.clone()),
                Box::new(cyl(DVec3::new(0.3, 1.0, 0.2), 0.4, 2.0)),
            ),
        ),
        (
            "nested difference",
            Shape::Difference(
                Box::new(ball(DVec3::ZERO, 1.0)),
                Box::new(Shape::Difference(
                    Box::new(ball(DVec3::new(0.6, 0.0, 0.0), 0.7)),
                    Box::new(ball(DVec3::new(0.8, 0.1, 0.0), 0.3)),
                )),
            ),
        ),
        (
            "clipped intersection",
            Shape::Intersection(vec![
                cyl(DVec3::new(1.0, 0.2, -0.3), 0.9, 1.0),
                slab.clone(),
                ell.clone(),
            ]),
        ),
        (
            "three-way union minus slab",
            Shape::Difference(
                Box::new(Shape::Union(vec![
                    ball(DVec3::new(-0.8, 0.0, 0.0), 0.6),
                    ell,
                    ball(DVec3::new(0.9, 0.4, 0.2), 0.5),
                ])),
                Box::new(slab),
            ),
        ),
    ];
    for method in METHODS {
        for (name, shape) in solids.clone() {
            let solid = Solid::new(shape).unwrap();
            let all = ActiveSet::all(&solid);
            let mut target = Target::new(&solid, &all, method);
            let b = solid.bounds();
            let (centre, diag) = (b.center(), b.diagonal());
            let eps = EPS_REL * diag;
            let mut rng = Rng(17);
            let mut tally = Tally::default();
            let mut i = 0;
            while tally.rays < 8_000 {
                i += 1;
                let ray = if i % 3 == 0 {
                    // Grazing a leaf's surface.
                    let leaf = &solid.leaves()[(i / 3) % solid.leaves().len()];
                    let Some(r) = grazing_ray(leaf, &mut rng, None, (-17.0, -3.0)) else {
                        continue;
                    };
                    r
                } else {
                    let origin = centre + rng.direction() * diag * rng.range(0.5, 3.0);
                    let Some(r) = Ray::new(origin, rng.in_box(b.min, b.max) - origin) else {
                        continue;
                    };
                    r
                };
                target.cast_checked(name, &ray, eps, &mut tally);
            }
            tally.report(&format!("CSG {name} ({method:?})"));
            assert!(tally.long * 10 >= tally.rays, "{name}: too few hits");
        }
    }
}

/// Perturbed solids (bumps and dents, alone and in CSG): the reference samples the exact value
/// (2000 steps over the ray's part in the box) and bisects the crossing, in double-double.
#[test]
fn perturbed_solids_keep_the_contract() {
    let base = Quadric::ellipsoid(DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.5, 1.0, 0.8));
    let mut rng = Rng(42);
    let bumps: Vec<Perturbation> = (0..8)
        .map(|i| {
            let at = DVec3::new(0.1, -0.2, 0.3) + rng.direction() * DVec3::new(1.5, 1.0, 0.8);
            let f = if i % 2 == 0 { 0.6 } else { -0.5 };
            Perturbation::new(f, Quadric::sphere(at, 0.3 + 0.2 * rng.unit()))
        })
        .collect();
    let bumpy = FreeForm::new(base, bumps.clone(), None).unwrap();
    let one = FreeForm::new(base, bumps[..1].to_vec(), None).unwrap();
    let ball = FreeForm::new(
        Quadric::sphere(DVec3::new(1.2, 0.0, 0.0), 0.7),
        vec![],
        None,
    )
    .unwrap();
    let solids = [
        ("one bump", Solid::from_free_form(one.clone())),
        (
            "eight bumps and dents",
            Solid::from_free_form(bumpy.clone()),
        ),
        (
            "bumpy minus ball",
            Solid::new(Shape::Difference(
                Box::new(Shape::FreeForm(bumpy.clone())),
                Box::new(Shape::FreeForm(ball.clone())),
            ))
            .unwrap(),
        ),
        (
            "ball minus bumpy",
            Solid::new(Shape::Difference(
                Box::new(Shape::FreeForm(ball)),
                Box::new(Shape::FreeForm(one)),
            ))
            .unwrap(),
        ),
    ];
    for method in METHODS {
        for (name, solid) in &solids {
            let all = ActiveSet::all(solid);
            let mut target = Target::new(solid, &all, method);
            let b = solid.bounds();
            let (centre, diag) = (b.center(), b.diagonal());
            let eps = EPS_REL * diag;
            let mut rng = Rng(5);
            let mut tally = Tally::default();
            let mut i = 0;
            while tally.rays < 1_000 {
                i += 1;
                let origin = centre + rng.direction() * diag * rng.range(0.6, 3.0);
                let Some(probe) = Ray::new(origin, rng.in_box(b.min, b.max) - origin) else {
                    continue;
                };
                let ray = if i % 3 == 0 {
                    // Grazing the perturbed surface: tangent at a hit, nudged off it.
                    let Some(t) = solid.cast(&probe, full_range(), 1e-13) else {
                        continue;
                    };
                    let p = probe.at(t);
                    let (n, _) = solid.surface_at(p, -probe.dir);
                    let w = rng.direction();
                    let Some(d) = (w - n * w.dot(n)).try_normalize() else {
                        continue;
                    };
                    let off = rng.log_uniform(-15.0, -4.0) * if i % 2 == 0 { 1.0 } else { -1.0 };
                    let Some(r) = Ray::new(p - n * off - d * diag, d) else {
                        continue;
                    };
                    r
                } else {
                    probe
                };
                let range = full_range();
                let hit = target.cast(&ray, range, eps, &mut tally.stats);
                let truth = reference::truth_by_sampling(solid, &ray, range, eps, 2_000);
                check(name, solid, &ray, range, eps, hit, &truth, &mut tally);
            }
            tally.report(&format!("perturbed {name} ({method:?})"));
            assert!(tally.long * 10 >= tally.rays, "{name}: too few hits");
        }
    }
}

/// Grazing spans (docs/accuracy.md, "Grazing rays"): rays within a hair of tangency to a
/// sphere, an ellipsoid and a clipped cylinder, from 3, 10 and 1000 sizes away and 10⁵ m from
/// the world origin. Every span at least ε long must be found (the contract); the table gives,
/// by the true span width `w` in units of the rounding noise `w_u = 2√(u S(t_v)/|a|)` (where
/// one unit roundoff of the term magnitude `S` equals the peak of `q`), how many are found —
/// spans of a few `w_u` are what f64 evaluation without the widening missed. Then the same with
/// `ε` a million times larger, to see spans just above ε (all found) and just below.
#[test]
fn grazing_spans_at_least_eps_long_are_found() {
    for (eps_rel, bins_of) in [(EPS_REL, "w_u"), (1e-4, "ε")] {
        for method in METHODS {
            let mut found = [0usize; 10];
            let mut total = [0usize; 10];
            let (mut near_miss, mut near_miss_hit) = (0, 0);
            for (k, (distance, offset)) in [(3.0, 0.0), (10.0, 0.0), (1e3, 0.0), (10.0, 1e5)]
                .into_iter()
                .enumerate()
            {
                let offset = DVec3::new(0.6, 0.48, -0.64) * offset;
                let c = offset + DVec3::new(0.3, -0.2, 0.7);
                let rot = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3);
                let leaves = [
                    FreeForm::new(Quadric::sphere(c, 1.0), vec![], None).unwrap(),
                    FreeForm::new(
                        Quadric::ellipsoid(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.5))
                            .transformed(&DAffine3::from_rotation_translation(rot, DVec3::ZERO))
                            .unwrap()
                            .translated(c),
                        vec![],
                        None,
                    )
                    .unwrap(),
                    FreeForm::new(
                        Quadric::cylinder(c, rot * DVec3::Y, 1.0),
                        vec![],
                        Some(cube(c, 2.0)),
                    )
                    .unwrap(),
                ];
                for (j, ff) in leaves.iter().enumerate() {
                    let solid = Solid::from_free_form(ff.clone());
                    let all = ActiveSet::all(&solid);
                    let mut target = Target::new(&solid, &all, method);
                    let eps = eps_rel * solid.bounds().diagonal();
                    let mut rng = Rng(1000 + 10 * k as u64 + j as u64);
                    let mut tally = Tally::default();
                    let camera_at = |rng: &mut Rng| c + rng.direction() * distance;
                    let offsets = if bins_of == "ε" {
                        (-14.0, -6.0)
                    } else {
                        (-18.0, -12.0)
                    };
                    while tally.rays < 6_000 {
                        let camera = camera_at(&mut rng);
                        let Some(ray) = grazing_ray(ff, &mut rng, Some(camera), offsets) else {
                            continue;
                        };
                        let hit = target.cast_checked("grazing", &ray, eps, &mut tally);
                        // The true span around the tangent point, and the noise width there.
                        let q = reference::quadric_on_ray(ff.base(), &ray);
                        let Some(tv) = q.vertex() else { continue };
                        let a = q.q.a.to_f64().abs();
                        let exact = q.spans(0.0, 0.0);
                        let span = exact.iter().find(|s| s.0 <= tv && tv <= s.1);
                        let Some(&(s0, s1)) = span else {
                            // A near miss: within the loose widening of tangency?
                            let peak = q.q.eval(tv).to_f64();
                            let loose =
                                reference::widenings(&solid, &ray, full_range())[0] + q.delta(tv);
                            if peak >= -loose && ff.bounds().contains(ray.at(tv)) {
                                near_miss += 1;
                                near_miss_hit += usize::from(hit.is_some());
                            }
                            continue;
                        };
                        if !ff.bounds().expanded(-1e-3).contains(ray.at(tv)) {
                            continue; // the box, not the quadric, bounds the span
                        }
                        let w = s1 - s0;
                        let unit = if bins_of == "ε" {
                            eps
                        } else {
                            2.0 * (U * q.magnitude(tv) / a).sqrt()
                        };
                        let bin = ((w / unit).log2() + 5.0).floor();
                        if !(0.0..10.0).contains(&bin) {
                            continue;
                        }
                        total[bin as usize] += 1;
                        found[bin as usize] += usize::from(hit.is_some());
                        if w >= eps {
                            assert!(hit.is_some(), "grazing span {w:e} ≥ ε missed: {ray:?}");
                        }
                    }
                }
            }
            let table: Vec<String> = (0..10)
                .map(|b| {
                    format!(
                        "[2^{}, 2^{}): {}/{}",
                        b as i32 - 5,
                        b as i32 - 4,
                        found[b],
                        total[b]
                    )
                })
                .collect();
            eprintln!(
                "grazing spans, ε = {eps_rel:e} × diag ({method:?}): found / total by w / {bins_of}: {}; \
                 near misses within the widening: {near_miss_hit} hit of {near_miss}",
                table.join(", ")
            );
            assert!(total.iter().sum::<usize>() >= 1000, "too few spans binned");
        }
    }
}

/// The rounding bound behind the widening (docs/accuracy.md): an f64 value of a quadric on a
/// ray (`Quadric::on_ray`, then Horner in `t`) is within `14 u S(t)` of the exact value — the
/// coefficients' 10 units and Horner's 4 — and the magnitude `S(t)` is within the stated
/// `Φ(‖o − origin‖₁ + |t|)`. Random quadrics (all ten coefficients), origins and rays at scales
/// 10⁻³–10⁶, parameters up to 10³ sizes, and points near the surface where `F` cancels.
#[test]
fn the_rounding_bound_holds() {
    let mut rng = Rng(77);
    let mut worst = 0.0f64;
    for i in 0..200_000 {
        let scale = rng.log_uniform(-3.0, 6.0);
        let coefficients: [f64; 10] = std::array::from_fn(|k| {
            let v = rng.range(-2.0, 2.0);
            match k {
                0..6 => v / (scale * scale),
                6..9 => v / scale,
                _ => v,
            }
        });
        let q = Quadric::new(
            rng.direction() * scale * rng.log_uniform(0.0, 6.0),
            coefficients,
        );
        let origin = q.origin + rng.direction() * scale * rng.log_uniform(-1.0, 3.0);
        let Some(ray) = Ray::new(origin, rng.direction()) else {
            continue;
        };
        let exact = reference::quadric_on_ray(&q, &ray);
        let f = q.on_ray(&ray);
        let t = if i % 2 == 0 {
            rng.range(0.0, 1e3) * scale
        } else {
            // Near a root, where the value cancels.
            match f.first_nonnegative(Interval::new(0.0, 1e3 * scale)) {
                Some(r) => r,
                None => continue,
            }
        };
        let err = (Dd::from(f.eval(t)) - exact.q.eval(t)).abs().to_f64();
        let ratio = err / (U * exact.magnitude(t));
        worst = worst.max(ratio);
        assert!(
            ratio <= 14.0,
            "rounding {ratio} u S(t) at t = {t} for {q:?} on {ray:?}"
        );
        let phi = reference::magnitude_bound(&q, &ray, t.abs());
        assert!(
            exact.magnitude(t) <= phi * (1.0 + 1e-12),
            "S(t) = {} > Φ = {phi}",
            exact.magnitude(t)
        );
    }
    eprintln!("f64 value of a quadric on a ray: worst rounding {worst:.2} u S(t) (bound 14)");
}

/// The double-double arithmetic against exact integer arithmetic: sums of 66-bit integers and
/// their products with 40-bit ones are exact in both; quotients and square roots to `2⁻¹⁰⁰`.
#[test]
fn double_double_is_exact_where_it_must_be() {
    let mut rng = Rng(3);
    let p40 = 2f64.powi(40);
    for _ in 0..100_000 {
        let mut int = |bits: u32| (rng.next_u64() >> (64 - bits)) as i64 - (1 << (bits - 1));
        let (a, b, c, d, z) = (int(26), int(26), int(26), int(26), int(40));
        let x = Dd::from(a as f64 * p40) + Dd::from(b as f64);
        let y = Dd::from(c as f64 * p40) + Dd::from(d as f64);
        let xi = (i128::from(a) << 40) + i128::from(b);
        let yi = (i128::from(c) << 40) + i128::from(d);
        let exact = |v: Dd| v.hi as i128 + v.lo as i128;
        assert_eq!(exact(x + y), xi + yi, "{a} {b} {c} {d}");
        assert_eq!(exact(x - y), xi - yi, "{a} {b} {c} {d}");
        let p = x * Dd::from(z as f64);
        assert_eq!(exact(p), xi * i128::from(z), "{a} {b} {z}");
        let tol = |v: Dd| 1e-30 * v.abs().to_f64().max(1.0);
        if z != 0 {
            assert!((p / Dd::from(z as f64) - x).abs().to_f64() <= tol(x));
        }
        let s = (x * x).sqrt();
        assert!((s - x.abs()).abs().to_f64() <= tol(x));
    }
}

/// Exactly tangent rays (up to the rounding of constructing them) on convex surfaces: no NaN, no
/// hit behind the origin, and a hit, if any, within `√(2 R (ε + η)) + ε` of the tangent point,
/// where `R` bounds the surface's radius of curvature and `η = 2Δ/|∇F| + 1e-13 L` the widening
/// and the rounding of the construction: the half chord of a ray that dips `ε + η` inside.
#[test]
fn tangent_rays_never_give_nan_or_a_far_hit() {
    for method in METHODS {
        let c = DVec3::new(0.3, -0.2, 0.7);
        let rot = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3);
        let radii = DVec3::new(2.0, 1.0, 0.5);
        let rotated = Quadric::ellipsoid(DVec3::ZERO, radii)
            .transformed(&DAffine3::from_rotation_translation(rot, c))
            .unwrap();
        let cases = [
            (
                "sphere",
                FreeForm::new(Quadric::sphere(c, 1.0), vec![], None).unwrap(),
                1.0,
                1.0,
            ),
            (
                "ellipsoid",
                FreeForm::new(Quadric::ellipsoid(c, radii), vec![], None).unwrap(),
                8.0,
                2.0,
            ),
            (
                "rotated ellipsoid",
                FreeForm::new(rotated, vec![], None).unwrap(),
                8.0,
                2.0,
            ),
            (
                "paraboloid",
                FreeForm::new(
                    Quadric::paraboloid(c, rot * DVec3::Y, 0.5),
                    vec![],
                    Some(cube(c, 2.0)),
                )
                .unwrap(),
                // R ≤ 2 f (1 + ρ²/(4f²))^{3/2} over the box: ρ ≤ 2√3 → R ≤ 1 · 13^{1.5} < 47.
                47.0,
                4.0,
            ),
            (
                "hyperboloid (2 sheets)",
                FreeForm::new(
                    Quadric::hyperboloid(c, rot * DVec3::Y, 0.8, 1.2, Sheets::Two),
                    vec![],
                    Some(cube(c, 2.0)),
                )
                .unwrap(),
                // R = (A⁴ρ² + B⁴s²)^{3/2} / (A⁴B⁴) for the meridian hyperbola (A = 1.2, B = 0.8),
                // |s|, ρ ≤ 3.5 in the box: < 200.
                200.0,
                4.0,
            ),
        ];
        let mut rng = Rng(7);
        for (name, ff, radius_of_curvature, size) in cases {
            let solid = Solid::from_free_form(ff.clone());
            let diag = solid.bounds().diagonal();
            let eps = EPS_REL * diag;
            let mut caster = RayCaster::with_method(method);
            let (mut tested, mut hits, mut worst) = (0, 0, 0.0f64);
            while tested < 20_000 {
                let b = ff.bounds();
                let origin = b.center() + rng.direction() * diag;
                let Some(probe) = Ray::new(origin, rng.in_box(b.min, b.max) - origin) else {
                    continue;
                };
                let Some(t) = ff.closed_form_hit(&probe, full_range()) else {
                    continue;
                };
                let p = probe.at(t);
                if !b.expanded(-1e-6 * diag).contains(p) {
                    continue;
                }
                let g = ff.base().gradient(p);
                let n = g.normalize();
                let w = rng.direction();
                let Some(d) = (w - n * w.dot(n)).try_normalize() else {
                    continue;
                };
                // Origins on both sides of the tangent point and exactly at it.
                let back = match tested % 3 {
                    0 => diag,
                    1 => -0.5 * diag,
                    _ => 0.0,
                };
                let ray = Ray::new(p - d * back, d).unwrap();
                let widening = reference::widenings(&solid, &ray, full_range())[0];
                let eta = 2.0 * widening / g.length() + 1e-13 * size;
                let bound = (2.0 * radius_of_curvature * (eps + eta)).sqrt() + eps;
                let mut stats = CastStats::default();
                let hit = caster.cast(&solid, &ray, full_range(), eps, &mut stats);
                tested += 1;
                if let Some(th) = hit {
                    assert!(
                        !th.is_nan() && th >= 0.0,
                        "{name}: t = {th} for tangent ray {ray:?}"
                    );
                    let off = (ray.at(th) - p).length();
                    assert!(
                        off <= bound,
                        "{name}: tangent hit {off:e} from the tangent point > bound {bound:e}"
                    );
                    worst = worst.max(off / bound);
                    hits += 1;
                }
                // Deterministic: the same ray gives the same bits.
                assert_eq!(
                    hit.map(f64::to_bits),
                    caster
                        .cast(&solid, &ray, full_range(), eps, &mut stats)
                        .map(f64::to_bits)
                );
            }
            eprintln!(
                "tangent {name:>22} ({method:?}): {tested} rays, {hits} hit, farthest hit {worst:.2} of the bound"
            );
        }
    }
}

/// Rays lying in a ruled surface (a cylinder's or cone's generator line): the value is 0 along
/// the whole ray up to rounding. The contract holds (a hit, if any, in the loose set), and the
/// hit is on the surface up to the widening along the normal.
#[test]
fn rays_along_generator_lines_are_stable() {
    for method in METHODS {
        let c = DVec3::new(0.3, -0.2, 0.7);
        let axis = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3) * DVec3::Y;
        let perp = axis.any_orthonormal_vector();
        let cyl =
            FreeForm::new(Quadric::cylinder(c, axis, 1.0), vec![], Some(cube(c, 2.0))).unwrap();
        let cone = FreeForm::new(Quadric::cone(c, axis, 0.5), vec![], Some(cube(c, 2.0))).unwrap();
        let generator_cone = (axis + perp * 0.5f64.tan()).normalize();
        let cases = [
            ("cylinder", cyl, c + perp, axis),
            ("cone", cone, c, generator_cone),
        ];
        for (name, ff, on_surface, dir) in cases {
            let solid = Solid::from_free_form(ff.clone());
            let all = ActiveSet::all(&solid);
            let mut target = Target::new(&solid, &all, method);
            let eps = EPS_REL * solid.bounds().diagonal();
            let mut tally = Tally::default();
            for s in [-5.0, -1.0, 0.0, 1.0, 5.0] {
                for sign in [1.0, -1.0] {
                    let ray = Ray::new(on_surface + dir * s, dir * sign).unwrap();
                    let hit = target.cast_checked(name, &ray, eps, &mut tally);
                    if let Some(t) = hit {
                        let p = ray.at(t);
                        let g = ff.base().gradient(p).length().max(1e-300);
                        let off_surface = ff.base().eval(p).abs() / g;
                        let w = reference::widenings(&solid, &ray, full_range())[0];
                        // At the cone's apex the gradient vanishes; there the point is the check.
                        let at_apex = name == "cone" && (p - c).length() < 1e-6;
                        assert!(
                            at_apex || off_surface <= eps + 2.0 * w / g + 1e-12,
                            "{name}: hit {off_surface:e} off the surface"
                        );
                    }
                }
            }
            tally.report(&format!("generator lines {name} ({method:?})"));
        }
    }
}

/// Zero form factors change nothing; a dent whose support touches the surface from outside and a
/// bump whose support touches it from inside leave `{F′ ≥ 0}` exactly `{F ≥ 0}`, so the bare
/// quadric's double-double sets are the exact truth, while the loose set is the perturbed
/// solid's (its widening includes the perturbations' rounding).
#[test]
fn degenerate_perturbations_keep_the_contract() {
    let c = DVec3::new(0.3, -0.2, 0.7);
    let base = Quadric::sphere(c, 1.0);
    let bare = Solid::from_free_form(FreeForm::new(base, vec![], None).unwrap());
    let bare_ff = bare.leaves()[0].clone();
    let x = DVec3::X;
    let variants = [
        (
            "zero form factors",
            vec![
                Perturbation::new(0.0, Quadric::sphere(c + x, 0.7)),
                Perturbation::new(-0.0, Quadric::sphere(c, 0.3)),
            ],
        ),
        (
            "dent touching from outside",
            vec![Perturbation::new(-0.8, Quadric::sphere(c + 1.5 * x, 0.5))],
        ),
        (
            "bump touching from inside",
            vec![Perturbation::new(0.8, Quadric::sphere(c + 0.5 * x, 0.5))],
        ),
        (
            "dent + bump both touching",
            vec![
                Perturbation::new(
                    -3.0,
                    Quadric::ellipsoid(c - 1.25 * DVec3::Y, DVec3::new(0.6, 0.25, 0.6)),
                ),
                Perturbation::new(
                    3.0,
                    Quadric::ellipsoid(c + 0.6 * DVec3::Z, DVec3::new(0.3, 0.3, 0.4)),
                ),
            ],
        ),
    ];
    for method in METHODS {
        for (name, perts) in variants.clone() {
            let solid = Solid::from_free_form(FreeForm::new(base, perts, None).unwrap());
            let all = ActiveSet::all(&solid);
            let mut target = Target::new(&solid, &all, method);
            let eps = EPS_REL * bare.bounds().diagonal();
            let mut rng = Rng(5);
            let mut tally = Tally::default();
            while tally.rays < 10_000 {
                let ray = if tally.rays % 4 == 0 {
                    let Some(r) = grazing_ray(&bare_ff, &mut rng, None, (-17.0, -3.0)) else {
                        continue;
                    };
                    r
                } else if tally.rays % 4 == 1 {
                    // Aimed near the touching points (±x, −y, +z of the sphere).
                    let touch = [c + x, c - DVec3::Y, c + DVec3::Z][tally.rays % 3];
                    let target = touch + (rng.direction() * rng.log_uniform(-6.0, -1.0));
                    let origin = c + rng.direction() * 4.0;
                    Ray::new(origin, target - origin).unwrap()
                } else {
                    let origin = c + rng.direction() * 4.0;
                    let b = bare.bounds();
                    Ray::new(origin, rng.in_box(b.min, b.max) - origin).unwrap()
                };
                let range = full_range();
                let hit = target.cast(&ray, range, eps, &mut tally.stats);
                // The bare quadric's sets are exact here; its loose set is not the perturbed
                // solid's, so only the pointwise loose check applies.
                let truth = Truth {
                    loose_first: None,
                    ..plain_truth(&bare, &ray, range, eps)
                };
                check(name, &solid, &ray, range, eps, hit, &truth, &mut tally);
            }
            tally.report(&format!("{name} ({method:?})"));
        }
    }
}

/// The widening keeps thin walls honest: a slab of thickness `h` cut by two parallel half-spaces
/// (a difference, so one leaf is widened down) is found for every `h ≥ ε` and never shows a
/// hit outside it by more than the rounding, whatever the slab's angle to the ray.
#[test]
fn thin_slabs_are_found_from_eps_up() {
    for method in METHODS {
        let mut tally = Tally::default();
        let mut rng = Rng(11);
        for i in 0..4_000 {
            let n = rng.direction();
            let h = 1e-10 * rng.log_uniform(-0.5, 3.0);
            let p = DVec3::new(0.1, 0.2, -0.3);
            let b = cube(p, 1.0);
            let below = FreeForm::new(Quadric::half_space(p + n * h, n), vec![], Some(b)).unwrap();
            let above = FreeForm::new(Quadric::half_space(p, n), vec![], Some(b)).unwrap();
            let solid = Solid::new(Shape::Difference(
                Box::new(Shape::FreeForm(below)),
                Box::new(Shape::FreeForm(above)),
            ))
            .unwrap();
            let all = ActiveSet::all(&solid);
            let mut target = Target::new(&solid, &all, method);
            let eps = 1e-10;
            let origin = p + n * rng.range(0.5, 1.5) + rng.direction() * 0.3;
            let Some(ray) = Ray::new(origin, p + rng.direction() * 0.2 - origin) else {
                continue;
            };
            target.cast_checked(&format!("slab {i} h = {h:e}"), &ray, eps, &mut tally);
        }
        tally.report(&format!("thin slabs ({method:?})"));
    }
}
