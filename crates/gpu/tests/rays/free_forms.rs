//! Free forms against an independent reference: each backend's nearest hit, normal and any-hit
//! answer on the free-form data scenes' camera, grazing and far rays, against the solids' own
//! `F` sampled in f64 along the ray and bisected.

use crate::Backend;
use crate::backend::{CaseRay, Tolerance};
use crate::cases::{camera_rays, data_scene, far_rays};
use crate::cpu::Cpu;
use crate::gpu::{Gpu, relative_rays};
use fray_core::{Interval, Ray};
use fray_geometry::{CastStats, RayCaster, Solid};
use fray_gpu::testing::FreeFormBatch;
use fray_test_support::roots::{inside_spans, samples};
use glam::DVec3;

/// What a backend found on a ray through free forms.
#[derive(Clone, Copy, Debug)]
pub struct Answer {
    /// The nearest hit's distance, `None` for a miss.
    pub t: Option<f64>,
    /// The outward unit normal there (zero for a miss).
    pub normal: DVec3,
    /// The any-hit answer over the same range.
    pub any: bool,
}

/// What a backend holds its free-form answers to, against the reference.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    /// How far (world units) a hit may be from where the reference's first span begins, at `t`.
    pub depth: fn(f64, &Tolerance) -> f64,
    /// The thickness of a span the backend may step over, at `t`.
    pub sliver: fn(f64, &Tolerance) -> f64,
    /// How far its unit normal may be from the reference's.
    pub normal: f64,
}

/// The free forms the rays of a call see, cast with the tolerances `tol`.
#[derive(Clone, Copy, Debug)]
pub struct FreeFormsSeen<'a> {
    pub solids: &'a [&'a Solid],
    /// The point a backend that works relative to one (the GPU) takes positions from.
    pub reference: DVec3,
    pub tol: &'a Tolerance,
}

/// What a backend of the suite answers for free forms.
pub trait FreeFormBackend {
    fn bounds(&self) -> Bounds;
    /// Nearest hit over `seen.solids`, its normal and the any-hit answer, for each ray.
    fn free_forms(&self, seen: FreeFormsSeen<'_>, rays: &[CaseRay]) -> Vec<Answer>;
}

impl FreeFormBackend for Cpu {
    fn bounds(&self) -> Bounds {
        Bounds {
            // The caster's contract: never past a span at least ε long by more than ε, up to the
            // f64 rounding of `F` it widens every leaf by (which the reference's own evaluation
            // shares), conditioned by the gradient along the ray. The rounding grows with the
            // terms, as the square of the distance from a quadric's origin and faster for a
            // perturbation's cube: measured up to 2.6e-9·t near the camera and 1.4e-2 at t = 10⁴
            // (turboprop's far rays: 1.4e-14·t³).
            depth: |t, tol| tol.eps + 1e-8 * t + 2e-14 * t * t * t,
            sliver: |t, tol| tol.eps + 1e-8 * t + 2e-14 * t * t * t,
            normal: 1e-6,
        }
    }

    fn free_forms(&self, seen: FreeFormsSeen<'_>, rays: &[CaseRay]) -> Vec<Answer> {
        let FreeFormsSeen { solids, tol, .. } = seen;
        let mut caster = RayCaster::new();
        let mut stats = CastStats::default();
        rays.iter()
            .map(|r| {
                let mut best: Option<(f64, usize)> = None;
                for (k, solid) in solids.iter().enumerate() {
                    let range = Interval::new(r.range.lo, best.map_or(r.range.hi, |b| b.0));
                    let hit = caster.cast(solid, &r.ray, range, tol.eps, &mut stats);
                    if let Some(t) = hit.filter(|&t| best.is_none_or(|b| t < b.0)) {
                        best = Some((t, k));
                    }
                }
                let normal = best.map_or(DVec3::ZERO, |(t, k)| {
                    solids[k].surface_at(r.ray.at(t), -r.ray.dir).0
                });
                let any = solids
                    .iter()
                    .any(|s| caster.occludes(s, &r.ray, r.range, tol.eps, None, &mut stats));
                Answer {
                    t: best.map(|b| b.0),
                    normal,
                    any,
                }
            })
            .collect()
    }
}

impl FreeFormBackend for Gpu {
    fn bounds(&self) -> Bounds {
        Bounds {
            // The frames' depth bound (tests/parity.rs): DEPTH_REL·t + 4·ε_gpu.
            depth: |t, tol| 2e-5 * t + 4.0 * tol.eps_gpu,
            sliver: |t, tol| 2e-5 * t + 4.0 * tol.eps_gpu,
            // f32 gradients: measured up to 6.7e-5 on csg's quadrics, 1.6e-2 on the turboprop's
            // perturbations (cubic terms cancelling near their support's edge).
            normal: 2e-2,
        }
    }

    fn free_forms(&self, seen: FreeFormsSeen<'_>, rays: &[CaseRay]) -> Vec<Answer> {
        let FreeFormsSeen {
            solids,
            reference,
            tol,
        } = seen;
        let ctx = self.context();
        let batch = FreeFormBatch::new(ctx, solids, reference).unwrap_or_else(|e| panic!("{e}"));
        let hits = batch
            .cast(ctx, &relative_rays(rays, reference), tol.eps_gpu as f32)
            .unwrap_or_else(|e| panic!("{e}"));
        hits.iter()
            .map(|h| Answer {
                t: h.is_hit().then_some(f64::from(h.t)),
                normal: DVec3::from(h.normal.map(f64::from)),
                any: h.any_hit,
            })
            .collect()
    }
}

/// The reference's inside spans of the union of `solids` on `r`: `F` sampled over each solid's
/// box interval at `SAMPLES` per box diagonal (or `step`, if coarser), each sign change refined
/// by bisection: every span thicker than the step is found.
fn reference_spans(solids: &[&Solid], r: &CaseRay, step: f64) -> Vec<(f64, f64)> {
    const SAMPLES: f64 = 2048.0;
    let mut spans = Vec::new();
    for solid in solids {
        let bounds = solid.bounds();
        let Some(range) = bounds.clip_ray(&r.ray, r.range) else {
            continue;
        };
        let f = |t: f64| solid.eval(r.ray.at(t));
        let step = step.max(bounds.diagonal() / SAMPLES);
        let n = ((range.hi - range.lo) / step).ceil().max(1.0) as usize;
        spans.extend(inside_spans(&f, &samples(range.lo, range.hi, n)));
    }
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    spans
}

/// A case: solids, the point the rays are relative to on a backend that needs one, the rays.
struct Case {
    name: String,
    /// Whether normals are checked: not on the far rays, whose f32 positions 10⁴ from the
    /// camera leave the GPU's normals to the pixel footprint (the frames' colour bound covers
    /// them).
    normals: bool,
    solids: Vec<Solid>,
    reference: DVec3,
    rays: Vec<CaseRay>,
    tol: Tolerance,
}

/// The camera rays of `name` on a `width`-wide grid, the grazing rays at their CPU hits, and the
/// same camera rays started 10⁴ back.
fn cases(name: &str, width: u32) -> Vec<Case> {
    let scene = data_scene(name);
    let height = (u64::from(scene.height) * u64::from(width) / u64::from(scene.width)) as u32;
    let solids: Vec<Solid> = scene.objects.iter().map(|o| o.solid.clone()).collect();
    let refs: Vec<&Solid> = solids.iter().collect();
    let tol = Tolerance {
        eps: scene.epsilon(),
        eps_gpu: fray_gpu::gpu_epsilon(&scene, scene.epsilon()),
    };
    let reference = fray_gpu::params::reference_point(&scene.camera);
    let camera = camera_rays(&scene, width, height);
    // Grazing rays: through each hit's neighbourhood along the tangent plane, just outside.
    let hits = Cpu.free_forms(
        FreeFormsSeen {
            solids: &refs,
            reference,
            tol: &tol,
        },
        &camera,
    );
    let mut grazing = Vec::new();
    for (r, a) in camera.iter().zip(&hits) {
        let Some(t) = a.t else { continue };
        let p = r.ray.at(t);
        let n = a.normal;
        let tangent = (r.ray.dir - n * r.ray.dir.dot(n)).normalize_or_zero();
        if tangent == DVec3::ZERO {
            continue;
        }
        let lift = 4.0 * tol.eps_gpu.max(tol.eps);
        let origin = p + n * lift - tangent * 2.0;
        if let Some(ray) = Ray::new(origin, tangent) {
            grazing.push(CaseRay {
                ray,
                range: Interval::new(0.0, 4.0),
            });
        }
    }
    // The camera 10⁴ back: a flight view of a model far ahead.
    let (far_eye, far) = far_rays(&camera, reference, 1e4, 10.0);
    let far_tol = Tolerance {
        eps_gpu: tol.eps_gpu.max(fray_gpu::EPSILON_FLOOR * 1e4),
        ..tol
    };
    [
        ("camera", camera, reference, tol),
        ("grazing", grazing, reference, tol),
        ("far", far, far_eye, far_tol),
    ]
    .into_iter()
    .map(|(kind, rays, reference, tol)| Case {
        name: format!("{name} {kind}"),
        normals: kind != "far",
        solids: solids.clone(),
        reference,
        rays,
        tol,
    })
    .collect()
}

/// What a run of the suite found wrong, per check.
#[derive(Debug, Default)]
struct Failures {
    rays: usize,
    hits: usize,
    early: Vec<String>,
    far_from_inside: Vec<String>,
    missed: Vec<String>,
    normal: Vec<String>,
    any: Vec<String>,
    worst_depth: f64,
    worst_normal: f64,
}

/// The suite: every case through `backend`, each answer against the reference.
pub fn suite(backend: &dyn Backend) {
    let bounds = backend.bounds();
    let mut total = Failures::default();
    for name in ["csg.ron", "turboprop.ron"] {
        for case in cases(name, 48) {
            let solids: Vec<&Solid> = case.solids.iter().collect();
            let answers = backend.free_forms(
                FreeFormsSeen {
                    solids: &solids,
                    reference: case.reference,
                    tol: &case.tol,
                },
                &case.rays,
            );
            let mut f = Failures::default();
            for (r, a) in case.rays.iter().zip(&answers) {
                check_ray(&solids, r, a, &case, &bounds, &mut f);
            }
            eprintln!(
                "{} {}: {} rays, {} hits; worst |Δt| {:.3e} of its bound, worst normal {:.2e}",
                backend.name(),
                case.name,
                f.rays,
                f.hits,
                f.worst_depth,
                f.worst_normal
            );
            total.rays += f.rays;
            total.hits += f.hits;
            total.worst_depth = total.worst_depth.max(f.worst_depth);
            total.worst_normal = total.worst_normal.max(f.worst_normal);
            for (all, these) in [
                (&mut total.early, f.early),
                (&mut total.far_from_inside, f.far_from_inside),
                (&mut total.missed, f.missed),
                (&mut total.normal, f.normal),
                (&mut total.any, f.any),
            ] {
                all.extend(these.into_iter().map(|s| format!("{}: {s}", case.name)));
            }
        }
    }
    eprintln!(
        "{}: free forms, {} rays, {} hits",
        backend.name(),
        total.rays,
        total.hits
    );
    for (what, list) in [
        ("a span began before the hit", &total.early),
        (
            "the hit is not near an inside point",
            &total.far_from_inside,
        ),
        ("a span at least the sliver thick was missed", &total.missed),
        ("normal off", &total.normal),
        ("any hit disagrees", &total.any),
    ] {
        assert!(
            list.is_empty(),
            "{}: {what} on {} rays, e.g. {:?}",
            backend.name(),
            list.len(),
            &list[..list.len().min(5)]
        );
    }
}

/// The reference's outward normal at the start of span `s` (of the solid most inside there) and
/// its deciding leaf, and `1 / max(|cos θ|, 0.02)` for the ray's angle θ to it: how much a
/// distance error along the ray grows at a grazing angle.
fn reference_surface(solids: &[&Solid], r: &CaseRay, t: f64) -> (DVec3, u32, usize, f64) {
    let p = r.ray.at(t);
    let k = (0..solids.len())
        .max_by(|&x, &y| solids[x].eval(p).total_cmp(&solids[y].eval(p)))
        .expect("a solid");
    let (n, leaf) = solids[k].surface_at(p, -r.ray.dir);
    (n, leaf, k, 1.0 / n.dot(r.ray.dir).abs().max(0.02))
}

fn check_ray(
    solids: &[&Solid],
    r: &CaseRay,
    a: &Answer,
    case: &Case,
    bounds: &Bounds,
    f: &mut Failures,
) {
    let tol = &case.tol;
    f.rays += 1;
    let spans = reference_spans(solids, r, 0.25 * tol.eps.min(tol.eps_gpu));
    // A span a backend must find: at least the sliver long, entered at an angle (|cos θ| ≥ 0.05
    // to the surface's normal): a grazing ray may run just inside a surface for a long way.
    let thick = |s: &(f64, f64)| {
        s.1 - s.0 >= (bounds.sliver)(s.0, tol) && reference_surface(solids, r, s.0).3 < 20.0
    };
    let describe = |what: &str| {
        format!(
            "{what}: origin {:?} dir {:?} answer {:?} spans {:?}",
            r.ray.origin,
            r.ray.dir,
            a.t,
            &spans[..spans.len().min(3)]
        )
    };
    match a.t {
        Some(t) => {
            f.hits += 1;
            // The depth bound across the surface, along the ray at its angle to it.
            let along =
                |s: &(f64, f64)| (bounds.depth)(t, tol) * reference_surface(solids, r, s.0).3;
            if let Some(s) = spans.iter().find(|s| s.0 < t - along(s) && thick(s)) {
                f.early.push(describe(&format!(
                    "span at {:.9} ({:.3e} thick)",
                    s.0,
                    s.1 - s.0
                )));
            }
            let nearest = spans
                .iter()
                .min_by(|x, y| (x.0 - t).abs().total_cmp(&(y.0 - t).abs()));
            let depth = nearest.map_or((bounds.depth)(t, tol), along);
            let near_span = spans.iter().any(|s| s.0 <= t + depth && s.1 >= t - depth);
            let near_point = (0..=64).any(|k| {
                let u = t - depth + 2.0 * depth * f64::from(k) / 64.0;
                solids.iter().any(|s| s.eval(r.ray.at(u)) >= 0.0)
            });
            if !near_span && !near_point {
                f.far_from_inside
                    .push(describe("no inside point within the depth bound"));
            }
            if let Some(s) = nearest.filter(|s| (s.0 - t).abs() <= depth) {
                f.worst_depth = f.worst_depth.max((s.0 - t).abs() / depth);
                // The normal where both points have the same deciding leaf, off grazing rays.
                let (n_ref, leaf_ref, k, grazing) = reference_surface(solids, r, s.0);
                let (_, leaf_hit) = solids[k].surface_at(r.ray.at(t), -r.ray.dir);
                if case.normals && leaf_ref == leaf_hit && grazing < 20.0 {
                    let off = (a.normal - n_ref).length();
                    f.worst_normal = f.worst_normal.max(off);
                    if off > bounds.normal {
                        f.normal.push(describe(&format!("normal off by {off:.3e}")));
                    }
                }
            }
            if !a.any && nearest.is_none_or(thick) {
                f.any.push(describe("a nearest hit but no any hit"));
            }
        }
        None => {
            if let Some(s) = spans.iter().find(|s| thick(s)) {
                f.missed.push(describe(&format!(
                    "span at {:.9} ({:.3e} thick)",
                    s.0,
                    s.1 - s.0
                )));
            }
            if spans.iter().any(thick) && !a.any {
                f.any
                    .push(describe("a span at least the sliver thick but no any hit"));
            }
        }
    }
}
