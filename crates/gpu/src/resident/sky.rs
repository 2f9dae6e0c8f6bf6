//! The sky's two tables on the GPU: their `[f32; 4]` texels (`fray_atmosphere`'s
//! `TransmittanceTable` and `SkyViewTable`, row-major) as `Rgba32Float` 2D textures that
//! `shaders/sky.wgsl` reads with `textureLoad` and interpolates itself, as the CPU does — no
//! sampler: the transmittance table is filtered on the optical depth before `exp`, the sky-view
//! table only within the half of the horizon a ray is on, and 32-bit float textures are not
//! filterable without a device feature anyway. Sampled textures have a per-stage limit of their
//! own, so the tables do not count against the shade pass's eight storage buffers.

use crate::{GpuContext, GpuError};

/// The texture format of a table: four f32 channels (RGB and 1).
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

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
