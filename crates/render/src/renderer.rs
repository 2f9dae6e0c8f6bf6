//! The renderer facade: options, backend choice, and the one `render` call.

use fray_core::Frame;
use fray_gpu::{GpuError, GpuSettings};
use fray_scene::Scene;
use fray_trace::{TraceError, TraceSettings};

/// Which backend renders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    /// The f64 CPU reference (`fray-trace`).
    Cpu,
    /// The wgpu backend (`fray-gpu`, f32): an error if there is no GPU adapter.
    Gpu,
    /// The GPU if a hardware adapter exists, else the CPU. A software adapter (Mesa lavapipe)
    /// is skipped: it is correct but slower than the CPU backend; ask for `Gpu` to use it.
    #[default]
    Auto,
}

impl Backend {
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::Gpu => "gpu",
            Backend::Auto => "auto",
        }
    }
}

/// The concrete backends that can run on this machine, reference first.
pub fn available_backends() -> Vec<Backend> {
    let mut backends = vec![Backend::Cpu];
    if fray_gpu::probe_adapter().is_ok() {
        backends.push(Backend::Gpu);
    }
    backends
}

/// Overrides of the scene's own settings; `None` keeps the scene's value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderOptions {
    pub backend: Backend,
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Ray-casting tolerance in world units.
    pub epsilon: Option<f64>,
    /// Worker threads for the CPU backend.
    pub threads: Option<usize>,
    pub shadows: Option<bool>,
    /// Quadtree culling on either backend (default on; the image is identical either way).
    pub culling: Option<bool>,
    /// CPU only: answer rays that meet only plain quadrics in closed form (default on); off, the
    /// CPU searches every ray by halving, as the GPU does (the same image to within ε).
    pub closed_form: Option<bool>,
    /// Anti-aliasing samples per pixel (overrides the scene's `settings.samples`).
    pub samples: Option<fray_core::PixelSamples>,
    /// CPU: the media's evaluation (overrides the scene's `atmosphere.grid`): `Some(0)` every
    /// pixel exactly, `Some(n)` on a grid of pixels `n` apart (`fray_scene::GRID_SPACINGS`).
    /// The GPU evaluates the media per pixel.
    pub media_grid: Option<u32>,
    /// Render one horizontal tile of the image ([`ImageTile`]); `None`: the whole image.
    pub tile: Option<ImageTile>,
    /// Parts of the scene switched off (fog, sky, clouds, reflections: [`Scene::switched`]);
    /// the default leaves everything on.
    pub switches: fray_scene::Switches,
}

/// Tile `index` of `count` of an image: a band of whole rows, in blocks of
/// [`ImageTile::ROW_BLOCK`] rows shared out as evenly as they go. Tiles rendered apart (on other
/// machines) and stacked in index order are the whole image, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageTile {
    pub index: u32,
    pub count: u32,
}

impl ImageTile {
    /// Rows come in blocks of the CPU backend's tile size, so a tile's rows are rendered exactly
    /// as the whole image's are.
    pub const ROW_BLOCK: u32 = 16;

    /// The rows `(start, end)`, end excluded, of this tile of an image `height` rows tall.
    pub fn rows(&self, height: u32) -> Result<(u32, u32), RenderError> {
        let blocks = height.div_ceil(Self::ROW_BLOCK);
        if self.count == 0 || self.index >= self.count || self.count > blocks {
            return Err(RenderError::BadTile {
                index: self.index,
                count: self.count,
                blocks,
                height,
            });
        }
        let at = |i: u32| (u64::from(i) * u64::from(blocks) / u64::from(self.count)) as u32;
        let start = at(self.index) * Self::ROW_BLOCK;
        let end = (at(self.index + 1) * Self::ROW_BLOCK).min(height);
        Ok((start, end))
    }
}

impl RenderOptions {
    /// Refuses what no scene could make right before anything is loaded or started: more
    /// worker threads than [`fray_trace::max_threads`] (`--threads`).
    pub fn check(&self) -> Result<(), RenderError> {
        fray_trace::check_threads(self.threads)?;
        Ok(())
    }
}

/// Why a render failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("image size must be 1..=16384 on each side, got {0} × {1}")]
    BadSize(u32, u32),
    #[error("cpu backend: {0}")]
    Cpu(#[from] TraceError),
    #[error("gpu backend: {0}")]
    Gpu(#[from] GpuError),
    #[error(
        "tile {index}/{count}: an image {height} rows tall has {blocks} blocks of {} rows, so \
         1..={blocks} tiles, numbered from 0",
        ImageTile::ROW_BLOCK
    )]
    BadTile {
        index: u32,
        count: u32,
        blocks: u32,
        height: u32,
    },
}

/// Renders scenes with fixed options. The GPU is opened at the first GPU render and kept, with
/// its pipeline cache, for every later render by this renderer (and its clones): the frames of an
/// animation open the device once and build each pipeline once.
#[derive(Clone, Debug, Default)]
pub struct Renderer {
    options: RenderOptions,
    gpu: std::sync::Arc<std::sync::OnceLock<Result<fray_gpu::GpuRenderer, GpuError>>>,
}

impl Renderer {
    pub fn new(options: RenderOptions) -> Self {
        Self {
            options,
            gpu: Default::default(),
        }
    }

    pub fn options(&self) -> &RenderOptions {
        &self.options
    }

    /// The backend `render` will use: `Auto` is the GPU when a hardware adapter exists, else
    /// the CPU.
    pub fn resolved_backend(&self) -> Backend {
        match self.options.backend {
            Backend::Auto => match fray_gpu::probe_adapter() {
                Ok(probe) if !probe.software => Backend::Gpu,
                _ => Backend::Cpu,
            },
            b => b,
        }
    }

    /// Renders `scene`.
    pub fn render(&self, scene: &Scene) -> Result<Frame, RenderError> {
        self.render_with_progress(scene, None)
    }

    /// Renders `scene`, reporting (pixels done, pixels in total) as work finishes.
    pub fn render_with_progress(
        &self,
        scene: &Scene,
        progress: Option<fray_trace::Progress<'_>>,
    ) -> Result<Frame, RenderError> {
        self.options.check()?;
        let scene = self.sized(scene)?;
        let mut settings = TraceSettings::for_scene(&scene);
        if let Some(eps) = self.options.epsilon {
            settings.epsilon = eps;
        }
        settings.threads = self.options.threads;
        if let Some(samples) = self.options.samples {
            settings.samples = samples;
        }
        if let Some(s) = self.options.shadows {
            settings.shadows = s;
        }
        if let Some(n) = self.options.media_grid {
            settings.media_grid = (n > 0).then_some(n);
        }
        if let Some(tile) = self.options.tile {
            settings.rows = Some(tile.rows(scene.height)?);
        }
        let cpu = |settings: &TraceSettings| fray_trace::render(&scene, settings, progress);
        if let Some(c) = self.options.culling {
            settings.culling = c;
        }
        if let Some(closed) = self.options.closed_form {
            settings.method = if closed {
                fray_trace::CastMethod::ClosedForm
            } else {
                fray_trace::CastMethod::Halving
            };
        }
        if self.options.backend == Backend::Auto {
            match fray_gpu::probe_adapter() {
                Err(e) => eprintln!("warning: no GPU adapter ({e}); rendering on the CPU"),
                Ok(probe) if probe.software => eprintln!(
                    "note: the only GPU adapter is a software one ({}); rendering on the faster CPU backend (--backend gpu uses it anyway)",
                    probe.name
                ),
                Ok(_) => {}
            }
        }
        match self.resolved_backend() {
            Backend::Cpu | Backend::Auto => Ok(cpu(&settings)?),
            Backend::Gpu => {
                let gpu_settings = GpuSettings {
                    epsilon: settings.epsilon,
                    shadows: settings.shadows,
                    culling: settings.culling,
                    samples: settings.samples,
                };
                let gpu = || {
                    let gpu = self
                        .gpu
                        .get_or_init(fray_gpu::GpuRenderer::new)
                        .as_ref()
                        .map_err(Clone::clone)?;
                    let frame = match settings.rows {
                        Some(rows) => gpu.render_rows(&scene, &gpu_settings, rows)?,
                        None => gpu.render(&scene, &gpu_settings)?,
                    };
                    if let Some(report) = progress {
                        let n = u64::from(scene.width) * u64::from(scene.height);
                        report(n, n);
                    }
                    Ok(frame)
                };
                gpu_or_fallback(self.options.backend, gpu, || cpu(&settings), &mut |w| {
                    eprintln!("{w}")
                })
            }
        }
    }

    /// The scene at the requested size (giving only one side keeps its aspect ratio), with the
    /// parts `switches` leaves off removed.
    fn sized<'s>(&self, scene: &'s Scene) -> Result<std::borrow::Cow<'s, Scene>, RenderError> {
        let switches = self.options.switches;
        let (w, h) = match (self.options.width, self.options.height) {
            (None, None) if switches == fray_scene::Switches::ALL_ON => {
                return Ok(std::borrow::Cow::Borrowed(scene));
            }
            (None, None) => (scene.width, scene.height),
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (
                w,
                ((u64::from(w) * u64::from(scene.height)) / u64::from(scene.width.max(1))).max(1)
                    as u32,
            ),
            (None, Some(h)) => (
                ((u64::from(h) * u64::from(scene.width)) / u64::from(scene.height.max(1))).max(1)
                    as u32,
                h,
            ),
        };
        if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
            return Err(RenderError::BadSize(w, h));
        }
        let mut s = if switches == fray_scene::Switches::ALL_ON {
            scene.clone()
        } else {
            scene.switched(switches)
        };
        s.width = w;
        s.height = h;
        Ok(std::borrow::Cow::Owned(s))
    }
}

/// Renders with `gpu`; when it fails in a way the request allows, warns (through `warn`) and
/// renders with `cpu` instead: a device lost mid-render always, any GPU failure under `Auto` (a GPU
/// that would not open, a scene its pipeline cannot hold). An explicit `Gpu` request reports the
/// other errors.
fn gpu_or_fallback(
    requested: Backend,
    gpu: impl FnOnce() -> Result<Frame, GpuError>,
    cpu: impl FnOnce() -> Result<Frame, TraceError>,
    warn: &mut dyn FnMut(String),
) -> Result<Frame, RenderError> {
    match gpu() {
        Ok(frame) => Ok(frame),
        Err(e) if matches!(e, GpuError::DeviceLost(_)) || requested == Backend::Auto => {
            warn(format!("warning: {e}; rendering on the CPU instead"));
            Ok(cpu()?)
        }
        Err(e) => Err(RenderError::Gpu(e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        fray_scene::parse(
            "Scene(image: (width: 24, height: 16), \
             camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), \
             objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
            "sphere.ron",
        )
        .unwrap()
    }

    /// The facade's fallback path with injected GPU failures (no real device loss needed).
    #[test]
    fn a_failed_gpu_falls_back_to_a_cpu_frame_with_a_warning_when_allowed() {
        let scene = scene();
        let cpu = || fray_trace::render(&scene, &TraceSettings::for_scene(&scene), None);
        let lost = GpuError::DeviceLost("injected loss".into());
        let missing = GpuError::NoAdapter("injected: none".into());
        let pipeline = GpuError::Pipeline {
            pass: "free-form",
            reason: "injected".into(),
        };
        // A scene past the device's limits (a buffer, private memory, a texture side).
        let too_large = GpuError::TooLarge {
            what: "per-invocation private memory (bytes) for the largest solid",
            needed: 32 << 10,
            limit: 16 << 10,
        };
        for (requested, error, falls_back) in [
            (Backend::Gpu, &lost, true),
            (Backend::Auto, &lost, true),
            (Backend::Auto, &missing, true),
            (Backend::Auto, &pipeline, true),
            (Backend::Auto, &too_large, true),
            (Backend::Gpu, &missing, false),
            (Backend::Gpu, &pipeline, false),
            (Backend::Gpu, &too_large, false),
        ] {
            let mut warnings = Vec::new();
            let result = gpu_or_fallback(requested, || Err(error.clone()), cpu, &mut |w| {
                warnings.push(w)
            });
            let what = format!("{requested:?} with {error}");
            if falls_back {
                let frame = result.unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_eq!(frame.stats.backend, "cpu", "{what}");
                assert!(frame.stats.hits > 0, "{what}");
                assert_eq!(
                    warnings,
                    [format!("warning: {error}; rendering on the CPU instead")],
                    "{what}"
                );
            } else {
                match result {
                    Err(RenderError::Gpu(e)) => assert_eq!(&e, error, "{what}"),
                    other => panic!("{what}: expected the GPU error, got {other:?}"),
                }
                assert!(warnings.is_empty(), "{what}: {warnings:?}");
            }
        }
        // A working GPU is used as it is: no warning, the CPU never runs.
        let gpu_frame = cpu().unwrap();
        let mut warnings = Vec::new();
        let frame = gpu_or_fallback(
            Backend::Gpu,
            || Ok(gpu_frame.clone()),
            || panic!("the CPU must not run"),
            &mut |w| warnings.push(w),
        )
        .unwrap();
        assert_eq!(frame.stats.hits, gpu_frame.stats.hits);
        assert!(warnings.is_empty());
    }
}
