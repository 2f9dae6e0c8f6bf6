//! The GPU backend in the loop: the resident scene (`fray_gpu::GpuScene`) rendered into its
//! textures and copied on the device to the presenter, with no image readback; one texel of
//! depth read back when the orbit picks a point.

use crate::present::{DebugView, Presenter};
use fray_core::RenderStats;
use fray_gpu::{GpuError, GpuRenderer, GpuScene, GpuSettings, View};
use fray_scene::Scene;
use std::sync::Arc;

/// The resident scene and what it was uploaded with.
#[derive(Debug)]
pub struct GpuPath {
    renderer: &'static GpuRenderer,
    scene: Arc<Scene>,
    resident: GpuScene<'static>,
    settings: GpuSettings,
    /// One row of a texture copy (256 bytes, the copy alignment): the picked texel lands here.
    pick: wgpu::Buffer,
}

impl GpuPath {
    /// Uploads `scene` (pipelines built once, here).
    pub fn new(
        renderer: &'static GpuRenderer,
        scene: Arc<Scene>,
        settings: GpuSettings,
    ) -> Result<Self, GpuError> {
        let resident = renderer.upload_shared(Arc::clone(&scene), &settings)?;
        let pick = renderer
            .context()
            .device
            .create_buffer(&wgpu::BufferDescriptor {
                label: Some("pick"),
                size: u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
        Ok(Self {
            renderer,
            scene,
            resident,
            settings,
            pick,
        })
    }

    /// Renders `scene` from now on, with shadows and culling as given: another scene (a part
    /// switched, the animation's next time) is uploaded in place of the resident one, and so is
    /// the same scene when a switch changed (the shadow switch specialises the pipelines;
    /// culling alone would not need it, but the settings live with the resident scene). The
    /// pipelines come from the renderer's cache: a scene with the same features builds none.
    pub fn set(
        &mut self,
        scene: &Arc<Scene>,
        shadows: bool,
        culling: bool,
    ) -> Result<(), GpuError> {
        let same_scene = Arc::ptr_eq(&self.scene, scene);
        if same_scene && (self.settings.shadows, self.settings.culling) == (shadows, culling) {
            return Ok(());
        }
        let settings = GpuSettings {
            shadows,
            culling,
            // A switched scene may need another epsilon (its size changed with a part left out).
            ..GpuSettings::for_scene(scene)
        };
        self.resident = self.renderer.upload_shared(Arc::clone(scene), &settings)?;
        self.scene = Arc::clone(scene);
        self.settings = settings;
        Ok(())
    }

    /// Renders `view` and copies what `debug` shows to the presenter (on the device).
    pub fn render(
        &mut self,
        view: &View,
        presenter: &mut Presenter,
        debug: DebugView,
    ) -> Result<RenderStats, GpuError> {
        let (stats, _) = self.resident.render_display(view)?;
        // The frame just rendered is the last frame: copied as a switched debug view is.
        self.copy_again(presenter, debug);
        Ok(stats)
    }

    /// Copies what `debug` shows of the last frame to the presenter again (a debug view
    /// switched; nothing re-renders). False before the first frame.
    pub fn copy_again(&self, presenter: &mut Presenter, debug: DebugView) -> bool {
        let Some(textures) = self.resident.textures() else {
            return false;
        };
        let ctx = self.renderer.context();
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("viewer copy"),
            });
        presenter.copy_gpu_frame(&ctx.device, &mut encoder, &textures, debug);
        ctx.queue.submit([encoder.finish()]);
        true
    }

    /// The last frame's depth at pixel `(x, y)` (`None`: no hit, no frame, or outside it).
    pub fn depth_at(&self, x: u32, y: u32) -> Option<f64> {
        let ctx = self.renderer.context();
        let texture = self.resident.textures()?.colour_depth;
        if x >= texture.width() || y >= texture.height() {
            return None;
        }
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("pick"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.pick,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT),
                    rows_per_image: Some(1),
                },
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
        ctx.queue.submit([encoder.finish()]);
        let slice = self.pick.slice(..16);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        ctx.device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
        rx.recv().ok()?.ok()?;
        let texel: Option<[f32; 4]> = slice
            .get_mapped_range()
            .ok()
            .map(|view| bytemuck::pod_read_unaligned(&view[..16]));
        self.pick.unmap();
        // The colour + depth texture's w: the depth along the unit ray, negative for no hit.
        let depth = f64::from(texel?[3]);
        (depth >= 0.0 && depth.is_finite()).then_some(depth)
    }
}
