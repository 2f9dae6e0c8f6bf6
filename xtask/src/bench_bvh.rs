//! `cargo xtask bench bvh`: the mesh BVH's build presets (`fray_mesh::BuildPreset`: median
//! splits, the SAH over 4, 16 — the default — and 64 bins) — build time against the trace time
//! of a fixed ray set — on the scanned meshes of `data/meshes` and the machined part.
//!
//! - Build: `MeshBvh::build_with` (the f32 boxes, the topology, the f64 refit), wall time, the
//!   median of the repeats.
//! - Rays, per mesh: the primary rays of a [`SIDE`]² pinhole view framing it, and as many
//!   incoherent ones (from random points round it toward random points of its box, as
//!   reflected and refracted rays go); the nearest hit of each by the f64 traversal
//!   (`nearest_hit`), one thread, the median of the repeats.
//! - Error: every preset must answer what the brute force over every triangle answers (the least
//!   `(t, triangle index)` of the watertight test): the largest `|Δt|` (and the rays whose
//!   triangle differs, and that hit in one and miss in the other) against it on every
//!   [`REFERENCE_STRIDE`]th ray, and against the default preset on every ray. All 0 by the
//!   contract; `crates/mesh/tests/robust.rs` tests every preset against the brute force.
//!
//! Written as `target/bench/bvh.md`, the plot `bvh_presets.{csv,svg,png}` (build time against
//! trace time, a line per mesh through its presets: the trade the presets make, at no error)
//! and one sweep per mesh `bvh_<mesh>.{csv,svg,png}` (`sweep_plot`: trace time against the
//! error — 0, on the floor —, the default marked; its summary row for `docs/accuracy.md`).

use crate::sweep_frame::median;
use crate::sweep_plot::{LinePlot, Series, Setting, Sweep};
use crate::workspace;
use fray_core::{Interval, MemoryBudget, Pinhole, Projector, Ray};
use fray_mesh::triangle::{RayFrame, intersect};
use fray_mesh::{BuildPreset, MeshBvh, TriangleMesh};
use glam::DVec3;
use std::fmt::Write as _;
use std::time::Instant;

/// The meshes swept (files in `data/meshes`).
const MESHES: [&str; 4] = [
    "bunny00.obj",
    "armadillo.obj",
    "ChineseDragon-10kv.obj",
    "boeing.obj",
];
/// Side of the primary view (and the incoherent rays are as many).
const SIDE: u32 = 128;
/// The brute-force reference checks every this-many-th ray.
const REFERENCE_STRIDE: usize = 32;
/// Threads of the brute force (the timed traversals run on one).
const REFERENCE_THREADS: usize = 2;
/// The fewest timed runs per setting (each is tens of milliseconds).
const MIN_REPEATS: usize = 3;

const ALL: Interval = Interval {
    lo: 0.0,
    hi: f64::INFINITY,
};

/// A small deterministic generator (SplitMix64): the incoherent rays are the same every run.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniform direction (rejection from the cube).
    fn direction(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - 1.0;
            let l = v.length_squared();
            if l > 1e-6 && l <= 1.0 {
                return v / l.sqrt();
            }
        }
    }
}

/// The ray set of a mesh: its primary view's rays, then the incoherent ones.
fn rays(mesh: &TriangleMesh) -> Result<Vec<Ray>, String> {
    let b = mesh.bounds();
    let eye = b.center() + DVec3::new(0.3, 0.4, -2.2).normalize() * 2.2 * b.diagonal();
    let camera = Pinhole::new(eye, b.center(), DVec3::Y, 25f64.to_radians(), 0.01)
        .map_err(|e| e.to_string())?;
    let projector = Projector::Pinhole(camera);
    let mut rays: Vec<Ray> = (0..SIDE * SIDE)
        .filter_map(|i| {
            projector
                .pixel_ray(i % SIDE, i / SIDE, SIDE, SIDE)
                .map(|c| c.ray)
        })
        .collect();
    let mut rng = SplitMix(0x0b5e_55ed);
    let n = rays.len();
    while rays.len() < 2 * n {
        let o = b.center() + rng.direction() * b.diagonal() * (0.1 + rng.unit());
        let toward = b.min + (b.max - b.min) * DVec3::new(rng.unit(), rng.unit(), rng.unit());
        if let Some(r) = Ray::new(o, toward - o) {
            rays.push(r);
        }
    }
    Ok(rays)
}

/// The brute force's nearest hit: the least `(t, triangle index)` over every triangle.
fn brute_force(mesh: &TriangleMesh, ray: &Ray) -> Option<(f64, u32)> {
    let frame = RayFrame::new(ray);
    (0..mesh.triangles.len())
        .filter_map(|i| intersect(&frame, mesh.corners(i), ALL).map(|h| (h.t, i as u32)))
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
}

/// The brute force on every [`REFERENCE_STRIDE`]th ray, on [`REFERENCE_THREADS`] threads.
fn reference(mesh: &TriangleMesh, rays: &[Ray]) -> Vec<Option<(f64, u32)>> {
    let picked: Vec<&Ray> = rays.iter().step_by(REFERENCE_STRIDE).collect();
    crate::parallel::map(&picked, REFERENCE_THREADS, |r| brute_force(mesh, r))
}

/// How two answer sets differ: the largest `|Δt|` over rays both hit, the rays whose triangle
/// differs, and the rays one hits and the other misses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct HitDifference {
    max_dt: f64,
    other_triangle: usize,
    flips: usize,
}

impl HitDifference {
    fn of(reference: &[Option<(f64, u32)>], got: &[Option<(f64, u32)>]) -> Self {
        let mut d = Self::default();
        for (a, b) in reference.iter().zip(got) {
            match (a, b) {
                (Some(a), Some(b)) => {
                    d.max_dt = d.max_dt.max((a.0 - b.0).abs());
                    d.other_triangle += usize::from(a.1 != b.1);
                }
                (None, None) => {}
                _ => d.flips += 1,
            }
        }
        d
    }

    fn is_zero(&self) -> bool {
        *self == Self::default()
    }
}

/// The traversal's answers on `rays`.
fn trace(bvh: &MeshBvh, rays: &[Ray]) -> Vec<Option<(f64, u32)>> {
    rays.iter()
        .map(|r| bvh.nearest_hit(r, ALL).map(|h| (h.t, h.triangle)))
        .collect()
}

/// Runs the sweep; returns its markdown, a sweep per mesh (trace time against error, all 0:
/// the summary rows) and the presets' build time against trace time, a line per mesh (the plot
/// `bvh_presets`).
pub fn run(repeats: usize) -> Result<(String, Vec<Sweep>, LinePlot), String> {
    let repeats = repeats.max(MIN_REPEATS);
    let mut md = format!(
        "# Mesh BVH: build presets (`cargo xtask bench bvh`)\n\n\
         Per mesh, per preset: the build (`MeshBvh::build_with`, wall, boxes + topology + f64 \
         refit) and the nearest hit of a fixed ray set by the f64 traversal (the primary rays of \
         a {SIDE}² view framing the mesh, then as many incoherent rays from all round it), one \
         thread, medians of {repeats}, the presets alternated round by round. Errors: the largest |Δt|, the rays whose triangle differs \
         and the hit/miss flips, against the brute force over every triangle on every \
         {REFERENCE_STRIDE}th ray, and against the default preset on every ray.\n\n\
         | mesh | triangles | preset | nodes | depth | build ms | trace ms | Mrays/s | vs brute force: max \\|Δt\\| / triangle / flips | vs default on all rays |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---|---|\n"
    );
    let mut sweeps = Vec::new();
    let mut plot = LinePlot {
        name: "bvh_presets".into(),
        title: "mesh BVH presets: build time against trace time (same hits)".into(),
        x_desc: "build ms (one thread)".into(),
        y_desc: format!("trace ms, {} rays (one thread)", 2 * SIDE * SIDE),
        series: Vec::new(),
    };
    let mut all_zero = true;
    for file in MESHES {
        let path = workspace::root().join("data/meshes").join(file);
        let mesh = TriangleMesh::load_obj(&path, &MemoryBudget::default())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let rays = rays(&mesh)?;
        eprintln!(
            "bvh {file}: brute force on {} rays",
            rays.len() / REFERENCE_STRIDE
        );
        let truth = reference(&mesh, &rays);
        let default_answers = trace(&MeshBvh::build(mesh.clone()), &rays);
        let stem = file.trim_end_matches(".obj");
        let mut sweep = Sweep {
            name: format!("bvh_{}", stem.to_ascii_lowercase().replace('-', "_")),
            method: format!("mesh BVH presets ({file})"),
            error_desc: "max |Δt| against the brute force (0: on the floor)".into(),
            time_desc: format!("{} rays, ms (one thread)", rays.len()),
            settings: Vec::new(),
            default: None,
        };
        // Builds and traces alternate between the presets round by round, so that drifting
        // machine load hits them alike.
        let mut build_ms = vec![Vec::new(); BuildPreset::ALL.len()];
        let mut trace_ms = vec![Vec::new(); BuildPreset::ALL.len()];
        let mut bvhs = Vec::new();
        for round in 0..repeats {
            for (i, preset) in BuildPreset::ALL.into_iter().enumerate() {
                let m = mesh.clone();
                let start = Instant::now();
                let built = MeshBvh::build_with(m, preset);
                build_ms[i].push(start.elapsed().as_secs_f64() * 1e3);
                if round == 0 {
                    bvhs.push(built);
                }
            }
        }
        // One untimed run each first: the timed ones start warm.
        let answers: Vec<_> = bvhs.iter().map(|b| trace(b, &rays)).collect();
        for _ in 0..repeats {
            for (i, bvh) in bvhs.iter().enumerate() {
                let start = Instant::now();
                std::hint::black_box(trace(bvh, &rays));
                trace_ms[i].push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let mut build_times = Vec::new();
        for (i, preset) in BuildPreset::ALL.into_iter().enumerate() {
            let (bvh, got) = (&bvhs[i], &answers[i]);
            let build_ms = median(std::mem::take(&mut build_ms[i]));
            build_times.push(build_ms);
            let trace_ms = median(std::mem::take(&mut trace_ms[i]));
            let sampled: Vec<_> = got.iter().step_by(REFERENCE_STRIDE).copied().collect();
            let vs_truth = HitDifference::of(&truth, &sampled);
            let vs_default = HitDifference::of(&default_answers, got);
            all_zero &= vs_truth.is_zero() && vs_default.is_zero();
            if preset == BuildPreset::default() {
                sweep.default = Some(sweep.settings.len());
            }
            sweep.settings.push(Setting {
                flips: vs_truth.flips,
                ..Setting::new(
                    format!("{}, build {build_ms:.0} ms", preset.name()),
                    trace_ms,
                    vs_truth.max_dt,
                )
            });
            let _ = writeln!(
                md,
                "| {stem} | {} | {} | {} | {} | {build_ms:.1} | {trace_ms:.1} | {:.2} | {:.0e} / {} / {} | {:.0e} / {} / {} |",
                mesh.triangles.len(),
                preset.name(),
                bvh.node_count(),
                bvh.max_depth(),
                rays.len() as f64 / trace_ms / 1e3,
                vs_truth.max_dt,
                vs_truth.other_triangle,
                vs_truth.flips,
                vs_default.max_dt,
                vs_default.other_triangle,
                vs_default.flips,
            );
        }
        plot.series.push(Series {
            label: format!("{stem} ({} triangles)", mesh.triangles.len()),
            points: sweep
                .settings
                .iter()
                .zip(&build_times)
                .map(|(s, &b)| (b, s.time_ms))
                .collect(),
            point_labels: BuildPreset::ALL
                .iter()
                .map(|p| p.name().to_owned())
                .collect(),
        });
        eprintln!("bvh {file}: done");
        sweeps.push(sweep);
    }
    if !all_zero {
        return Err(format!(
            "{md}\na build preset changed a hit: every preset must answer as the brute force does"
        ));
    }
    md.push_str(
        "\nEvery preset answered every ray as the brute force and the default do (all 0).\n",
    );
    Ok((md, sweeps, plot))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hit that moved, one on another triangle at the same `t`, a flip each way, and equal
    /// answers: counted apart.
    #[test]
    fn differences_are_counted_by_kind() {
        let reference = [Some((1.0, 3)), Some((2.0, 4)), None, Some((5.0, 1)), None];
        let got = [Some((1.25, 3)), Some((2.0, 7)), Some((3.0, 0)), None, None];
        let d = HitDifference::of(&reference, &got);
        assert_eq!(
            d,
            HitDifference {
                max_dt: 0.25,
                other_triangle: 1,
                flips: 2
            }
        );
        assert!(!d.is_zero());
        assert!(HitDifference::of(&reference, &reference).is_zero());
    }

    /// The brute force finds a unit triangle's hit at the plane's distance, and misses beside.
    #[test]
    fn the_brute_force_finds_the_nearest_triangle() {
        let mesh = TriangleMesh::new(
            vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                DVec3::new(0.0, 0.0, 2.0),
                DVec3::new(1.0, 0.0, 2.0),
                DVec3::new(0.0, 1.0, 2.0),
            ],
            vec![[3, 4, 5], [0, 1, 2]],
        )
        .unwrap();
        let ray = Ray::new(DVec3::new(0.2, 0.2, -1.0), DVec3::Z).unwrap();
        assert_eq!(brute_force(&mesh, &ray), Some((1.0, 1)));
        let beside = Ray::new(DVec3::new(0.8, 0.8, -1.0), DVec3::Z).unwrap();
        assert_eq!(brute_force(&mesh, &beside), None);
    }
}
