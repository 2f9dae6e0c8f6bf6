//! The window and its loop (winit): the surface, the backend in use (GPU or progressive CPU),
//! input, the overlay and the frames shown.

use crate::camera::FlyCamera;
use crate::gpu_path::GpuPath;
use crate::input::{Held, SPEED_PER_NOTCH, TURN_PER_PIXEL};
use crate::overlay::{self, Controls, Look, Offers, Readout};
use crate::present::{DebugView, Presenter};
use crate::probe_view;
use crate::progressive::{Job, Level, Progression};
use crate::save::{SaveSettings, save, save_path};
use crate::worker::{Request, Worker};
use crate::{ViewBackend, ViewError, ViewOptions, cameras};
use fray_core::{Frame, PixelSamples, Projector, RenderStats};
use fray_gpu::{GpuContext, GpuRenderer, GpuSettings, View};
use fray_render::output::{PngOptions, srgb8};
use fray_render::{Backend, RenderOptions};
use fray_scene::{Scene, Switches};
use glam::DVec3;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::keyboard::{KeyCode, ModifiersState, PhysicalKey};
use winit::window::{Window, WindowId};

/// The shortest time between two redraws of a moving camera (60 per second): redrawing faster
/// would only spin the UI thread (on the CPU backend, against the worker's threads). The GPU
/// under `--turntable` redraws without it, to measure its frame rate.
const TICK: Duration = Duration::from_micros(16_667);

/// The samples per pixel a still CPU frame is refined to when neither `--samples` nor the scene
/// asks for more.
const STILL_SAMPLES: u32 = 4;

/// The worker's message to the loop: a CPU frame is ready.
#[derive(Clone, Copy, Debug)]
pub struct Wake;

/// Opens the window and runs until it is closed (or a test hook ends it).
pub fn run(options: ViewOptions) -> Result<(), ViewError> {
    let started = Instant::now();
    let event_loop = EventLoop::<Wake>::with_user_event()
        .build()
        .map_err(|e| ViewError::Window(e.to_string()))?;
    let mut app = App {
        proxy: event_loop.create_proxy(),
        options: Some(options),
        state: None,
        error: None,
        started,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| ViewError::Window(e.to_string()))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

struct App {
    proxy: EventLoopProxy<Wake>,
    /// Taken when the window opens.
    options: Option<ViewOptions>,
    state: Option<State>,
    error: Option<ViewError>,
    started: Instant,
}

/// What a frame depends on: the projector, the controls that change it, the size, the scene.
type FrameKey = (Projector, (bool, bool, u32), (u32, u32), u64);

/// Which backend renders, and its state.
enum Path {
    Gpu(Box<GpuPath>),
    Cpu(Box<CpuPath>),
}

/// The progressive CPU backend: its worker, the progression and the last frame shown.
struct CpuPath {
    worker: Worker,
    progression: Progression,
    /// The last frame shown and its level (depth picking, debug views).
    last: Option<(Frame, Level)>,
}

/// Frames shown and when, for frames per second and the test hooks.
#[derive(Default)]
struct Counts {
    shown: u64,
    first: Option<Duration>,
    /// The time the counting window started and the frames shown in it.
    window: Option<(Instant, u64)>,
    frames_per_second: f64,
    /// The view generation a "still frame" line was printed for.
    still_printed: Option<u64>,
    saves: u32,
    /// Render time per level (CPU) or of GPU frames: (sum, count).
    times: Vec<(String, Duration, u32)>,
}

struct State {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: &'static GpuRenderer,
    /// The scene as loaded (with its animation).
    base: Arc<Scene>,
    /// What the backends render: `base` at `scene_for`'s time, with its parts switched.
    scene: Arc<Scene>,
    scene_for: (f64, Switches),
    /// Counts the scenes made from `base` (a frame of another scene renders again).
    scene_generation: u64,
    offers: Offers,
    options: ViewOptions,
    presenter: Presenter,
    egui: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    path: Path,
    backend_name: String,
    camera: FlyCamera,
    /// What the frame last rendered depends on: projector, controls, size, scene (a change
    /// renders again).
    rendered: Option<FrameKey>,
    /// What the probed view last shown was made for (`None`: none is shown).
    probed: Option<(FrameKey, Look)>,
    /// A GPU frame must be copied again (the debug view changed).
    recopy: bool,
    speed: f64,
    held: Held,
    modifiers: ModifiersState,
    cursor: Option<(f64, f64)>,
    controls: Controls,
    overlay: bool,
    readout: Readout,
    counts: Counts,
    last_tick: Instant,
    /// When a moving camera's next redraw is due.
    next_tick: Option<Instant>,
    generation: u64,
}

impl ApplicationHandler<Wake> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(options) = self.options.take() else {
            return;
        };
        match State::open(event_loop, options, self.proxy.clone(), self.started) {
            Ok(state) => {
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, _event: Wake) {
        if let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }

    /// A moving camera ticks at most every [`TICK`]: the loop sleeps until then.
    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(state) = &mut self.state else {
            return;
        };
        match state.next_tick {
            Some(at) if Instant::now() >= at => {
                state.next_tick = None;
                state.window.request_redraw();
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(at) => event_loop.set_control_flow(ControlFlow::WaitUntil(at)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(state) = &mut self.state else {
            return;
        };
        match state.event(event, self.started) {
            Ok(true) => {}
            Ok(false) => event_loop.exit(),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }
}

/// The format the blit writes raw bytes to: a non-sRGB 8-bit one where the surface offers it
/// (the window then holds the frame's PNG bytes exactly), else the surface's first.
fn surface_format(caps: &wgpu::SurfaceCapabilities) -> Option<wgpu::TextureFormat> {
    [
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureFormat::Rgba8Unorm,
    ]
    .into_iter()
    .find(|f| caps.formats.contains(f))
    .or_else(|| caps.formats.first().copied())
}

impl State {
    fn open(
        event_loop: &ActiveEventLoop,
        options: ViewOptions,
        proxy: EventLoopProxy<Wake>,
        started: Instant,
    ) -> Result<Self, ViewError> {
        // The scene at time 0 of its animation, everything on.
        let base = Arc::new(options.scene.clone());
        let scene = Arc::new(base.at_time(0.0)?);
        let offers = offers(&base);
        let (width, height) = options.size.unwrap_or((scene.width, scene.height));
        let attributes = Window::default_attributes()
            .with_title(format!("fray view — {}", options.name))
            .with_inner_size(PhysicalSize::new(width.max(1), height.max(1)));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| ViewError::Window(e.to_string()))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(Arc::clone(&window))
            .map_err(|e| ViewError::Window(e.to_string()))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| ViewError::NoAdapter(e.to_string()))?;
        // The GPU backend's own device, opened on the adapter that presents: one device draws
        // and presents, so a frame never leaves it. The resident `GpuScene` borrows the renderer
        // for as long as it lives, and the loop keeps it for the process's life: the renderer is
        // leaked once, here, so the window's state needs no self-reference.
        let ctx = GpuContext::from_adapter(&adapter)?;
        let software = ctx.software;
        let renderer: &'static GpuRenderer = Box::leak(Box::new(GpuRenderer::from_context(ctx)));
        let device = &renderer.context().device;
        let caps = surface.get_capabilities(&adapter);
        let format = surface_format(&caps)
            .ok_or_else(|| ViewError::NoAdapter("the surface offers no format".into()))?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            // Measuring (the turntable) must not wait for the display's refresh.
            present_mode: if options.turntable {
                wgpu::PresentMode::AutoNoVsync
            } else {
                wgpu::PresentMode::AutoVsync
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        surface.configure(device, &config);
        let mut presenter = Presenter::new(device, format);
        presenter.depth_scale = scene_distance(&scene, &scene.camera) as f32;
        let egui = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(renderer.context().limits.max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(device, format, Default::default());
        let samples = options.samples.unwrap_or(scene.settings.samples).count();
        let mut controls = Controls {
            shadows: scene.settings.shadows,
            culling: true,
            samples,
            look: options.look,
            switches: Switches::ALL_ON,
            playing: options.play && offers.duration.is_some(),
            time: 0.0,
            follow: true,
        };
        let use_gpu = match options.backend {
            ViewBackend::Gpu => true,
            ViewBackend::Cpu => false,
            ViewBackend::Auto => !software,
        };
        let adapter_name = renderer.context().adapter_name.clone();
        let gpu = if use_gpu {
            let settings = GpuSettings {
                shadows: controls.shadows,
                culling: controls.culling,
                ..GpuSettings::for_scene(&scene)
            };
            match GpuPath::new(renderer, Arc::clone(&scene), settings) {
                Ok(path) => Some(path),
                Err(e) if options.backend == ViewBackend::Auto => {
                    eprintln!("warning: {e}; rendering on the CPU instead");
                    None
                }
                Err(e) => return Err(e.into()),
            }
        } else {
            None
        };
        let (path, backend_name) = match gpu {
            Some(path) => (
                Path::Gpu(Box::new(path)),
                format!("gpu ({adapter_name}, {})", renderer.context().backend),
            ),
            None => {
                // A still CPU frame is refined to anti-aliased: at least 4 samples unless asked.
                if options.samples.is_none() {
                    controls.samples = controls.samples.max(STILL_SAMPLES);
                }
                let threads = options.threads.unwrap_or_else(|| {
                    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
                });
                let worker = Worker::start(move || {
                    let _ = proxy.send_event(Wake);
                });
                (
                    Path::Cpu(Box::new(CpuPath {
                        worker,
                        progression: Progression::new(controls.samples > 1),
                        last: None,
                    })),
                    format!("cpu ({threads} threads; presented by {adapter_name})"),
                )
            }
        };
        window.set_title(&format!("fray view — {} — {backend_name}", options.name));
        println!(
            "fray view: {} on {backend_name}, window opened after {:.0} ms",
            options.name,
            started.elapsed().as_secs_f64() * 1e3
        );
        let camera = FlyCamera::of(&scene.camera);
        let speed = 0.25 * scene_distance(&scene, &scene.camera);
        Ok(Self {
            window,
            surface,
            config,
            renderer,
            base,
            scene,
            scene_for: (0.0, Switches::ALL_ON),
            scene_generation: 0,
            offers,
            overlay: options.overlay,
            options,
            presenter,
            egui,
            egui_state,
            egui_renderer,
            path,
            backend_name,
            camera,
            rendered: None,
            probed: None,
            recopy: false,
            speed,
            held: Held::default(),
            modifiers: ModifiersState::empty(),
            cursor: None,
            controls,
            readout: Readout::default(),
            counts: Counts::default(),
            last_tick: Instant::now(),
            next_tick: None,
            generation: 0,
        })
    }

    /// Handles one window event; `Ok(false)` ends the viewer.
    fn event(&mut self, event: WindowEvent, started: Instant) -> Result<bool, ViewError> {
        let response = self.egui_state.on_window_event(&self.window, &event);
        // egui asks to repaint after every redraw too; honouring that would spin an idle window.
        if response.repaint && !matches!(event, WindowEvent::RedrawRequested) {
            self.window.request_redraw();
        }
        let consumed = response.consumed && self.overlay;
        match event {
            WindowEvent::CloseRequested => return Ok(false),
            WindowEvent::Resized(size) => {
                self.config.width = size.width.max(1);
                self.config.height = size.height.max(1);
                self.surface
                    .configure(&self.renderer.context().device, &self.config);
                self.window.request_redraw();
            }
            WindowEvent::Focused(false) => self.held.release_all(),
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            WindowEvent::KeyboardInput { event, .. } if !consumed => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return Ok(true);
                };
                let pressed = event.state == ElementState::Pressed;
                // Ctrl+S saves; S alone flies back.
                let command = code == KeyCode::KeyS && self.modifiers.control_key();
                if !command && self.held.key(code, pressed) {
                    self.last_tick = Instant::now();
                } else if pressed && !event.repeat {
                    return self.key(code);
                }
                self.window.request_redraw();
            }
            WindowEvent::MouseInput { state, button, .. } if !consumed => {
                let pressed = state == ElementState::Pressed;
                match button {
                    MouseButton::Right => self.held.looking = pressed,
                    MouseButton::Left => {
                        self.held.orbit = if pressed { self.pick() } else { None };
                    }
                    _ => {}
                }
                self.window.request_redraw();
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let Some((px, py)) = self.cursor {
                    let (dx, dy) = (x - px, y - py);
                    if let Some((pivot, distance)) = self.held.orbit {
                        let (d_yaw, d_pitch) = (-dx * TURN_PER_PIXEL, dy * TURN_PER_PIXEL);
                        self.camera.orbit(pivot, distance, d_yaw, d_pitch);
                    } else if self.held.looking {
                        self.camera.turn(-dx * TURN_PER_PIXEL, -dy * TURN_PER_PIXEL);
                    }
                    if self.held.moving() {
                        self.window.request_redraw();
                    }
                }
                self.cursor = Some((x, y));
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => f64::from(y),
                    MouseScrollDelta::PixelDelta(p) => p.y / 50.0,
                };
                self.speed *= SPEED_PER_NOTCH.powf(notches);
                self.window.request_redraw();
            }
            WindowEvent::RedrawRequested => return self.redraw(started),
            _ => {}
        }
        Ok(true)
    }

    /// A key that is not a movement key.
    fn key(&mut self, code: KeyCode) -> Result<bool, ViewError> {
        let save = code == KeyCode::F12 || (code == KeyCode::KeyS && self.modifiers.control_key());
        if save {
            return Ok(self.save());
        }
        match code {
            KeyCode::F1 | KeyCode::KeyH => self.overlay = !self.overlay,
            KeyCode::Escape => return Ok(false),
            KeyCode::Space if self.offers.duration.is_some() => {
                self.controls.playing = !self.controls.playing;
                println!(
                    "{} at {:.3} s",
                    if self.controls.playing {
                        "playing"
                    } else {
                        "paused"
                    },
                    self.controls.time
                );
                self.last_tick = Instant::now();
            }
            _ => {
                if let Some(n) = digit(code) {
                    let cameras = cameras::named(&self.scene);
                    if let Some((name, projector)) = n.checked_sub(1).and_then(|i| cameras.get(i)) {
                        println!("camera {n}: {name}");
                        self.camera = FlyCamera::of(projector);
                        // A chosen camera holds still while the animation plays on.
                        self.controls.follow = false;
                    }
                }
            }
        }
        self.window.request_redraw();
        Ok(true)
    }

    /// Saves the current view; returns whether the viewer goes on.
    fn save(&mut self) -> bool {
        self.counts.saves += 1;
        let stem = std::path::Path::new(&self.options.name)
            .file_stem()
            .map_or_else(|| "fray".to_owned(), |s| s.to_string_lossy().into_owned());
        let stem = stem.split(' ').next().unwrap_or("fray").to_owned();
        let path = save_path(self.options.save_as.as_deref(), &stem, self.counts.saves);
        let settings = SaveSettings {
            backend: match self.path {
                Path::Gpu(_) => Backend::Gpu,
                Path::Cpu(_) => Backend::Cpu,
            },
            size: (self.config.width, self.config.height),
            threads: self.options.threads,
            controls: self.controls,
            time: self.offers.duration.map(|_| self.controls.time),
        };
        match save(&self.scene, &self.camera, &settings, &path) {
            Ok(flags) => {
                println!(
                    "saved {} (fray render {flags}, with this camera):",
                    path.display()
                );
                println!("{}", self.camera.snippet());
            }
            Err(e) => eprintln!("error: cannot save {}: {e}", path.display()),
        }
        !self.options.exit_after_save
    }

    /// The point under the cursor in the last frame (else one at the scene's distance ahead),
    /// and the eye's distance from it: the orbit's pivot.
    fn pick(&self) -> Option<(DVec3, f64)> {
        let (cx, cy) = self.cursor?;
        let projector = self.rendered.map(|r| r.0)?;
        let (w, h) = (self.config.width, self.config.height);
        let point = match self.depth_under(cx, cy) {
            Some(d) => {
                let (origin, through) = projector.pair(cx, cy, w, h);
                origin + (through - origin).normalize_or_zero() * d
            }
            None => {
                self.camera.eye + self.camera.forward() * scene_distance(&self.scene, &projector)
            }
        };
        let distance = (point - self.camera.eye).length();
        (distance > 0.0 && distance.is_finite()).then_some((point, distance))
    }

    /// The last frame's depth at window position `(cx, cy)` (`None` where nothing was hit).
    fn depth_under(&self, cx: f64, cy: f64) -> Option<f64> {
        let (w, h) = (self.config.width, self.config.height);
        match &self.path {
            Path::Gpu(gpu) => gpu.depth_at(cx as u32, cy as u32),
            Path::Cpu(cpu) => cpu.last.as_ref().and_then(|(frame, _)| {
                let (fw, fh) = (frame.depth.width(), frame.depth.height());
                let x = ((cx / f64::from(w)) * f64::from(fw)) as u32;
                let y = ((cy / f64::from(h)) * f64::from(fh)) as u32;
                (x < fw && y < fh)
                    .then(|| *frame.depth.get(x, y))
                    .filter(|d| d.is_finite())
            }),
        }
    }

    /// One frame of the loop: move the camera, play the animation, render (GPU), advance the
    /// progression (CPU) or probe (a probed look), draw the picture and the overlay.
    fn redraw(&mut self, started: Instant) -> Result<bool, ViewError> {
        let now = Instant::now();
        let dt = (now - self.last_tick).as_secs_f64().min(0.25);
        self.last_tick = now;
        if self.held.moving() {
            // Flying leaves the camera path.
            self.controls.follow = false;
        }
        self.held.fly(&mut self.camera, self.speed, dt);
        if self.options.turntable {
            self.camera.turn(0.01, 0.0);
        }
        if self.controls.playing {
            self.play(dt);
        }
        self.update_scene()?;
        let moving = self.held.moving() || self.options.turntable || self.controls.playing;
        let size = (self.config.width, self.config.height);
        let projector = self.camera.projector();
        let key: FrameKey = (
            projector,
            self.controls.frame_key(),
            size,
            self.scene_generation,
        );
        let changed = self.rendered != Some(key);
        if let Some(view) = self.controls.look.probe() {
            // Probed from the camera at the coarse size while moving, else at the window's.
            let at = if moving {
                Level::Coarse.size(size)
            } else {
                size
            };
            let probe_key = (
                (
                    projector,
                    self.controls.frame_key(),
                    at,
                    self.scene_generation,
                ),
                self.controls.look,
            );
            if self.probed != Some(probe_key) {
                let mut scene = (*self.scene).clone();
                scene.camera = projector;
                (scene.width, scene.height) = at;
                let image =
                    probe_view::probe(view, &scene, self.controls.culling, self.options.threads)
                        .map_err(ViewError::Options)?;
                let ctx = self.renderer.context();
                self.presenter
                    .upload_picture(&ctx.device, &ctx.queue, image.size, &image.rgba);
                self.probed = Some(probe_key);
                let stats = RenderStats {
                    backend: "cpu probe".into(),
                    elapsed: image.elapsed,
                    ..RenderStats::default()
                };
                let frame = format!("{}×{} {}", at.0, at.1, image.legend);
                // Each probed picture is a view of its own (its "still frame" line once).
                self.generation += 1;
                if !self.show_frame(stats, frame, "probe", !moving, started) {
                    return Ok(false);
                }
            }
            self.draw()?;
            self.schedule(moving, now);
            return Ok(true);
        }
        let mut shown = None;
        match &mut self.path {
            Path::Gpu(gpu) => {
                let debug = self.controls.look.frame_view();
                if self.recopy && !changed && gpu.copy_again(&mut self.presenter, debug) {
                    self.recopy = false;
                } else if changed || self.recopy {
                    gpu.set(&self.scene, self.controls.shadows, self.controls.culling)?;
                    let samples = PixelSamples::new(self.controls.samples)
                        .map_err(|e| ViewError::Options(e.to_string()))?;
                    let view = View {
                        camera: projector,
                        width: size.0,
                        height: size.1,
                        samples,
                        tone_map: fray_core::ToneMap::Clamp,
                        exposure: 1.0,
                    };
                    let stats = gpu.render(&view, &mut self.presenter, debug)?;
                    if changed {
                        self.generation += 1;
                    }
                    self.recopy = false;
                    shown = Some((stats, format!("{}×{}", size.0, size.1), "gpu", !moving));
                    self.rendered = Some(key);
                } else if !moving && self.counts.still_printed != Some(self.generation) {
                    // The camera stopped where the last frame (rendered while it moved) shows
                    // it: that frame is the still one.
                    self.counts.still_printed = Some(self.generation);
                    println!(
                        "still frame: {} in {:.1} ms",
                        self.readout.frame,
                        self.readout.stats.elapsed.as_secs_f64() * 1e3
                    );
                }
            }
            Path::Cpu(cpu) => {
                let debug = self.controls.look.frame_view();
                if changed {
                    cpu.progression.changed();
                    cpu.progression.refine = self.controls.samples > 1;
                    self.rendered = Some(key);
                }
                if self.recopy {
                    if let Some((frame, _)) = &cpu.last {
                        upload_cpu_frame(&mut self.presenter, self.renderer, frame, debug);
                    }
                    self.recopy = false;
                }
                while let Some(done) = cpu.worker.try_done() {
                    let job = done.job;
                    let frame = done.frame.map_err(ViewError::Options)?;
                    // Shown even when the view moved on since: it is the newest picture there is.
                    let current = cpu.progression.finished(job);
                    upload_cpu_frame(&mut self.presenter, self.renderer, &frame, debug);
                    let label = match job.level {
                        Level::Coarse => "coarse",
                        Level::Full => "full",
                        Level::Refined => "refined",
                    };
                    let still = current && cpu.progression.is_final();
                    shown = Some((
                        frame.stats.clone(),
                        format!("{}×{} {label}", frame.colour.width(), frame.colour.height()),
                        label,
                        still,
                    ));
                    cpu.last = Some((frame, job.level));
                }
                self.generation = cpu.progression.generation();
                if let Some(job) = cpu.progression.next(moving) {
                    let request = cpu_request(
                        &self.scene,
                        projector,
                        job,
                        size,
                        &self.controls,
                        self.options.threads,
                    )?;
                    cpu.worker.send(request).map_err(ViewError::Options)?;
                }
            }
        }
        if let Some((stats, frame, label, still)) = shown
            && !self.show_frame(stats, frame, label, still, started)
        {
            return Ok(false);
        }
        self.draw()?;
        self.schedule(moving, now);
        Ok(true)
    }

    /// Asks for the next frame of a moving view: at once (the GPU's turntable, measuring), else
    /// at the next tick.
    fn schedule(&mut self, moving: bool, now: Instant) {
        if moving {
            let unthrottled = self.options.turntable && matches!(self.path, Path::Gpu(_));
            if unthrottled {
                self.window.request_redraw();
            } else {
                self.next_tick = Some(now + TICK);
            }
        }
    }

    /// Advances the animation by `seconds`: it wraps at its end if it loops, else stops there.
    fn play(&mut self, seconds: f64) {
        let Some(duration) = self.offers.duration else {
            self.controls.playing = false;
            return;
        };
        let looped = self.base.animation.as_ref().is_some_and(|a| a.looped);
        let t = self.controls.time + seconds;
        self.controls.time = if t < duration {
            t
        } else if looped && duration > 0.0 {
            t % duration
        } else {
            self.controls.playing = false;
            println!("stopped at the end, {duration:.3} s");
            duration
        };
    }

    /// Makes the scene the backends render again when the time or a part's switch changed;
    /// a camera that rides the path moves with it.
    fn update_scene(&mut self) -> Result<(), ViewError> {
        let wanted = (self.controls.time, self.controls.switches);
        if wanted == self.scene_for {
            return Ok(());
        }
        // From the file's scene each time: a part switched back on returns.
        let scene = self.base.at_time(wanted.0)?.switched(wanted.1);
        if self.controls.follow && self.offers.camera_path {
            self.camera = FlyCamera::of(&scene.camera);
        }
        self.scene = Arc::new(scene);
        self.scene_for = wanted;
        self.scene_generation += 1;
        Ok(())
    }

    /// Bookkeeping of a frame shown: the overlay's readout, frames per second, the first and
    /// still frames' lines, the exit hook. Returns whether the viewer goes on.
    fn show_frame(
        &mut self,
        stats: RenderStats,
        frame: String,
        label: &str,
        still: bool,
        started: Instant,
    ) -> bool {
        self.counts.shown += 1;
        let now = Instant::now();
        if self.counts.first.is_none() {
            // Fly a quarter of the way to what the camera looks at per second (the scene's box
            // says little when a ground plane is a huge sphere).
            let centre = (
                0.5 * f64::from(self.config.width),
                0.5 * f64::from(self.config.height),
            );
            if let Some(d) = self.depth_under(centre.0, centre.1) {
                self.speed = 0.25 * d;
                // The depth view's scale: what the camera looks at mid-grey.
                self.presenter.depth_scale = d as f32;
            }
        }
        let c = &mut self.counts;
        if c.first.is_none() {
            let after = started.elapsed();
            c.first = Some(after);
            println!(
                "first frame: {frame} after {:.0} ms ({})",
                after.as_secs_f64() * 1e3,
                self.backend_name
            );
        }
        match c.times.iter_mut().find(|(l, _, _)| l == label) {
            Some((_, sum, n)) => {
                *sum += stats.elapsed;
                *n += 1;
            }
            None => c.times.push((label.to_owned(), stats.elapsed, 1)),
        }
        match c.window {
            Some((t0, n)) if now - t0 >= Duration::from_secs(1) => {
                c.frames_per_second = (c.shown - n) as f64 / (now - t0).as_secs_f64();
                c.window = Some((now, c.shown));
            }
            None => c.window = Some((now, c.shown)),
            _ => {}
        }
        if still && c.still_printed != Some(self.generation) {
            c.still_printed = Some(self.generation);
            println!(
                "still frame: {frame} in {:.1} ms",
                stats.elapsed.as_secs_f64() * 1e3
            );
        }
        self.readout = Readout {
            backend: self.backend_name.clone(),
            frame,
            stats,
            frames_per_second: c.frames_per_second,
            camera: self.camera.snippet(),
            speed: self.speed,
        };
        if let Some(n) = self.options.exit_after_frames
            && c.shown >= n
        {
            let first = c.first.unwrap_or_default();
            let since = first.as_secs_f64();
            let total = started.elapsed().as_secs_f64();
            let times: Vec<String> = c
                .times
                .iter()
                .map(|(l, sum, n)| {
                    format!(
                        "{l} {:.1} ms × {n}",
                        sum.as_secs_f64() * 1e3 / f64::from(*n)
                    )
                })
                .collect();
            println!(
                "{} frames: first after {:.0} ms, then {:.2} frames/s; mean render time: {}",
                c.shown,
                since * 1e3,
                (c.shown - 1) as f64 / (total - since).max(1e-9),
                times.join(", ")
            );
            return false;
        }
        true
    }

    /// Draws the last frame and the overlay to the window and presents.
    fn draw(&mut self) -> Result<(), ViewError> {
        let ctx = self.renderer.context();
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&ctx.device, &self.config);
                self.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(());
            }
            other => {
                return Err(ViewError::Window(format!(
                    "the surface has no texture to draw: {other:?}"
                )));
            }
        };
        let target = frame.texture.create_view(&Default::default());
        let size = (self.config.width, self.config.height);
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("present"),
            });
        self.presenter.draw(&ctx.queue, &mut encoder, &target, size);
        let input = self.egui_state.take_egui_input(&self.window);
        let before = self.controls;
        let (overlay, readout, offers) = (self.overlay, &self.readout, &self.offers);
        let mut after = before;
        let mut output = self.egui.run_ui(input, |ui| {
            if overlay {
                after = overlay::show(ui.ctx(), before, readout, offers);
            }
        });
        if after != before {
            if after.look != before.look {
                self.recopy = true;
                self.probed = None;
            }
            if after.playing && !before.playing {
                self.last_tick = Instant::now();
            }
            self.controls = after;
            self.window.request_redraw();
        }
        self.egui_state
            .handle_platform_output(&self.window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let jobs = self.egui.tessellate(output.shapes, pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point,
        };
        // Taken, not borrowed: egui checks in debug builds that every delta was applied.
        let set: Vec<_> = output.textures_delta.set.drain().collect();
        for (id, deltas) in &set {
            for delta in deltas {
                self.egui_renderer
                    .update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        let extra = self.egui_renderer.update_buffers(
            &ctx.device,
            &ctx.queue,
            &mut encoder,
            &jobs,
            &screen,
        );
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in output.textures_delta.free.drain() {
            self.egui_renderer.free_texture(&id);
        }
        ctx.queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        ctx.queue.present(frame);
        if output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero())
        {
            self.window.request_redraw();
        }
        Ok(())
    }
}

/// What the overlay can offer for `scene`: switches for the parts it has, the animation.
fn offers(scene: &Scene) -> Offers {
    let moving_heights = scene.terrains.iter().any(|t| t.heights.is_some());
    let duration = match &scene.animation {
        Some(a) => Some(a.duration()),
        None if moving_heights => Some(f64::INFINITY),
        None => None,
    };
    Offers {
        parts: Switches {
            fog: scene.atmosphere.fog.is_some(),
            sky: scene.atmosphere.sky.is_some(),
            clouds: scene.clouds.is_some(),
            reflections: scene.features.reflection || scene.features.transmission,
        },
        duration,
        camera_path: scene.animation.as_ref().is_some_and(|a| a.camera.is_some()),
    }
}

/// The number of a digit key 1–9.
fn digit(code: KeyCode) -> Option<usize> {
    const DIGITS: [KeyCode; 9] = [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::Digit3,
        KeyCode::Digit4,
        KeyCode::Digit5,
        KeyCode::Digit6,
        KeyCode::Digit7,
        KeyCode::Digit8,
        KeyCode::Digit9,
    ];
    DIGITS.iter().position(|d| *d == code).map(|i| i + 1)
}

/// The distance from `camera`'s eye to the centre of the scene's box (10 for an empty or
/// unbounded scene): the orbit's default pivot distance, the depth view's scale, the speed's.
fn scene_distance(scene: &Scene, camera: &Projector) -> f64 {
    let b = scene.bounds();
    let eye = match camera {
        Projector::Pinhole(p) => p.eye,
        Projector::Parallel(p) => p.eye,
        Projector::Sphere(s) => s.eye,
    };
    let d = if b.is_empty() || !b.is_finite() {
        10.0
    } else {
        (0.5 * (b.min + b.max) - eye).length()
    };
    if d.is_finite() && d > 0.0 { d } else { 10.0 }
}

/// The worker's request for `job`: the scene seen from `projector` at the job's level's size.
fn cpu_request(
    scene: &Scene,
    projector: Projector,
    job: Job,
    window: (u32, u32),
    controls: &Controls,
    threads: Option<usize>,
) -> Result<Request, ViewError> {
    let (width, height) = job.level.size(window);
    let samples = match job.level {
        Level::Coarse | Level::Full => 1,
        Level::Refined => controls.samples,
    };
    let samples = PixelSamples::new(samples).map_err(|e| ViewError::Options(e.to_string()))?;
    let mut scene = scene.clone();
    scene.camera = projector;
    Ok(Request {
        job,
        scene,
        options: RenderOptions {
            backend: Backend::Cpu,
            width: Some(width),
            height: Some(height),
            threads,
            shadows: Some(controls.shadows),
            culling: Some(controls.culling),
            samples: Some(samples),
            ..RenderOptions::default()
        },
    })
}

/// Uploads a CPU frame to the presenter as RGBA8: its PNG bytes, or its depth or normals.
fn upload_cpu_frame(
    presenter: &mut Presenter,
    renderer: &GpuRenderer,
    frame: &Frame,
    debug: DebugView,
) {
    let (w, h) = (frame.colour.width(), frame.colour.height());
    let scale = f64::from(presenter.depth_scale);
    let rgba: Vec<u8> = match debug {
        DebugView::Colour => srgb8(frame, &PngOptions::default())
            .pixels()
            .iter()
            .flat_map(|&[r, g, b]| [r, g, b, 255])
            .collect(),
        DebugView::Depth => frame
            .depth
            .pixels()
            .iter()
            .flat_map(|&d| {
                let v = if d.is_finite() && d >= 0.0 {
                    ((-d / scale).exp() * 255.0).round() as u8
                } else {
                    0
                };
                [v, v, v, 255]
            })
            .collect(),
        DebugView::Normals => frame
            .normals
            .pixels()
            .iter()
            .flat_map(|n| {
                let c = |v: f32| ((0.5 + 0.5 * v) * 255.0).round().clamp(0.0, 255.0) as u8;
                if *n == glam::Vec3::ZERO {
                    [0, 0, 0, 255]
                } else {
                    [c(n.x), c(n.y), c(n.z), 255]
                }
            })
            .collect(),
    };
    let ctx = renderer.context();
    presenter.upload_picture(&ctx.device, &ctx.queue, (w, h), &rgba);
}
