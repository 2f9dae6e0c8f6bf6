//! The GPU frame: settings, the f32 ε, the renderer (a device and its pipeline cache) and the
//! resident scene a frame is rendered from ([`GpuScene`]) — per frame the rebase, the quadtree
//! work list, then per band of rows the passes (ray generation → free forms → terrains →
//! meshes → shading → media (fog, sky, clouds) → resolve into storage textures), and the
//! textures read back into a [`Frame`].

use crate::bindings::{self, FRAME, FREE_FORMS, Part, QUEUE, TARGETS, WORK};
use crate::counters::{self, Counter};
use crate::features::Feature;
use crate::params::{self, FrameParams, GpuPath, GpuSecondary, View};
use crate::passes::band::{Band, BindGroups, Pass, Role};
use crate::passes::rebase::RebasePass;
use crate::passes::whitted::QUEUE_SLOTS_PER_RAY;
use crate::passes::{PassSetup, PipelineCache};
use crate::readback::{map_read, read_back, readback_buffer};
use crate::resident::ResidentScene;
use crate::shader::{self, ModuleOptions, Specialisation};
use crate::timestamps::{PassClock, PassTimes, TimedEncoder, Timestamps};
use crate::work::{GpuWork, TILE, quadtree_config};
use crate::{GpuContext, GpuError};
use fray_core::{Frame, Image, PixelSamples, RenderStats};
use fray_scene::{PrimitiveKind, Scene};
use glam::{DVec3, Vec3};
use std::sync::Arc;
use std::time::{Duration, Instant};
use wgpu::BufferUsages as U;

/// The f32 floor of ε relative to the camera distance: `2⁻²⁰ ≈ 9.5e-7`, about 8 f32 ulps of a
/// distance — below it f32 halving cannot make progress and roots are not resolved better.
pub const EPSILON_FLOOR: f64 = 1.0 / 1_048_576.0;
/// Shadow rays start this many (GPU) ε along the normal: far beyond the f32 hit error.
pub const SHADOW_OFFSET_EPSILONS: f64 = 100.0;
/// Upper bound of one band's rays in flight (smaller bands keep device memory modest).
const BAND_BYTES: u64 = 64 << 20;
/// Upper bound of one readback of the frame's textures.
const READBACK_BYTES: u64 = 64 << 20;
/// Host bytes per pixel a GPU frame needs: the read-back textures (2 × 16) and the frame's
/// images (32).
pub const HOST_BYTES_PER_PIXEL: u64 = 64;

/// How the GPU backend renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuSettings {
    /// The requested ray-casting tolerance ε (world units); raised to the f32 floor.
    pub epsilon: f64,
    /// Cast shadow rays toward the lights.
    pub shadows: bool,
    /// Render from the quadtree work list (`fray_scene::work_list`): culled tiles run nothing
    /// and each tile casts only its candidates' active parts. Lossless: the same image as off.
    pub culling: bool,
    /// Anti-aliasing samples per pixel.
    pub samples: PixelSamples,
}

impl GpuSettings {
    /// The scene's own ε, shadow switch and samples.
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            epsilon: scene.epsilon(),
            shadows: scene.settings.shadows,
            culling: true,
            samples: scene.settings.samples,
        }
    }
}

/// The largest distance from `camera`'s eye to the scene's box (1 for an empty or unbounded
/// scene).
pub fn camera_distance(scene: &Scene, camera: &fray_core::Projector) -> f64 {
    let b = scene.bounds();
    if b.is_empty() || !b.is_finite() {
        return 1.0;
    }
    let eye = params::reference_point(camera);
    let far = DVec3::new(
        (b.min.x - eye.x).abs().max((b.max.x - eye.x).abs()),
        (b.min.y - eye.y).abs().max((b.max.y - eye.y).abs()),
        (b.min.z - eye.z).abs().max((b.max.z - eye.z).abs()),
    );
    far.length().max(f64::MIN_POSITIVE)
}

/// The ε the GPU uses for `scene` seen from its own camera:
/// `max(requested, EPSILON_FLOOR · camera distance)`.
pub fn gpu_epsilon(scene: &Scene, requested: f64) -> f64 {
    gpu_epsilon_for(scene, &scene.camera, requested)
}

/// [`gpu_epsilon`] for a view from `camera`.
pub fn gpu_epsilon_for(scene: &Scene, camera: &fray_core::Projector, requested: f64) -> f64 {
    requested.max(EPSILON_FLOOR * camera_distance(scene, camera))
}

/// A GPU backend: one device and its pipelines, reused across scenes and frames.
#[derive(Debug)]
pub struct GpuRenderer {
    ctx: GpuContext,
    cache: PipelineCache,
}

impl GpuRenderer {
    /// Opens the GPU (fails with [`GpuError::NoAdapter`] on a machine without one).
    pub fn new() -> Result<Self, GpuError> {
        Ok(Self {
            ctx: GpuContext::new()?,
            cache: PipelineCache::default(),
        })
    }

    /// A backend on an already open device (e.g. one whose adapter can present to a window).
    pub fn from_context(ctx: GpuContext) -> Self {
        Self {
            ctx,
            cache: PipelineCache::default(),
        }
    }

    /// The device context.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Uploads `scene` and builds (or fetches from the cache) the pipelines it needs: a scene
    /// that stays resident for any number of frames.
    pub fn upload<'a>(
        &'a self,
        scene: &Scene,
        settings: &GpuSettings,
    ) -> Result<GpuScene<'a>, GpuError> {
        // A copy is cheap: what a scene built (pyramids, meshes, cloud grids, sky tables) is
        // shared by `Arc`.
        GpuScene::new(self, Arc::new(scene.clone()), settings)
    }

    /// [`GpuRenderer::upload`] of a scene the caller shares: no copy.
    pub fn upload_shared<'a>(
        &'a self,
        scene: Arc<Scene>,
        settings: &GpuSettings,
    ) -> Result<GpuScene<'a>, GpuError> {
        GpuScene::new(self, scene, settings)
    }

    /// Renders `scene` as its camera sees it (one upload, one frame).
    pub fn render(&self, scene: &Scene, settings: &GpuSettings) -> Result<Frame, GpuError> {
        let start = Instant::now();
        let mut gpu_scene = self.upload(scene, settings)?;
        let mut frame = gpu_scene.render(&View::of_scene(scene, settings.samples))?;
        frame.stats.elapsed = start.elapsed();
        Ok(frame)
    }

    /// Renders rows `rows` (start, end excluded) of `scene` as its camera sees it: one upload,
    /// one tile of a frame ([`GpuScene::render_rows`]).
    pub fn render_rows(
        &self,
        scene: &Scene,
        settings: &GpuSettings,
        rows: (u32, u32),
    ) -> Result<Frame, GpuError> {
        let start = Instant::now();
        let mut gpu_scene = self.upload(scene, settings)?;
        let view = View::of_scene(scene, settings.samples);
        let mut frame = gpu_scene.render_rows(&view, rows)?;
        frame.stats.elapsed = start.elapsed();
        Ok(frame)
    }
}

/// What of `scene` this backend does not draw, if anything (`Auto` renders such a scene on the
/// CPU; `--backend gpu` refuses it before any upload). Nothing today: free forms, terrains,
/// meshes, media, Whitted's secondary rays and textures are drawn by both backends; the one
/// place a feature the GPU lacks would be named, which the CLI, `cargo xtask regress` and the GPU
/// tests consult.
pub fn unsupported_feature(scene: &Scene) -> Option<&'static str> {
    let _ = scene;
    None
}

/// Renders `scene` on a freshly opened GPU.
pub fn render(scene: &Scene, settings: &GpuSettings) -> Result<Frame, GpuError> {
    GpuRenderer::new()?.render(scene, settings)
}

/// The passes of a scene's frames: the rebase (when the camera moved) and the frame's band
/// passes in order (`passes::frame::frame_passes`), built once per resident scene.
#[derive(Debug)]
struct Passes {
    rebase: RebasePass,
    frame: Vec<Box<dyn Pass>>,
}

/// The frame's buffers that grow with the work list or the image: reallocated (never per
/// frame) when a frame needs more.
#[derive(Debug)]
struct FrameBuffers {
    params: wgpu::Buffer,
    counters: wgpu::Buffer,
    counters_readback: wgpu::Buffer,
    paths: wgpu::Buffer,
    /// Whitted's records of the rays in `paths` and the queue passes' indirect dispatch (empty
    /// without reflecting or transmitting materials).
    secondaries: wgpu::Buffer,
    queue_args: wgpu::Buffer,
    items: wgpu::Buffer,
    candidates: wgpu::Buffer,
    /// The scene's programs (head, copied on the GPU) and the frame's work-list words.
    indices: wgpu::Buffer,
}

impl FrameBuffers {
    /// The frame's buffers before its first view: its parameters and counters, and empty
    /// placeholders that the first frame sizes.
    fn new(ctx: &GpuContext) -> Result<Self, GpuError> {
        Ok(Self {
            params: bindings::empty(
                ctx,
                "frame params",
                std::mem::size_of::<FrameParams>() as u64,
                U::UNIFORM | U::COPY_DST,
            )?,
            counters: bindings::empty(
                ctx,
                "counters",
                (counters::WORDS * 4) as u64,
                U::STORAGE | U::COPY_SRC | U::COPY_DST,
            )?,
            counters_readback: readback_buffer(
                &ctx.device,
                "counters readback",
                (counters::WORDS * 4) as u64,
            ),
            paths: bindings::empty(ctx, "paths", 0, U::STORAGE)?,
            secondaries: bindings::empty(ctx, "secondary rays", 0, U::STORAGE)?,
            queue_args: bindings::empty(ctx, "queue dispatch", 16, U::STORAGE | U::INDIRECT)?,
            items: bindings::empty(ctx, "work items", 0, U::STORAGE | U::COPY_DST)?,
            candidates: bindings::empty(ctx, "candidates", 0, U::STORAGE | U::COPY_DST)?,
            indices: bindings::empty(ctx, "indices", 0, U::STORAGE | U::COPY_DST)?,
        })
    }
}

/// Refuses a composition the device cannot run: a solid whose per-invocation arrays pass the
/// private memory the backend allows, or a Whitted shade pass past the device's storage buffers.
fn check_device_fits(ctx: &GpuContext, options: &ModuleOptions) -> Result<(), GpuError> {
    let private = shader::private_bytes(&options.sizes);
    if private > shader::MAX_PRIVATE_BYTES {
        return Err(GpuError::TooLarge {
            what: "the private memory one GPU invocation needs for the largest solid, in bytes \
                   (it grows with the solid's leaves and perturbations)",
            needed: private,
            limit: shader::MAX_PRIVATE_BYTES,
        });
    }
    if options.has(Feature::Whitted) {
        // The shade pass binds the secondary rays' records besides the frame's, the free
        // forms' and the kinds' storage buffers.
        let needed: u32 = crate::passes::shade::SHADE
            .groups(options)
            .iter()
            .map(|(_, g)| g.storage_buffers())
            .sum();
        let limit = ctx.limits.max_storage_buffers_per_shader_stage;
        if needed > limit {
            return Err(GpuError::TooLarge {
                what: "storage buffers of the Whitted shade pass",
                needed: u64::from(needed),
                limit: u64::from(limit),
            });
        }
    }
    Ok(())
}

/// The frame's images on the GPU and their readback.
#[derive(Debug)]
struct Targets {
    width: u32,
    height: u32,
    colour_depth: wgpu::Texture,
    normals: wgpu::Texture,
    display: wgpu::Texture,
    readback: wgpu::Buffer,
}

/// The textures a frame left on the device ([`GpuScene::render_display`]), each `width ×
/// height` of the view.
#[derive(Clone, Copy, Debug)]
pub struct FrameTextures<'t> {
    /// Tone-mapped sRGB colour, `Rgba8Unorm` (the bytes a PNG of the frame holds, alpha 255).
    pub display: &'t wgpu::Texture,
    /// Linear colour and depth (`w`, negative for no hit), `Rgba32Float`.
    pub colour_depth: &'t wgpu::Texture,
    /// The unit normal and a hit flag (`w > 0.5`), `Rgba32Float`.
    pub normals: &'t wgpu::Texture,
}

/// What a frame's passes leave for its statistics.
struct PassRun {
    work: GpuWork,
    words: Vec<u32>,
    epsilon: f64,
    pass_times: PassTimes,
    timed: bool,
    encode_time: Duration,
    uploaded: u64,
}

/// The camera's offset from the anchor as the rebase pass takes it: its f32 high and low parts.
type CameraOffset = ([f32; 4], [f32; 4]);

/// A scene resident on the GPU: render it from any view; a frame from a moved camera re-runs the
/// quadtree and uploads only the camera, the media's parameters, the mesh instance blocks and the
/// work list — and, with a sky, its sky-view table when the eye's height changed ([`RenderStats::uploaded_bytes`],
/// [`RenderStats::scene_uploaded_bytes`], [`RenderStats::pipelines_built`] say so).
#[derive(Debug)]
pub struct GpuScene<'a> {
    renderer: &'a GpuRenderer,
    /// The scene, shared (not borrowed) so that a caller can hold a resident scene as long as
    /// it likes and swap it for another (the viewer's switches and animation).
    scene: Arc<Scene>,
    settings: GpuSettings,
    specialisation: Specialisation,
    resident: ResidentScene,
    passes: Passes,
    buffers: FrameBuffers,
    targets: Option<Targets>,
    timestamps: Option<Timestamps>,
    /// The camera offset the camera-relative copies hold (`None`: not yet rebased).
    rebased_for: Option<CameraOffset>,
    /// Scene bytes and pipeline builds not yet reported by a frame (the upload's).
    pending_scene_bytes: u64,
    pending_pipelines: (u32, Duration),
    /// Whitted's queue slots per camera ray of a band (grown when a frame's queue overflows).
    queue_slots: u32,
    /// The rows `(start, end)` the frame renders and reads back ([`GpuScene::render_rows`]);
    /// `None`: every row.
    rows: Option<(u32, u32)>,
}

impl<'a> GpuScene<'a> {
    fn new(
        renderer: &'a GpuRenderer,
        shared: Arc<Scene>,
        settings: &GpuSettings,
    ) -> Result<Self, GpuError> {
        let scene = &*shared;
        if !(settings.epsilon.is_finite() && settings.epsilon > 0.0) {
            return Err(GpuError::BadEpsilon(settings.epsilon));
        }
        // Refused before anything is uploaded, so `Auto` falls back to the CPU at once.
        if let Some(feature) = unsupported_feature(scene) {
            return Err(GpuError::Unsupported { feature });
        }
        let ctx = &renderer.ctx;
        let cache = &renderer.cache;
        let anchor = params::reference_point(&scene.camera);
        let resident = ResidentScene::upload(ctx, cache, scene, anchor, &scene.budget)?;
        let specialisation = Specialisation::for_scene(scene, settings.shadows);
        let options = ModuleOptions {
            sizes: shader::array_sizes(scene, &resident.flat),
            features: specialisation.features,
        };
        check_device_fits(ctx, &options)?;
        cache.take_built();
        let setup = PassSetup {
            cache,
            ctx,
            options: &options,
            specialisation: &specialisation,
        };
        let passes = Passes {
            rebase: RebasePass::new(cache, ctx)?,
            frame: crate::passes::frame::frame_passes(&setup)?,
        };
        let pending_pipelines = cache.take_built();
        let buffers = FrameBuffers::new(ctx)?;
        Ok(Self {
            renderer,
            scene: Arc::clone(&shared),
            settings: *settings,
            specialisation,
            pending_scene_bytes: resident.bytes,
            resident,
            passes,
            buffers,
            targets: None,
            timestamps: Timestamps::new(ctx),
            rebased_for: None,
            pending_pipelines,
            queue_slots: QUEUE_SLOTS_PER_RAY,
            rows: None,
        })
    }

    /// The device memory the resident scene's buffers and textures hold, each charged to the
    /// scene's budget before it was allocated.
    pub fn resident_device_bytes(&self) -> u64 {
        self.resident.device_bytes()
    }

    /// What the pipelines are specialised for.
    pub fn specialisation(&self) -> Specialisation {
        self.specialisation
    }

    /// Renders the resident scene as `view` shows it. A Whitted frame whose queue of secondary
    /// rays overflowed is rendered again with twice the queue per camera ray (in bands half as
    /// tall), so every frame returned traced every secondary ray it should. The queue never
    /// grows past the most secondary rays a camera ray can trace
    /// (`Settings::secondary_rays_per_camera_ray`: the budget, or the full tree of `max_depth`
    /// levels), which no band can overflow; where one row of tiles' rays and queue at that size
    /// cannot fit a band, the frame is refused (`band_rows`).
    pub fn render(&mut self, view: &View) -> Result<Frame, GpuError> {
        let start = Instant::now();
        let mut frame = self.growing_queue(|s| s.render_frame(view))?;
        frame.stats.elapsed = start.elapsed();
        Ok(frame)
    }

    /// Renders rows `(start, end)`, end excluded, of the frame `view` shows — a tile of a still,
    /// for many machines — and reads back only those: the frame is those rows, each pixel as in
    /// the whole frame (bands are cut at the same rows, which are multiples of the 8-pixel
    /// tiles). `start` must be a multiple of 8 and `end` one too or the image's height.
    pub fn render_rows(
        &mut self,
        view: &View,
        (start, end): (u32, u32),
    ) -> Result<Frame, GpuError> {
        let tile = TILE;
        if !(start < end
            && end <= view.height
            && start % tile == 0
            && (end % tile == 0 || end == view.height))
        {
            return Err(GpuError::BadRows {
                start,
                end,
                height: view.height,
                tile,
            });
        }
        self.rows = Some((start, end));
        let frame = self.render(view);
        self.rows = None;
        frame
    }

    /// Renders the resident scene as `view` shows it, as [`GpuScene::render`] does, but reads
    /// nothing back except the counters: the frame stays on the device, in the textures returned
    /// (the display texture is what a window presents). For a viewer's loop.
    pub fn render_display(
        &mut self,
        view: &View,
    ) -> Result<(RenderStats, FrameTextures<'_>), GpuError> {
        let start = Instant::now();
        let mut stats = self.growing_queue(|s| s.display_frame(view))?;
        stats.elapsed = start.elapsed();
        let textures = self.textures().ok_or(GpuError::EmptyImage(0, 0))?;
        Ok((stats, textures))
    }

    /// The last frame's textures on the device (`None` before the first frame).
    pub fn textures(&self) -> Option<FrameTextures<'_>> {
        self.targets.as_ref().map(|t| FrameTextures {
            display: &t.display,
            colour_depth: &t.colour_depth,
            normals: &t.normals,
        })
    }

    /// Runs `frame` (one try at a frame, returning it and how many secondary rays found the
    /// queue full) until no secondary ray overflowed, doubling the queue in between.
    fn growing_queue<T>(
        &mut self,
        mut frame: impl FnMut(&mut Self) -> Result<(T, u64), GpuError>,
    ) -> Result<T, GpuError> {
        let bound = self.scene.settings.secondary_rays_per_camera_ray();
        loop {
            let (result, overflows) = frame(self)?;
            if overflows == 0 {
                return Ok(result);
            }
            // Past one tile row per band the queue cannot grow within the band's bytes.
            let most = (BAND_BYTES / Self::bytes_per_ray(true, 1)) as u32;
            if self.queue_slots >= bound.min(most) {
                return Err(GpuError::TooLarge {
                    what: "Whitted queue slots per camera ray (secondary rays of one band)",
                    needed: u64::from(self.queue_slots) * 2,
                    limit: u64::from(bound.min(most)),
                });
            }
            self.queue_slots = (self.queue_slots * 2).min(bound);
        }
    }

    /// Device bytes per camera ray of a band: its path, and with Whitted (`whitted`) its record
    /// and `queue_slots` queue slots of both.
    fn bytes_per_ray(whitted: bool, queue_slots: u32) -> u64 {
        let path = std::mem::size_of::<GpuPath>() as u64;
        if whitted {
            (path + std::mem::size_of::<GpuSecondary>() as u64) * (1 + u64::from(queue_slots))
        } else {
            path
        }
    }

    /// One try at [`GpuScene::render`]: the frame and how many secondary rays found the queue
    /// full (0 without Whitted).
    fn render_frame(&mut self, view: &View) -> Result<(Frame, u64), GpuError> {
        let start = Instant::now();
        let _host_images = self.check_frame(view)?;
        let run = self.run_passes(view, start)?;
        let (colour, depth, normals) =
            self.read_frame(self.scene.background, self.specialisation.media())?;
        let (stats, overflows) = self.finish_frame(view, run, start)?;
        Ok((
            Frame {
                colour,
                depth,
                normals,
                stats,
            },
            overflows,
        ))
    }

    /// One try at [`GpuScene::render_display`]: the frame's statistics and its queue overflows.
    fn display_frame(&mut self, view: &View) -> Result<(RenderStats, u64), GpuError> {
        let start = Instant::now();
        let _host_images = self.check_frame(view)?;
        let run = self.run_passes(view, start)?;
        self.finish_frame(view, run, start)
    }

    /// A frame's passes, up to its counters read back: the work list, the view's uploads, the
    /// rebase and the bands.
    fn run_passes(&mut self, view: &View, start: Instant) -> Result<PassRun, GpuError> {
        let shared = Arc::clone(&self.scene);
        let scene = &*shared;
        let epsilon = gpu_epsilon_for(scene, &view.camera, self.settings.epsilon);
        let work = self.work_list(view)?;
        self.upload_work(&work)?;
        let mut uploaded = work.bytes();
        self.ensure_targets(view.width, view.height)?;
        let band_rows = self.band_rows(view)?;
        let band_rays =
            u64::from(view.width) * u64::from(band_rows) * u64::from(view.rays_per_pixel());
        self.ensure_paths(band_rays)?;
        let mut params = params::frame_params(
            scene,
            view,
            self.resident.anchor,
            epsilon,
            SHADOW_OFFSET_EPSILONS * epsilon,
        );
        params.programs_base = work.programs_base;
        params.max_depth = scene.settings.max_depth;
        params.min_contribution = scene.settings.min_contribution as f32;
        params.queue_capacity = (band_rays * u64::from(self.queue_slots)) as u32;
        params.max_secondary_rays = scene.settings.max_secondary_rays;
        uploaded += self.write_view(view)?;
        let clock = PassClock::of(&self.renderer.ctx, self.timestamps.as_ref());
        let mut pass_times = PassTimes::default();
        let (rebase_bytes, rebased_for) = self.rebase_to(&params, clock, &mut pass_times)?;
        uploaded += rebase_bytes;
        uploaded +=
            self.encode_bands(view, &work, &mut params, band_rows, clock, &mut pass_times)?;
        self.copy_counters();
        let timed = clock.times();
        self.rebased_for = rebased_for;
        // The host's part of the frame: up to its last submission, less the waits for timings.
        let encode_time = start.elapsed().saturating_sub(pass_times.waited());
        let ctx = &self.renderer.ctx;
        let words: Vec<u32> = read_back(
            &ctx.device,
            &self.buffers.counters_readback,
            (counters::WORDS * 4) as u64,
            "counters",
        )?;
        Ok(PassRun {
            work,
            words,
            epsilon,
            pass_times,
            timed,
            encode_time,
            uploaded,
        })
    }

    /// A frame's statistics from its run, once its images are read (or left on the device),
    /// and its queue overflows; fails with an error no scope caught.
    fn finish_frame(
        &mut self,
        view: &View,
        run: PassRun,
        start: Instant,
    ) -> Result<(RenderStats, u64), GpuError> {
        let PassRun {
            work,
            words,
            epsilon,
            pass_times,
            timed,
            encode_time,
            uploaded,
        } = run;
        let ctx = &self.renderer.ctx;
        // An error no scope caught (or a lost device) would otherwise go unnoticed: fail with it.
        if let Some(reason) = ctx.take_uncaptured_error() {
            return Err(if reason.starts_with("device lost") {
                GpuError::DeviceLost(reason)
            } else {
                GpuError::Dispatch {
                    pass: "frame",
                    reason,
                }
            });
        }
        let mut stats = self.frame_stats(view, &work, &words, epsilon);
        stats.elapsed = start.elapsed();
        stats.kernel_time = timed.then(|| pass_times.total());
        stats.pass_times = pass_times.into_stats();
        stats.encode_time = encode_time;
        stats.uploaded_bytes += uploaded;
        let overflows = Counter::QueueOverflows.read(&words);
        Ok((stats, overflows))
    }

    /// Refuses a frame this backend cannot make — an empty image, host images past the memory
    /// budget, a side past the device's 2D texture limit —; returns the host images' charge.
    fn check_frame(&self, view: &View) -> Result<fray_core::Reservation, GpuError> {
        let (width, height) = (view.width, view.height);
        if width == 0 || height == 0 {
            return Err(GpuError::EmptyImage(width, height));
        }
        let pixels = u64::from(width) * u64::from(height);
        let host_images = self
            .scene
            .budget
            .reserve_elements(
                format!("the GPU frame's readback and images ({width} × {height} pixels, {HOST_BYTES_PER_PIXEL} bytes each)"),
                pixels,
                HOST_BYTES_PER_PIXEL,
            )
            .map_err(GpuError::Budget)?;
        let max_side = self.renderer.ctx.limits.max_texture_dimension_2d;
        if width.max(height) > max_side {
            return Err(GpuError::TooLarge {
                what: "the image's longer side, in pixels (the device's 2D texture limit)",
                needed: u64::from(width.max(height)),
                limit: u64::from(max_side),
            });
        }
        Ok(host_images)
    }

    /// The work list of `view` (with culling, the quadtree over its camera).
    fn work_list(&self, view: &View) -> Result<GpuWork, GpuError> {
        let shared = Arc::clone(&self.scene);
        let scene = &*shared;
        let size = (view.width, view.height);
        if self.settings.culling {
            let config = quadtree_config(view.samples.count(), scene.budget.clone());
            GpuWork::culled(
                scene,
                (&view.camera, size.0, size.1),
                &self.resident.flat,
                &config,
            )
            .map_err(|e| GpuError::WorkList(e.to_string()))
        } else {
            Ok(GpuWork::everything(scene, &self.resident.flat, size))
        }
    }

    /// This view's data of each medium and kind (the media's blocks, the mesh instances, the
    /// terrain levels) and the texture mappings (queue writes, before the frame's first
    /// submission); returns the bytes written.
    fn write_view(&mut self, view: &View) -> Result<u64, GpuError> {
        let ctx = &self.renderer.ctx;
        let mut uploaded = 0;
        for (_, medium) in &mut self.resident.media {
            uploaded += medium.write_view(ctx, &self.scene, view);
        }
        let reference = params::reference_point(&view.camera);
        for (_, resident) in &mut self.resident.kinds {
            uploaded += resident.write_view(ctx, &self.scene, view)?;
        }
        if let Some(t) = &mut self.resident.textures {
            // The mapping blocks and the ramps' reference height for this camera, from f64.
            uploaded += t.move_to(ctx, reference);
        }
        Ok(uploaded)
    }

    /// The resident scene rebased to this camera if it moved, and the counters zeroed, in one
    /// submission; returns the bytes the rebase wrote and the camera offset it is now at.
    fn rebase_to(
        &self,
        params: &FrameParams,
        clock: PassClock<'_>,
        pass_times: &mut PassTimes,
    ) -> Result<(u64, Option<CameraOffset>), GpuError> {
        let ctx = &self.renderer.ctx;
        let mut encoder = TimedEncoder::new(ctx, clock);
        let offset = (params.camera_hi, params.camera_lo);
        let mut uploaded = 0;
        if self.rebased_for != Some(offset) {
            uploaded += self.passes.rebase.encode(
                ctx,
                &mut encoder.pass("rebase")?,
                &self.resident.rebased(),
                params.camera_hi,
                params.camera_lo,
            );
            self.resident.copy_tables(encoder.encoder());
        }
        ctx.queue
            .write_buffer(&self.buffers.counters, 0, &[0u8; counters::WORDS * 4]);
        encoder.submit(pass_times)?;
        Ok((uploaded, Some(offset)))
    }

    /// Encodes and submits the frame's bands of `band_rows` rows, each with its parameters;
    /// returns the bytes written.
    fn encode_bands(
        &self,
        view: &View,
        work: &GpuWork,
        params: &mut FrameParams,
        band_rows: u32,
        clock: PassClock<'_>,
        pass_times: &mut PassTimes,
    ) -> Result<u64, GpuError> {
        let ctx = &self.renderer.ctx;
        let groups = self.bind_groups()?;
        let width = view.width;
        let (row0, row1) = self.rows.unwrap_or((0, view.height));
        let mut uploaded = 0;
        for y0 in (row0..row1).step_by(band_rows as usize) {
            let rows = band_rows.min(row1 - y0);
            let items = work.band(y0, y0 + rows);
            params.band_y0 = y0;
            params.band_rows = rows;
            params.items = items.len() as u32;
            params.first_item = work.items.partition_point(|it| it.y0 < y0) as u32;
            ctx.queue
                .write_buffer(&self.buffers.params, 0, bytemuck::bytes_of(params));
            uploaded += std::mem::size_of::<FrameParams>() as u64;
            if self.specialisation.has(Feature::Whitted) {
                // An empty queue at level 0 for this band.
                let at = (counters::QUEUE_TOP * 4) as u64;
                ctx.queue.write_buffer(
                    &self.buffers.counters,
                    at,
                    &[0u8; counters::QUEUE_WORDS * 4],
                );
            }
            let mut band = TimedEncoder::new(ctx, clock);
            let rays = width * rows * view.rays_per_pixel();
            self.encode_band(&mut band, &groups, (width, rows, rays), items.len() as u32)?;
            band.submit(pass_times)?;
        }
        Ok(uploaded)
    }

    /// Copies the counters to their readback buffer (a submission of its own, after the bands).
    fn copy_counters(&self) {
        let ctx = &self.renderer.ctx;
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("counters"),
            });
        encoder.copy_buffer_to_buffer(
            &self.buffers.counters,
            0,
            &self.buffers.counters_readback,
            0,
            (counters::WORDS * 4) as u64,
        );
        ctx.queue.submit([encoder.finish()]);
    }

    /// The frame's statistics from its counters (`words`) and work list; what the passes timed
    /// and the frame uploaded the caller adds.
    fn frame_stats(
        &mut self,
        view: &View,
        work: &GpuWork,
        words: &[u32],
        epsilon: f64,
    ) -> RenderStats {
        let ctx = &self.renderer.ctx;
        let shared = Arc::clone(&self.scene);
        let scene = &*shared;
        let (pipelines_built, pipeline_build_time) = {
            let (n, t) = std::mem::take(&mut self.pending_pipelines);
            let (m, u) = self.renderer.cache.take_built();
            (n + m, t + u)
        };
        let scene_uploaded = std::mem::take(&mut self.pending_scene_bytes);
        let mut passes = vec![format!(
            "pipelines [{}]: {pipelines_built} built ({:.1} ms)",
            self.specialisation.describe(),
            pipeline_build_time.as_secs_f64() * 1e3
        )];
        if ctx.software && pipelines_built > 0 {
            // Lavapipe compiles a pipeline's shader at its first dispatch, inside the passes.
            passes.push(
                "pass times may include the software adapter's shader compile (pipelines new to this process)"
                    .to_owned(),
            );
        }
        if work.stats.is_some() {
            passes.push("quadtree".to_owned());
        }
        passes.push("primary".to_owned());
        if view.samples.count() > 1 {
            passes.push(format!("{} samples per pixel", view.samples.count()));
        }
        passes.extend(scene.features.names().iter().map(|s| s.to_string()));
        if !self.specialisation.shadows {
            passes.retain(|p| p != "shadows");
        }
        if self.specialisation.has(Feature::Whitted) {
            passes.push(format!(
                "whitted queue: {} slots per camera ray",
                self.queue_slots
            ));
        }
        let (row0, row1) = self.rows.unwrap_or((0, view.height));
        let pixels = u64::from(view.width) * u64::from(row1 - row0);
        let mut stats = RenderStats {
            backend: format!("gpu ({}, {})", ctx.adapter_name, ctx.backend),
            threads: 1,
            primary_rays: pixels * u64::from(view.rays_per_pixel()),
            shadow_rays: Counter::ShadowRays.read(words),
            hits: Counter::Hits.read(words),
            epsilon,
            passes,
            secondary_rays: Counter::SecondaryRays.read(words),
            uploaded_bytes: scene_uploaded,
            scene_uploaded_bytes: scene_uploaded,
            pipelines_built,
            pipeline_build_time,
            ..RenderStats::default()
        };
        // Each kind's and medium's own counters (zero where the scene lacks it).
        for kind in crate::kinds::KINDS {
            kind.read_stats(words, &mut stats);
        }
        for medium in crate::media::MEDIA {
            medium.read_stats(words, &mut stats);
        }
        if let Some(w) = work.stats {
            stats.cells_visited = w.cells_visited;
            stats.cells_culled = w.cells_culled;
            stats.work_items = w.items;
        }
        stats
    }

    /// Encodes one band's passes (`width × rows` pixels, `rays` camera rays, `items` work
    /// items), each its own (timed) compute pass, in the frame's order.
    fn encode_band(
        &self,
        encoder: &mut TimedEncoder<'_>,
        groups: &Groups,
        (width, rows, rays): (u32, u32, u32),
        items: u32,
    ) -> Result<(), GpuError> {
        let band = Band {
            ctx: &self.renderer.ctx,
            groups,
            width,
            rows,
            rays,
            items,
            queue_args: &self.buffers.queue_args,
            max_depth: self.scene.settings.max_depth,
        };
        for pass in &self.passes.frame {
            pass.encode(&mut encoder.pass(pass.label())?, &band)?;
        }
        Ok(())
    }

    /// Rows per band for `view`: a multiple of the tile side (every item lies in one band) whose
    /// rays in flight fit the device's storage binding and [`BAND_BYTES`].
    fn band_rows(&self, view: &View) -> Result<u32, GpuError> {
        let limits = &self.renderer.ctx.limits;
        let limit = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size)
            .min(BAND_BYTES);
        let per_row =
            Self::bytes_per_ray(self.specialisation.has(Feature::Whitted), self.queue_slots)
                * u64::from(view.width)
                * u64::from(view.rays_per_pixel());
        let tile = u64::from(TILE);
        if per_row * tile > limit {
            return Err(GpuError::TooLarge {
                what: if self.specialisation.has(Feature::Whitted) {
                    "the rays in flight for one row of 8-pixel tiles, in bytes: each camera ray \
                     with its queue of secondary rays (at most settings.max_secondary_rays; a \
                     smaller budget, depth, width or sample count needs less)"
                } else {
                    "the rays in flight for one row of 8-pixel tiles, in bytes (image width × \
                     rays per pixel × bytes per ray; many anti-aliasing samples make it large)"
                },
                needed: per_row * tile,
                limit,
            });
        }
        let rows = (limit / per_row / tile).max(1) * tile;
        Ok(rows.min(u64::from(view.height).next_multiple_of(tile)) as u32)
    }

    /// Room for `rays` camera rays in flight, and with Whitted their records and queue.
    fn ensure_paths(&mut self, rays: u64) -> Result<(), GpuError> {
        let slots = if self.specialisation.has(Feature::Whitted) {
            rays * (1 + u64::from(self.queue_slots))
        } else {
            rays
        };
        let bytes = slots * std::mem::size_of::<GpuPath>() as u64;
        if self.buffers.paths.size() < bytes {
            self.buffers.paths = bindings::empty(&self.renderer.ctx, "paths", bytes, U::STORAGE)?;
        }
        if self.specialisation.has(Feature::Whitted) {
            let bytes = slots * std::mem::size_of::<GpuSecondary>() as u64;
            if self.buffers.secondaries.size() < bytes {
                self.buffers.secondaries =
                    bindings::empty(&self.renderer.ctx, "secondary rays", bytes, U::STORAGE)?;
            }
        }
        Ok(())
    }

    /// Uploads the frame's work list, growing its buffers (and copying the scene's programs to
    /// the head of a new `indices` on the GPU) where it does not fit.
    fn upload_work(&mut self, work: &GpuWork) -> Result<(), GpuError> {
        let ctx = &self.renderer.ctx;
        let grow = |buffer: &mut wgpu::Buffer, label: &'static str, bytes: u64| {
            if buffer.size() < bytes {
                *buffer = bindings::empty(
                    ctx,
                    label,
                    bytes.next_power_of_two(),
                    U::STORAGE | U::COPY_DST,
                )?;
                Ok::<bool, GpuError>(true)
            } else {
                Ok(false)
            }
        };
        let items = bytemuck::cast_slice(&work.items);
        let candidates = bytemuck::cast_slice(&work.candidates);
        grow(&mut self.buffers.items, "work items", items.len() as u64)?;
        grow(
            &mut self.buffers.candidates,
            "candidates",
            candidates.len() as u64,
        )?;
        let head_words = self.resident.flat.program.len() as u64 * 4;
        let indices_bytes = head_words + 4 * work.indices.len() as u64;
        let fresh = grow(&mut self.buffers.indices, "indices", indices_bytes)?;
        if fresh || self.rebased_for.is_none() {
            let mut encoder = ctx
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("programs"),
                });
            if head_words > 0 {
                encoder.copy_buffer_to_buffer(
                    &self.resident.programs,
                    0,
                    &self.buffers.indices,
                    0,
                    head_words,
                );
            }
            ctx.queue.submit([encoder.finish()]);
        }
        if !items.is_empty() {
            ctx.queue.write_buffer(&self.buffers.items, 0, items);
        }
        if !candidates.is_empty() {
            ctx.queue
                .write_buffer(&self.buffers.candidates, 0, candidates);
        }
        if !work.indices.is_empty() {
            ctx.queue.write_buffer(
                &self.buffers.indices,
                head_words,
                bytemuck::cast_slice(&work.indices),
            );
        }
        Ok(())
    }

    /// The frame's textures (and their readback) for a `width × height` image.
    fn ensure_targets(&mut self, width: u32, height: u32) -> Result<(), GpuError> {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| (t.width, t.height) == (width, height))
        {
            return Ok(());
        }
        let device = &self.renderer.ctx.device;
        let texture = |label, format| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let row = padded_row(width, 16);
        let rows = (READBACK_BYTES / row).clamp(1, u64::from(height));
        let readback = readback_buffer(device, "frame readback", row * rows);
        self.targets = Some(Targets {
            width,
            height,
            colour_depth: texture("colour + depth", wgpu::TextureFormat::Rgba32Float),
            normals: texture("normals", wgpu::TextureFormat::Rgba32Float),
            display: texture("display", wgpu::TextureFormat::Rgba8Unorm),
            readback,
        });
        Ok(())
    }

    /// The bind groups every band shares.
    fn bind_groups(&self) -> Result<Groups, GpuError> {
        let ctx = &self.renderer.ctx;
        let cache = &self.renderer.cache;
        let (b, r) = (&self.buffers, &self.resident);
        let bind = |group: &bindings::Group, resources: &[wgpu::BindingResource<'_>]| {
            group.bind(&ctx.device, &cache.layout(ctx, group), resources)
        };
        let frame = bind(
            &FRAME,
            &[
                b.params.as_entire_binding(),
                b.paths.as_entire_binding(),
                b.counters.as_entire_binding(),
            ],
        );
        let free_forms = bind(
            &FREE_FORMS,
            &[
                r.solids.target.as_entire_binding(),
                r.leaves.target.as_entire_binding(),
                r.perturbations.target.as_entire_binding(),
                b.indices.as_entire_binding(),
            ],
        );
        // The groups made of parts — lights and media, the kinds' — from what the resident scene
        // has, in the order `bindings` composes them for the modules.
        let whitted = self.specialisation.has(Feature::Whitted);
        let views = r.part_views();
        let bind_parts = |parts: &[Part]| {
            let resources: Vec<wgpu::BindingResource<'_>> = parts
                .iter()
                .flat_map(|&part| r.part_resources(part, &views, &b.secondaries))
                .collect();
            bind(&bindings::group_of(parts), &resources)
        };
        let features = self.specialisation.features;
        let shading = bind_parts(&bindings::shading_parts(features));
        // Each kind's own group (its intersection pass's), and the shade pass's fourth: the
        // kinds' and the textures' parts in one.
        let kinds = PrimitiveKind::ALL
            .into_iter()
            .filter(|k| features.has_kind(*k))
            .filter_map(|k| Some((k, bind_parts(&[Part::of_kind(k)?]))))
            .collect();
        let surface_parts = bindings::surface_parts(features);
        let surfaces = (!surface_parts.is_empty()).then(|| bind_parts(&surface_parts));
        let work = bind(
            &WORK,
            &[
                b.items.as_entire_binding(),
                b.candidates.as_entire_binding(),
            ],
        );
        let t = self.targets.as_ref().ok_or(GpuError::EmptyImage(0, 0))?;
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let (c, n, d) = (view(&t.colour_depth), view(&t.normals), view(&t.display));
        let targets = bind(
            &TARGETS,
            &[
                wgpu::BindingResource::TextureView(&c),
                wgpu::BindingResource::TextureView(&n),
                wgpu::BindingResource::TextureView(&d),
            ],
        );
        let queue = whitted.then(|| bind(&QUEUE, &[b.queue_args.as_entire_binding()]));
        Ok(Groups {
            frame,
            free_forms,
            work,
            shading,
            queue,
            kinds,
            surfaces,
            targets,
        })
    }

    /// Reads the frame's colour + depth and normal textures back into images (misses: depth
    /// `+∞`, normal 0, and the background — or, where the media pass ran (`media`), the
    /// texture's colour: the background through the media).
    fn read_frame(&self, background: fray_core::Rgb, media: bool) -> Result<FrameImages, GpuError> {
        let t = self.targets.as_ref().ok_or(GpuError::EmptyImage(0, 0))?;
        let (row0, row1) = self.rows.unwrap_or((0, t.height));
        let (w, h) = (t.width, row1 - row0);
        let n = w as usize * h as usize;
        let mut colour = Vec::with_capacity(n);
        let mut depth = Vec::with_capacity(n);
        let mut normals = Vec::with_capacity(n);
        let mut normal_rows: Vec<[f32; 4]> = Vec::with_capacity(n);
        for (texture, into_colour) in [(&t.colour_depth, true), (&t.normals, false)] {
            self.read_texture(
                texture,
                w,
                (row0, row1),
                16,
                &t.readback,
                |row: &[[f32; 4]]| {
                    if into_colour {
                        for &[r, g, b, d] in row {
                            let hit = d >= 0.0;
                            colour.push(if hit || media {
                                Vec3::new(r, g, b)
                            } else {
                                background
                            });
                            depth.push(if hit { f64::from(d) } else { f64::INFINITY });
                        }
                    } else {
                        normal_rows.extend_from_slice(row);
                    }
                },
            )?;
        }
        for [x, y, z, hit] in normal_rows {
            normals.push(if hit > 0.5 {
                Vec3::new(x, y, z)
            } else {
                Vec3::ZERO
            });
        }
        let missing = || GpuError::EmptyImage(w, h);
        Ok((
            Image::from_pixels(w, h, colour).ok_or_else(missing)?,
            Image::from_pixels(w, h, depth).ok_or_else(missing)?,
            Image::from_pixels(w, h, normals).ok_or_else(missing)?,
        ))
    }

    /// A check of the rebase pass against its CPU twin: every resident array and its
    /// camera-relative copy read back, the copy compared bit for bit with
    /// [`crate::passes::rebase::rebase_words`] of the array for the offset of the last frame.
    /// Returns how many 16-byte slots were compared, or which differed.
    pub fn check_rebase_against_cpu(&self) -> Result<usize, GpuError> {
        let ctx = &self.renderer.ctx;
        let Some((hi, lo)) = self.rebased_for else {
            return Ok(0);
        };
        let mut compared = 0;
        for array in self.resident.rebased() {
            let read = |buffer: &wgpu::Buffer| -> Result<Vec<[u32; 4]>, GpuError> {
                let staging = readback_buffer(&ctx.device, "rebase check", buffer.size());
                let mut encoder = ctx
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
                encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
                ctx.queue.submit([encoder.finish()]);
                read_back(&ctx.device, &staging, buffer.size(), "rebase check")
            };
            let (source, target) = (read(&array.source)?, read(&array.target)?);
            let twin = crate::passes::rebase::rebase_words(&source, &array.layout, hi, lo);
            if let Some(k) = (0..twin.len()).find(|&k| twin[k] != target[k]) {
                return Err(GpuError::Dispatch {
                    pass: "rebase",
                    reason: format!(
                        "slot {k}: the GPU wrote {:?}, the CPU twin {:?}",
                        target[k], twin[k]
                    ),
                });
            }
            compared += twin.len();
        }
        Ok(compared)
    }

    /// The last frame's display image (tone-mapped sRGB, made on the GPU), as 8-bit RGB.
    pub fn display_image(&self) -> Result<Image<[u8; 3]>, GpuError> {
        let t = self.targets.as_ref().ok_or(GpuError::EmptyImage(0, 0))?;
        let (w, h) = (t.width, t.height);
        let mut pixels = Vec::with_capacity(w as usize * h as usize);
        self.read_texture(
            &t.display,
            w,
            (0, h),
            4,
            &t.readback,
            |row: &[[u8; 4]]| {
                pixels.extend(row.iter().map(|p| [p[0], p[1], p[2]]));
            },
        )?;
        Image::from_pixels(w, h, pixels).ok_or(GpuError::EmptyImage(w, h))
    }

    /// Copies rows `row0..row1` of `texture` (`texel` bytes per pixel) to `readback` a band of
    /// rows at a time and hands each row to `row` (unpadded).
    fn read_texture<T: bytemuck::Pod>(
        &self,
        texture: &wgpu::Texture,
        width: u32,
        (row0, row1): (u32, u32),
        texel: u64,
        readback: &wgpu::Buffer,
        mut row: impl FnMut(&[T]),
    ) -> Result<(), GpuError> {
        let ctx = &self.renderer.ctx;
        let stride = padded_row(width, texel);
        let rows_per_copy = (readback.size() / stride).clamp(1, u64::from(row1 - row0)) as u32;
        for y0 in (row0..row1).step_by(rows_per_copy as usize) {
            let rows = rows_per_copy.min(row1 - y0);
            let mut encoder = ctx
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("readback"),
                });
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: y0, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(stride as u32),
                        rows_per_image: Some(rows),
                    },
                },
                wgpu::Extent3d {
                    width,
                    height: rows,
                    depth_or_array_layers: 1,
                },
            );
            ctx.queue.submit([encoder.finish()]);
            let bytes = stride * u64::from(rows);
            map_read(&ctx.device, readback, bytes, "readback", |data| {
                for r in 0..rows as usize {
                    let start = r * stride as usize;
                    let line = &data[start..start + (u64::from(width) * texel) as usize];
                    match bytemuck::try_cast_slice::<u8, T>(line) {
                        Ok(texels) => row(texels),
                        Err(_) => row(&bytemuck::pod_collect_to_vec::<u8, T>(line)),
                    }
                }
            })?;
        }
        Ok(())
    }
}

/// A frame's colour, depth and normal images.
type FrameImages = (Image<fray_core::Rgb>, Image<f64>, Image<Vec3>);

/// The bind groups of one frame.
struct Groups {
    frame: wgpu::BindGroup,
    free_forms: wgpu::BindGroup,
    work: wgpu::BindGroup,
    shading: wgpu::BindGroup,
    /// Whitted's queue passes' (with reflecting or transmitting materials).
    queue: Option<wgpu::BindGroup>,
    /// Each kind's own group (its part: `Part::of_kind`), for the kinds the scene has.
    kinds: Vec<(PrimitiveKind, wgpu::BindGroup)>,
    /// The shade pass's fourth (with terrains, meshes or textures: `bindings::surfaces`).
    surfaces: Option<wgpu::BindGroup>,
    targets: wgpu::BindGroup,
}

impl BindGroups for Groups {
    fn group(&self, role: Role) -> Option<&wgpu::BindGroup> {
        match role {
            Role::Frame => Some(&self.frame),
            Role::FreeForms => Some(&self.free_forms),
            Role::Work => Some(&self.work),
            Role::Shading => Some(&self.shading),
            Role::Surfaces => self.surfaces.as_ref(),
            Role::Kind(kind) => self.kinds.iter().find(|(k, _)| *k == kind).map(|(_, g)| g),
            Role::Queue => self.queue.as_ref(),
            Role::Targets => Some(&self.targets),
        }
    }
}

/// Bytes per row of a texture copy: `width × texel`, padded to wgpu's 256-byte alignment.
fn padded_row(width: u32, texel: u64) -> u64 {
    (u64::from(width) * texel).next_multiple_of(u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_of_texture_copies_are_aligned() {
        assert_eq!(padded_row(96, 16), 1536);
        assert_eq!(padded_row(100, 16), 1792);
        assert_eq!(padded_row(1, 4), 256);
    }
}
