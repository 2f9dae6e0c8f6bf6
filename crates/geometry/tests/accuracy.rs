//! Accuracy of the ray caster on plain quadrics against the closed-form hit, for both ways it
//! answers plain rays ([`CastMethod`]): the binary search, and the certified closed form.
//!
//! The bound proved here (DESIGN.md, "Fast and accurate, both measured"): with the renderer's
//! default `ε = 1e-10 × diagonal`, the depth that [`RayCaster::cast`] returns differs from the
//! closed form ([`FreeForm::closed_form_hit`]) by at most `1e-9 × diagonal`, over ≥ 10⁵ random
//! rays per quadric kind of which ≥ 20 % graze the silhouette; hit and miss agree except for rays
//! within rounding of tangency (or whose inside part is shorter than ε: documented as missable);
//! no NaN, no hit before the range start. Then: exactly tangent rays, far-from-origin objects,
//! huge and tiny objects, rays along axes, zero form factors and perturbations that just touch.
//!
//! Run with `--nocapture` to see the measured figures (max error, evaluations per ray).

use fray_core::{Interval, Ray};
use fray_geometry::{
    CastMethod, CastStats, FreeForm, Perturbation, Quadric, RayCaster, RayQuadratic, Sheets, Solid,
};
use glam::{DAffine3, DQuat, DVec3, EulerRot};

mod common;
use common::rng::Rng;

const RAYS_PER_KIND: usize = 100_000;
/// Every test runs with both ways of answering plain rays: the halving search (the method, and
/// what the GPU runs) and the certified closed form the CPU uses by default.
const METHODS: [CastMethod; 2] = [CastMethod::Halving, CastMethod::ClosedForm];
/// The renderer's default ε, relative to the scene diagonal.
const EPS_REL: f64 = 1e-10;
/// The depth bound proved, relative to the scene diagonal.
const ERR_REL: f64 = 1e-9;
/// A ray counts as tangent (hit/miss may legitimately differ) when the largest value of the
/// quadratic over the clipped range is within this fraction of the size of its terms: that is
/// the rounding of evaluating `a t² + b t + c` (a few ulps, with a wide margin).
const TANGENCY_REL: f64 = 1e-12;

fn full_range() -> Interval {
    Interval::new(0.0, f64::INFINITY)
}

/// Total length of `{t ∈ range : f(t) ≥ 0}` for a quadratic, from its exact roots (computed in
/// the same cancellation-free way as the closed form).
fn inside_length(f: &RayQuadratic, range: Interval) -> f64 {
    let mut cuts = vec![range.lo, range.hi];
    if f.a != 0.0 {
        let disc = f.b * f.b - 4.0 * f.a * f.c;
        if disc >= 0.0 {
            let q = -0.5 * (f.b + f.b.signum() * disc.sqrt());
            if q != 0.0 {
                cuts.push(q / f.a);
                cuts.push(f.c / q);
            }
        }
    } else if f.b != 0.0 {
        cuts.push(-f.c / f.b);
    }
    cuts.retain(|t| t.is_finite() && *t >= range.lo && *t <= range.hi);
    cuts.sort_by(f64::total_cmp);
    cuts.windows(2)
        .filter(|w| f.eval(0.5 * (w[0] + w[1])) >= 0.0)
        .map(|w| w[1] - w[0])
        .sum()
}

/// Whether `ray` is so close to tangent to the quadric (over the part of the range inside the
/// object's box) that rounding decides hit or miss, or its inside part is thinner than `eps`.
fn ambiguous(ff: &FreeForm, ray: &Ray, eps: f64) -> bool {
    let Some(range) = ff.bounds().clip_ray(ray, full_range()) else {
        return false;
    };
    let f = ff.base().on_ray(ray);
    let tmax = range.lo.abs().max(range.hi.abs());
    let scale = (f.a.abs() * tmax * tmax)
        .max(f.b.abs() * tmax)
        .max(f.c.abs());
    let peak = f.range(range).hi;
    peak.abs() <= TANGENCY_REL * scale || inside_length(&f, range) <= eps
}

#[derive(Default)]
struct Tally {
    rays: usize,
    grazing: usize,
    hits: usize,
    ambiguous_disagreements: usize,
    max_err_rel: f64,
    hit_stats: CastStats,
    miss_stats: CastStats,
    misses: usize,
}

impl Tally {
    fn report(&self, name: &str) {
        let per = |s: u64, n: usize| s as f64 / n.max(1) as f64;
        eprintln!(
            "{name:>22}: {} rays ({} grazing), {} hits, max |Δt|/diag = {:.2e}, tangent disagreements {}, \
             per hit ray {:.1} bound + {:.1} point evals, per miss ray {:.1} bound + {:.1} point evals",
            self.rays,
            self.grazing,
            self.hits,
            self.max_err_rel,
            self.ambiguous_disagreements,
            per(self.hit_stats.bound_evaluations, self.hits),
            per(self.hit_stats.point_evaluations, self.hits),
            per(self.miss_stats.bound_evaluations, self.misses),
            per(self.miss_stats.point_evaluations, self.misses),
        );
    }
}

/// Casts `ray` by search and by closed form and checks the contract; updates `tally`.
fn check_ray(
    name: &str,
    ff: &FreeForm,
    solid: &Solid,
    caster: &mut RayCaster,
    ray: &Ray,
    tally: &mut Tally,
) {
    let diag = solid.bounds().diagonal();
    let eps = EPS_REL * diag;
    let mut stats = CastStats::default();
    let searched = caster.cast(solid, ray, full_range(), eps, &mut stats);
    let closed = ff.closed_form_hit(ray, full_range());
    tally.rays += 1;
    if let Some(t) = searched {
        assert!(!t.is_nan(), "{name}: NaN depth for {ray:?}");
        assert!(
            t >= 0.0,
            "{name}: hit at t = {t} before the range start 0 for {ray:?}"
        );
    }
    match (searched, closed) {
        (Some(ts), Some(tc)) => {
            let err = (ts - tc).abs() / diag;
            assert!(
                err <= ERR_REL,
                "{name}: |t_search − t_closed| = {:e} × diag > 1e-9 × diag (search {ts}, closed {tc}) for {ray:?}",
                err
            );
            tally.max_err_rel = tally.max_err_rel.max(err);
            tally.hits += 1;
            tally.hit_stats += stats;
        }
        (None, None) => {
            tally.misses += 1;
            tally.miss_stats += stats;
        }
        (s, c) => {
            assert!(
                ambiguous(ff, ray, eps),
                "{name}: hit/miss disagreement away from tangency: search {s:?}, closed {c:?} for {ray:?}"
            );
            tally.ambiguous_disagreements += 1;
        }
    }
}

/// A ray that grazes the surface of `ff`: through a surface point `p` (interior of the box, not a
/// cap), along a random tangent direction, offset along the normal by `±δ L` with
/// `δ ∈ [1e-6, 1e-3]` (log-uniform) — for a sphere an impact parameter `r (1 ∓ δ)`.
fn grazing_ray(ff: &FreeForm, rng: &mut Rng, scale: f64) -> Option<Ray> {
    let b = ff.bounds();
    let diag = b.diagonal();
    let centre = b.center();
    let origin = centre + rng.direction() * diag * rng.range(0.6, 2.0);
    let probe = Ray::new(origin, rng.in_box(b.min, b.max) - origin)?;
    let t = ff.closed_form_hit(&probe, full_range())?;
    let p = probe.at(t);
    // Skip hits on the clipping box's faces and at singular points (a cone's apex).
    if !b.expanded(-1e-6 * diag).contains(p) {
        return None;
    }
    let g = ff.base().gradient(p);
    if g.length() <= 1e-9 * ff.base().eval(centre).abs().max(1.0) / diag || !g.is_finite() {
        return None;
    }
    let n_in = g.normalize(); // F increases inward
    let w = rng.direction();
    let d = (w - n_in * w.dot(n_in)).try_normalize()?;
    let delta = rng.log_uniform(-6.0, -3.0);
    let side = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
    let q = p + n_in * (side * delta * scale);
    let back = diag * rng.range(0.6, 2.0);
    Ray::new(q - d * back, d)
}

/// ≥ `n` random rays (a quarter of them grazing) against one quadric kind.
fn run_kind(
    name: &str,
    ff: &FreeForm,
    scale: f64,
    n: usize,
    seed: u64,
    method: CastMethod,
) -> Tally {
    let solid = Solid::from_free_form(ff.clone());
    let mut caster = RayCaster::with_method(method);
    let mut rng = Rng(seed);
    let mut tally = Tally::default();
    let b = ff.bounds();
    let diag = b.diagonal();
    let centre = b.center();
    while tally.rays < n {
        if rng.unit() < 0.25 {
            // Retry until the probe finds a surface point, so a quarter of the rays graze.
            let ray = loop {
                if let Some(ray) = grazing_ray(ff, &mut rng, scale) {
                    break ray;
                }
            };
            tally.grazing += 1;
            check_ray(name, ff, &solid, &mut caster, &ray, &mut tally);
            continue;
        }
        // Origins around the object (some inside its box), aimed at random points of the box.
        let origin = centre + rng.direction() * diag * rng.range(0.3, 3.0);
        let Some(ray) = Ray::new(origin, rng.in_box(b.min, b.max) - origin) else {
            continue;
        };
        check_ray(name, ff, &solid, &mut caster, &ray, &mut tally);
    }
    assert!(
        tally.grazing * 5 >= tally.rays,
        "{name}: fewer than 20 % grazing rays"
    );
    assert!(
        tally.hits * 10 >= tally.rays,
        "{name}: too few hits to measure anything"
    );
    tally.report(&format!("{name} ({method:?})"));
    tally
}

fn cube(centre: DVec3, half: f64) -> fray_core::Aabb {
    fray_core::Aabb::from_center_half(centre, DVec3::splat(half))
}

fn kinds() -> Vec<(&'static str, FreeForm, f64)> {
    let c = DVec3::new(0.3, -0.2, 0.7);
    let rot = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3);
    let axis = rot * DVec3::Y;
    let ellipsoid = Quadric::ellipsoid(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.5));
    let rotated = ellipsoid
        .transformed(&DAffine3::from_rotation_translation(rot, c))
        .unwrap();
    let general = Quadric::new(c, [1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -3.0]);
    let free = |q: Quadric| FreeForm::new(q, vec![], None).unwrap();
    let clipped = |q: Quadric, half: f64| FreeForm::new(q, vec![], Some(cube(c, half))).unwrap();
    vec![
        ("sphere", free(Quadric::sphere(c, 1.0)), 1.0),
        (
            "ellipsoid",
            free(Quadric::ellipsoid(c, DVec3::new(2.0, 1.0, 0.5))),
            1.0,
        ),
        ("rotated ellipsoid", free(rotated), 1.0),
        (
            "cylinder",
            clipped(Quadric::cylinder(c, axis, 1.0), 2.0),
            1.0,
        ),
        ("cone", clipped(Quadric::cone(c, axis, 0.5), 2.0), 2.0),
        (
            "half-space",
            clipped(Quadric::half_space(c, DVec3::new(0.3, 1.0, -0.2)), 2.0),
            2.0,
        ),
        (
            "paraboloid",
            clipped(Quadric::paraboloid(c, axis, 0.5), 2.0),
            2.0,
        ),
        (
            "hyperboloid (1 sheet)",
            clipped(Quadric::hyperboloid(c, axis, 0.8, 1.2, Sheets::One), 2.0),
            2.0,
        ),
        (
            "hyperboloid (2 sheets)",
            clipped(Quadric::hyperboloid(c, axis, 0.8, 1.2, Sheets::Two), 2.0),
            2.0,
        ),
        ("general quadric", clipped(general, 2.0), 2.0),
    ]
}

#[test]
fn plain_quadrics_match_the_closed_form_to_1e_9_of_the_diagonal() {
    for method in METHODS {
        plain_quadrics_match_the_closed_form_to_1e_9_of_the_diagonal_with(method);
    }
}

fn plain_quadrics_match_the_closed_form_to_1e_9_of_the_diagonal_with(method: CastMethod) {
    for (i, (name, ff, scale)) in kinds().into_iter().enumerate() {
        assert!(ff.clips() || ff.bounds().diagonal() < 10.0, "{name}");
        run_kind(name, &ff, scale, RAYS_PER_KIND, 0xF4A7 + i as u64, method);
    }
}

/// Exactly tangent rays (up to the rounding of constructing them) on convex surfaces: no NaN, no
/// hit behind the origin, and a hit, if any, within `√(2 R (ε + η)) + ε` of the tangent point,
/// where `R` bounds the surface's radius of curvature and `η = 1e-13 L` the rounding of the
/// construction: that is the half chord of a ray that dips `ε + η` inside, i.e. the hit is
/// explained by moving the surface by ε.
#[test]
fn tangent_rays_never_give_nan_or_a_far_hit() {
    for method in METHODS {
        tangent_rays_never_give_nan_or_a_far_hit_with(method);
    }
}

fn tangent_rays_never_give_nan_or_a_far_hit_with(method: CastMethod) {
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
        let bound = (2.0 * radius_of_curvature * (eps + 1e-13 * size)).sqrt() + eps;
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
            let n = ff.base().gradient(p).normalize();
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
                worst = worst.max(off);
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
            "tangent {name:>22}: {tested} rays, {hits} hit, farthest hit {worst:.2e} from the tangent point (bound {bound:.2e})"
        );
    }
}

/// Rays lying in a ruled surface (a cylinder's or cone's generator line): the value is 0 along
/// the whole ray up to rounding; the cast must not produce NaN, a hit before the range start, or
/// a hit off the surface by more than ε along the normal.
#[test]
fn rays_along_generator_lines_are_stable() {
    for method in METHODS {
        rays_along_generator_lines_are_stable_with(method);
    }
}

fn rays_along_generator_lines_are_stable_with(method: CastMethod) {
    let c = DVec3::new(0.3, -0.2, 0.7);
    let axis = DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3) * DVec3::Y;
    let perp = axis.any_orthonormal_vector();
    let cyl = FreeForm::new(Quadric::cylinder(c, axis, 1.0), vec![], Some(cube(c, 2.0))).unwrap();
    let cone = FreeForm::new(Quadric::cone(c, axis, 0.5), vec![], Some(cube(c, 2.0))).unwrap();
    let generator_cone = (axis + perp * 0.5f64.tan()).normalize();
    let cases = [
        ("cylinder", cyl, c + perp, axis),
        ("cone", cone, c, generator_cone),
    ];
    for (name, ff, on_surface, dir) in cases {
        let solid = Solid::from_free_form(ff.clone());
        let eps = EPS_REL * solid.bounds().diagonal();
        for s in [-5.0, -1.0, 0.0, 1.0, 5.0] {
            for sign in [1.0, -1.0] {
                let ray = Ray::new(on_surface + dir * s, dir * sign).unwrap();
                let hit = RayCaster::with_method(method).cast(
                    &solid,
                    &ray,
                    full_range(),
                    eps,
                    &mut CastStats::default(),
                );
                if let Some(t) = hit {
                    assert!(!t.is_nan() && t >= 0.0, "{name}: t = {t}");
                    let p = ray.at(t);
                    let g = ff.base().gradient(p).length().max(1e-300);
                    let off_surface = ff.base().eval(p).abs() / g;
                    // At the cone's apex the gradient vanishes; there the point itself is the check.
                    let at_apex = name == "cone" && (p - c).length() < 1e-6;
                    assert!(
                        at_apex || off_surface <= eps + 1e-12,
                        "{name}: hit {off_surface:e} off the surface"
                    );
                }
            }
        }
    }
}

/// A unit sphere 1e6 m and 1e7 m from the world origin, camera 10 m away: the depth is still
/// within `1e-9 × diagonal` of the closed form, and the hit point, taken relative to the centre,
/// lies on the sphere to within `1e-9 × diagonal` (an independent check of the closed form).
#[test]
fn far_from_the_origin_keeps_relative_accuracy() {
    for method in METHODS {
        far_from_the_origin_keeps_relative_accuracy_with(method);
    }
}

fn far_from_the_origin_keeps_relative_accuracy_with(method: CastMethod) {
    for (k, distance) in [1e6, 1e7].into_iter().enumerate() {
        let centre = DVec3::new(0.6, 0.48, -0.64) * distance;
        let ff = FreeForm::new(Quadric::sphere(centre, 1.0), vec![], None).unwrap();
        let solid = Solid::from_free_form(ff.clone());
        let diag = solid.bounds().diagonal();
        let mut rng = Rng(100 + k as u64);
        let mut caster = RayCaster::with_method(method);
        let mut tally = Tally::default();
        let mut max_radial = 0.0f64;
        while tally.rays < 20_000 {
            let ray = if rng.unit() < 0.25 {
                let Some(r) = grazing_ray(&ff, &mut rng, 1.0) else {
                    continue;
                };
                tally.grazing += 1;
                r
            } else {
                let camera = centre + rng.direction() * 10.0;
                let b = ff.bounds();
                Ray::new(camera, rng.in_box(b.min, b.max) - camera).unwrap()
            };
            check_ray("far sphere", &ff, &solid, &mut caster, &ray, &mut tally);
            if let Some(t) = caster.cast(
                &solid,
                &ray,
                full_range(),
                EPS_REL * diag,
                &mut CastStats::default(),
            ) {
                let radial = ((ray.origin - centre) + ray.dir * t).length() - 1.0;
                assert!(
                    radial.abs() <= ERR_REL * diag,
                    "sphere at {distance:e} m: hit {radial:e} m off the surface"
                );
                max_radial = max_radial.max(radial.abs());
            }
        }
        tally.report(&format!("sphere at {distance:.0e} m"));
        eprintln!("{:>22}  max radial error {max_radial:.2e} m", "");
    }
}

/// Huge (1e6 m) and tiny (1e-6 m) spheres and rotated ellipsoids: the bound is relative, so it must
/// hold unchanged.
#[test]
fn huge_and_tiny_objects_keep_relative_accuracy() {
    for method in METHODS {
        huge_and_tiny_objects_keep_relative_accuracy_with(method);
    }
}

fn huge_and_tiny_objects_keep_relative_accuracy_with(method: CastMethod) {
    let rot = DAffine3::from_rotation_translation(
        DQuat::from_euler(EulerRot::XYZ, 0.4, -0.9, 1.3),
        DVec3::ZERO,
    );
    for size in [1e6, 1e-6] {
        let c = DVec3::new(0.3, -0.2, 0.7) * size;
        let sphere = FreeForm::new(Quadric::sphere(c, size), vec![], None).unwrap();
        let ell = Quadric::ellipsoid(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.5) * size)
            .transformed(&rot)
            .unwrap()
            .translated(c);
        let ell = FreeForm::new(ell, vec![], None).unwrap();
        let cyl = FreeForm::new(
            Quadric::cylinder(c, DVec3::new(1.0, 2.0, 0.5), size),
            vec![],
            Some(cube(c, 2.0 * size)),
        )
        .unwrap();
        run_kind(
            &format!("sphere r = {size:e}"),
            &sphere,
            size,
            20_000,
            11,
            method,
        );
        run_kind(
            &format!("ellipsoid {size:e}"),
            &ell,
            size,
            20_000,
            12,
            method,
        );
        run_kind(
            &format!("cylinder r = {size:e}"),
            &cyl,
            size,
            20_000,
            13,
            method,
        );
    }
}

/// Directions with exact zero components (along the axes and in the coordinate planes), where the
/// slab test and the quadratic's coefficients see exact zeros.
#[test]
fn rays_along_axes() {
    for method in METHODS {
        rays_along_axes_with(method);
    }
}

fn rays_along_axes_with(method: CastMethod) {
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
    let mut rng = Rng(99);
    for (name, ff, _) in kinds() {
        let solid = Solid::from_free_form(ff.clone());
        let mut caster = RayCaster::with_method(method);
        let mut tally = Tally::default();
        let b = ff.bounds();
        for i in 0..12_000 {
            let d = dirs[i % dirs.len()];
            // Start outside the box along −d, at a random point of the box's shadow; one in
            // eight exactly on a box face plane or through the object's origin.
            let mut target = rng.in_box(b.min, b.max);
            if i % 8 == 0 {
                target[(i / 8) % 3] = ff.base().origin[(i / 8) % 3];
            }
            let ray = Ray::new(target - d * b.diagonal() * rng.range(0.0, 2.0), d).unwrap();
            check_ray(name, &ff, &solid, &mut caster, &ray, &mut tally);
        }
        tally.report(&format!("{name} (axes)"));
    }
}

/// Zero form factors change nothing; a dent whose support touches the surface from outside and a
/// bump whose support touches it from inside leave `{F′ ≥ 0}` exactly `{F ≥ 0}`, so the closed
/// form of the bare quadric is still the reference, to the same `1e-9 × diagonal`.
#[test]
fn degenerate_perturbations_match_the_bare_quadric() {
    for method in METHODS {
        degenerate_perturbations_match_the_bare_quadric_with(method);
    }
}

fn degenerate_perturbations_match_the_bare_quadric_with(method: CastMethod) {
    let c = DVec3::new(0.3, -0.2, 0.7);
    let base = Quadric::sphere(c, 1.0);
    let bare = FreeForm::new(base, vec![], None).unwrap();
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
    for (name, perts) in variants {
        let ff = FreeForm::new(base, perts, None).unwrap();
        let solid = Solid::from_free_form(ff.clone());
        let diag = bare.bounds().diagonal();
        let eps = EPS_REL * diag;
        let mut rng = Rng(5);
        let mut caster = RayCaster::with_method(method);
        let mut tally = Tally::default();
        let mut stats = CastStats::default();
        while tally.rays < 20_000 {
            let ray = if tally.rays % 4 == 0 {
                let Some(r) = grazing_ray(&bare, &mut rng, 1.0) else {
                    continue;
                };
                tally.grazing += 1;
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
            tally.rays += 1;
            let searched = caster.cast(&solid, &ray, full_range(), eps, &mut stats);
            let closed = bare.closed_form_hit(&ray, full_range());
            match (searched, closed) {
                (Some(ts), Some(tc)) => {
                    assert!(!ts.is_nan() && ts >= 0.0);
                    let err = (ts - tc).abs() / diag;
                    assert!(err <= ERR_REL, "{name}: |Δt| = {err:e} × diag for {ray:?}");
                    tally.max_err_rel = tally.max_err_rel.max(err);
                    tally.hits += 1;
                }
                (None, None) => tally.misses += 1,
                (s, cl) => {
                    assert!(
                        ambiguous(&bare, &ray, eps),
                        "{name}: search {s:?} vs closed {cl:?} for {ray:?}"
                    );
                    tally.ambiguous_disagreements += 1;
                }
            }
        }
        eprintln!(
            "{name:>28}: {} rays, {} hits, max |Δt|/diag = {:.2e}, tangent disagreements {}",
            tally.rays, tally.hits, tally.max_err_rel, tally.ambiguous_disagreements
        );
    }
}
