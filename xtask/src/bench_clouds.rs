//! `cargo xtask bench clouds`: the cloud march's time/error knob, written to
//! `target/bench/clouds.md`, on `data/scenes/clouds_aircraft_inside.ron` (the turboprop inside a
//! cumulus layer over the DEM) at 320×180 on the CPU with 2 worker threads.
//!
//! - The reference: the same frame marched with steps 16× finer than the scene's and 8× the sun
//!   steps (the per-pixel jitter is left as it is: it offsets each pixel's samples within a
//!   step, which the finer step makes irrelevant).
//! - Time against error: the scene's step × {4, 2, 1, ½, ¼} at its sun steps, and its sun steps
//!   × {½, 1, 2} at its step; each the median of the repeats, and its error against the reference
//!   over every pixel: the largest channel's `|Δ|` of the linear colour, its max and RMS over the
//!   frame, absolute and in units of the reference's brightest pixel (its largest channel). The
//!   step also sets the shadow rays' optical-depth step through the cloud (its shadows on the
//!   ground), so the error is the whole picture's. Each knob's own error besides: the step's
//!   rows also against the fine step at the scene's sun steps, the sun steps' rows against 8×
//!   the sun steps at the scene's step. And the same frame without clouds, for scale.
//! - Empty-space skipping: every `clouds_*` data scene at 320 px wide with its max grid and
//!   without (`volume.skip = None`), renders alternated; the ratio of medians, that the images
//!   are the same bits, and the density samples per camera ray of each.
//! - Grid storage: every cloud scene with its grid rounded as u8 and f16 grids would hold it,
//!   the frame's error against the f32 grid's.
//! - Bake time against grid size: the scene's layer (its field, its region) re-read with a
//!   resolution of 64³ … 512³, the bake the scene loader times itself (one bake each), the
//!   grid's bytes, and its max grid's build time.
//!
//! The step and sun-step rows are also plotted (`sweep_plot`): `clouds_march.{csv,svg,png}`,
//! frame time against the max error over the brightest pixel, the scene's march the default.

use crate::sweep_frame::{ImageError, brightest, median};
use crate::sweep_plot::{Setting, Sweep};
use crate::workspace;
use fray_core::Frame;
use fray_scene::{CloudSource, Scene};
use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

/// One CPU render with [`THREADS`] threads: its wall time (ms) and the frame.
fn render_once(scene: &Scene) -> Result<(f64, Frame), String> {
    crate::sweep_frame::render_once(scene, THREADS)
}

/// The median wall time of `repeats` renders (ms) and the last frame.
fn timed(scene: &Scene, repeats: usize) -> Result<(f64, Frame), String> {
    crate::sweep_frame::timed(scene, THREADS, repeats)
}

/// The scene the sweep renders.
const SCENE: &str = "data/scenes/clouds_aircraft_inside.ron";
/// The frame size of every render.
const SIZE: (u32, u32) = (320, 180);
/// Worker threads of the CPU renders.
const THREADS: usize = 2;
/// The reference's step is the scene's divided by this; its sun steps are the scene's times
/// [`REFERENCE_SUN`].
const REFERENCE_STEP_DIVISOR: f64 = 16.0;
const REFERENCE_SUN: u32 = 8;
/// Factors on the scene's step (at its sun steps).
const STEP_FACTORS: [(f64, &str); 5] = [
    (4.0, "4"),
    (2.0, "2"),
    (1.0, "1"),
    (0.5, "1/2"),
    (0.25, "1/4"),
];
/// Factors on the scene's sun steps (at its step; ×1 renders the step sweep's ×1 frame again,
/// for its sun steps' own error).
const SUN_FACTORS: [(f64, &str); 3] = [(0.5, "1/2"), (1.0, "1"), (2.0, "2")];
/// Grid sides of the bake sweep.
const BAKE_SIDES: [u32; 4] = [64, 128, 256, 512];

/// `scene` with its clouds' step and sun steps set, and its max grid kept or dropped.
fn with_march(scene: &Scene, step: f64, sun_steps: u32, skip: bool) -> Result<Scene, String> {
    let mut clouds = scene
        .clouds
        .as_deref()
        .cloned()
        .ok_or_else(|| format!("{SCENE}: the scene has no clouds"))?;
    clouds.march.step = step;
    clouds.march.sun_steps = sun_steps.max(1);
    if !skip {
        clouds.volume.skip = None;
    }
    let mut s = scene.clone();
    s.clouds = Some(Arc::new(clouds));
    Ok(s)
}

/// Density samples per camera ray.
fn samples_per_ray(frame: &Frame) -> f64 {
    frame.stats.cloud_samples as f64 / frame.stats.primary_rays.max(1) as f64
}

fn bits(frame: &Frame) -> Vec<[u32; 3]> {
    frame
        .colour
        .pixels()
        .iter()
        .map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()])
        .collect()
}

/// The scene's text with its clouds' `resolution: (…)` replaced by `n³`.
fn with_resolution(source: &str, n: u32) -> Result<String, String> {
    let at = source
        .find("resolution:")
        .ok_or_else(|| format!("{SCENE}: no `resolution:` in the clouds' layer"))?;
    let open = source[at..]
        .find('(')
        .map(|i| at + i)
        .ok_or_else(|| format!("{SCENE}: `resolution:` is not followed by a tuple"))?;
    let close = source[open..]
        .find(')')
        .map(|i| open + i)
        .ok_or_else(|| format!("{SCENE}: `resolution:`'s tuple is not closed"))?;
    Ok(format!(
        "{}({n}, {n}, {n}){}",
        &source[..open],
        &source[close + 1..]
    ))
}

/// Runs the sweep; returns its markdown and the march's time against error.
pub fn run(repeats: usize) -> Result<(String, Sweep), String> {
    let path = workspace::root().join(SCENE);
    let mut scene = fray_scene::load(&path).map_err(|e| e.to_string())?;
    (scene.width, scene.height) = SIZE;
    let clouds = scene
        .clouds
        .clone()
        .ok_or_else(|| format!("{SCENE}: the scene has no clouds"))?;
    let (step, sun) = (clouds.march.step, clouds.march.sun_steps);
    let skip = clouds.volume.skip.is_some();
    let [gx, gy, gz] = clouds.volume.grid.size();
    let mut out = format!(
        "# Clouds: the march's step against its error (`cargo xtask bench clouds`)\n\n\
         `{SCENE}` ({}), frames {}×{}, CPU, {THREADS} threads, medians of {repeats}.\n",
        clouds.describe(),
        SIZE.0,
        SIZE.1
    );

    // The references: both knobs fine, and each alone (for the knob's own error).
    let fine_step = step / REFERENCE_STEP_DIVISOR;
    let fine_sun = sun * REFERENCE_SUN;
    eprintln!("clouds: reference (step {fine_step} m, {fine_sun} sun steps)");
    let (reference_ms, reference) = render_once(&with_march(&scene, fine_step, fine_sun, skip)?)?;
    eprintln!("clouds: step-only reference (step {fine_step} m, {sun} sun steps)");
    let (_, step_reference) = render_once(&with_march(&scene, fine_step, sun, skip)?)?;
    eprintln!("clouds: sun-only reference (step {step} m, {fine_sun} sun steps)");
    let (_, sun_reference) = render_once(&with_march(&scene, step, fine_sun, skip)?)?;
    let bright = brightest(&reference).max(1e-30);
    let mut clear = scene.clone();
    clear.clouds = None;
    clear.features.clouds = false;
    eprintln!("clouds: the frame without clouds");
    let (clear_ms, _) = timed(&clear, repeats)?;

    // Time against error.
    let _ = write!(
        out,
        "\n## Time against error\n\n\
         Errors against the reference (step {fine_step:.4} m = the scene's / \
         {REFERENCE_STEP_DIVISOR}, {fine_sun} sun steps = the scene's × {REFERENCE_SUN}; one \
         render, {:.1} s): per pixel the largest channel's |Δ| of the linear colour, max and RMS \
         over the frame, also in units of the reference's brightest pixel ({bright:.4}). \
         \"Knob alone\": the same in units of the brightest pixel against the reference that \
         refines only the row's knob — the step's rows against step {fine_step:.4} m at {sun} sun \
         steps, the sun steps' rows against {fine_sun} sun steps at step {step} m — so the \
         knob's own error, without the other's.\n\n\
         | step × | step m | sun steps | frame ms | × scene's | samples / ray | max \\|Δ\\| | RMS \\|Δ\\| | max / brightest | RMS / brightest | knob alone: max / RMS |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        reference_ms / 1e3
    );
    struct Row {
        factor: String,
        step: f64,
        sun: u32,
        ms: f64,
        samples: f64,
        error: ImageError,
        alone: ImageError,
    }
    let mut rows = Vec::new();
    let mut variants: Vec<(String, f64, u32, &Frame)> = STEP_FACTORS
        .iter()
        .map(|&(f, name)| (name.to_owned(), step * f, sun, &step_reference))
        .collect();
    for (f, name) in SUN_FACTORS {
        let sun_steps = ((f64::from(sun) * f).round() as u32).max(1);
        variants.push((format!("1, sun × {name}"), step, sun_steps, &sun_reference));
    }
    for (factor, step_m, sun_steps, alone) in variants {
        eprintln!("clouds: step {step_m} m, {sun_steps} sun steps");
        let s = with_march(&scene, step_m, sun_steps, skip)?;
        let (ms, frame) = timed(&s, repeats)?;
        rows.push(Row {
            factor,
            step: step_m,
            sun: sun_steps,
            ms,
            samples: samples_per_ray(&frame),
            error: ImageError::of(&reference, &frame)?,
            alone: ImageError::of(alone, &frame)?,
        });
    }
    let scene_ms = rows
        .iter()
        .find(|r| r.step == step && r.sun == sun)
        .map_or(f64::NAN, |r| r.ms);
    let mut plotted = Sweep {
        name: "clouds_march".into(),
        method: format!("clouds ({})", SCENE.trim_start_matches("data/scenes/")),
        error_desc: "max |Δ| / brightest pixel".into(),
        time_desc: format!("frame ms ({}×{}, {THREADS} threads)", SIZE.0, SIZE.1),
        settings: Vec::new(),
        default: None,
    };
    for r in &rows {
        let label = if r.factor.contains("sun") {
            // "1, sun × 1" is the step sweep's × 1 again: drawn once.
            if r.sun == sun {
                continue;
            }
            format!("sun steps {}", r.sun)
        } else {
            if r.step == step {
                plotted.default = Some(plotted.settings.len());
            }
            format!("step × {}", r.factor)
        };
        plotted
            .settings
            .push(Setting::new(label, r.ms, r.error.max / bright));
    }
    for r in &rows {
        let _ = writeln!(
            out,
            "| {} | {:.2} | {} | {:.0} | {:.2} | {:.1} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | \
             {:.2e} / {:.2e} |",
            r.factor,
            r.step,
            r.sun,
            r.ms,
            r.ms / scene_ms,
            r.samples,
            r.error.max,
            r.error.rms,
            r.error.max / bright,
            r.error.rms / bright,
            r.alone.max / bright,
            r.alone.rms / bright
        );
    }
    let _ = writeln!(
        out,
        "| reference | {fine_step:.4} | {fine_sun} | {reference_ms:.0} (once) | {:.2} | {:.1} | 0 \
         | 0 | 0 | 0 | |\n\nThe same frame without clouds: {clear_ms:.0} ms ({:.2}× the \
         scene's).",
        reference_ms / scene_ms,
        samples_per_ray(&reference),
        clear_ms / scene_ms
    );

    // Empty-space skipping, on every cloud scene.
    eprintln!("clouds: empty-space skipping");
    out.push_str(&skipping(repeats)?);
    eprintln!("clouds: grid storage");
    out.push_str(&storage()?);

    // Bake time against grid size.
    let source = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let block = clouds.skip_block.unwrap_or(4) as usize;
    let _ = write!(
        out,
        "\n## Bake time against grid size\n\n\
         The scene's layer (its noise, coverage, profile and region; the scene's own grid is \
         {gx}×{gy}×{gz}) baked at n³ by the scene loader (its own timing; z slices in parallel \
         on all {} cores), one bake each; the max grid of {block}³ blocks built after it (one \
         thread).\n\n\
         | grid | samples | bytes | bake ms | ns / sample (wall) | max grid ms |\n\
         |---|---:|---:|---:|---:|---:|\n",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    for n in BAKE_SIDES {
        eprintln!("clouds: bake {n}³");
        let text = with_resolution(&source, n)?;
        let baked =
            fray_scene::parse(&text, &path.display().to_string()).map_err(|e| e.to_string())?;
        let c = baked
            .clouds
            .as_ref()
            .ok_or_else(|| format!("{SCENE}: the scene has no clouds"))?;
        let CloudSource::Layer { bake } = c.source else {
            return Err(format!("{SCENE}: the clouds are not a baked layer"));
        };
        let count = c.volume.grid.data().len();
        let bytes = std::mem::size_of_val(c.volume.grid.data());
        let start = Instant::now();
        let max = c.volume.grid.max_grid(block);
        let max_ms = start.elapsed().as_secs_f64() * 1e3;
        std::hint::black_box(max);
        let bake_ms = bake.as_secs_f64() * 1e3;
        let _ = writeln!(
            out,
            "| {n}³ | {count} | {} | {bake_ms:.0} | {:.0} | {max_ms:.0} |",
            mib(bytes),
            bake_ms * 1e6 / count.max(1) as f64
        );
    }
    Ok((out, plotted))
}

/// Bytes as MiB (or KiB below one MiB).
fn mib(bytes: usize) -> String {
    if bytes >= 1 << 20 {
        format!("{:.0} MiB", bytes as f64 / f64::from(1u32 << 20))
    } else {
        format!("{:.0} KiB", bytes as f64 / 1024.0)
    }
}

/// Every `clouds_*.ron` data scene, sorted: its file name, the scene at 320 px wide and its
/// clouds.
fn cloud_scenes() -> Result<Vec<(String, Scene, Arc<fray_scene::Clouds>)>, String> {
    let dir = workspace::root().join("data/scenes");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "ron")
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("clouds_"))
        })
        .collect();
    paths.sort();
    let mut scenes = Vec::new();
    for path in paths {
        let scene = load_narrow(&path)?;
        let name = path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        // A scene named clouds_ without clouds has nothing to measure.
        let Some(clouds) = scene.clouds.clone() else {
            continue;
        };
        scenes.push((name, scene, clouds));
    }
    Ok(scenes)
}

/// A scene loaded at 320 px wide (its aspect kept).
fn load_narrow(path: &std::path::Path) -> Result<Scene, String> {
    let mut scene = fray_scene::load(path).map_err(|e| e.to_string())?;
    let aspect = f64::from(scene.height) / f64::from(scene.width);
    scene.width = 320;
    scene.height = (320.0 * aspect).round().max(1.0) as u32;
    Ok(scene)
}

/// `v` rounded to the nearest IEEE half (ties to even; subnormals in 2⁻²⁴ steps): what an f16
/// grid would hold.
fn to_f16(v: f32) -> f32 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let a = v.abs();
    let quantum = (a.log2().floor().max(-14.0) - 10.0).exp2();
    (a / quantum).round_ties_even() * quantum * v.signum()
}

/// Grid storage: every cloud scene rendered with its grid rounded to 8-bit steps of its largest
/// value and to f16, against the f32 grid it has (the max grid rebuilt from the rounded one).
fn storage() -> Result<String, String> {
    let mut out = String::from(
        "\n## Grid storage: f32 against u8 and f16\n\n\
         Every cloud data scene at 320 px wide, CPU, its grid rounded as an 8-bit grid (steps of \
         its largest value / 255) or an f16 grid would hold it, against the f32 grid: the \
         frame's largest channel |Δ| per pixel, max and RMS over the frame, in units of the f32 \
         frame's brightest pixel.\n\n\
         | scene | grid | f32 bytes | u8: max / RMS | f16: max / RMS |\n|---|---|---:|---:|---:|\n",
    );
    for (name, scene, clouds) in cloud_scenes()? {
        let (_, reference) = render_once(&scene)?;
        let top = brightest(&reference);
        let grid = &clouds.volume.grid;
        let largest = grid.data().iter().copied().fold(0.0f32, f32::max);
        let as_u8 = |v: f32| (v / largest * 255.0).round() * largest / 255.0;
        let mut cells = Vec::new();
        for round in [&as_u8 as &dyn Fn(f32) -> f32, &to_f16] {
            let data = grid.data().iter().map(|v| round(*v)).collect();
            let rounded = fray_clouds::DensityGrid::from_data(grid.size(), data)
                .map_err(|e| e.to_string())?;
            let mut c = (*clouds).clone();
            c.volume.skip = clouds.skip_block.map(|b| rounded.max_grid(b as usize));
            c.volume.grid = rounded;
            let mut s = scene.clone();
            s.clouds = Some(Arc::new(c));
            let (_, frame) = render_once(&s)?;
            let e = ImageError::of(&reference, &frame)?;
            cells.push(format!("{:.1e} / {:.1e}", e.max / top, e.rms / top));
        }
        let [x, y, z] = grid.size();
        let _ = writeln!(
            out,
            "| {name} | {x}×{y}×{z} | {} | {} | {} |",
            mib(x * y * z * 4),
            cells[0],
            cells[1]
        );
    }
    Ok(out)
}

/// Empty-space skipping on and off on every `clouds_*.ron` data scene (320 px wide, each with its
/// own march settings), renders alternated so that drifting load hits both alike; fails if an
/// image changes (skipping must be lossless).
fn skipping(repeats: usize) -> Result<String, String> {
    let mut out = String::from(
        "\n## Empty-space skipping\n\n\
         Every cloud data scene at 320 px wide, CPU, with its max grid and without \
         (`volume.skip = None`), renders alternated, medians:\n\n\
         | scene | plain ms | skipping ms | skipping / plain | samples / ray, plain | skipping | images |\n\
         |---|---:|---:|---:|---:|---:|---|\n",
    );
    for (name, scene, clouds) in cloud_scenes()? {
        if clouds.volume.skip.is_none() {
            let _ = writeln!(out, "| {name} | | | skipping off in the scene | | | |");
            continue;
        }
        let (step, sun) = (clouds.march.step, clouds.march.sun_steps);
        let with_skip = with_march(&scene, step, sun, true)?;
        let without = with_march(&scene, step, sun, false)?;
        let (mut on_ms, mut off_ms) = (Vec::new(), Vec::new());
        let (mut on, mut off) = (None, None);
        for _ in 0..repeats.max(1) {
            let (ms, f) = render_once(&without)?;
            off_ms.push(ms);
            off = Some(f);
            let (ms, f) = render_once(&with_skip)?;
            on_ms.push(ms);
            on = Some(f);
        }
        let (Some(on), Some(off)) = (on, off) else {
            return Err("no frame rendered".into());
        };
        let (on_ms, off_ms) = (median(on_ms), median(off_ms));
        let identical = bits(&on) == bits(&off);
        let _ = writeln!(
            out,
            "| {name} | {off_ms:.0} | {on_ms:.0} | {:.3}× | {:.1} | {:.1} | {} |",
            on_ms / off_ms,
            samples_per_ray(&off),
            samples_per_ray(&on),
            if identical {
                "bit-identical"
            } else {
                "DIFFERENT"
            }
        );
        if !identical {
            let e = ImageError::of(&off, &on)?;
            return Err(format!(
                "{out}\n{name}: empty-space skipping changed the image (max |Δ| {:.2e}); it must be lossless",
                e.max
            ));
        }
    }
    Ok(out)
}
