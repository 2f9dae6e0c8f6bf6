//! `cargo xtask bench`: the terrain sweeps (issue 4), written machine-readable to
//! `target/bench/terrain.csv` with a short markdown table `target/bench/terrain.md`.
//!
//! The setup (the DEM upsampled to 256² … 4096² over the same 30 km square, the fixed oblique
//! screen, depth errors) is `fray_terrain::sweep`, the same code the criterion bench
//! (`cargo bench -p fray-terrain`) uses. Times are medians of a few repetitions on a shared
//! machine: compare ratios within one run.
//!
//! - `size`: ray batches (128² rays, one thread) exact and pixel-LOD, and rendered frames
//!   (256², the CPU backend, 2 threads, shaded with exact shadow rays) with the default LOD
//!   (`Pixel`) and `Exact`, per map size; the 4096²/256² ratios.
//! - `lod`: time against depth error over the LOD bias on the 1024² map (pixel rule shifted by
//!   whole levels, and fixed levels above the finest), against the exact hits; the fixed-step
//!   march at several steps, so the step with the same error can be read off.
//! - `dem`: the DEM scenes (`terrain_low`, `terrain_high`) at their size, 2 threads, `Exact` vs
//!   the default `Pixel`: frame times and the default's depth error in cells.
//!
//! The `lod` and `march` rows (and the exact cast) are also a time-against-error sweep
//! (`sweep_plot`): the largest relative depth error `|Δt| / t` against the exact hits, plotted
//! as `terrain_lod.{svg,png}` with its CSV. The `size` rows are plotted as time against the map's
//! side (`terrain_map_size.{csv,svg,png}`, a `LinePlot`): the pixel LOD's flat line is the cost
//! independent of map size.

use crate::sweep_plot::{self, LinePlot, Series, Setting, Sweep};
use crate::workspace;
use fray_core::{Interval, Pinhole, PixelFootprint, Projector, Ray, glam::DVec3};
use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::{Scene, TerrainLod};
use fray_terrain::sweep::{self, DepthError};
use fray_terrain::{Heightmap, Interpolation, Placement, Terrain, TerrainOptions};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// What `cargo xtask bench` runs.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Where `terrain.csv` and `terrain.md` go.
    pub out: PathBuf,
    /// Repetitions per timing (the median is reported).
    pub repeats: usize,
}

/// Side of the ray-batch screen (the criterion bench's).
const SCREEN: usize = 128;
/// Side of the rendered sweep frames.
const FRAME: u32 = 256;
/// Worker threads of the rendered frames.
const THREADS: usize = 2;
const SIZES: [usize; 5] = [256, 512, 1024, 2048, 4096];

/// One result row.
struct Row {
    sweep: &'static str,
    variant: String,
    param: String,
    median_ms: f64,
    error: Option<DepthError>,
}

/// The median wall time of `repeats` runs of `f`, in milliseconds, and its last result.
fn timed<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        last = Some(f());
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    // `repeats.max(1)` runs happened, so `last` is set.
    (median, last.expect("at least one run"))
}

/// The DEM (`data/terrain`) as a bicubic terrain at its own size: what the sweeps upsample.
pub(crate) fn dem(root: &Path) -> Result<Terrain, String> {
    let path = root.join("data/terrain/jacksboro_fault_dem.png");
    let map = Heightmap::load(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let placement =
        Placement::new(DVec3::ZERO, fray_core::glam::DVec2::ONE, 1.0).map_err(|e| e.to_string())?;
    let options = TerrainOptions {
        interpolation: Interpolation::Bicubic,
        ..TerrainOptions::default()
    };
    Terrain::new(map, placement, options).map_err(|e| e.to_string())
}

/// Hits of a ray batch with the pixel footprint `footprint` (zero: exact).
fn cast_batch(t: &Terrain, rays: &[Ray], footprint: PixelFootprint) -> Vec<Option<f64>> {
    let all = Interval::new(0.0, f64::INFINITY);
    let mut stats = fray_terrain::TerrainStats::default();
    rays.iter()
        .map(|r| {
            t.cast_footprint(r, all, 1e-6, footprint, &mut stats)
                .map(|h| h.t)
        })
        .collect()
}

fn set_lod(scene: &mut Scene, lod: TerrainLod) {
    for t in &mut scene.terrains {
        t.lod = lod;
    }
}

fn render(scene: &Scene, repeats: usize) -> Result<(f64, fray_core::Frame), String> {
    let renderer = Renderer::new(RenderOptions {
        backend: Backend::Cpu,
        threads: Some(THREADS),
        ..RenderOptions::default()
    });
    let (ms, frame) = timed(repeats, || renderer.render(scene));
    Ok((ms, frame.map_err(|e| e.to_string())?))
}

/// Depth error of `got` against `reference` over the pixels, in cells of `cell` world units.
fn frame_error(reference: &fray_core::Frame, got: &fray_core::Frame, cell: f64) -> DepthError {
    let hits = |f: &fray_core::Frame| -> Vec<Option<f64>> {
        f.depth
            .pixels()
            .iter()
            .map(|&d| d.is_finite().then_some(d))
            .collect()
    };
    DepthError::of(&hits(reference), &hits(got), cell)
}

/// Runs the sweeps and writes the results; returns the markdown summary.
pub fn run(options: &BenchOptions) -> Result<String, String> {
    let root = workspace::root();
    let base = dem(&root)?;
    let rays = sweep::screen_rays(SCREEN);
    let screen = PixelFootprint {
        size: 0.0,
        angle: sweep::screen_footprint(SCREEN),
    };
    let repeats = options.repeats;
    let mut rows = Vec::new();

    // A scene to render the sweep maps in: terrain_high's lights and material, the fixed
    // screen's camera at FRAME², the terrain replaced per map size.
    let mut frame_scene = crate::render::load(&root.join("data/scenes/terrain_high.ron"))?;
    frame_scene.camera = Projector::Pinhole(
        Pinhole::new(
            sweep::EYE,
            sweep::TARGET,
            DVec3::Y,
            sweep::FOV_DEGREES.to_radians(),
            1.0,
        )
        .map_err(|e| e.to_string())?,
    );
    (frame_scene.width, frame_scene.height) = (FRAME, FRAME);

    eprintln!("size sweep: {SIZES:?}");
    for n in SIZES {
        let t = Arc::new(
            sweep::upsampled(&base, n, TerrainOptions::default()).map_err(|e| e.to_string())?,
        );
        let (exact_ms, exact) = timed(repeats, || cast_batch(&t, &rays, PixelFootprint::ZERO));
        let (pixel_ms, pixel) = timed(repeats, || cast_batch(&t, &rays, screen));
        let cell = sweep::cell_size(n);
        rows.push(Row {
            sweep: "size_rays",
            variant: "exact".into(),
            param: n.to_string(),
            median_ms: exact_ms,
            error: None,
        });
        rows.push(Row {
            sweep: "size_rays",
            variant: "pixel".into(),
            param: n.to_string(),
            median_ms: pixel_ms,
            error: Some(DepthError::of(&exact, &pixel, cell)),
        });
        let mut scene = frame_scene.clone();
        if let Some(obj) = scene.terrains.first_mut() {
            obj.terrain = t;
        }
        set_lod(&mut scene, TerrainLod::Exact);
        let (exact_ms, exact) = render(&scene, repeats)?;
        set_lod(&mut scene, TerrainLod::Pixel);
        let (pixel_ms, pixel) = render(&scene, repeats)?;
        rows.push(Row {
            sweep: "size_frame",
            variant: "exact".into(),
            param: n.to_string(),
            median_ms: exact_ms,
            error: None,
        });
        rows.push(Row {
            sweep: "size_frame",
            variant: "pixel".into(),
            param: n.to_string(),
            median_ms: pixel_ms,
            error: Some(frame_error(&exact, &pixel, cell)),
        });
        eprintln!("  {n}²: done");
    }

    eprintln!("lod sweep on 1024²");
    let n = 1024;
    let cell = sweep::cell_size(n);
    let exact_terrain =
        sweep::upsampled(&base, n, TerrainOptions::default()).map_err(|e| e.to_string())?;
    let (exact_ms, reference) = timed(repeats, || {
        cast_batch(&exact_terrain, &rays, PixelFootprint::ZERO)
    });
    // Time against relative depth error on the 1024² map's ray batch: the plot's settings.
    let mut settings = vec![Setting::new("exact", exact_ms, 0.0)];
    let mut add = |label: String, ms: f64, got: &[Option<f64>]| {
        let (error, flips) = relative_depth_error(&reference, got);
        settings.push(Setting {
            flips,
            ..Setting::new(label, ms, error)
        });
    };
    for bias in 0..=4u32 {
        let t = sweep::upsampled(
            &base,
            n,
            TerrainOptions {
                lod_bias: bias,
                ..TerrainOptions::default()
            },
        )
        .map_err(|e| e.to_string())?;
        // The renderer's rule: `Pixel` with bias b is the footprint 2^b times wider.
        let (ms, got) = timed(repeats, || cast_batch(&t, &rays, screen.coarser(bias)));
        add(format!("pixel +{bias}"), ms, &got);
        rows.push(Row {
            sweep: "lod",
            variant: "pixel".into(),
            param: bias.to_string(),
            median_ms: ms,
            error: Some(DepthError::of(&reference, &got, cell)),
        });
        let (ms, got) = timed(repeats, || cast_batch(&t, &rays, PixelFootprint::ZERO));
        if bias > 0 {
            add(format!("level {bias}"), ms, &got);
        }
        rows.push(Row {
            sweep: "lod",
            variant: "fixed_level".into(),
            param: bias.to_string(),
            median_ms: ms,
            error: Some(DepthError::of(&reference, &got, cell)),
        });
    }
    let all = Interval::new(0.0, f64::INFINITY);
    for cells in [4.0, 1.0, 0.25, 0.1, 0.03] {
        let step = cells * cell;
        let march = || -> Vec<Option<f64>> {
            rays.iter()
                .map(|r| {
                    exact_terrain
                        .march(r, all, step)
                        .expect("the sweep's steps are within MAX_MARCH_STEPS")
                })
                .collect()
        };
        // The finest steps are slow: time them once.
        let (ms, got) = timed(if cells < 0.2 { 1 } else { repeats }, march);
        add(format!("march {cells}"), ms, &got);
        rows.push(Row {
            sweep: "march",
            variant: "fixed_step".into(),
            param: cells.to_string(),
            median_ms: ms,
            error: Some(DepthError::of(&reference, &got, cell)),
        });
    }

    let lod = Sweep {
        name: "terrain_lod".into(),
        method: "terrain (1024², 128² rays)".into(),
        error_desc: "max |Δt| / t against exact".into(),
        time_desc: "ray batch ms (one thread)".into(),
        settings,
        // The renderer's default LOD: `Pixel`, bias 0.
        default: Some(1),
    };

    eprintln!("DEM scenes");
    for name in ["terrain_low", "terrain_high"] {
        let mut scene = crate::render::load(&root.join(format!("data/scenes/{name}.ron")))?;
        let cell = scene
            .terrains
            .first()
            .map_or(1.0, |t| t.terrain.placement().spacing().min_element());
        // Alternate the two so that drifting machine load hits both alike.
        let (mut exact_ms, mut pixel_ms) = (Vec::new(), Vec::new());
        let (mut exact, mut pixel) = (None, None);
        for _ in 0..repeats.max(1) {
            set_lod(&mut scene, TerrainLod::Exact);
            let (ms, f) = render(&scene, 1)?;
            exact_ms.push(ms);
            exact = Some(f);
            set_lod(&mut scene, TerrainLod::Pixel);
            let (ms, f) = render(&scene, 1)?;
            pixel_ms.push(ms);
            pixel = Some(f);
        }
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (Some(exact), Some(pixel)) = (exact, pixel) else {
            return Err(format!("{name}: no frame rendered"));
        };
        rows.push(Row {
            sweep: "dem_frame",
            variant: "exact".into(),
            param: name.into(),
            median_ms: median(exact_ms),
            error: None,
        });
        rows.push(Row {
            sweep: "dem_frame",
            variant: "pixel".into(),
            param: name.into(),
            median_ms: median(pixel_ms),
            error: Some(frame_error(&exact, &pixel, cell)),
        });
    }

    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    let csv = to_csv(&rows);
    let md = format!(
        "{}\n## Time against error (`terrain_lod.{{csv,svg,png}}`)\n\n{}{}",
        to_markdown(&rows, repeats),
        sweep_plot::summary_header(),
        lod.summary()
    );
    for (file, text) in [("terrain.csv", &csv), ("terrain.md", &md)] {
        let path = options.out.join(file);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    lod.write(&options.out)?;
    map_size_plot(&rows).write(&options.out)?;
    Ok(md)
}

/// The `size` rows as time against the map's side, one line per sweep and LOD rule.
fn map_size_plot(rows: &[Row]) -> LinePlot {
    let series = [
        (
            "size_frame",
            "pixel",
            format!("{FRAME}² frame, pixel LOD ({THREADS} threads)"),
        ),
        (
            "size_frame",
            "exact",
            format!("{FRAME}² frame, exact ({THREADS} threads)"),
        ),
        (
            "size_rays",
            "pixel",
            format!("{SCREEN}² rays, pixel LOD (one thread)"),
        ),
        (
            "size_rays",
            "exact",
            format!("{SCREEN}² rays, exact (one thread)"),
        ),
    ]
    .into_iter()
    .map(|(sweep, variant, label)| Series {
        label,
        points: rows
            .iter()
            .filter(|r| r.sweep == sweep && r.variant == variant)
            .filter_map(|r| Some((r.param.parse::<f64>().ok()?, r.median_ms)))
            .collect(),
        point_labels: Vec::new(),
    })
    .collect();
    LinePlot {
        name: "terrain_map_size".into(),
        title: "terrain: time against map size (same ground, same camera)".into(),
        x_desc: "map side (samples)".into(),
        y_desc: "ms".into(),
        series,
    }
}

/// The largest `|Δt| / t` over the rays both hit, and the rays one hits and the other misses.
fn relative_depth_error(reference: &[Option<f64>], got: &[Option<f64>]) -> (f64, usize) {
    let (mut max, mut flips) = (0.0f64, 0);
    for (a, b) in reference.iter().zip(got) {
        match (a, b) {
            (Some(a), Some(b)) => max = max.max((a - b).abs() / a.abs().max(f64::MIN_POSITIVE)),
            (None, None) => {}
            _ => flips += 1,
        }
    }
    (max, flips)
}

fn to_csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "sweep,variant,param,median_ms,mean_error_cells,max_error_cells,hit_miss_flips\n",
    );
    for r in rows {
        let (mean, max, flips) = match r.error {
            Some(e) => (e.mean.to_string(), e.max.to_string(), e.flips.to_string()),
            None => Default::default(),
        };
        let _ = writeln!(
            s,
            "{},{},{},{:.3},{mean},{max},{flips}",
            r.sweep, r.variant, r.param, r.median_ms
        );
    }
    s
}

/// The median time of a row, if there is one.
fn time_of(rows: &[Row], sweep: &str, variant: &str, param: &str) -> Option<f64> {
    rows.iter()
        .find(|r| r.sweep == sweep && r.variant == variant && r.param == param)
        .map(|r| r.median_ms)
}

fn to_markdown(rows: &[Row], repeats: usize) -> String {
    let mut s = format!(
        "# Terrain sweeps (`cargo xtask bench`; medians of {repeats}; errors in cells vs exact)\n\n\
         | sweep | variant | param | median ms | mean err | max err | flips |\n\
         |---|---|---|---:|---:|---:|---:|\n"
    );
    for r in rows {
        let (mean, max, flips) = match r.error {
            Some(e) => (
                format!("{:.2e}", e.mean),
                format!("{:.2e}", e.max),
                e.flips.to_string(),
            ),
            None => ("".into(), "".into(), "".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {mean} | {max} | {flips} |",
            r.sweep, r.variant, r.param, r.median_ms
        );
    }
    s.push_str("\nRatios 4096² / 256² (target ≤ 1.5 with the pixel LOD):\n\n");
    for sweep in ["size_rays", "size_frame"] {
        for variant in ["exact", "pixel"] {
            if let (Some(a), Some(b)) = (
                time_of(rows, sweep, variant, "4096"),
                time_of(rows, sweep, variant, "256"),
            ) {
                let _ = writeln!(s, "- {sweep} {variant}: {:.2}×", a / b.max(1e-9));
            }
        }
    }
    for name in ["terrain_low", "terrain_high"] {
        if let (Some(e), Some(p)) = (
            time_of(rows, "dem_frame", "exact", name),
            time_of(rows, "dem_frame", "pixel", name),
        ) {
            let _ = writeln!(
                s,
                "- {name}: pixel / exact frame time {:.2}×",
                p / e.max(1e-9)
            );
        }
    }
    s
}
