//! The GPU frame: settings, the f32 ε, and assembling a [`Frame`] from the free-form pass.

use crate::freeform_pass::FreeFormPass;
use crate::params::reference_point;
use crate::shader::Specialisation;
use crate::{GpuContext, GpuError};
use fray_core::{Frame, Image, RenderStats};
use fray_scene::Scene;
use glam::{DVec3, Vec3};
use std::time::Instant;

/// The f32 floor of ε relative to the camera distance: `2⁻²⁰ ≈ 9.5e-7`, about 8 f32 ulps of a
/// distance — below it f32 halving cannot make progress and roots are not resolved better.
pub const EPSILON_FLOOR: f64 = 1.0 / 1_048_576.0;
/// Shadow rays start this many (GPU) ε along the normal: far beyond the f32 hit error.
pub const SHADOW_OFFSET_EPSILONS: f64 = 100.0;

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
    pub samples: fray_core::PixelSamples,
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

/// The largest distance from the eye to the scene's box (1 for an empty or unbounded scene).
pub fn camera_distance(scene: &Scene) -> f64 {
    let b = scene.bounds();
    if b.is_empty() || !b.is_finite() {
        return 1.0;
    }
    let eye = reference_point(&scene.camera);
    let far = DVec3::new(
        (b.min.x - eye.x).abs().max((b.max.x - eye.x).abs()),
        (b.min.y - eye.y).abs().max((b.max.y - eye.y).abs()),
        (b.min.z - eye.z).abs().max((b.max.z - eye.z).abs()),
    );
    far.length().max(f64::MIN_POSITIVE)
}

/// The ε the GPU uses: `max(requested, EPSILON_FLOOR · camera distance)`.
pub fn gpu_epsilon(scene: &Scene, requested: f64) -> f64 {
    requested.max(EPSILON_FLOOR * camera_distance(scene))
}

/// A GPU backend: one device, reused across frames.
#[derive(Debug)]
pub struct GpuRenderer {
    ctx: GpuContext,
}

impl GpuRenderer {
    /// Opens the GPU (fails with [`GpuError::NoAdapter`] on a machine without one).
    pub fn new() -> Result<Self, GpuError> {
        Ok(Self {
            ctx: GpuContext::new()?,
        })
    }

    /// The device context.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Builds the pass for `scene` (pipeline specialised to it, buffers uploaded).
    pub fn prepare(&self, scene: &Scene, settings: &GpuSettings) -> Result<FreeFormPass, GpuError> {
        if !(settings.epsilon.is_finite() && settings.epsilon > 0.0) {
            return Err(GpuError::BadEpsilon(settings.epsilon));
        }
        if scene.width == 0 || scene.height == 0 {
            return Err(GpuError::EmptyImage(scene.width, scene.height));
        }
        if settings.samples.count() > 1 {
            return Err(GpuError::Unsupported {
                feature: "anti-aliasing (samples > 1)",
            });
        }
        let eps = gpu_epsilon(scene, settings.epsilon);
        let spec = Specialisation::for_scene(scene, settings.shadows);
        FreeFormPass::new(
            &self.ctx,
            scene,
            eps,
            SHADOW_OFFSET_EPSILONS * eps,
            spec,
            settings.culling,
        )
    }

    /// Renders `scene`.
    pub fn render(&self, scene: &Scene, settings: &GpuSettings) -> Result<Frame, GpuError> {
        let start = Instant::now();
        let pass = self.prepare(scene, settings)?;
        let built = start.elapsed();
        let out = pass.run(&self.ctx)?;
        // An error no scope caught (or a lost device) would otherwise go unnoticed: fail with it.
        if let Some(reason) = self.ctx.take_uncaptured_error() {
            return Err(if reason.starts_with("device lost") {
                GpuError::DeviceLost(reason)
            } else {
                GpuError::Dispatch {
                    pass: "free-form",
                    reason,
                }
            });
        }
        let (w, h) = (scene.width, scene.height);
        let mut colour = Image::filled(w, h, fray_core::Rgb::ZERO);
        let mut depth = Image::filled(w, h, f64::INFINITY);
        let mut normals = Image::filled(w, h, Vec3::ZERO);
        for y in 0..h {
            for x in 0..w {
                let k = (y as usize) * (w as usize) + x as usize;
                let (Some(c), Some(n)) = (out.colour_depth.get(k), out.normal.get(k)) else {
                    continue;
                };
                if n[3] > 0.5 {
                    colour.set(x, y, Vec3::new(c[0], c[1], c[2]));
                    depth.set(x, y, f64::from(c[3]));
                    normals.set(x, y, Vec3::new(n[0], n[1], n[2]));
                } else {
                    // A miss, or a pixel no work item covered (culled).
                    colour.set(x, y, scene.background);
                }
            }
        }
        let spec = pass.specialisation();
        let mut passes = vec![format!(
            "pipelines built: {} ({:.1} ms)",
            spec.describe(),
            built.as_secs_f64() * 1e3
        )];
        let work = pass.work_stats();
        if work.is_some() {
            passes.push("quadtree".to_owned());
        }
        passes.push("primary".to_owned());
        passes.extend(scene.features.names().iter().map(|s| s.to_string()));
        if !spec.shadows {
            passes.retain(|p| p != "shadows");
        }
        let mut stats = RenderStats {
            backend: format!("gpu ({}, {})", self.ctx.adapter_name, self.ctx.backend),
            threads: 1,
            primary_rays: u64::from(w) * u64::from(h),
            shadow_rays: out.shadow_rays,
            hits: out.hits,
            bound_evaluations: out.bound_evaluations,
            point_evaluations: out.point_evaluations,
            epsilon: gpu_epsilon(scene, settings.epsilon),
            passes,
            elapsed: start.elapsed(),
            kernel_time: out.kernel_time,
            terrain_rays: out.terrain_rays,
            terrain_segments: out.terrain.segments,
            terrain_cells: out.terrain.cells,
            terrain_stops: out.terrain.stops,
            terrain_stop_levels: out.terrain.stop_levels_above_finest,
            ..RenderStats::default()
        };
        if let Some(work) = work {
            stats.cells_visited = work.cells_visited;
            stats.cells_culled = work.cells_culled;
            stats.work_items = work.items;
        }
        Ok(Frame {
            colour,
            depth,
            normals,
            stats,
        })
    }
}

/// Renders `scene` on a freshly opened GPU.
pub fn render(scene: &Scene, settings: &GpuSettings) -> Result<Frame, GpuError> {
    GpuRenderer::new()?.render(scene, settings)
}
