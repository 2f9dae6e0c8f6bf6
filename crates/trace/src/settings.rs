//! Settings of the CPU backend, and the most worker threads a render may start.

use fray_core::{BudgetError, PixelSamples};
use fray_geometry::CastMethod;

/// How the CPU backend renders. Scene settings feed the defaults; the caller may override.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceSettings {
    /// Ray-casting tolerance ε in world units.
    pub epsilon: f64,
    /// Worker threads; `None` = rayon's default (all cores).
    pub threads: Option<usize>,
    /// Cast shadow rays toward the lights.
    pub shadows: bool,
    /// Side of the square tiles the image is split into for parallel work.
    pub tile_size: u32,
    /// Cull with the quadtree scheduler (`fray-quadtree`): tiles and candidate objects, leaves
    /// and perturbations that provably cannot matter are skipped. Lossless: the image is the same
    /// with it off.
    pub culling: bool,
    /// Shade hit points (lights, shadows). Off, the frame holds visibility only — depth and
    /// normals, with the colour showing the normal as `0.5 + 0.5 n` — which is what "primary
    /// visibility + normals" timings measure.
    pub shading: bool,
    /// How rays that meet only plain quadrics are answered: the certified closed form (the
    /// default) or the halving search everywhere, as the GPU does.
    pub method: CastMethod,
    /// Anti-aliasing samples per pixel (the scene's `settings.samples`): colour is their
    /// box-filtered radiance; depth and normals come from the pixel centre.
    pub samples: PixelSamples,
    /// The media's evaluation: `Some(n)`, on a grid of pixels `n` apart, interpolated where the
    /// depths agree (the scene's `atmosphere.grid`); `None`, every pixel exactly.
    pub media_grid: Option<u32>,
    /// Render only rows `(start, end)`, end excluded, of the image (a tile of a still, for many
    /// machines): the frame is those rows, each pixel the same bits as in the whole image.
    /// `start` is a multiple of `tile_size`; `None`: every row.
    pub rows: Option<(u32, u32)>,
}

impl TraceSettings {
    /// The settings a scene asks for: its ε (or the size-relative default) and its shadow switch.
    pub fn for_scene(scene: &fray_scene::Scene) -> Self {
        Self {
            epsilon: scene.epsilon(),
            threads: None,
            shadows: scene.settings.shadows,
            tile_size: 16,
            culling: true,
            shading: true,
            method: CastMethod::ClosedForm,
            samples: scene.settings.samples,
            media_grid: scene.atmosphere.grid,
            rows: None,
        }
    }
}

/// How many worker threads per core a render may ask for. Past the machine's cores more threads
/// only take turns on them (8× leaves room to oversubscribe on purpose); each one costs its
/// stack and its start, so `--threads 10000` spent 30 s starting threads before its error.
pub const MAX_THREADS_PER_CORE: usize = 8;

/// The most worker threads a render may ask for here: [`MAX_THREADS_PER_CORE`] times the cores
/// `std::thread::available_parallelism` reports (one if it cannot tell).
pub fn max_threads() -> usize {
    machine_cores() * MAX_THREADS_PER_CORE
}

fn machine_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// `Ok` for rayon's default (`None` or `Some(0)`: all cores) and for counts up to
/// [`max_threads`]; past it [`TraceError::TooManyThreads`], before any thread starts.
pub fn check_threads(threads: Option<usize>) -> Result<(), TraceError> {
    match threads {
        Some(n) if n > max_threads() => Err(TraceError::TooManyThreads {
            threads: n,
            limit: max_threads(),
            cores: machine_cores(),
        }),
        _ => Ok(()),
    }
}

/// The worker pool of a render: `threads` threads (`None`: rayon's default, all cores).
pub(crate) fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, TraceError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    builder.build().map_err(|e| TraceError::ThreadPool {
        threads: threads.unwrap_or(0),
        reason: e.to_string(),
    })
}

/// Why the CPU backend refused to render.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TraceError {
    #[error("epsilon must be finite and > 0, got {0}")]
    BadEpsilon(f64),
    #[error("image size must be at least 1 × 1, got {0} × {1}")]
    EmptyImage(u32, u32),
    #[error("tile size must be at least 1")]
    BadTileSize,
    #[error(
        "rows {start}..{end} are not a band of the {height}-row image starting on a multiple of \
         the {tile}-row tile size"
    )]
    BadRows {
        start: u32,
        end: u32,
        height: u32,
        tile: u32,
    },
    #[error("quadtree: {0}")]
    Quadtree(#[from] fray_quadtree::QuadtreeError),
    #[error(
        "{threads} worker threads asked for, over the limit of {limit} ({} per core × {cores} cores)",
        MAX_THREADS_PER_CORE
    )]
    TooManyThreads {
        threads: usize,
        limit: usize,
        cores: usize,
    },
    #[error("could not start {threads} worker threads: {reason}")]
    ThreadPool { threads: usize, reason: String },
    #[error(transparent)]
    Budget(#[from] BudgetError),
}
