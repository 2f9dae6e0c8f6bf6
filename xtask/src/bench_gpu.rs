//! `cargo xtask bench gpu`: every data scene's frames on the GPU backend at fixed image sizes,
//! pass by pass. Each scene is uploaded once (resident) and rendered from its own camera at each
//! size: warm-up frames first (a software adapter compiles a pipeline at its first dispatch, and
//! a new size allocates its images), then the timed frames, whose medians go to
//! `target/bench/gpu.{csv,md}` (`bench_gpu_table`). A scene the GPU refuses is listed with the
//! reason.
//!
//! The sizes are exact (`--sizes`, default 1280×720 and 1920×1080): the image's aspect ratio
//! comes from the size, not the scene — a pinhole keeps its vertical field of view and widens or
//! narrows horizontally, a parallel projection keeps its picture height, a sphere surface maps its
//! `fov_x × fov_y` onto the image whatever its shape.

use crate::bench_gpu_table::{Adapter, FrameTimes, GpuBench, Outcome, Run};
use crate::workspace;
use fray_gpu::{GpuRenderer, GpuScene, GpuSettings, View};
use std::path::PathBuf;
use std::time::Instant;

/// The largest image side `--sizes` accepts (the CLI's).
const MAX_SIDE: u32 = 16384;

/// The sizes timed unless `--sizes` says otherwise.
pub const DEFAULT_SIZES: [(u32, u32); 2] = [(1280, 720), (1920, 1080)];

/// `--quick`'s one size.
pub const QUICK_SIZE: (u32, u32) = (1280, 720);

/// What `cargo xtask bench gpu` runs.
#[derive(Clone, Debug)]
pub struct GpuBenchOptions {
    /// The directory of `*.ron` scenes.
    pub scenes: PathBuf,
    /// Scenes by file stem; all when empty.
    pub stems: Vec<String>,
    /// Image sizes, `(width, height)`.
    pub sizes: Vec<(u32, u32)>,
    /// Frames rendered and discarded per scene and size before timing.
    pub warmup: usize,
    /// Frames timed per scene and size.
    pub frames: usize,
    /// Where `gpu.csv` and `gpu.md` go.
    pub out: PathBuf,
    /// Refuse a software adapter (its figures are the host CPU's, not a GPU's).
    pub hardware_only: bool,
}

/// Why the bench did not run.
#[derive(Debug)]
pub enum GpuBenchError {
    /// `hardware_only` and the adapter is a software one (named).
    SoftwareOnly(String),
    /// No adapter, no scenes, or the results could not be written.
    Failed(String),
}

impl std::fmt::Display for GpuBenchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GpuBenchError::SoftwareOnly(name) => write!(
                f,
                "the only adapter is a software one ({name}): its times are the host CPU's, not \
                 a GPU's; run without --hardware-only (benches/gpu-device.sh: --allow-software) \
                 to time it anyway"
            ),
            GpuBenchError::Failed(reason) => f.write_str(reason),
        }
    }
}

/// `WIDTHxHEIGHT` (also `×`), each side in `1..=16384`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("`{s}`: expected WIDTHxHEIGHT, e.g. 1280x720"))?;
    let side = |v: &str, name: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: the {name} `{v}` is not a whole number"))?;
        if (1..=MAX_SIDE).contains(&n) {
            Ok(n)
        } else {
            Err(format!("`{s}`: the {name} must be in 1..={MAX_SIDE}"))
        }
    };
    Ok((side(w, "width")?, side(h, "height")?))
}

/// Renders `warmup` frames of `view` and discards them, then times `frames` frames.
fn time_frames(
    resident: &mut GpuScene<'_>,
    view: &View,
    warmup: usize,
    frames: usize,
) -> Result<Vec<FrameTimes>, fray_gpu::GpuError> {
    for _ in 0..warmup {
        resident.render(view)?;
    }
    let mut times = Vec::with_capacity(frames);
    for _ in 0..frames.max(1) {
        let start = Instant::now();
        let frame = resident.render(view)?;
        let wall = start.elapsed();
        let s = frame.stats;
        times.push(FrameTimes {
            wall,
            encode: s.encode_time,
            kernel: s.kernel_time,
            passes: s.pass_times,
        });
    }
    Ok(times)
}

/// One line of progress for a run.
fn progress(run: &Run, seconds: f64) -> String {
    let what = match &run.outcome {
        Outcome::Refused(reason) => format!("refused: {reason}"),
        Outcome::Timed(frames) => match crate::bench_gpu_table::summarise(frames) {
            Some(s) => format!(
                "frame {:.1} ms, encode {:.1} ms, kernels {}",
                s.wall_ms,
                s.encode_ms,
                s.kernel_ms
                    .map_or_else(|| "untimed".to_owned(), |k| format!("{k:.1} ms"))
            ),
            None => "no frames".to_owned(),
        },
    };
    format!(
        "  {} {}×{}: {what} [{seconds:.1} s]",
        run.scene, run.width, run.height
    )
}

/// Runs the bench and writes `gpu.csv` and `gpu.md`; returns the Markdown.
pub fn run(options: &GpuBenchOptions) -> Result<String, GpuBenchError> {
    let failed = GpuBenchError::Failed;
    if options.sizes.is_empty() {
        return Err(failed("no image sizes to render".into()));
    }
    let scenes = workspace::list_scenes(&options.scenes)
        .and_then(|all| workspace::select(all, &options.stems))
        .map_err(failed)?;
    if scenes.is_empty() {
        return Err(failed(format!("no scenes in {}", options.scenes.display())));
    }
    let gpu = GpuRenderer::new().map_err(|e| failed(format!("cannot open the GPU: {e}")))?;
    let ctx = gpu.context();
    let adapter = Adapter {
        name: ctx.adapter_name.clone(),
        backend: ctx.backend.clone(),
        software: ctx.software,
        clock: if ctx.software {
            "host clock"
        } else if ctx.timestamp_period_ns.is_some() {
            "timestamps"
        } else {
            "none"
        }
        .to_owned(),
    };
    eprintln!(
        "adapter: {} ({}, {}; passes timed by {})",
        adapter.name,
        adapter.backend,
        if adapter.software {
            "software"
        } else {
            "hardware"
        },
        adapter.clock
    );
    if options.hardware_only && adapter.software {
        return Err(GpuBenchError::SoftwareOnly(adapter.name));
    }
    let mut runs = Vec::new();
    for file in &scenes {
        let start = Instant::now();
        let refuse_all = |runs: &mut Vec<Run>, reason: String| {
            for &(width, height) in &options.sizes {
                let run = Run {
                    scene: file.stem.clone(),
                    width,
                    height,
                    outcome: Outcome::Refused(reason.clone()),
                };
                eprintln!("{}", progress(&run, start.elapsed().as_secs_f64()));
                runs.push(run);
            }
        };
        let scene = match crate::render::load(&file.path) {
            Ok(s) => s,
            Err(e) => {
                refuse_all(&mut runs, format!("the scene did not load: {e}"));
                continue;
            }
        };
        if let Some(feature) = fray_gpu::unsupported_feature(&scene) {
            refuse_all(
                &mut runs,
                format!("the GPU backend does not draw {feature}"),
            );
            continue;
        }
        let settings = GpuSettings::for_scene(&scene);
        let mut resident = match gpu.upload(&scene, &settings) {
            Ok(r) => r,
            Err(e) => {
                refuse_all(&mut runs, e.to_string());
                continue;
            }
        };
        for &(width, height) in &options.sizes {
            let sized = Instant::now();
            let view = View {
                width,
                height,
                ..View::of_scene(&scene, settings.samples)
            };
            let outcome = match time_frames(&mut resident, &view, options.warmup, options.frames) {
                Ok(frames) => Outcome::Timed(frames),
                Err(e) => Outcome::Refused(e.to_string()),
            };
            let run = Run {
                scene: file.stem.clone(),
                width,
                height,
                outcome,
            };
            eprintln!("{}", progress(&run, sized.elapsed().as_secs_f64()));
            runs.push(run);
        }
    }
    let bench = GpuBench {
        adapter,
        warmup: options.warmup,
        frames: options.frames.max(1),
        runs,
    };
    let csv = crate::bench_gpu_table::to_csv(&bench);
    let md = crate::bench_gpu_table::to_markdown(&bench);
    std::fs::create_dir_all(&options.out)
        .map_err(|e| failed(format!("cannot create {}: {e}", options.out.display())))?;
    for (file, text) in [("gpu.csv", &csv), ("gpu.md", &md)] {
        let path = options.out.join(file);
        std::fs::write(&path, text)
            .map_err(|e| failed(format!("cannot write {}: {e}", path.display())))?;
    }
    eprintln!(
        "wrote {} and {}",
        options.out.join("gpu.csv").display(),
        options.out.join("gpu.md").display()
    );
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_say_why() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert_eq!(parse_size("1920×1080"), Ok((1920, 1080)));
        assert_eq!(parse_size("64X48"), Ok((64, 48)));
        for (bad, says) in [
            ("1280", "WIDTHxHEIGHT"),
            ("x720", "width"),
            ("1280x", "height"),
            ("0x720", "1..=16384"),
            ("1280x99999", "height must be"),
            ("-5x5", "not a whole number"),
        ] {
            let err = parse_size(bad).unwrap_err();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }
}
