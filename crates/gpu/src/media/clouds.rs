//! The cloud volume on the GPU: its parameter block (`GpuClouds`, written for each view from f64:
//! the box relative to the camera, the sun's light through the sky — [`cloud_light`]) and its
//! grids. The grids: the density grid (`fray_clouds::DensityGrid`, x fastest)
//! and, with empty-space skipping, its max grid (one bound per block,
//! `fray_clouds::gpu_layout::max_grid_texels`) as `R32Float` 3D textures that
//! `shaders/clouds.wgsl` reads with `textureLoad` and interpolates itself, exactly as the CPU's
//! trilinear formula with clamped edges — no sampler, and no filtering feature for 32-bit float
//! textures. Without skipping the max grid is a single zero texel the shader never reads (the
//! bind group's layout is the same either way). Each side is checked against the device's
//! `max_texture_dimension_3d` first.

use super::{GpuMedium, ResidentMedium};
use crate::bindings::Part;
use crate::counters::Counter;
use crate::features::Feature;
use crate::kinds::Upload;
use crate::{DeviceCharges, GpuContext, GpuError, View};
use fray_clouds::gpu_layout::GpuClouds;
use fray_clouds::march::{CloudLight, GridVolume};
use fray_scene::Scene;
use glam::DVec3;
use wgpu::BufferUsages as U;

/// The texture format of both grids.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The cloud volume on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct Clouds;

impl GpuMedium for Clouds {
    fn feature(&self) -> Feature {
        Feature::Clouds
    }

    fn part(&self) -> Part {
        Part::Clouds
    }

    fn read_stats(&self, words: &[u32], stats: &mut fray_core::RenderStats) {
        stats.cloud_samples = Counter::CloudSamples.read(words);
    }

    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentMedium>>, GpuError> {
        let Some(c) = &at.scene.clouds else {
            return Ok(None);
        };
        let (textures, bytes) = CloudTextures::upload(at.ctx, charges, &c.volume)?;
        let size = std::mem::size_of::<GpuClouds>() as u64;
        let params = charges.empty(at.ctx, "clouds", size, U::UNIFORM | U::COPY_DST)?;
        let (density, max) = textures.views();
        Ok(Some(Box::new(ResidentClouds {
            params,
            textures,
            density,
            max,
            bytes,
        })))
    }
}

/// The clouds on the GPU.
#[derive(Debug)]
pub struct ResidentClouds {
    /// Their parameters (`GpuClouds`, a uniform written per view from f64: the box relative to
    /// the camera, the sun's light through the sky).
    pub params: wgpu::Buffer,
    /// The density grid and the max grid, uploaded once.
    pub textures: CloudTextures,
    density: wgpu::TextureView,
    max: wgpu::TextureView,
    bytes: u64,
}

impl ResidentMedium for ResidentClouds {
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>> {
        vec![
            self.params.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.density),
            wgpu::BindingResource::TextureView(&self.max),
        ]
    }

    fn write_view(&mut self, ctx: &GpuContext, scene: &Scene, view: &View) -> u64 {
        let Some(c) = &scene.clouds else {
            return 0;
        };
        let eye = crate::params::reference_point(&view.camera);
        let light = cloud_light(scene, c, eye);
        let block = GpuClouds::new(&c.volume, &light, &c.march, c.jitter, eye.to_array());
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&block));
        std::mem::size_of::<GpuClouds>() as u64
    }

    fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// How the scene's clouds are lit seen from `eye` (fray-trace's `Media::of`): by the scene's
/// first sun — its irradiance dimmed by the air above the volume's centre when it is the sky's
/// sun — and the scene's ambient radiance times the clouds' factor.
pub fn cloud_light(scene: &Scene, clouds: &fray_scene::Clouds, eye: DVec3) -> CloudLight {
    let sun_light = scene
        .lights
        .iter()
        .position(|l| matches!(l, fray_scene::Light::Sun { .. }));
    let (sun_direction, mut sun_irradiance) = match sun_light.map(|i| scene.lights[i]) {
        Some(fray_scene::Light::Sun {
            direction,
            irradiance,
        }) => (direction, irradiance.as_dvec3()),
        _ => (DVec3::Y, DVec3::ZERO),
    };
    if let Some(s) = scene
        .atmosphere
        .sky
        .as_ref()
        .filter(|s| sun_light.is_some() && s.sun_light == sun_light)
    {
        let r = &clouds.volume.region;
        let centre = DVec3::from_array(std::array::from_fn(|a| 0.5 * (r.min[a] + r.max[a])));
        sun_irradiance *= s.sky.transmittance_to_sun(centre, eye);
    }
    CloudLight {
        sun_direction: sun_direction.to_array(),
        sun_irradiance: sun_irradiance.to_array(),
        ambient: (scene.ambient.as_dvec3() * clouds.ambient).to_array(),
        albedo: clouds.albedo,
        phase: clouds.phase,
    }
}

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
