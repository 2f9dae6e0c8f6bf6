//! `cargo xtask bench freeform`: the CPU free-form caster's time against its depth error over
//! the accuracy ε, on the camera rays of the `csg` and `turboprop` data scenes.
//!
//! - Rays: each scene's camera through the pixel centres of a [`WIDTH`]-wide image (its aspect
//!   kept), every object cast and the nearest hit kept — what a primary-ray pass asks.
//! - Settings: ε = 10⁻¹ … 10⁻⁷ of the scene's diagonal and the scene's own ε (10⁻¹⁰ of it, the
//!   default), each with both ways of answering plain rays (`CastMethod::ClosedForm`, the
//!   default, and `Halving`, the search everywhere); one thread, the median of the repeats.
//! - The reference, independent of the caster: each solid's `eval` sampled along the ray over
//!   its box at [`SAMPLES`] points per box diagonal, each sign change bisected to f64's
//!   resolution (as the GPU ray suite's free-form reference does), the first entry over the
//!   objects.
//! - Error: the 99th percentile of `|t − t_ref|` over the rays both hit, over the scene's
//!   diagonal (the unit of ε) — the largest is in the table too, but a handful of rays set it
//!   whatever ε: grazing hits within the caster's rounding allowance of a tangent surface (the
//!   contract allows them), and spans thinner than the reference's step that the caster finds
//!   and the reference misses. Rays one hits and the other misses are counted apart.
//!
//! Written as `target/bench/freeform_<scene>.{csv,svg,png}` (`sweep_plot`) and `freeform.md`.

use crate::sweep_plot::{self, Setting, Sweep};
use crate::workspace;
use fray_core::{Interval, Ray};
use fray_geometry::{CastMethod, CastStats, RayCaster, Solid};
use std::fmt::Write as _;
use std::time::Instant;

/// The scenes swept.
const SCENES: [&str; 2] = ["csg", "turboprop"];
/// Width of the ray image.
const WIDTH: u32 = 128;
/// ε over the scene's diagonal, coarse to fine.
const EPS: [f64; 7] = [1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7];
/// The reference's samples per solid's box diagonal.
const SAMPLES: f64 = 4096.0;
/// The fewest timed runs per setting (each is a few milliseconds).
const MIN_REPEATS: usize = 7;
/// Threads of the reference (the timed casts run on one).
const REFERENCE_THREADS: usize = 2;

/// A camera ray and the range it is cast over.
struct CameraRay {
    ray: Ray,
    range: Interval,
}

/// The first inside point of `f` between `a` and `b`, where the sign of `f ≥ 0` differs, by
/// bisection down to adjacent f64s.
fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let inside_a = f(a) >= 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        if (f(m) >= 0.0) == inside_a {
            a = m;
        } else {
            b = m;
        }
    }
    if inside_a { a } else { b }
}

/// The reference's first hit of `solid` on `r`: the first sample at or inside, its entry
/// bisected against the sample before it.
fn reference_hit(solid: &Solid, r: &CameraRay) -> Option<f64> {
    let bounds = solid.bounds();
    let range = bounds.clip_ray(&r.ray, r.range)?;
    let f = |t: f64| solid.eval(r.ray.at(t));
    if f(range.lo) >= 0.0 {
        return Some(range.lo);
    }
    let n = ((range.hi - range.lo) / (bounds.diagonal() / SAMPLES))
        .ceil()
        .max(1.0) as usize;
    let h = (range.hi - range.lo) / n as f64;
    let mut prev = range.lo;
    for k in 1..=n {
        let t = if k == n {
            range.hi
        } else {
            range.lo + h * k as f64
        };
        if f(t) >= 0.0 {
            return Some(bisect(&f, prev, t));
        }
        prev = t;
    }
    None
}

/// The nearest reference hit over the solids, per ray, on [`REFERENCE_THREADS`] threads.
fn reference(solids: &[Solid], rays: &[CameraRay]) -> Vec<Option<f64>> {
    crate::parallel::map(rays, REFERENCE_THREADS, |r| {
        solids
            .iter()
            .filter_map(|solid| reference_hit(solid, r))
            .min_by(f64::total_cmp)
    })
}

/// The caster's nearest hit over the solids, per ray.
fn cast(solids: &[Solid], rays: &[CameraRay], method: CastMethod, eps: f64) -> Vec<Option<f64>> {
    let mut caster = RayCaster::with_method(method);
    let mut stats = CastStats::default();
    rays.iter()
        .map(|r| {
            solids
                .iter()
                .filter_map(|s| caster.cast(s, &r.ray, r.range, eps, &mut stats))
                .min_by(f64::total_cmp)
        })
        .collect()
}

/// `|Δt|` over the rays both hit — its 99th percentile and its largest — and the rays one hits
/// and the other misses.
fn depth_error(reference: &[Option<f64>], got: &[Option<f64>]) -> (f64, f64, usize) {
    let mut errors = Vec::new();
    let mut flips = 0;
    for (a, b) in reference.iter().zip(got) {
        match (a, b) {
            (Some(a), Some(b)) => errors.push((a - b).abs()),
            (None, None) => {}
            _ => flips += 1,
        }
    }
    if errors.is_empty() {
        return (0.0, 0.0, flips);
    }
    errors.sort_by(f64::total_cmp);
    let p99 = errors[(errors.len() * 99 / 100).min(errors.len() - 1)];
    (p99, errors[errors.len() - 1], flips)
}

/// Runs the sweep on both scenes; returns its markdown and the sweeps.
pub fn run(repeats: usize) -> Result<(String, Vec<Sweep>), String> {
    let mut md = format!(
        "# Free-form caster: time against depth error (`cargo xtask bench freeform`)\n\n\
         Camera rays of a {WIDTH}-wide image, every object cast, the nearest hit kept; one \
         thread, medians of {} after a warm-up run. Error: the 99th percentile (and the max) of \
         |t − t_ref| over the rays both hit, over the scene's diagonal; the reference samples \
         each solid's `eval` at {SAMPLES} points per box diagonal and bisects. Flips: rays one \
         hits and the other misses.\n",
        repeats.max(MIN_REPEATS)
    );
    let mut sweeps = Vec::new();
    for name in SCENES {
        let (text, sweep) = scene_sweep(name, repeats)?;
        md.push_str(&text);
        sweeps.push(sweep);
    }
    Ok((md, sweeps))
}

fn scene_sweep(name: &str, repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(format!("data/scenes/{name}.ron"));
    let scene = fray_scene::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let diagonal = scene.bounds().diagonal();
    let height =
        ((u64::from(scene.height) * u64::from(WIDTH)) / u64::from(scene.width)).max(1) as u32;
    let rays: Vec<CameraRay> = (0..height)
        .flat_map(|y| (0..WIDTH).map(move |x| (x, y)))
        .filter_map(|(x, y)| {
            let c = scene.camera.pixel_ray(x, y, WIDTH, height)?;
            Some(CameraRay {
                ray: c.ray,
                range: Interval::new(c.t_near, f64::INFINITY),
            })
        })
        .collect();
    let solids: Vec<Solid> = scene.objects.iter().map(|o| o.solid.clone()).collect();
    eprintln!("freeform {name}: reference over {} rays", rays.len());
    let start = Instant::now();
    let truth = reference(&solids, &rays);
    let reference_s = start.elapsed().as_secs_f64();
    let hits = truth.iter().flatten().count();

    let default_eps = scene.epsilon();
    let mut settings = Vec::new();
    let mut maxima = Vec::new();
    let mut default = None;
    let eps_list = EPS
        .iter()
        .map(|&e| (format!("{e:.0e}"), e * diagonal))
        .chain([(
            format!("{:.0e} (scene)", default_eps / diagonal),
            default_eps,
        )]);
    for (label, eps) in eps_list {
        for (method, tag) in [
            (CastMethod::ClosedForm, ""),
            (CastMethod::Halving, ", halving"),
        ] {
            // One untimed run first: the timed ones start warm.
            let mut got = cast(&solids, &rays, method, eps);
            let mut times = Vec::new();
            for _ in 0..repeats.max(MIN_REPEATS) {
                let start = Instant::now();
                got = cast(&solids, &rays, method, eps);
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
            times.sort_by(f64::total_cmp);
            let (p99, max, flips) = depth_error(&truth, &got);
            maxima.push(max / diagonal);
            if eps == default_eps && method == CastMethod::default() {
                default = Some(settings.len());
            }
            settings.push(Setting {
                flips,
                ..Setting::new(
                    format!("ε {label}{tag}"),
                    times[times.len() / 2],
                    p99 / diagonal,
                )
            });
        }
        eprintln!("freeform {name}: ε {label} done");
    }
    let sweep = Sweep {
        name: format!("freeform_{name}"),
        method: format!("free forms, CPU ({name}.ron)"),
        error_desc: "99th percentile |Δt| / scene diagonal".into(),
        time_desc: format!("{} rays, ms (one thread)", rays.len()),
        settings,
        default,
    };
    let mut md = format!(
        "\n## {name}.ron\n\n{} rays, {hits} hits in the reference ({reference_s:.1} s on \
         {REFERENCE_THREADS} threads); scene diagonal {diagonal:.3} m.\n\n\
         | setting | ms | p99 \\|Δt\\| / diagonal | max | flips |\n|---|---:|---:|---:|---:|\n",
        rays.len()
    );
    for (s, max) in sweep.settings.iter().zip(&maxima) {
        let _ = writeln!(
            md,
            "| {} | {:.2} | {:.2e} | {max:.2e} | {} |",
            s.label, s.time_ms, s.error, s.flips
        );
    }
    md.push('\n');
    md.push_str(&sweep_plot::summary_header());
    md.push_str(&sweep.summary());
    Ok((md, sweep))
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_geometry::{FreeForm, Quadric, Shape};
    use glam::DVec3;

    /// The reference's first hit on a unit sphere at distance 10 is the closed form's 9 to f64
    /// resolution, though its samples are 2/4096 apart; a ray that passes beside misses.
    #[test]
    fn the_reference_bisects_to_the_surface() {
        let sphere = Quadric::sphere(DVec3::ZERO, 1.0);
        let solid = Solid::new(Shape::FreeForm(
            FreeForm::new(sphere, Vec::new(), None).unwrap(),
        ))
        .unwrap();
        let r = CameraRay {
            ray: Ray::new(DVec3::new(-10.0, 0.3, 0.0), DVec3::X).unwrap(),
            range: Interval::new(0.0, f64::INFINITY),
        };
        let exact = 10.0 - (1.0f64 - 0.09).sqrt();
        let t = reference_hit(&solid, &r).unwrap();
        assert!((t - exact).abs() < 1e-12, "{t} against {exact}");
        let miss = CameraRay {
            ray: Ray::new(DVec3::new(-10.0, 1.01, 0.0), DVec3::X).unwrap(),
            ..r
        };
        assert_eq!(reference_hit(&solid, &miss), None);
    }
}
