//! The fog layer on the GPU: its parameter block (`GpuFog`, a uniform) written for each view from
//! f64 — the layer's heights relative to the eye, and the sky's sun's irradiance at its top,
//! through the air above it, as the CPU's `Media::of` takes it. `shaders/fog.wgsl` is its f32
//! twin of fray-atmosphere's `FogLayer`.

use super::{GpuMedium, ResidentMedium};
use crate::bindings::Part;
use crate::features::Feature;
use crate::kinds::Upload;
use crate::{DeviceCharges, GpuContext, GpuError, View};
use fray_atmosphere::gpu_layout::GpuFog;
use fray_scene::Scene;
use glam::DVec3;
use wgpu::BufferUsages as U;

/// The fog layer on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct Fog;

impl GpuMedium for Fog {
    fn feature(&self) -> Feature {
        Feature::Fog
    }

    fn part(&self) -> Part {
        Part::Fog
    }

    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentMedium>>, GpuError> {
        if at.scene.atmosphere.fog.is_none() {
            return Ok(None);
        }
        let size = std::mem::size_of::<GpuFog>() as u64;
        let params = charges.empty(at.ctx, "fog", size, U::UNIFORM | U::COPY_DST)?;
        Ok(Some(Box::new(ResidentFog { params })))
    }
}

/// The fog layer's parameters on the GPU (written per view).
#[derive(Debug)]
pub struct ResidentFog {
    pub params: wgpu::Buffer,
}

impl ResidentMedium for ResidentFog {
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>> {
        vec![self.params.as_entire_binding()]
    }

    fn write_view(&mut self, ctx: &GpuContext, scene: &Scene, view: &View) -> u64 {
        let Some(fog) = &scene.atmosphere.fog else {
            return 0;
        };
        let eye = crate::params::reference_point(&view.camera);
        // The layer's heights relative to this view's eye, in f64 before rounding.
        let mut gpu_fog = GpuFog::new(&fog.layer, fog.model, eye.y);
        let sky = scene.atmosphere.sky.as_ref();
        if let Some((s, index)) = sky.and_then(|s| s.sun_light.map(|i| (s, i))) {
            let top = DVec3::new(eye.x, fog.layer.top, eye.z);
            gpu_fog = gpu_fog.with_sky_sun(index, s.sky.transmittance_to_sun(top, eye));
        }
        ctx.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&gpu_fog));
        std::mem::size_of::<GpuFog>() as u64
    }

    fn bytes(&self) -> u64 {
        0
    }
}
