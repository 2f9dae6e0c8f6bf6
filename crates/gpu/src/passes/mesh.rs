//! The mesh intersection pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's mesh candidates — one instance each, its BVH nearest child
//! first and the watertight triangle test in f32 (`shaders/mesh.wgsl`, the f32 twin of
//! `fray_mesh::Instance::nearest_hit`) — over `(t_near, nearest hit so far)`, narrowing the
//! paths' hits after the free forms and the terrains (a tie keeps the earlier kind's hit) and
//! recording the instance, the triangle and its barycentrics for the shade pass. Built only
//! for scenes with meshes.

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, Group, MESHES, WORK};
use crate::{GpuContext, GpuError};

/// The mesh intersection pass.
#[derive(Debug)]
pub struct MeshIntersectPass {
    kernel: Kernel,
}

impl MeshIntersectPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 3] = [FRAME, WORK, MESHES];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "intersect_mesh.wgsl", &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Casts the rays of `items` work items at their mesh candidates (bind groups in
    /// [`MeshIntersectPass::GROUPS`] order).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        groups: [&wgpu::BindGroup; 3],
        items: u32,
    ) {
        self.kernel.run(pass, ctx, &groups, items);
    }
}
