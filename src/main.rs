//! The `fray` command line: render a scene file to PNG or EXR.

use clap::{Parser, Subcommand, ValueEnum};
use fray_core::ToneMap;
use fray_render::output::{BitDepth, PngOptions, write_image};
use fray_render::{Backend, RenderOptions, Renderer};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The scene rendered when none is named: the turboprop aircraft.
const DEFAULT_SCENE: &str = include_str!("../data/scenes/turboprop.ron");
const DEFAULT_SCENE_NAME: &str = "data/scenes/turboprop.ron (built in)";

#[derive(Parser, Debug)]
#[command(
    name = "fray",
    version,
    about = "Ray casting of functionally defined scenes"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene file (the built-in default scene if none is given).
    Render(RenderArgs),
    /// Fly through a scene in a window (the showcase if none is given and the data is there, else the built-in scene): the GPU
    /// draws every frame, or the CPU renders progressively; F12 saves what `fray render` would.
    View(fray_view::ViewArgs),
    /// Stack PNG tiles rendered with `fray render --tile I/N` (given in tile order) into one
    /// image.
    Assemble {
        /// The tiles, tile 0 first.
        #[arg(required = true)]
        tiles: Vec<PathBuf>,
        /// The whole image (.png).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Parse and validate a scene file, and print what it holds (objects of every kind), what it
    /// uses and what it charged to the memory budget.
    Check {
        /// The scene file (.ron).
        scene: PathBuf,
        /// The memory budget to build the scene within [default: FRAY_MEMORY_BUDGET or 4G].
        #[arg(long, value_name = "BYTES")]
        memory_budget: Option<fray_core::MemoryBudget>,
    },
}

#[derive(clap::Args, Debug)]
struct RenderArgs {
    /// The scene file (.ron); the built-in turboprop scene if omitted.
    scene: Option<PathBuf>,
    /// Output image: .png (sRGB, tone-mapped) or .exr (linear colour, depth Z, normals).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Image width in pixels (keeps the aspect ratio if --height is not given).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (keeps the aspect ratio if --width is not given).
    #[arg(long)]
    height: Option<u32>,
    /// Render from the scene's camera of this name (`cameras` in the scene file).
    #[arg(long, value_name = "NAME")]
    camera: Option<String>,
    /// Render the scene's animation at this time, in seconds.
    #[arg(long, value_name = "SECONDS", conflicts_with = "frames")]
    time: Option<f64>,
    /// Render frames A to B−1 of the scene's animation, each to the output path with its number
    /// in place of a printf pattern (`-o out_%04d.png`; default: `<scene>_%04d.png`). A frame's
    /// bytes do not depend on the frames rendered before it.
    #[arg(long, value_name = "A..B", value_parser = parse_frames)]
    frames: Option<std::ops::Range<u32>>,
    /// Render tile I of N of the image: a band of rows (`fray assemble` stacks the tiles back
    /// into the whole image, bit for bit).
    #[arg(long, value_name = "I/N", value_parser = parse_tile, conflicts_with = "frames")]
    tile: Option<fray_render::ImageTile>,
    /// Ray-casting tolerance in world units (default: 1e-10 × the scene's size).
    #[arg(long)]
    eps: Option<f64>,
    /// Worker threads (default: all cores; at most 8 per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Which backend renders.
    #[arg(long, value_enum, default_value_t = BackendArg::Auto)]
    backend: BackendArg,
    /// Anti-aliasing: stratified samples per pixel, box-filtered, in 1..=1024 [default: the
    /// scene's `settings.samples`, else 1]. Depth and normals come from the pixel centre.
    #[arg(long, value_name = "N", value_parser = parse_samples)]
    samples: Option<fray_core::PixelSamples>,
    /// CPU: evaluate fog and air on a grid of pixels N apart (2..=64; 8 if N is left out),
    /// interpolated where depths agree (the method's per-vertex mode); 0 evaluates every pixel
    /// exactly [default: the scene's `atmosphere.grid`, else every pixel]
    #[arg(long, value_name = "N", value_parser = parse_media_grid, num_args = 0..=1,
          default_missing_value = fray_scene::DEFAULT_GRID_SPACING_TEXT)]
    media_grid: Option<u32>,
    /// Turn shadow rays off.
    #[arg(long)]
    no_shadows: bool,
    /// Turn the CPU quadtree culling off (same image, more work; for comparisons).
    #[arg(long)]
    no_culling: bool,
    /// Leave the scene's fog out (nothing of it is computed).
    #[arg(long)]
    no_fog: bool,
    /// Leave the scene's sky out: rays that hit nothing take `background`, the sunlight arrives
    /// as given.
    #[arg(long)]
    no_sky: bool,
    /// Leave the scene's clouds out.
    #[arg(long)]
    no_clouds: bool,
    /// Trace no reflected or refracted rays (Whitted's `max_depth` 0).
    #[arg(long)]
    no_reflections: bool,
    /// CPU: search every ray by halving, as the GPU does, instead of answering rays that meet
    /// only plain quadrics in closed form (same image to within ε; for comparisons).
    #[arg(long)]
    no_closed_form: bool,
    /// The most a render may allocate for what grows with the input (images, work lists, height
    /// maps): bytes with an optional K/M/G/T suffix, e.g. 8G [default: FRAY_MEMORY_BUDGET or 4G].
    #[arg(long, value_name = "BYTES")]
    memory_budget: Option<fray_core::MemoryBudget>,
    /// Exposure multiplier applied before tone mapping (PNG only).
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Tone map for PNG output.
    #[arg(long, value_enum, default_value_t = ToneMapArg::Clamp)]
    tone_map: ToneMapArg,
    /// Bits per channel for PNG output.
    #[arg(long, value_enum, default_value_t = BitDepthArg::Eight)]
    bit_depth: BitDepthArg,
    /// No progress bar and no summary line.
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Clone, Copy, Debug, Default, ValueEnum)]
enum BackendArg {
    Cpu,
    Gpu,
    #[default]
    Auto,
}

#[derive(Clone, Copy, Debug, Default, ValueEnum)]
enum BitDepthArg {
    #[default]
    #[value(name = "8")]
    Eight,
    #[value(name = "16")]
    Sixteen,
}

#[derive(Clone, Copy, Debug, Default, ValueEnum)]
enum ToneMapArg {
    #[default]
    Clamp,
    Reinhard,
}

fn main() -> ExitCode {
    // No subcommand means `fray render`, parsed as such: clap fills in the arguments' declared
    // defaults only when it parses, so a hand-built `RenderArgs` would have none of them (the
    // all-black first picture of an exposure of 0 came from exactly that).
    let command = Cli::parse()
        .command
        .or_else(|| Cli::parse_from(["fray", "render"]).command);
    let result = match command {
        Some(Command::Render(args)) => render(&args),
        Some(Command::Assemble { tiles, output }) => {
            fray_render::assemble_png_tiles(&tiles, &output).map_err(|e| e.to_string())
        }
        Some(Command::Check {
            scene,
            memory_budget,
        }) => check(&scene, memory_budget.unwrap_or_default()),
        Some(Command::View(args)) => {
            let scene = args.scene.clone().or_else(showcase);
            // An animated scene goes whole: the viewer starts at time 0 and plays it.
            load(scene.as_deref(), &args.build_options())
                .and_then(|(scene, name)| args.run(scene, name))
        }
        None => Err("no command".to_owned()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn parse_media_grid(text: &str) -> Result<u32, String> {
    let range = fray_scene::GRID_SPACINGS;
    match text.parse::<u32>() {
        Ok(n) if n == 0 || range.contains(&n) => Ok(n),
        _ => Err(format!(
            "0 (every pixel) or a spacing in {}..={} pixels is needed, got {text:?}",
            range.start(),
            range.end()
        )),
    }
}

fn parse_frames(text: &str) -> Result<std::ops::Range<u32>, String> {
    let bad = || format!("frames are `A..B` (B excluded), e.g. 0..240, got {text:?}");
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let (a, b): (u32, u32) = (a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?);
    if a < b { Ok(a..b) } else { Err(bad()) }
}

fn parse_tile(text: &str) -> Result<fray_render::ImageTile, String> {
    let bad = || format!("a tile is `I/N` (tile I of N, from 0), e.g. 3/8, got {text:?}");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (index, count) = (i.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
    if count == 0 || index >= count {
        return Err(bad());
    }
    Ok(fray_render::ImageTile { index, count })
}

/// `pattern` with its printf pattern (`%d`, `%04d`, …) replaced by `n`.
fn numbered(pattern: &Path, n: u32) -> Result<PathBuf, String> {
    let text = pattern.to_string_lossy();
    let start = text.find('%').ok_or_else(|| {
        format!(
            "{}: an output for many frames needs a frame-number pattern such as %04d",
            pattern.display()
        )
    })?;
    let rest = &text[start + 1..];
    let end = rest.find('d').ok_or_else(|| {
        format!(
            "{}: the pattern after % must be like %04d",
            pattern.display()
        )
    })?;
    let spec = &rest[..end];
    let width: usize = if spec.is_empty() {
        0
    } else if spec.chars().all(|c| c.is_ascii_digit()) && spec.len() <= 2 {
        spec.parse().unwrap_or(0)
    } else {
        return Err(format!(
            "{}: the pattern after % must be like %04d",
            pattern.display()
        ));
    };
    Ok(PathBuf::from(format!(
        "{}{n:0width$}{}",
        &text[..start],
        &rest[end + 1..]
    )))
}

fn parse_samples(text: &str) -> Result<fray_core::PixelSamples, String> {
    let n: u32 = text
        .parse()
        .map_err(|_| format!("a whole number of samples is needed, got {text:?}"))?;
    fray_core::PixelSamples::new(n).map_err(|e| e.to_string())
}

/// The viewer's default scene: the showcase where the project's data is (the current folder, as
/// after `git clone` and `cd`, or the checkout this binary was built from); else `None` (the
/// built-in turboprop, which needs no files).
fn showcase() -> Option<PathBuf> {
    [
        PathBuf::from("data/scenes/showcase.ron"),
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes/showcase.ron"),
    ]
    .into_iter()
    .find(|p| p.is_file())
}

/// The scene at `path` (or the default scene), built as `options` say.
fn load(
    path: Option<&Path>,
    options: &fray_scene::BuildOptions,
) -> Result<(fray_scene::Scene, String), String> {
    match path {
        Some(p) => fray_scene::load_with(p, options)
            .map(|s| (s, p.display().to_string()))
            .map_err(|e| e.to_string()),
        None => fray_scene::parse_with(DEFAULT_SCENE, DEFAULT_SCENE_NAME, options)
            .map(|s| (s, DEFAULT_SCENE_NAME.to_string()))
            .map_err(|e| e.to_string()),
    }
}

fn check(path: &Path, budget: fray_core::MemoryBudget) -> Result<(), String> {
    use fray_scene::PrimitiveKind;
    let (scene, name) = load(Some(path), &fray_scene::BuildOptions::within(budget))?;
    let leaves: usize = scene.objects.iter().map(|o| o.solid.leaves().len()).sum();
    let perturbations: usize = scene
        .objects
        .iter()
        .map(|o| o.solid.perturbation_count())
        .sum();
    // Every kind of object counts (a mesh-only scene is not "0 objects").
    let total: usize = PrimitiveKind::ALL.iter().map(|&k| scene.count(k)).sum();
    let kinds: Vec<String> = PrimitiveKind::ALL
        .iter()
        .map(|&k| match k {
            PrimitiveKind::FreeForm => format!(
                "{} {} with {leaves} free forms and {perturbations} perturbations",
                scene.count(k),
                k.name()
            ),
            _ => format!("{} {}", scene.count(k), k.name()),
        })
        .collect();
    println!(
        "{name}: ok — {}×{}, {total} objects ({}), {} lights, {} materials; features: {}",
        scene.width,
        scene.height,
        kinds.join(", "),
        scene.lights.len(),
        scene.materials.len(),
        scene.features.names().join(", ")
    );
    print_ledger(&scene.budget);
    Ok(())
}

/// What the scene charged to its memory account, item by item, and the total against the limit.
fn print_ledger(budget: &fray_core::MemoryBudget) {
    use fray_core::budget::human;
    println!(
        "memory: {} charged of the {} budget",
        human(budget.charged()),
        human(budget.bytes())
    );
    for (what, bytes) in budget.ledger() {
        println!("  {:>10}  {what}", human(bytes));
    }
}

fn render(args: &RenderArgs) -> Result<(), String> {
    let renderer = Renderer::new(RenderOptions {
        backend: match args.backend {
            BackendArg::Cpu => Backend::Cpu,
            BackendArg::Gpu => Backend::Gpu,
            BackendArg::Auto => Backend::Auto,
        },
        width: args.width,
        height: args.height,
        epsilon: args.eps,
        threads: args.threads,
        shadows: args.no_shadows.then_some(false),
        culling: args.no_culling.then_some(false),
        switches: fray_scene::Switches {
            fog: !args.no_fog,
            sky: !args.no_sky,
            clouds: !args.no_clouds,
            reflections: !args.no_reflections,
        },
        closed_form: args.no_closed_form.then_some(false),
        samples: args.samples,
        media_grid: args.media_grid,
        tile: args.tile,
    });
    // Options no scene could make right (`--threads` past the machine's limit) are refused
    // before the scene is loaded.
    renderer.options().check().map_err(|e| e.to_string())?;
    // Long builds (a cloud layer's bake) show a bar on a terminal.
    let build_bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {pos}/{len} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar
    });
    let build_report = |what: &str, done: usize, total: usize| {
        if let Some(bar) = &build_bar {
            bar.set_message(what.to_owned());
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    };
    let options = fray_scene::BuildOptions {
        budget: args.memory_budget.clone().unwrap_or_default(),
        progress: Some(&build_report),
    };
    let loaded = load(args.scene.as_deref(), &options);
    if let Some(bar) = &build_bar {
        bar.finish_and_clear();
    }
    let (mut scene, name) = loaded?;
    if let Some(camera) = &args.camera {
        scene = scene
            .with_camera(camera)
            .map_err(|e| format!("{name}: {e}"))?;
    }
    let stem = args
        .scene
        .as_deref()
        .and_then(|p| p.file_stem())
        .map_or_else(
            || "turboprop".to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
    let output = args.output.clone().unwrap_or_else(|| {
        PathBuf::from(match (&args.frames, args.tile) {
            (Some(_), _) => format!("{stem}_%04d.png"),
            (None, Some(t)) => format!("{stem}_tile{}of{}.png", t.index, t.count),
            (None, None) => format!("{stem}.png"),
        })
    });
    // Refuse an output the writers cannot produce before rendering, not after.
    fray_render::output::check_extension(&output).map_err(|e| e.to_string())?;
    let at = |n: u32| scene.at_frame(n).map_err(|e| format!("{name}: {e}"));
    match &args.frames {
        Some(frames) => {
            if let Some(a) = &scene.animation
                && frames.end > a.frames
            {
                eprintln!(
                    "note: the animation has {} frames; frames from {} on hold its {} end",
                    a.frames,
                    a.frames,
                    if a.looped { "looped" } else { "last" }
                );
            }
            numbered(&output, frames.start)?;
            for n in frames.clone() {
                render_still(&renderer, &at(n)?, &name, &numbered(&output, n)?, args)?;
            }
            Ok(())
        }
        None => {
            // A still of an animated scene is its frame at `--time`, else at time 0.
            let still = match args.time {
                Some(t) => scene.at_time(t).map_err(|e| format!("{name}: {e}"))?,
                None => at(0)?,
            };
            render_still(&renderer, &still, &name, &output, args)
        }
    }
}

/// Renders `scene` with `renderer`, writes it to `output` and prints the summary line.
fn render_still(
    renderer: &Renderer,
    scene: &fray_scene::Scene,
    name: &str,
    output: &Path,
    args: &RenderArgs,
) -> Result<(), String> {
    let bar = (!args.quiet && std::io::stderr().is_terminal()).then(|| {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} rendering [{bar:40}] {percent:>3}% {elapsed} eta {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar
    });
    let report = |done: u64, total: u64| {
        if let Some(bar) = &bar {
            bar.set_length(total);
            bar.set_position(done);
        }
    };
    let frame = renderer
        .render_with_progress(scene, Some(&report))
        .map_err(|e| format!("{name}: {e}"))?;
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let png = PngOptions {
        bit_depth: match args.bit_depth {
            BitDepthArg::Eight => BitDepth::Eight,
            BitDepthArg::Sixteen => BitDepth::Sixteen,
        },
        tone_map: match args.tone_map {
            ToneMapArg::Clamp => ToneMap::Clamp,
            ToneMapArg::Reinhard => ToneMap::Reinhard,
        },
        exposure: args.exposure,
    };
    write_image(&frame, output, &png).map_err(|e| e.to_string())?;
    if !args.quiet {
        let s = &frame.stats;
        // Terrain work, when a terrain was searched: per terrain cast of a camera ray.
        let terrain = if s.terrain_rays > 0 {
            let per = |n: u64| n as f64 / s.terrain_rays as f64;
            format!(
                ", terrain: {} rays, {:.1} segment + {:.2} cell tests per ray, mean LOD {:.2} levels above the finest",
                s.terrain_rays,
                per(s.terrain_segments),
                per(s.terrain_cells),
                s.terrain_mean_lod(),
            )
        } else {
            String::new()
        };
        // How many casts the CPU answered in closed form rather than by search.
        let closed = if s.closed_form_casts > 0 {
            format!(" ({} casts in closed form)", s.closed_form_casts)
        } else {
            String::new()
        };
        // The media grid's share of interpolated evaluations (the per-vertex mode).
        let media = s.media_interpolated + s.media_exact;
        let grid = if media > 0 {
            format!(
                ", media grid: {:.1}% of {} evaluations interpolated",
                100.0 * s.media_interpolated as f64 / media as f64,
                media
            )
        } else {
            String::new()
        };
        // The clouds: what was built, and what the marches of camera rays sampled.
        let clouds = match &scene.clouds {
            Some(c) => format!(
                ", clouds: {}, {:.1} density samples per camera ray",
                c.describe(),
                s.cloud_samples as f64 / s.primary_rays.max(1) as f64
            ),
            None => String::new(),
        };
        // Meshes and Whitted's secondary rays, where the scene has them.
        let meshes = if scene.meshes.is_empty() {
            String::new()
        } else {
            let triangles: usize = scene
                .meshes
                .iter()
                .map(|m| m.instance.mesh.mesh().triangles.len())
                .sum();
            let shadow_packets = if s.mesh_shadow_tile_rays > 0 {
                format!(
                    ", {} shadow-ray casts in tile packets",
                    s.mesh_shadow_tile_rays
                )
            } else {
                String::new()
            };
            format!(
                ", meshes: {} instances, {triangles} triangles, {} mesh casts ({} in tile \
                 packets){shadow_packets}",
                scene.meshes.len(),
                s.mesh_rays,
                s.mesh_tile_rays
            )
        };
        let whitted = if s.secondary_rays > 0 {
            format!(", {} secondary rays", s.secondary_rays)
        } else {
            String::new()
        };
        // The GPU's kernel time, where the device measured it (timestamp queries), pass by pass.
        let kernel = s
            .kernel_time
            .map(|k| {
                let passes: Vec<String> = s
                    .pass_times
                    .iter()
                    .map(|(label, d)| format!("{label} {:.1}", d.as_secs_f64() * 1e3))
                    .collect();
                format!(
                    ", GPU kernels {:.1} ms [{} ms]",
                    k.as_secs_f64() * 1e3,
                    passes.join(", ")
                )
            })
            .unwrap_or_default();
        println!(
            "{name} → {}: {}×{} in {:.1} ms{kernel} ({}, {} threads) — {:.2} Mrays/s, {} primary + {} shadow rays, {:.1}% hit, {:.2} bound + {:.2} point evaluations per ray{closed}{terrain}{grid}{clouds}{meshes}{whitted}, ε = {:.3e}; ran: {}",
            output.display(),
            frame.colour.width(),
            frame.colour.height(),
            s.elapsed.as_secs_f64() * 1e3,
            s.backend,
            s.threads,
            s.rays_per_second() / 1e6,
            s.primary_rays,
            s.shadow_rays,
            100.0 * frame.hit_fraction(),
            s.steps_per_ray(),
            s.point_evaluations as f64 / s.rays().max(1) as f64,
            s.epsilon,
            s.passes.join(", "),
        );
    }
    Ok(())
}
