//! `cargo xtask`: fray's developer tasks. This file only parses arguments and dispatches.

mod bench;
mod bench_atmosphere;
mod bench_bvh;
mod bench_clouds;
mod bench_freeform;
mod bench_gpu;
mod bench_gpu_table;
mod bench_samples;
mod bench_sky;
mod bench_terrain_scaling;
mod bench_whitted;
mod bless;
mod compare;
mod datasize;
mod datasize_plot;
mod hausdorff;
mod package;
mod parallel;
mod plot_font;
mod polygonise;
mod regress;
mod render;
mod report;
mod sweep_frame;
mod sweep_plot;
mod thresholds;
mod triangle_grid;
mod workspace;

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(name = "cargo xtask", about = "fray's developer tasks")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// One variant per task; add new tasks (e.g. `Bench(BenchArgs)`) here and in `main`.
#[derive(Debug, Subcommand)]
enum Command {
    /// Render every scene on every available backend and compare with the references.
    Regress(RegressArgs),
    /// Render scenes on the CPU backend and write them as the new references.
    Bless(BlessArgs),
    /// Sweeps. `terrain`: time vs map size (exact, pixel LOD), time vs error over the LOD bias
    /// and the fixed-step march, DEM scenes exact vs default; target/bench/terrain.{csv,md}.
    /// `atmosphere`: frame time and error against the numerical reference of each fog
    /// evaluation mode; target/bench/atmosphere.md. `clouds`: frame time against the march's
    /// step and sun steps with the error against a fine-step reference, empty-space skipping
    /// on and off, bake time against grid size; target/bench/clouds.md. `freeform`: the CPU
    /// free-form caster's time against depth error over ε on the csg and turboprop camera
    /// rays; target/bench/freeform.md. `whitted`: frame time against the Whitted depth with the
    /// error against a depth-64 frame; target/bench/whitted.md. `samples`: frame time against
    /// samples per pixel with the error against a 1024-sample frame; target/bench/samples.md.
    /// `bvh`: the mesh BVH's build presets, build and trace time on the data meshes, hits
    /// against a brute force; target/bench/bvh.md. `terrain-scaling`: terrain frame time against
    /// screen size and camera distance (time plots); target/bench/terrain_scaling.md. `sky`: the
    /// sky's table sizes, build time against the error to the quadrature; target/bench/sky.md.
    /// Each of these also writes its time-against-error sweeps as <name>.{csv,svg,png}, the
    /// Pareto front and the default marked. Default: all (these). `gpu`: every scene's frames on the GPU at 1280×720 and 1920×1080, each pass's
    /// median time; target/bench/gpu.{csv,md} (not part of `all`).
    Bench(BenchArgs),
    /// A scene's free forms as one closed triangle mesh (OBJ): marching tetrahedra with vertices
    /// on F = 0 and normals from its gradient; prints both descriptions' sizes.
    Polygonise(PolygoniseArgs),
    /// The data-size claim at equal error: a scene's free form polygonised at several cell
    /// counts, each mesh's two-sided Hausdorff distance to the surface, the bytes of the
    /// functional model (GPU arrays) and of each mesh (indexed f32), and their ratio at the error
    /// of one 1080p pixel; target/bench/datasize.{csv,md,svg,png}.
    Datasize(DatasizeArgs),
    /// Package every library crate (`cargo package --no-verify --offline`, in dependency
    /// order) and check that each archive holds every file its sources `include_str!` or
    /// `include_bytes!`, its README and both licence texts.
    Package,
}

#[derive(Debug, Args)]
struct PolygoniseArgs {
    /// The scene whose free forms (all of them, united) to polygonise
    scene: PathBuf,
    /// Cubic cells along the longest side of the free forms' box
    #[arg(long, value_name = "N", default_value_t = 160,
          value_parser = clap::value_parser!(u32).range(2..=4096))]
    cells: u32,
    /// The OBJ file to write
    #[arg(short, long, value_name = "FILE")]
    out: PathBuf,
}

#[derive(Debug, Args)]
struct DatasizeArgs {
    /// The scene (one free-form object) [default: data/scenes/turboprop.ron]
    scene: Option<PathBuf>,
    /// Cubic cells along the longest side of the solid's box, one mesh each
    #[arg(long, value_name = "N,…", value_delimiter = ',',
          default_values_t = [40, 60, 80, 120, 160, 240, 320, 480, 640, 960],
          value_parser = clap::value_parser!(u32).range(2..=4096))]
    cells: Vec<u32>,
    /// Directory for datasize.csv, datasize.md, datasize.svg and datasize.png [default:
    /// target/bench]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Also write the plot as DIR/datasize.svg and DIR/datasize.png (the docs' copies: `docs`)
    #[arg(long, value_name = "DIR")]
    docs: Option<PathBuf>,
    /// Random points per triangle for mesh → surface, besides vertices, edge midpoints and the
    /// centroid
    #[arg(long, value_name = "N", default_value_t = 2)]
    random: u32,
    /// Directions of the parallel rays that sample the surface (surface → mesh)
    #[arg(long, value_name = "N", default_value_t = 64,
          value_parser = clap::value_parser!(u32).range(1..=100_000))]
    directions: u32,
    /// Rays per side of each direction's square grid
    #[arg(long, value_name = "N", default_value_t = 256,
          value_parser = clap::value_parser!(u32).range(1..=100_000))]
    rays: u32,
    /// Worker threads [default: the machine's parallelism]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
}

#[derive(Debug, Args)]
struct BenchArgs {
    /// Which sweeps to run
    #[arg(value_enum, default_value_t = Sweeps::All)]
    sweeps: Sweeps,
    /// Directory for terrain.csv, terrain.md, atmosphere.md, clouds.md, freeform.md, the
    /// sweeps' plots, gpu.csv and gpu.md
    /// [default: target/bench]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Repetitions per timing (the median is reported); `gpu`: timed frames per scene and size
    #[arg(long, value_name = "N", default_value_t = 5,
          value_parser = clap::value_parser!(u32).range(1..=100))]
    repeats: u32,
    /// `gpu`: image sizes, exactly (the camera's aspect follows the size) [default:
    /// 1280x720,1920x1080]
    #[arg(long, value_name = "WxH,…", value_delimiter = ',', value_parser = bench_gpu::parse_size)]
    sizes: Vec<(u32, u32)>,
    /// `gpu`: frames rendered and discarded per scene and size before timing [default: 2]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(0..=100))]
    warmup: Option<u32>,
    /// `gpu`: only these scenes (file stems; repeatable) [default: all]
    #[arg(long = "scene", value_name = "STEM")]
    stems: Vec<String>,
    /// `gpu`: directory of `*.ron` scenes [default: data/scenes]
    #[arg(long, value_name = "DIR")]
    scenes: Option<PathBuf>,
    /// `gpu`: refuse a software adapter (e.g. lavapipe), exit code 3
    #[arg(long)]
    hardware_only: bool,
    /// `gpu`: a run of 6–11 minutes on lavapipe on 2 shared cores: 1280x720 alone, 1 warm-up
    /// frame, 3 timed frames
    #[arg(long, conflicts_with_all = ["sizes", "warmup", "repeats"])]
    quick: bool,
}

impl BenchArgs {
    /// The `gpu`-only options given, by flag.
    fn gpu_options_given(&self) -> Vec<&'static str> {
        [
            ("--sizes", !self.sizes.is_empty()),
            ("--warmup", self.warmup.is_some()),
            ("--scene", !self.stems.is_empty()),
            ("--scenes", self.scenes.is_some()),
            ("--hardware-only", self.hardware_only),
            ("--quick", self.quick),
        ]
        .into_iter()
        .filter_map(|(flag, given)| given.then_some(flag))
        .collect()
    }
}

/// The sweep sets of `cargo xtask bench`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum Sweeps {
    Terrain,
    Atmosphere,
    Clouds,
    Freeform,
    Whitted,
    Samples,
    Bvh,
    TerrainScaling,
    Sky,
    Gpu,
    All,
}

/// Arguments shared by the tasks that render the scene set.
#[derive(Debug, Args)]
struct SceneSetArgs {
    /// Directory of `*.ron` scenes [default: data/scenes]
    #[arg(long, value_name = "DIR")]
    scenes: Option<PathBuf>,
    /// Directory of reference images and thresholds.ron [default: data/reference]
    #[arg(long, value_name = "DIR")]
    reference: Option<PathBuf>,
    /// Test image width in pixels; the height keeps each scene's aspect ratio
    #[arg(long, value_name = "N", default_value_t = 160,
          value_parser = clap::value_parser!(u32).range(1..=16384))]
    size: u32,
}

impl SceneSetArgs {
    fn scenes(&self) -> PathBuf {
        self.scenes
            .clone()
            .unwrap_or_else(workspace::default_scenes)
    }

    fn reference(&self) -> PathBuf {
        self.reference
            .clone()
            .unwrap_or_else(workspace::default_reference)
    }
}

#[derive(Debug, Args)]
struct RegressArgs {
    #[command(flatten)]
    set: SceneSetArgs,
    /// Directory for the rendered images, diffs and index.html [default: target/regress]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct BlessArgs {
    #[command(flatten)]
    set: SceneSetArgs,
    /// Scenes to bless, by file stem; all when none are given
    #[arg(value_name = "SCENE_STEMS")]
    stems: Vec<String>,
}

/// Writes `md` as `out/file`.
fn write_md(out: &std::path::Path, file: &str, md: &str) -> Result<(), String> {
    let path = out.join(file);
    std::fs::create_dir_all(out)
        .and_then(|()| std::fs::write(&path, md))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Writes each sweep's CSV and plots under `out`; returns `md` with their summary table.
fn with_sweeps(
    mut md: String,
    sweeps: &[sweep_plot::Sweep],
    out: &std::path::Path,
) -> Result<String, String> {
    md.push_str("\n## Time against error\n\n");
    md.push_str(&sweep_plot::summary_header());
    for s in sweeps {
        s.write(out)?;
        md.push_str(&s.summary());
    }
    Ok(md)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Regress(args) => regress::run(&regress::RegressOptions {
            scenes: args.set.scenes(),
            reference: args.set.reference(),
            out: args.out.unwrap_or_else(workspace::default_regress_out),
            width: args.set.size,
        }),
        Command::Bless(args) => bless::run(&bless::BlessOptions {
            scenes: args.set.scenes(),
            reference: args.set.reference(),
            width: args.set.size,
            stems: args.stems,
        })
        .map(|()| true),
        Command::Polygonise(args) => polygonise::run(&polygonise::PolygoniseOptions {
            scene: args.scene,
            cells: args.cells,
            out: args.out,
        })
        .map(|summary| {
            println!("{summary}");
            true
        }),
        Command::Datasize(args) => datasize::run(&datasize::DatasizeOptions {
            scene: args
                .scene
                .unwrap_or_else(|| workspace::default_scenes().join("turboprop.ron")),
            cells: args.cells,
            out: args.out.unwrap_or_else(workspace::default_bench_out),
            docs: args.docs,
            sampling: hausdorff::Sampling {
                random_per_triangle: args.random,
                seed: 0x5eed_da7a,
                directions: args.directions,
                rays_across: args.rays,
                eps_share: 1e-7,
                threads: args.threads.map_or_else(
                    || std::thread::available_parallelism().map_or(1, |n| n.get()),
                    |n| n as usize,
                ),
            },
        })
        .map(|md| {
            println!("{md}");
            true
        }),
        Command::Package => package::run(),
        Command::Bench(args) if args.sweeps == Sweeps::Gpu => {
            let (sizes, warmup, frames) = if args.quick {
                (vec![bench_gpu::QUICK_SIZE], 1, 3)
            } else {
                let sizes = if args.sizes.is_empty() {
                    bench_gpu::DEFAULT_SIZES.to_vec()
                } else {
                    args.sizes
                };
                (
                    sizes,
                    args.warmup.unwrap_or(2) as usize,
                    args.repeats as usize,
                )
            };
            let options = bench_gpu::GpuBenchOptions {
                scenes: args.scenes.unwrap_or_else(workspace::default_scenes),
                stems: args.stems,
                sizes,
                warmup,
                frames,
                out: args.out.unwrap_or_else(workspace::default_bench_out),
                hardware_only: args.hardware_only,
            };
            match bench_gpu::run(&options) {
                Ok(md) => {
                    println!("{md}");
                    Ok(true)
                }
                Err(e @ bench_gpu::GpuBenchError::SoftwareOnly(_)) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(3);
                }
                Err(e) => Err(e.to_string()),
            }
        }
        Command::Bench(args) if !args.gpu_options_given().is_empty() => Err(format!(
            "{}: only for `cargo xtask bench gpu`",
            args.gpu_options_given().join(", ")
        )),
        Command::Bench(args) => {
            let out = args.out.unwrap_or_else(workspace::default_bench_out);
            let repeats = args.repeats as usize;
            let mut summary = String::new();
            let terrain = matches!(args.sweeps, Sweeps::Terrain | Sweeps::All);
            let atmosphere = matches!(args.sweeps, Sweeps::Atmosphere | Sweeps::All);
            let clouds = matches!(args.sweeps, Sweeps::Clouds | Sweeps::All);
            let freeform = matches!(args.sweeps, Sweeps::Freeform | Sweeps::All);
            let mut result = Ok(());
            if terrain {
                result = bench::run(&bench::BenchOptions {
                    out: out.clone(),
                    repeats,
                })
                .map(|md| summary.push_str(&md));
            }
            if atmosphere && result.is_ok() {
                result = bench_atmosphere::run(repeats).and_then(|(md, sweeps)| {
                    let md = with_sweeps(md, &sweeps, &out)?;
                    let path = out.join("atmosphere.md");
                    std::fs::create_dir_all(&out)
                        .and_then(|()| std::fs::write(&path, &md))
                        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                    summary.push_str(&md);
                    Ok(())
                });
            }
            if clouds && result.is_ok() {
                result = bench_clouds::run(repeats).and_then(|(md, sweep)| {
                    let md = with_sweeps(md, &[sweep], &out)?;
                    let path = out.join("clouds.md");
                    std::fs::create_dir_all(&out)
                        .and_then(|()| std::fs::write(&path, &md))
                        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                    summary.push_str(&md);
                    Ok(())
                });
            }
            if freeform && result.is_ok() {
                result = bench_freeform::run(repeats).and_then(|(md, sweeps)| {
                    for s in &sweeps {
                        s.write(&out)?;
                    }
                    let path = out.join("freeform.md");
                    std::fs::create_dir_all(&out)
                        .and_then(|()| std::fs::write(&path, &md))
                        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                    summary.push_str(&md);
                    Ok(())
                });
            }
            // The sweeps that write one markdown file with their summary table.
            type Run = fn(usize) -> Result<(String, Vec<sweep_plot::Sweep>), String>;
            let sets: [(Sweeps, &str, Run); 3] = [
                (Sweeps::Whitted, "whitted.md", |r| {
                    bench_whitted::run(r).map(|(md, s)| (md, vec![s]))
                }),
                (Sweeps::Samples, "samples.md", |r| {
                    bench_samples::run(r).map(|(md, s)| (md, vec![s]))
                }),
                (Sweeps::Sky, "sky.md", |r| {
                    bench_sky::run(r).map(|(md, s)| (md, vec![s]))
                }),
            ];
            for (which, file, run) in sets {
                if result.is_ok() && (args.sweeps == which || args.sweeps == Sweeps::All) {
                    result = run(repeats).and_then(|(md, sweeps)| {
                        let md = with_sweeps(md, &sweeps, &out)?;
                        write_md(&out, file, &md)?;
                        summary.push_str(&md);
                        Ok(())
                    });
                }
            }
            if result.is_ok() && matches!(args.sweeps, Sweeps::Bvh | Sweeps::All) {
                result = bench_bvh::run(repeats).and_then(|(md, sweeps, plot)| {
                    let md = with_sweeps(md, &sweeps, &out)?;
                    plot.write(&out)?;
                    write_md(&out, "bvh.md", &md)?;
                    summary.push_str(&md);
                    Ok(())
                });
            }
            if result.is_ok() && matches!(args.sweeps, Sweeps::TerrainScaling | Sweeps::All) {
                result = bench_terrain_scaling::run(repeats).and_then(|(md, plots)| {
                    for p in &plots {
                        p.write(&out)?;
                    }
                    write_md(&out, "terrain_scaling.md", &md)?;
                    summary.push_str(&md);
                    Ok(())
                });
            }
            result.map(|()| {
                println!("{summary}");
                true
            })
        }
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
