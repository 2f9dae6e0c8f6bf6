//! The cloud volume's grids on the GPU: the density grid (`fray_clouds::DensityGrid`, x fastest)
//! and, with empty-space skipping, its max grid (one bound per block,
//! `fray_clouds::gpu_layout::max_grid_texels`) as `R32Float` 3D textures that
//! `shaders/clouds.wgsl` reads with `textureLoad` and interpolates itself, exactly as the CPU's
//! trilinear formula with clamped edges — no sampler, and no filtering feature for 32-bit float
//! textures. Without skipping the max grid is a single zero texel the shader never reads (the
//! bind group's layout is the same either way). Each side is checked against the device's
//! `max_texture_dimension_3d` first.

use crate::{GpuContext, GpuError};
use fray_clouds::march::GridVolume;

/// The texture format of both grids.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// A volume's grids on the device.
#[derive(Debug)]
pub struct CloudTextures {
    pub density: wgpu::Texture,
    /// The max grid (a 1×1×1 placeholder without skipping).
    pub max: wgpu::Texture,
}

impl CloudTextures {
    /// Uploads `volume`'s grids; returns them and the bytes uploaded.
    pub fn upload(
        ctx: &GpuContext,
        charges: &mut crate::DeviceCharges,
        volume: &GridVolume,
    ) -> Result<(Self, u64), GpuError> {
        let size = volume.grid.size().map(|n| n as u64);
        let density = texture(
            ctx,
            charges,
            "the cloud density grid (samples per side)",
            size,
        )?;
        let mut bytes = write(ctx, &density, size, volume.grid.data());
        let max = match &volume.skip {
            Some(m) => {
                let blocks = m.blocks().map(|n| n as u64);
                let texels = fray_clouds::gpu_layout::max_grid_texels(m, &volume.grid);
                let t = texture(ctx, charges, "the cloud max grid (blocks per side)", blocks)?;
                bytes += write(ctx, &t, blocks, &texels);
                t
            }
            None => {
                let t = texture(
                    ctx,
                    charges,
                    "the cloud max grid (blocks per side)",
                    [1, 1, 1],
                )?;
                bytes += write(ctx, &t, [1, 1, 1], &[0.0]);
                t
            }
        };
        Ok((Self { density, max }, bytes))
    }

    /// Views of both, for a bind group.
    pub fn views(&self) -> (wgpu::TextureView, wgpu::TextureView) {
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        (view(&self.density), view(&self.max))
    }
}

/// An empty `size` R32Float 3D texture, every side checked against the device's limit, charged
/// to `charges` first.
fn texture(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    what: &'static str,
    size: [u64; 3],
) -> Result<wgpu::Texture, GpuError> {
    let limit = u64::from(ctx.limits.max_texture_dimension_3d);
    let side = size.into_iter().max().unwrap_or(1);
    if side > limit {
        return Err(GpuError::TooLarge {
            what,
            needed: side,
            limit,
        });
    }
    // R32Float: 4 bytes a texel.
    charges.charge_uploaded(what, size.iter().map(|&n| n.max(1)).product::<u64>() * 4)?;
    Ok(ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(what),
        size: wgpu::Extent3d {
            width: size[0].max(1) as u32,
            height: size[1].max(1) as u32,
            depth_or_array_layers: size[2].max(1) as u32,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    }))
}

/// Writes `texels` (x fastest, then y, then z; `size` of them) into `texture`; returns the bytes.
fn write(ctx: &GpuContext, texture: &wgpu::Texture, size: [u64; 3], texels: &[f32]) -> u64 {
    ctx.write_texels(texture, size.map(|n| n as u32), texels)
}
