//! The physically based sky on the GPU: its parameter block (`GpuSky`, written for each view from
//! f64), its transmittance table (uploaded once: it depends on the model only) and its sky-view
//! table of the eye's height (written when that height changes). The two tables on the GPU: their
//! `[f32; 4]` texels (`fray_atmosphere`'s `TransmittanceTable` and `SkyViewTable`, row-major) as
//! `Rgba32Float` 2D textures that `shaders/sky.wgsl` reads with `textureLoad` and interpolates
//! itself, as the CPU does — no sampler: the transmittance table is filtered on the optical depth
//! before `exp`, the sky-view table only within the half of the horizon a ray is on, and 32-bit
//! float textures are not filterable without a device feature anyway. Sampled textures have a
//! per-stage limit of their own, so the tables do not count against the shade pass's eight storage
//! buffers.

use super::{GpuMedium, ResidentMedium};
use crate::bindings::Part;
use crate::features::Feature;
use crate::kinds::Upload;
use crate::{DeviceCharges, GpuContext, GpuError, View};
use fray_atmosphere::gpu_layout::{GpuSky, GpuSkyOptions};
use fray_scene::Scene;
use wgpu::BufferUsages as U;

/// The texture format of a table: four f32 channels (RGB and 1).
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The sky on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct Sky;

impl GpuMedium for Sky {
    fn feature(&self) -> Feature {
        Feature::Sky
    }

    fn part(&self) -> Part {
        Part::Sky
    }

    /// Its parameter block (empty: written per view), its transmittance table (uploaded) and
    /// its sky-view table (empty: written per eye height).
    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentMedium>>, GpuError> {
        let ctx = at.ctx;
        let Some(sky) = &at.scene.atmosphere.sky else {
            return Ok(None);
        };
        let sky = &sky.sky;
        let table = sky.transmittance_table();
        let transmittance = table_texture(
            ctx,
            charges,
            "the sky's transmittance table (texels per side)",
            table.width(),
            table.height(),
        )?;
        let bytes = write_table(ctx, &transmittance, table.width(), table.texels());
        let sizes = sky.tables();
        let view_table = table_texture(
            ctx,
            charges,
            "the sky-view table (texels per side)",
            sizes.sky_view_width,
            sizes.sky_view_height,
        )?;
        let size = std::mem::size_of::<GpuSky>() as u64;
        let params = charges.empty(ctx, "sky", size, U::UNIFORM | U::COPY_DST)?;
        Ok(Some(Box::new(ResidentSky {
            params,
            transmittance_view: view(&transmittance),
            sky_view: view(&view_table),
            transmittance,
            view_table,
            view_for: None,
            bytes,
        })))
    }
}

/// The sky on the GPU.
#[derive(Debug)]
pub struct ResidentSky {
    /// Its parameters (`GpuSky`, a uniform written per view from f64).
    pub params: wgpu::Buffer,
    /// The transmittance table (optical depth), uploaded once: it depends on the model only.
    pub transmittance: wgpu::Texture,
    /// The sky-view table of the eye's height (`Sky::view`), written when that height changes:
    /// it depends neither on the eye's horizontal position nor on where the camera looks.
    pub view_table: wgpu::Texture,
    transmittance_view: wgpu::TextureView,
    sky_view: wgpu::TextureView,
    /// The observer radius (f64 bits) the sky-view table holds the table of (`None`: not yet
    /// written); the table depends on nothing else that moves.
    view_for: Option<u64>,
    bytes: u64,
}

impl ResidentMedium for ResidentSky {
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>> {
        vec![
            self.params.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.transmittance_view),
            wgpu::BindingResource::TextureView(&self.sky_view),
        ]
    }

    /// The sky's block for the eye, and the sky-view table of the eye's height when that height
    /// changed since the last frame (a camera moving level uploads none).
    fn write_view(&mut self, ctx: &GpuContext, scene: &Scene, view: &View) -> u64 {
        let Some(s) = &scene.atmosphere.sky else {
            return 0;
        };
        let eye = crate::params::reference_point(&view.camera);
        let mut uploaded = 0;
        let radius = s.sky.model().observer_radius(eye.y).to_bits();
        if self.view_for != Some(radius) {
            // The CPU builds the table in f64 (as fray-trace's Media::of does per frame).
            let sky_view = s.sky.view(eye);
            let table = sky_view.table();
            uploaded += write_table(ctx, &self.view_table, table.width(), table.texels());
            self.view_for = Some(radius);
        }
        let block = GpuSky::new(
            &s.sky,
            eye.y,
            GpuSkyOptions {
                sun_disc: s.sun_disc,
                aerial_perspective: s.aerial_perspective,
                steps: s.steps,
                sun_light: s.sun_light,
            },
        );
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&block));
        uploaded + std::mem::size_of::<GpuSky>() as u64
    }

    fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// An empty `width × height` table texture, checked against the device's texture limit and
/// charged to `charges` first.
pub(crate) fn table_texture(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    label: &'static str,
    width: u32,
    height: u32,
) -> Result<wgpu::Texture, GpuError> {
    let limit = ctx.limits.max_texture_dimension_2d;
    if width.max(height) > limit {
        return Err(GpuError::TooLarge {
            what: label,
            needed: u64::from(width.max(height)),
            limit: u64::from(limit),
        });
    }
    // Rgba32Float: 16 bytes a texel.
    charges.charge_uploaded(
        label,
        u64::from(width.max(1)) * u64::from(height.max(1)) * 16,
    )?;
    Ok(ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: width.max(1),
            height: height.max(1),
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    }))
}

/// Writes `texels` (row-major, `width` per row, as many rows as they fill) into `texture`;
/// returns the bytes uploaded. The caller made the texture for this size.
pub(crate) fn write_table(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    width: u32,
    texels: &[[f32; 4]],
) -> u64 {
    let rows = (texels.len() as u64 / u64::from(width.max(1))) as u32;
    if rows == 0 {
        return 0;
    }
    let whole_rows = &texels[..(width * rows) as usize];
    ctx.write_texels(texture, [width, rows, 1], whole_rows)
}

/// A view of the whole table, for a bind group.
pub(crate) fn view(texture: &wgpu::Texture) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}
