//! Terrains under stress: height maps drawn by the strategy — flat (a zero-thickness solid when
//! the constant is 0), spikes, steps (cliffs), noise, a threshold cutting holes a quarter of the
//! time —, `2..1024` samples a side, spacing and vertical scale `10^[−3, 6]`, rotated about the
//! vertical, a third of them `10⁵`–`3·10⁶` from the world origin, bilinear or bicubic; rays
//! grazing the surface, along the world's and the map's axes (on cell lines), vertical, from
//! below the base and from inside the solid, from `10⁵` away, over segments — `Terrain::cast`,
//! the pixel LOD (`cast_lod`), a LOD bias (a second terrain of the same map) and `occluded`
//! (with and without the min pyramid).
//!
//! The reference is the interpolated height `S = Terrain::surface(u, v)` along the ray in map
//! space, `g(t) = r(t) − S(u(t), v(t))` (inside the solid where `g ≤ 0` and `r ≥ bottom`),
//! allowed the rounding of the map point (`8u (|o| + |d| t)` per axis, times the steepest slope
//! the samples allow) and of `S` itself. Per ray:
//! - **no nonsense**: every hit finite, in the range, its normal a unit vector;
//! - **on the surface**: a surface hit has `|g| ≤ tol` (bicubic: plus the root tolerance `2ε`
//!   times `|g′|`), a wall or start hit `g ≤ tol` (inside the closed solid);
//! - **nothing missed**: no sample of `g` along the ray before the hit (52 jittered and
//!   geometric ones toward it, and around the family's target point) is inside by more than the
//!   allowance, past the stated bound `δ = 10⁻⁶` cell `+ 2ε` before the hit
//!   (`crates/terrain/tests/exactness.rs`: the search equals the brute force to `10⁻⁶` cell,
//!   bicubic to `2ε`); on a miss, none anywhere in the box; on maps of at most `24²` cells, the
//!   brute force over every cell (`cast_brute_force`) agrees to `δ`;
//! - **LOD**: the biased and the pixel-LOD hits are never later than the exact one by more
//!   than `δ`, never miss one, and lie in the max column (`Terrain::column_bounds`) they
//!   report;
//! - **shadows**: `occluded` answers as `cast` does.

use super::runner::{self, Family, Tally};
use fray_core::{Interval, Ray};
use fray_terrain::{Heightmap, HitKind, Interpolation, Placement, Terrain, TerrainOptions};
use fray_test_support::Rng;
use glam::{DMat3, DVec2, DVec3};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const U: f64 = f64::EPSILON / 2.0;
const FAMILIES: [&str; 8] = [
    "random",
    "grazing",
    "axes",
    "vertical",
    "below/inside",
    "far camera",
    "segment",
    "cell lines",
];
const RAYS_PER_CASE: usize = 2048;
/// The search's stated agreement with the brute force, in cells (`exactness.rs`).
const CELL_BOUND: f64 = 1e-6;
const SAMPLES: usize = 40;
const APPROACH: usize = 12;

/// One terrain: its map's kind and size, placement and options, and the rays' seed.
#[derive(Clone, Debug)]
pub struct TerrainCase {
    kind: u8,
    size: (usize, usize),
    spacing: DVec2,
    vertical: f64,
    amplitude: f64,
    far: bool,
    yaw: f64,
    bicubic: bool,
    holes: bool,
    lod_bias: u32,
    min_pyramid: bool,
    seed: u64,
}

fn terrain_case() -> impl Strategy<Value = TerrainCase> {
    (
        (0..4u8, 1.0..10.0f64, 1.0..10.0f64),
        (-3.0..6.0f64, -1.0..1.0f64, -3.0..6.0f64, -3.0..3.0f64),
        (0..3u8, -3.2..3.2f64, any::<bool>(), 0..4u8),
        (1..4u32, any::<bool>(), any::<u64>()),
    )
        .prop_map(
            |((kind, w, h), (s, aspect, v, a), (far, yaw, bicubic, holes), (bias, min, seed))| {
                TerrainCase {
                    kind,
                    size: (2f64.powf(w).round() as usize, 2f64.powf(h).round() as usize),
                    spacing: DVec2::new(10f64.powf(s), 10f64.powf(s + aspect)),
                    vertical: 10f64.powf(v),
                    amplitude: 10f64.powf(a),
                    far: far == 0,
                    yaw,
                    // Bicubic on spike maps: seconds per ray (docs/stress.md, findings).
                    bicubic: bicubic && (kind == 0 || kind == 3),
                    holes: holes == 0,
                    lod_bias: bias,
                    min_pyramid: min,
                    seed,
                }
            },
        )
}

/// The samples of `case`'s map (raw units), row-major.
fn samples(case: &TerrainCase, rng: &mut Rng) -> Vec<f32> {
    let (w, h) = case.size;
    let a = case.amplitude;
    let offset = if rng.unit() < 0.5 {
        0.0
    } else {
        a * rng.range(-2.0, 2.0)
    };
    let (fu, fv, levels) = (
        rng.range(0.05, 0.7),
        rng.range(0.05, 0.7),
        rng.range(2.0, 9.0),
    );
    (0..w * h)
        .map(|k| {
            let (i, j) = ((k % w) as f64, (k / w) as f64);
            let z = match case.kind {
                0 => offset,
                1 if rng.unit() < 0.02 => offset + a * rng.log_uniform(0.0, 3.0),
                1 if rng.unit() < 0.01 => offset - a * rng.log_uniform(0.0, 1.0),
                1 => offset,
                2 => offset + a * ((i * fu + j * fv).floor() % levels),
                _ => offset + a * rng.unit(),
            };
            z as f32
        })
        .collect()
}

fn build(case: &TerrainCase, rng: &mut Rng) -> (Terrain, Terrain) {
    let (w, h) = case.size;
    let values = samples(case, rng);
    let mut map = Heightmap::from_samples(w, h, values.clone()).expect("a valid map");
    if case.holes && case.kind != 0 {
        let mut sorted = values;
        sorted.sort_by(f32::total_cmp);
        // Cut the lowest third out (a threshold under the highest sample keeps some solid).
        let cut = sorted[sorted.len() / 3];
        if cut < sorted[sorted.len() - 1] {
            map = map.with_threshold(cut).expect("a finite threshold");
        }
    }
    let origin = if case.far {
        rng.direction() * rng.log_uniform(5.0, 6.5)
    } else {
        DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0) * case.spacing.x
    };
    let placement = Placement::new(origin, case.spacing, case.vertical)
        .and_then(|p| p.with_rotation(DMat3::from_rotation_y(case.yaw)))
        .expect("a valid placement");
    let interpolation = if case.bicubic {
        Interpolation::Bicubic
    } else {
        Interpolation::Bilinear
    };
    let options = TerrainOptions {
        interpolation,
        lod_bias: 0,
        min_pyramid: case.min_pyramid,
    };
    let exact = match Terrain::new(map.clone(), placement, options) {
        Ok(t) => t,
        // Every cell cut out (a bicubic-free threshold can still leave none): no threshold.
        Err(_) => {
            let plain = Heightmap::from_samples(w, h, map.samples().to_vec()).expect("valid");
            return build_plain(plain, placement, options, case.lod_bias);
        }
    };
    let biased = Terrain::new(
        map,
        placement,
        TerrainOptions {
            lod_bias: case.lod_bias,
            min_pyramid: !case.min_pyramid,
            ..options
        },
    )
    .expect("the same map builds");
    (exact, biased)
}

fn build_plain(
    map: Heightmap,
    placement: Placement,
    options: TerrainOptions,
    lod_bias: u32,
) -> (Terrain, Terrain) {
    let exact = Terrain::new(map.clone(), placement, options).expect("a map without holes");
    let biased = Terrain::new(
        map,
        placement,
        TerrainOptions {
            lod_bias,
            ..options
        },
    )
    .expect("the same map builds");
    (exact, biased)
}

/// What the reference needs of a terrain and one ray.
struct Probe<'a> {
    terrain: &'a Terrain,
    o: DVec3,
    d: DVec3,
    /// The steepest raw slope per sample the map allows (its height range).
    slope: f64,
    /// `[bottom, top]` of the solid.
    bottom: f64,
    top: f64,
}

impl Probe<'_> {
    /// The map point at `t` and the rounding allowance there (per axis).
    fn at(&self, t: f64) -> (DVec3, DVec3) {
        let e = (self.o.abs() + self.d.abs() * t.abs()) * (16.0 * U) + DVec3::splat(1e-300);
        (self.o + self.d * t, e)
    }

    /// `g(t)` and its allowance: `None` off the map or over a cut-out cell.
    fn g(&self, t: f64) -> Option<(f64, f64, DVec3)> {
        let (p, e) = self.at(t);
        let s = self.terrain.surface(p.x, p.y)?;
        let mag = self.bottom.abs().max(self.top.abs());
        let tol = 2.0 * (e.z + self.slope * (e.x + e.y)) + 32.0 * U * mag + 1e-300;
        Some((p.z - s, tol, p))
    }

    /// How fast `g` can change per unit of `t`.
    fn g_rate(&self) -> f64 {
        self.d.z.abs() + self.slope * (self.d.x.abs() + self.d.y.abs())
    }

    /// Whether the sample at `t` lies inside the solid by more than its allowance plus
    /// `slack` of `g`.
    fn deep_inside(&self, t: f64, slack: f64) -> Option<f64> {
        let (g, tol, p) = self.g(t)?;
        // On a wall (an outline or the map's border, within rounding) a point is on the
        // solid's boundary, not inside: every neighbour a little off must be solid too —
        let (_, e) = self.at(t);
        let mu = 4.0 * e.x.max(e.y) + 1e-9;
        // And on a cell line where bicubic border patches step, inside under both.
        let mut g = g;
        for (du, dv) in [(mu, 0.0), (-mu, 0.0), (0.0, mu), (0.0, -mu)] {
            g = g.max(p.z - self.terrain.surface(p.x + du, p.y + dv)?);
        }
        let margin = tol + slack;
        (g < -margin && p.z - self.bottom > margin).then_some(-g)
    }
}

/// The box clip in map space, independent of the crate's: `[t0, t1]` within `range`.
fn clip(t: &Terrain, o: DVec3, d: DVec3, range: Interval) -> Option<(f64, f64)> {
    let (lo, hi) = t.map_box();
    let (mut a, mut b) = (range.lo, range.hi);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (p, q) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
        a = a.max(p.min(q));
        b = b.min(p.max(q));
    }
    (a <= b).then_some((a, b))
}

#[allow(clippy::too_many_lines)]
fn run_case(case: &TerrainCase, tally: &Tally) -> Result<(), TestCaseError> {
    let mut rng = Rng(case.seed);
    let (exact, biased) = build(case, &mut rng);
    let place = *exact.placement();
    let (bottom, top) = exact.height_range();
    let (cw, ch) = exact.map().cells();
    let cell = case.spacing.min_element();
    let eps = 1e-9 * cell;
    let bounds = exact.bounds();
    let diag = bounds.diagonal();
    let centre = 0.5 * (bounds.min + bounds.max);
    let n = exact.max_pyramid().levels();
    let small = cw * ch <= 24 * 24;
    let mut families = [Family::default(); FAMILIES.len()];
    // A point of the surface (world) and its map position.
    let surface_point = |rng: &mut Rng| loop {
        let (u, v) = (rng.range(0.0, cw as f64), rng.range(0.0, ch as f64));
        if let Some(s) = exact.surface(u, v) {
            return place.to_world(DVec3::new(u, v, s));
        }
    };
    let sign = |rng: &mut Rng| if rng.unit() < 0.5 { -1.0 } else { 1.0 };
    for i in 0..RAYS_PER_CASE {
        let k = i % FAMILIES.len();
        let full = Interval::new(0.0, f64::INFINITY);
        let dist = diag * rng.range(0.6, 3.0);
        let (u_axis, v_axis) = (place.rotation() * DVec3::X, place.rotation() * DVec3::Z);
        // (origin, direction, range, target point the family aims at)
        let (o, d, range, target) = match k {
            1 => {
                // Tangent to the horizontal at a surface point, tilted ±10^[−12, −3] rad.
                let p = surface_point(&mut rng);
                let a = rng.range(0.0, std::f64::consts::TAU);
                let e = sign(&mut rng) * rng.log_uniform(-12.0, -3.0);
                let d = DVec3::new(a.cos(), e, a.sin()).normalize();
                (p - d * dist, d, full, Some(p))
            }
            2 => {
                // Along a world axis or the map's, through a surface point.
                let p = surface_point(&mut rng);
                let axes = [DVec3::X, DVec3::Y, DVec3::Z, u_axis, v_axis];
                let d = axes[rng.below(axes.len())] * sign(&mut rng);
                (p - d * dist, d, full, Some(p))
            }
            3 => {
                // Vertical through a sample, a cell line or anywhere; down or up.
                let mut q = DVec3::new(rng.range(0.0, cw as f64), rng.range(0.0, ch as f64), 0.0);
                match rng.below(3) {
                    0 => q = q.floor(),
                    1 => q.x = q.x.floor(),
                    _ => {}
                }
                let p = place.to_world(q);
                let d = DVec3::Y * if rng.unit() < 0.8 { -1.0 } else { 1.0 };
                let h = place.vertical_scale() * (top - bottom).max(1.0);
                (p - d * (h * rng.range(1.5, 3.0)), d, full, None)
            }
            4 => {
                // From below the base or from inside the solid (under the surface).
                let p = surface_point(&mut rng);
                let q = place.to_map(p);
                let r = q.z - (q.z - bottom + case.amplitude) * rng.range(0.0, 2.0);
                let below = place.to_world(DVec3::new(q.x, q.y, r));
                (below, rng.direction(), full, Some(p))
            }
            5 => {
                let p = surface_point(&mut rng);
                let d = (p - (centre + rng.direction() * diag)).normalize_or(DVec3::NEG_Y);
                (p - d * rng.range(1e5, 3e5), d, full, Some(p))
            }
            6 => {
                let p = surface_point(&mut rng);
                let d = rng.direction();
                let lo = dist + diag * rng.range(-0.5, 0.5);
                let range =
                    Interval::new(lo.max(0.0), lo.max(0.0) + diag * rng.log_uniform(-6.0, 0.0));
                (p - d * dist, d, range, Some(p))
            }
            7 => {
                // Along a cell line of the map (an exact integer u or v), tilted down a little.
                let p = surface_point(&mut rng);
                let q = place.to_map(p);
                let along_u = rng.unit() < 0.5;
                let line = if along_u {
                    DVec3::new(q.x, (rng.below(ch + 1)) as f64, q.z)
                } else {
                    DVec3::new((rng.below(cw + 1)) as f64, q.y, q.z)
                };
                let w = place.to_world(line);
                let axis = if along_u { u_axis } else { v_axis };
                let d = (axis * sign(&mut rng) - DVec3::Y * rng.log_uniform(-9.0, 0.0)).normalize();
                (w - d * dist, d, full, Some(w))
            }
            _ => {
                let q = rng.in_box(bounds.min, bounds.max);
                let d = rng.direction();
                (q - d * dist, d, full, Some(q))
            }
        };
        let ray = Ray::new(o, d).expect("a unit direction");
        let m = place.map_ray(&ray);
        let probe = Probe {
            terrain: &exact,
            o: m.origin,
            d: m.dir,
            slope: (top - bottom).max(0.0),
            bottom,
            top,
        };
        let fail = |what: String| {
            TestCaseError::fail(format!(
                "{} ray on {case:?} (origin {:?}): {what} for {ray:?} over {range:?}",
                FAMILIES[k],
                place.origin()
            ))
        };
        let hit = exact.cast(&ray, range, eps);
        let span = clip(&exact, m.origin, m.dir, range);
        // The stated bound in t, and what it is worth in g.
        let delta = CELL_BOUND * cell + 2.0 * eps;
        let slack = probe.g_rate() * delta;
        if let Some(h) = hit {
            if !(h.t.is_finite() && h.t >= range.lo && h.t <= range.hi) {
                return Err(fail(format!("hit t = {} outside the range", h.t)));
            }
            if !(h.normal.is_finite() && (h.normal.length() - 1.0).abs() < 1e-9) {
                return Err(fail(format!("normal {:?}", h.normal)));
            }
            if let Some((g, tol, p)) = probe.g(h.t) {
                let root = if case.bicubic {
                    2.0 * eps * probe.g_rate()
                } else {
                    0.0
                };
                // On a cell line bicubic border patches may step (`Interpolation`): `surface`
                // reads one side, the hit may be on the other.
                let mu = 4.0 * probe.at(h.t).1.max_element() + 1e-9;
                let step = case.bicubic && [p.x, p.y].iter().any(|c| (c - c.round()).abs() < mu);
                let above = g > tol + root && !step;
                let below = h.kind == HitKind::Surface && g < -(tol + root) && !step;
                if above || below {
                    return Err(fail(format!(
                        "{:?} hit at {} where g = {g:e} (allowed {:e})",
                        h.kind,
                        h.t,
                        tol + root
                    )));
                }
                if h.kind == HitKind::Surface && !step {
                    families[k].worst = families[k].worst.max(g.abs() / (tol + root));
                }
            }
        }
        // Nothing inside the solid before the hit (or anywhere, on a miss).
        if let Some((t0, t1)) = span {
            let end = hit.map_or(t1, |h| h.t - delta);
            if end > t0 {
                let mut ts: Vec<f64> = (0..SAMPLES)
                    .map(|j| t0 + (end - t0) * ((j as f64 + rng.unit()) / SAMPLES as f64))
                    .collect();
                ts.extend((1..=APPROACH).map(|j| end - (end - t0) * 0.5f64.powi(2 * j as i32)));
                ts.push(t0);
                if let Some(p) = target {
                    let tt = (p - o).dot(d);
                    for j in [-9, -6, -3] {
                        ts.push(tt * (1.0 - 10f64.powi(j)));
                    }
                }
                for t in ts.into_iter().filter(|&t| t >= t0 && t <= end) {
                    if let Some(depth) = probe.deep_inside(t, slack) {
                        return Err(fail(format!(
                            "{:?}: inside the solid by {depth:e} (raw) at t = {t}",
                            hit.map(|h| h.t)
                        )));
                    }
                }
            }
        }
        // The first sample deep inside the solid in `[a, b]` (16 jittered and its ends).
        let footprint = rng.log_uniform(-4.0, -1.0);
        let mut jitter = Rng(rng.next_u64());
        let mut deep_between = |a: f64, b: f64| {
            let ts = (0..16).map(|j| a + (b - a) * ((j as f64 + jitter.unit()) / 16.0));
            ts.chain([a, b])
                .find_map(|t| probe.deep_inside(t, slack).map(|depth| (t, depth)))
        };
        // Two answers differ only where no point between them lies inside by more than the
        // allowance (a grazing ray's `t` moves far with the rounding of its height); a hit the
        // other lacks only where nothing near it lies that deep (a touch).
        let mut differ = |what: &str, first: Option<f64>, second: Option<f64>| -> Option<String> {
            let bad = match (first, second) {
                (Some(a), Some(b)) if b > a + delta => deep_between(a, b - delta),
                (Some(a), None) => deep_between(a, span.map_or(a, |s| s.1.min(a + 1e-3 * diag))),
                _ => None,
            };
            bad.map(|(t, depth)| {
                format!("{what}: {first:?} then {second:?}, inside by {depth:e} at {t}")
            })
        };
        if small {
            let brute = exact.cast_brute_force(&ray, range, eps).map(|h| h.t);
            if let Some(e) = differ("brute force, search", brute, hit.map(|h| h.t)) {
                return Err(fail(e));
            }
        }
        let occ = exact.occluded(&ray, range, eps);
        if occ != hit.is_some() {
            return Err(fail(format!("occluded disagrees with the hit {hit:?}")));
        }
        let biased_hit = biased.cast(&ray, range, eps);
        if biased.occluded(&ray, range, eps) != biased_hit.is_some() {
            return Err(fail(format!(
                "the biased occluded disagrees with {biased_hit:?}"
            )));
        }
        // Level of detail: never later, never missing, inside the column it reports.
        for (what, t, lod) in [
            ("bias", &biased, biased_hit),
            ("pixel", &exact, exact.cast_lod(&ray, range, eps, footprint)),
        ] {
            if let Some(e) = differ(what, hit.map(|h| h.t), lod.map(|l| l.t)) {
                return Err(fail(format!("the LOD is late or missing: {e}")));
            }
            if let Some(l) = lod {
                if !(l.t.is_finite() && l.t >= range.lo && l.t <= range.hi) {
                    return Err(fail(format!(
                        "{what} LOD hit t = {} outside the range",
                        l.t
                    )));
                }
                let level = n - l.levels_above_finest;
                let column = t
                    .column_bounds(level, l.cell[0] as usize, l.cell[1] as usize)
                    .ok_or_else(|| fail(format!("{what} LOD hit on an empty column {l:?}")))?;
                let p = ray.at(l.t);
                let grow = 1e-9 * diag + 64.0 * U * (o.abs().max_element() + l.t);
                let outside = (column.min - p).max(p - column.max).max_element();
                if outside > grow {
                    return Err(fail(format!(
                        "{what} LOD hit {l:?} {outside:e} outside its column {column:?}"
                    )));
                }
            }
        }
        families[k].count(hit.is_some());
    }
    tally.add(&families);
    Ok(())
}

#[test]
fn terrains() {
    let name = "terrains";
    let cases = 300;
    let tally = Tally::new(name, &FAMILIES, "|g| at the hit ÷ its allowance");
    runner::run(name, cases, terrain_case(), |case| run_case(&case, &tally));
    let total = tally.report();
    let planned = runner::cases(cases) * RAYS_PER_CASE as u64;
    assert!(total >= planned, "{name}: {total} rays, planned {planned}");
}
