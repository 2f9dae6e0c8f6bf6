//! Resolve: the band's pixels from their camera rays — colour the samples' box-filtered
//! radiance, depth and normal from the centre ray — into the frame's storage textures, with the
//! tone-mapped sRGB display image made on the GPU (`shaders/resolve.wgsl`; the CPU twins are the
//! frame loop's box filter, `fray_core::ToneMap` and `linear_to_srgb`).

use super::{Kernel, PassSetup};
use crate::GpuError;
use crate::bindings::{FRAME, Group, TARGETS};

/// The resolve pass.
#[derive(Debug)]
pub struct ResolvePass {
    kernel: Kernel,
}

impl ResolvePass {
    /// The groups it binds.
    pub const GROUPS: [Group; 2] = [FRAME, TARGETS];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "resolve.wgsl", &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Resolves a band `width` pixels wide and `rows` tall (8 × 8 pixels per workgroup).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        groups: [&wgpu::BindGroup; 2],
        width: u32,
        rows: u32,
    ) {
        self.kernel
            .run_2d(pass, &groups, width.div_ceil(8), rows.div_ceil(8));
    }
}
