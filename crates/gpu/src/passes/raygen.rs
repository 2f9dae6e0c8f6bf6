//! Ray generation: the camera rays of a band of rows — per pixel its centre and, with
//! anti-aliasing, its samples — into the frame's paths (`shaders/raygen.wgsl`). The CPU twin is
//! `fray_core::Projector::ray` with `fray_core::PixelSamples` (the GPU's depth and anti-aliased
//! colour are checked against the CPU's frames).

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, Group};
use crate::{GpuContext, GpuError};

/// The ray generation pass.
#[derive(Debug)]
pub struct RayGenPass {
    kernel: Kernel,
}

impl RayGenPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 1] = [FRAME];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "raygen.wgsl", &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Generates `rays` rays (the band's pixels × rays per pixel).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        frame: &wgpu::BindGroup,
        rays: u32,
    ) {
        self.kernel.run(pass, ctx, &[frame], rays.div_ceil(64));
    }
}
