//! The GPU's share of the numerical stress suite (issue 27; the CPU's is
//! `crates/trace/tests/stress/`, `docs/stress.md`): ~10⁶ adversarial rays through the batch
//! kernels of `fray_gpu::testing`, seeded (the same rays every run; `FRAY_STRESS_SEED` changes
//! them, `FRAY_STRESS_SCALE` multiplies the cases), each answer checked for nonsense and against
//! the f64 reference within the bounds `tests/rays.rs` states for the GPU.
//!
//! - **Terrains** (`TerrainBatch`, exact): maps of flat, spiky, stepped and noisy samples,
//!   `2..512` a side, spacing `10^[−2, 4]`, slopes up to 100, bilinear or bicubic, seen from
//!   a camera near the map, at the surface's height (grazing), under the base, or `10³`–`10⁴`
//!   diagonals away; rays from it through surface points, points just above the surface,
//!   cell lines and anywhere in the box, over `[0, ∞)` or segments. Per ray: a hit's `t` finite
//!   and in the range (never before its start); against the f64 `Terrain::cast` of the same ray,
//!   within `depth(t) = 10⁻⁵ t + 4 ε_gpu` across the surface (`|Δt| |cos θ|`), or a hit up to
//!   `depth` above the interpolated height (a skimmed ridge), a later hit or a miss only where
//!   the ray stays within `depth` of the surface (a graze: rays.rs's "spans entered at a grazing
//!   angle"; its terrain rule, a span left within `50 depth`, misses a ray that runs along a
//!   flat surface at its height).
//! - **Fog** (`FogBatch`): layers `10^[−1, 4]` m thick, homogeneous or falling off, extinction
//!   `10^[−6, 1]` per thickness; rays from inside, above, below, from `10⁴` away, horizontal
//!   and nearly so, over bounded and unbounded ranges. Per ray: `T ∈ [0, 1]`, `τ ≥ 0` and a
//!   number; against `FogLayer`'s f64 closed form, `T` within `10⁻⁶ + 5·10⁻⁵ T` (rays.rs) and
//!   `τ` within `10⁻⁶ + 5·10⁻⁵ τ`, each plus the f32 rounding of the crossing's length
//!   (`c = B · 4 · 2⁻²³ |Δy| / |d_y|` of `τ`, `T c` of `T`; `Δy` the layer's bounds relative to
//!   the camera — what a camera far above or a nearly horizontal ray costs in f32 —, and with
//!   a falloff `τ · 4 · 2⁻²³ |Δy| / H`; and `B 2⁻²³ (|lo| + |hi|)` for the range's ends).
//!
//! - **Meshes** (`MeshBatch`): the cube `[−1, 1]³` scaled `10^[−2, 4]`, axis-aligned or rotated,
//!   a third `10⁵` from the origin; cameras near it, in a face's plane (grazing), `10³`–`10⁴`
//!   diagonals away, or inside; rays through its vertices, edges, faces and centre, over
//!   `[0, ∞)` or segments. Against an f64 brute force over its triangles: a hit finite, in the
//!   range, any-hit true there; `|Δt| cos θ ≤ 4 ε_f32 s` (rays.rs's GPU bound, `s = |camera −
//!   centre| + t + diagonal`), a difference beyond it, a miss or an extra hit only within
//!   `64 ε_f32 s` of an edge (the reference's, or the cube's silhouette at the GPU's hit) or on a
//!   face the ray grazes; a ray from outside through the centre always hits.
//!
//! Uses the libtest-mimic harness: ignored without an adapter, a failure under
//! `FRAY_REQUIRE_GPU=1`.

mod common;

use fray_atmosphere::gpu_layout::GpuFog;
use fray_atmosphere::{FogLayer, FogModel, Phase};
use fray_core::{Interval, Ray};
use fray_gpu::GpuContext;
use fray_gpu::testing::{FogBatch, GpuFogRay, GpuRay, MeshBatch, TerrainBatch};
use fray_mesh::{Instance, MeshBvh, TriangleMesh};
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use fray_test_support::Rng;
use fray_test_support::triangles::{edge_distance, moller_trumbore};
use glam::{DAffine3, DMat3, DQuat, DVec2, DVec3, EulerRot};
use std::sync::Arc;
use std::time::Instant;

/// `cases × FRAY_STRESS_SCALE`.
fn cases(n: u32) -> u32 {
    let scale = std::env::var("FRAY_STRESS_SCALE")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or(1.0);
    (f64::from(n) * scale).ceil() as u32
}

/// The seed of case `k` of test `salt`.
fn seed(salt: u64, k: u32) -> u64 {
    let extra = std::env::var("FRAY_STRESS_SEED")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(0);
    Rng(salt ^ extra.rotate_left(17) ^ u64::from(k).wrapping_mul(0x9E37_79B9_7F4A_7C15)).next_u64()
}

fn relative(rays: &[(Ray, Interval)], reference: DVec3) -> Vec<GpuRay> {
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

/// A terrain of the strategy's kinds, its camera (the rays' origin and the GPU's reference).
fn terrain_case(rng: &mut Rng) -> Terrain {
    let (w, h) = (
        2f64.powf(rng.range(1.0, 9.0)).round() as usize,
        2f64.powf(rng.range(1.0, 9.0)).round() as usize,
    );
    let a = rng.log_uniform(-2.0, 2.0);
    let kind = rng.below(4);
    let (fu, fv) = (rng.range(0.05, 0.7), rng.range(0.05, 0.7));
    let samples: Vec<f32> = (0..w * h)
        .map(|k| {
            let (i, j) = ((k % w) as f64, (k / w) as f64);
            (match kind {
                0 => a,
                1 if rng.unit() < 0.02 => a * rng.log_uniform(0.0, 2.0),
                1 => 0.0,
                2 => a * ((i * fu + j * fv).floor() % 5.0),
                _ => a * rng.unit(),
            }) as f32
        })
        .collect();
    let map = Heightmap::from_samples(w, h, samples).expect("a valid map");
    let s = rng.log_uniform(-2.0, 4.0);
    let placement = Placement::new(
        DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ) * s
            * 10.0,
        DVec2::new(s, s * rng.log_uniform(-0.5, 0.5)),
        // Relief up to 100 samples' spacing per sample (slopes ≤ 100): steeper needles seen from
        // 10⁷ away are past the stated bound (docs/stress.md, findings).
        s * rng.log_uniform(-3.0, 2.0) / a,
    )
    .and_then(|p| p.with_rotation(DMat3::from_rotation_y(rng.range(-3.2, 3.2))))
    .expect("a valid placement");
    let interpolation = if kind == 3 && rng.unit() < 0.5 {
        Interpolation::Bicubic
    } else {
        Interpolation::Bilinear
    };
    let options = TerrainOptions {
        interpolation,
        ..TerrainOptions::default()
    };
    Terrain::new(map, placement, options).expect("a map without holes")
}

const TERRAIN_RAYS: usize = 8192;

/// What the f64 reference says along a ray: how far (world) the point at `s` lies outside the
/// solid — above the interpolated surface (across it, to first order), or under the base —, or,
/// negative, inside it (from its nearest boundary);
/// `None` off the map.
fn height_above(t: &Terrain, ray: &Ray, s: f64) -> Option<f64> {
    let p = t.placement().map_ray(ray).at(s);
    let bottom = t.map_box().0.z;
    let h = t.surface(p.x, p.y)?;
    if p.z < bottom {
        return Some((bottom - p.z) * t.placement().vertical_scale());
    }
    // Across the surface: the vertical gap times the cosine of the slope there.
    let w = ray.at(s);
    let cos = t.surface_normal_at(w).map_or(1.0, |n| n.y.abs());
    let vs = t.placement().vertical_scale();
    let above = (p.z - h) * vs * cos;
    if above > 0.0 {
        return Some(above);
    }
    // Inside: as deep as the nearest boundary — the surface, the base, the map's border walls.
    let (cw, ch) = t.map().cells();
    let sp = t.placement().spacing();
    let walls = (p.x.min(cw as f64 - p.x) * sp.x).min(p.y.min(ch as f64 - p.y) * sp.y);
    Some(-(-above).min((p.z - bottom) * vs).min(walls))
}

/// A ray's range: a fifth of them a segment starting between half the distance to the target
/// and the target, up to a diagonal long; the others `[0, ∞)`.
fn case_range(rng: &mut Rng, to_target: f64, diag: f64) -> Interval {
    if rng.unit() < 0.2 {
        let lo = to_target * rng.range(0.5, 1.0);
        Interval::new(lo, lo + diag * rng.log_uniform(-3.0, 0.0))
    } else {
        Interval::new(0.0, f64::INFINITY)
    }
}

fn terrains(ctx: &GpuContext) -> (u64, f64, u64) {
    let mut total = 0u64;
    let mut base_slivers = 0u64;
    let mut worst = 0.0f64;
    for case in 0..cases(48) {
        let mut rng = Rng(seed(0x7e55, case));
        let terrain = terrain_case(&mut rng);
        let b = terrain.bounds();
        let diag = b.diagonal();
        let centre = 0.5 * (b.min + b.max);
        let (cw, ch) = terrain.map().cells();
        let place = *terrain.placement();
        let surface_point = |rng: &mut Rng, lift: f64| {
            let (u, v) = (rng.range(0.0, cw as f64), rng.range(0.0, ch as f64));
            let s = terrain.surface(u, v).expect("no holes");
            place.to_world(DVec3::new(u, v, s)) + DVec3::Y * lift
        };
        let family = case % 4;
        let camera = match family {
            0 => centre + rng.direction() * diag * rng.range(0.6, 2.0),
            1 => {
                // At the surface's height, off the map: every ray grazes.
                let p = surface_point(&mut rng, 0.0);
                let a = rng.range(0.0, std::f64::consts::TAU);
                p + DVec3::new(a.cos(), 0.0, a.sin()) * diag
            }
            2 => centre - DVec3::Y * diag * rng.range(0.1, 1.0),
            _ => centre + rng.direction() * diag * rng.log_uniform(3.0, 4.0),
        };
        let eps_gpu = (1.0 / 1_048_576.0) * (camera - centre).length();
        let depth = |t: f64| 1e-5 * t + 4.0 * eps_gpu;
        let rays: Vec<(Ray, Interval)> = (0..TERRAIN_RAYS)
            .map(|i| {
                let target = match i % 4 {
                    0 => surface_point(&mut rng, 0.0),
                    1 => {
                        let lift = diag * rng.log_uniform(-9.0, -3.0);
                        surface_point(&mut rng, lift)
                    }
                    2 => {
                        let mut q = place.to_map(surface_point(&mut rng, 0.0));
                        q.x = q.x.floor();
                        place.to_world(q)
                    }
                    _ => rng.in_box(b.min, b.max),
                };
                let d = (target - camera).normalize_or(DVec3::NEG_Y);
                let range = case_range(&mut rng, (target - camera).length(), diag);
                (Ray::new(camera, d).expect("a unit direction"), range)
            })
            .collect();
        let batch = TerrainBatch::new(ctx, &terrain, camera)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_epsilon(eps_gpu);
        let hits = batch
            .cast_hits(ctx, &relative(&rays, camera))
            .unwrap_or_else(|e| panic!("{e}"));
        for ((ray, range), g) in rays.iter().zip(&hits) {
            total += 1;
            let reference = terrain.cast(ray, *range, 1e-9 * diag);
            let fail = |what: String| {
                panic!(
                    "terrain case {case} (family {family}, {:?}, {cw}×{ch} cells, spacing {:?}, \
                     vertical {}): {what} for {ray:?} over {range:?}",
                    terrain.options().interpolation,
                    place.spacing(),
                    place.vertical_scale()
                )
            };
            let gt = g.is_hit().then_some(f64::from(g.t));
            if let Some(t) = gt {
                let lo = f64::from(range.lo as f32);
                if !(t.is_finite() && t >= lo && t <= range.hi * (1.0 + 1e-6)) {
                    fail(format!("GPU hit t = {t} outside the range"));
                }
                if !g.normal.iter().all(|c| c.is_finite()) {
                    fail(format!("GPU normal {:?}", g.normal));
                }
            }
            // A graze: the ray stays within the depth bound of the surface (across it) over
            // `[a, b]` (65 samples; off the map is outside).
            let shallow = |a: f64, b: f64| {
                (0..=64).all(|j| {
                    let s = a + (b - a) * f64::from(j) / 64.0;
                    height_above(&terrain, ray, s).is_none_or(|h| h >= -depth(s))
                })
            };
            // A base sliver: the ray enters through the base from below where the solid above
            // the base is thinner than the depth bound (a flat stretch at the base height is a
            // sheet of zero thickness, which the f64 cast reports as a wall). f32 rounding of
            // the entry point may step over it, as over any sliver thinner than the GPU's
            // bound (docs/stress.md, finding 4). Counted; a thicker solid must be found.
            let through_base = reference.is_some_and(|c| {
                let p = place.map_ray(ray).at(c.t);
                let (lo, hi) = terrain.map_box();
                let thickness = terrain
                    .surface(p.x, p.y)
                    .map_or(0.0, |s| (s - lo.z) * place.vertical_scale());
                c.kind == fray_terrain::HitKind::Wall
                    && ray.dir.dot(place.rotation() * DVec3::Y) > 0.0
                    && (p.z - lo.z).abs() <= 1e-6 * (hi.z - lo.z).max(1.0)
                    && thickness <= depth(c.t)
                    && gt.is_none_or(|t| t > c.t + depth(c.t))
            });
            if through_base {
                base_slivers += 1;
                continue;
            }
            match (gt, reference) {
                (Some(t), Some(c)) => {
                    let cos = c.normal.dot(ray.dir).abs();
                    let off = (t - c.t).abs() * cos.max(1e-300);
                    let skim =
                        t < c.t && height_above(&terrain, ray, t).is_none_or(|h| h <= depth(t));
                    let late = t > c.t && shallow(c.t, t);
                    if !skim && !late {
                        worst = worst.max(off / depth(c.t));
                    }
                    if off > depth(c.t) && !skim && !late {
                        fail(format!(
                            "GPU hit at {t}, the f64 cast at {} (cos θ {cos:e})",
                            c.t
                        ));
                    }
                }
                (None, Some(c)) if !shallow(c.t, c.t + 2.0 * diag) => {
                    let whole = [(*ray, Interval::new(0.0, f64::INFINITY))];
                    let again = batch.cast_hits(ctx, &relative(&whole, camera)).ok();
                    fail(format!(
                        "GPU missed the f64 {:?} hit at {} (over [0, ∞) the GPU: {again:?}, the f64: {:?})",
                        c.kind,
                        c.t,
                        terrain
                            .cast(ray, whole[0].1, 1e-9 * diag)
                            .map(|h| (h.t, h.kind))
                    ));
                }
                (Some(t), None) if height_above(&terrain, ray, t).is_some_and(|h| h > depth(t)) => {
                    fail(format!(
                        "GPU {:?} hit at {t} where the f64 cast misses: {:?} outside (depth bound {})",
                        g.hit_kind(),
                        height_above(&terrain, ray, t),
                        depth(t)
                    ));
                }
                _ => {}
            }
        }
    }
    (total, worst, base_slivers)
}

const MESH_RAYS: usize = 8192;

/// The f64 reference: every triangle of `inst` in world space (Möller–Trumbore, no BVH, not
/// the watertight test either backend uses): `(t, distance to the triangle's nearest edge,
/// |cos θ|)` of the nearest hit in `range`.
fn brute_force(inst: &Instance, ray: &Ray, range: Interval) -> Option<(f64, f64, f64)> {
    let mut best: Option<(f64, f64, f64)> = None;
    for i in 0..12 {
        let c = inst.world_corners(i);
        let Some(t) = moller_trumbore(ray.origin, ray.dir, &c) else {
            continue;
        };
        if !range.contains(t) || best.is_some_and(|b| b.0 <= t) {
            continue;
        }
        let (e1, e2) = (c[1] - c[0], c[2] - c[0]);
        let n = e1.cross(e2).normalize_or_zero();
        best = Some((t, edge_distance(&c, ray.at(t)), n.dot(ray.dir).abs()));
    }
    best
}

/// A closed mesh about the origin: the cube `[−1, 1]³` (its 12 triangles).
fn cube() -> MeshBvh {
    let (p, tris) = fray_test_support::triangles::cube();
    MeshBvh::build(TriangleMesh::new(p, tris).expect("a valid mesh"))
}

fn meshes(ctx: &GpuContext) -> (u64, f64, u64) {
    let e32 = f64::from(f32::EPSILON);
    // tests/rays.rs's GPU mesh bounds: 4 and 64 units of f32 rounding of the scale.
    let (depth_k, edge_k) = (4.0 * e32, 64.0 * e32);
    let mesh = Arc::new(cube());
    let (mut total, mut worst, mut excused) = (0u64, 0.0f64, 0u64);
    for case in 0..cases(24) {
        let mut rng = Rng(seed(0x3e5, case));
        let scale = rng.log_uniform(-2.0, 4.0);
        let rotation = if case % 2 == 0 {
            DMat3::IDENTITY
        } else {
            DMat3::from_quat(DQuat::from_euler(
                EulerRot::XYZ,
                rng.range(-3.2, 3.2),
                rng.range(-3.2, 3.2),
                rng.range(-3.2, 3.2),
            ))
        };
        let offset = if case % 3 == 0 {
            rng.direction() * 1e5
        } else {
            DVec3::ZERO
        };
        let to_world = DAffine3::from_mat3_translation(rotation * scale, offset);
        let inst = Instance::new(Arc::clone(&mesh), to_world).expect("invertible");
        let diag = inst.bounds().diagonal();
        let family = case % 4;
        let camera = match family {
            0 => offset + rng.direction() * diag * rng.range(0.8, 3.0),
            // In the plane of the top face (world y of the unrotated cube's top): grazing.
            1 => {
                offset
                    + to_world.matrix3 * DVec3::new(rng.range(-4.0, 4.0), 1.0, rng.range(3.0, 6.0))
            }
            2 => offset + rng.direction() * diag * rng.log_uniform(3.0, 4.0),
            _ => offset + rng.direction() * diag * 0.2,
        };
        let rays: Vec<(Ray, Interval)> = (0..MESH_RAYS)
            .map(|i| {
                let local = match i % 4 {
                    0 => DVec3::new(
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                    ),
                    1 => DVec3::new(
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0).signum(),
                        rng.range(-1.0, 1.0),
                    ),
                    2 => DVec3::new(rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0)),
                    _ => DVec3::ZERO,
                };
                let target = to_world.transform_point3(local);
                let d = (target - camera).normalize_or(DVec3::Y);
                let range = case_range(&mut rng, (target - camera).length(), diag);
                (Ray::new(camera, d).expect("a unit direction"), range)
            })
            .collect();
        let batch = MeshBatch::new(ctx, &[mesh.as_ref()], &[(0, to_world)], camera)
            .unwrap_or_else(|e| panic!("{e}"));
        let hits = batch
            .cast(ctx, &relative(&rays, camera))
            .unwrap_or_else(|e| panic!("{e}"));
        for (i, ((ray, range), g)) in rays.iter().zip(&hits).enumerate() {
            total += 1;
            let reference = brute_force(&inst, ray, *range);
            let gt = g.is_hit().then_some(f64::from(g.t));
            let fail = |what: String| -> ! {
                panic!(
                    "mesh case {case} (family {family}, scale {scale:e}, offset {offset:?}): {what} for {ray:?} over {range:?}: GPU {g:?}, f64 {reference:?}"
                )
            };
            let s =
                (camera - offset).length() + gt.or(reference.map(|r| r.0)).unwrap_or(0.0) + diag;
            if let Some(t) = gt {
                if !(t.is_finite()
                    && t >= f64::from(range.lo as f32)
                    && t <= range.hi * (1.0 + 1e-6))
                {
                    fail(format!("GPU hit t = {t} outside the range"));
                }
                if !g.any_hit {
                    fail("no any hit where the nearest hit is".into());
                }
            }
            match (gt, reference) {
                (Some(t), Some((tr, edge, cos))) => {
                    let across = (t - tr).abs() * cos;
                    if across > depth_k * s {
                        // The GPU's hit on an edge the f64 ray passes (a silhouette): within
                        // the edge bound of two faces' planes at once.
                        let q = to_world.inverse().transform_point3(ray.at(t)).abs();
                        let mut a = [q.x, q.y, q.z];
                        a.sort_by(|x, y| y.total_cmp(x));
                        let silhouette =
                            (a[0] - 1.0).abs().max((a[1] - 1.0).abs()) * scale <= edge_k * s;
                        if edge >= edge_k * s && cos * diag > 4.0 * depth_k * s && !silhouette {
                            fail(format!("depth off by {across:e} across"));
                        }
                        excused += 1;
                    } else {
                        worst = worst.max(across / (depth_k * s));
                    }
                }
                (None, Some((_, edge, cos))) => {
                    // Missed only at an edge or on a face the ray grazes (within the depth bound
                    // of its plane all across it); a ray through the centre never misses.
                    if (edge >= edge_k * s && cos * diag > 4.0 * depth_k * s)
                        || (i % 4 == 3 && range.lo == 0.0 && family != 3)
                    {
                        fail("missed".into());
                    }
                    excused += 1;
                }
                (Some(t), None) => {
                    // The cube's surface is `|q|∞ = 1` in its own frame: `||q|∞ − 1| · scale`
                    // never exceeds the distance to it.
                    let q = to_world.inverse().transform_point3(ray.at(t));
                    let off = (q.abs().max_element() - 1.0).abs() * scale;
                    if off > edge_k * s {
                        fail(format!("a hit at {t}, {off:e} from the cube's surface"));
                    }
                    excused += 1;
                }
                (None, None) => {}
            }
        }
    }
    (total, worst, excused)
}

const FOG_RAYS: usize = 16384;

fn fogs(ctx: &GpuContext) -> (u64, f64) {
    let mut total = 0u64;
    let mut worst = 0.0f64;
    for case in 0..cases(40) {
        let mut rng = Rng(seed(0xf0, case));
        let thickness = rng.log_uniform(-1.0, 4.0);
        let base = rng.range(-1.0, 1.0) * thickness;
        let layer = FogLayer {
            base,
            top: base + thickness,
            extinction: rng.log_uniform(-6.0, 1.0) / thickness,
            albedo: DVec3::splat(0.9),
            falloff: (rng.unit() < 0.5).then(|| thickness * rng.log_uniform(-1.0, 1.0)),
            phase: Phase::Isotropic,
        };
        // The camera: inside, above, below the layer, or 10⁴ thicknesses away.
        let eye_y = match case % 4 {
            0 => base + thickness * rng.unit(),
            1 => base + thickness * rng.range(1.0, 3.0),
            2 => base - thickness * rng.range(0.0, 2.0),
            _ => base + thickness * rng.range(-1.0, 2.0) * 1e4,
        };
        let eye = DVec3::new(0.0, eye_y, 0.0);
        let block = GpuFog::new(&layer, FogModel::Exact, eye_y);
        let batch = FogBatch::new(ctx, &block).unwrap_or_else(|e| panic!("{e}"));
        let rays: Vec<(DVec3, Interval)> = (0..FOG_RAYS)
            .map(|i| {
                let d = match i % 4 {
                    0 => {
                        let a = rng.range(0.0, std::f64::consts::TAU);
                        DVec3::new(a.cos(), 0.0, a.sin())
                    }
                    1 => {
                        let a = rng.range(0.0, std::f64::consts::TAU);
                        let e =
                            rng.log_uniform(-7.0, -1.0) * if rng.unit() < 0.5 { -1.0 } else { 1.0 };
                        DVec3::new(a.cos(), e, a.sin()).normalize()
                    }
                    2 => DVec3::Y * if rng.unit() < 0.5 { -1.0 } else { 1.0 },
                    _ => rng.direction(),
                };
                let lo = if rng.unit() < 0.5 {
                    0.0
                } else {
                    thickness * rng.log_uniform(-3.0, 1.0)
                };
                let hi = if rng.unit() < 0.3 {
                    f64::INFINITY
                } else {
                    lo + thickness * rng.log_uniform(-3.0, 3.0)
                };
                (d, Interval::new(lo, hi))
            })
            .collect();
        let queries: Vec<GpuFogRay> = rays
            .iter()
            .map(|(d, r)| {
                let d = d.as_vec3();
                [
                    [0.0, 0.0, 0.0, r.lo as f32],
                    [d.x, d.y, d.z, r.hi.min(1e30) as f32],
                    [0.0, 1.0, 0.0, 0.0],
                ]
            })
            .collect();
        let terms = batch.terms(ctx, &queries).unwrap_or_else(|e| panic!("{e}"));
        for ((d, range), g) in rays.iter().zip(&terms) {
            total += 1;
            let ray = Ray::new(eye, *d).expect("a unit direction");
            let fail = |what: String| {
                panic!(
                    "fog case {case} ({layer:?}, eye y {eye_y}): {what} for dir {d:?} over {range:?}"
                )
            };
            let (t, tau) = (f64::from(g.transmittance), f64::from(g.depth));
            if !((0.0..=1.0).contains(&t) && tau >= 0.0 && !tau.is_nan()) {
                fail(format!("T = {t}, τ = {tau}"));
            }
            let depth = layer.optical_depth(&ray, *range);
            // The crossing's ends: heights relative to the camera rounded to f32 (`2⁻²³` of the
            // larger of the layer's bounds' and the eye's), over the sine.
            let heights = (layer.base - eye_y).abs().max((layer.top - eye_y).abs());
            let e = 4.0 * f64::from(f32::EPSILON) * heights;
            // (A level ray crosses nothing; with a falloff, the rounded height also moves the
            // density by `e / H` relative.)
            let crossing = if d.y == 0.0 {
                0.0
            } else {
                (layer.extinction * e / d.y.abs()).min(1e300)
            } + layer.falloff.map_or(0.0, |h| depth.min(1e300) * e / h)
                // The range's ends rounded to f32.
                + layer.extinction
                    * f64::from(f32::EPSILON)
                    * (range.lo.abs() + if range.hi.is_finite() { range.hi } else { 0.0 });
            let want_t = (-depth).exp();
            let off_t = (t - want_t).abs();
            let bound_t = 1e-6 + 5e-5 * want_t + want_t * crossing;
            worst = worst.max(off_t / bound_t);
            if off_t > bound_t {
                fail(format!(
                    "T = {t} against the f64 {want_t} (bound {bound_t:e})"
                ));
            }
            if depth.is_finite() && tau < 1e29 {
                let bound = 1e-6 + 5e-5 * depth + crossing;
                if (tau - depth).abs() > bound {
                    fail(format!(
                        "τ = {tau} against the f64 {depth} (bound {bound:e})"
                    ));
                }
            } else if depth.is_infinite() != (tau >= 1e29 || tau.is_infinite()) {
                fail(format!("τ = {tau} against the f64 {depth}"));
            }
        }
    }
    (total, worst)
}

fn stress_on_the_gpu() {
    let renderer = common::gpu("stress");
    let ctx = renderer.context();
    let clock = Instant::now();
    let (t_rays, t_worst, base_slivers) = terrains(ctx);
    let t_time = clock.elapsed();
    let clock = Instant::now();
    let (m_rays, m_worst, m_excused) = meshes(ctx);
    println!(
        "gpu stress: meshes {m_rays} rays in {:?} (worst depth ÷ bound {m_worst:.3e}; {m_excused} excused at edges or grazed faces)",
        clock.elapsed()
    );
    let clock = Instant::now();
    let (f_rays, f_worst) = fogs(ctx);
    println!(
        "gpu stress: terrains {t_rays} rays in {t_time:?} (worst |Δt| cos θ ÷ depth bound {t_worst:.3e}; {base_slivers} base slivers thinner than the bound stepped over); \
         fog {f_rays} rays in {:?} (worst |ΔT| ÷ bound {f_worst:.3e})",
        clock.elapsed()
    );
    let planned =
        u64::from(cases(48)) * TERRAIN_RAYS as u64 + u64::from(cases(40)) * FOG_RAYS as u64;
    assert!(
        t_rays + f_rays >= planned,
        "{} rays, planned {planned}",
        t_rays + f_rays
    );
}

fn main() {
    common::run(&[("stress_on_the_gpu", stress_on_the_gpu)], &[]);
}
