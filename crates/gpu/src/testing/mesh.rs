//! The meshes' batch kernel (`shaders/mesh_batch.wgsl`): `mesh.wgsl` casts reference-relative
//! rays against every mesh instance — the f32 twin of `fray_mesh::MeshBvh::nearest_hit`/`any_hit`
//! under `fray_mesh::Instance` — and reads back per ray the nearest hit `(t, instance, triangle,
//! barycentrics)`, the any-hit flag over the same range, and the hit's surface (world geometric
//! and shading normals, uv), over the resources the resident scene uploads
//! (`crate::kinds::mesh`).

use super::batch::{BatchPass, Kernel, floats};
use super::terrain::GpuRay;
use crate::bindings::MESHES;
use crate::kinds::mesh::{MeshBuffers, layout_error, mesh_buffers, mesh_layout};
use crate::shader::ModuleOptions;
use crate::{DeviceCharges, GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_mesh::MeshBvh;
use fray_mesh::gpu_layout::{GpuMeshes, MESH_NO_HIT};
use glam::{DAffine3, DVec3};

/// The kernel: every mesh instance.
pub const KERNEL: Kernel = Kernel {
    label: "mesh",
    module: "mesh_batch.wgsl",
    options: ModuleOptions::BATCH,
    data: &[MESHES],
    query_rows: 2,
    answer_rows: 4,
};

/// What a batch ray hit, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuMeshHit {
    /// Distance along the ray (in units of its direction); −1 for a miss.
    pub t: f32,
    /// The barycentric weights of the triangle's corners.
    pub barycentric: [f32; 3],
    /// The instance hit (`MESH_NO_HIT` for a miss).
    pub instance: u32,
    /// The mesh's own index of the triangle hit.
    pub triangle: u32,
    /// Whether the any-hit query over the same range found a hit.
    pub any_hit: bool,
    /// World geometric normal (unit, outward by the winding) and shading normal, and the uv.
    pub normal: [f32; 3],
    pub shading_normal: [f32; 3],
    pub uv: [f32; 2],
}

impl GpuMeshHit {
    /// Whether the ray hit.
    pub fn is_hit(&self) -> bool {
        self.instance != MESH_NO_HIT
    }
}

/// Meshes and their instances uploaded for the kernel, relative to a reference point.
#[derive(Debug)]
pub struct MeshBatch {
    pass: BatchPass,
    layout: GpuMeshes,
    buffers: MeshBuffers,
    meshes: wgpu::BindGroup,
}

impl MeshBatch {
    /// Uploads `meshes` with `instances` (mesh index, mesh-to-world transform) relative to
    /// `reference` (the camera), under the default memory budget.
    pub fn new(
        ctx: &GpuContext,
        meshes: &[&MeshBvh],
        instances: &[(u32, DAffine3)],
        reference: DVec3,
    ) -> Result<Self, GpuError> {
        let layout = mesh_layout(meshes, instances, reference, &MemoryBudget::default())?;
        Self::from_layout(ctx, layout)
    }

    /// Uploads `layout`.
    pub fn from_layout(ctx: &GpuContext, layout: GpuMeshes) -> Result<Self, GpuError> {
        let buffers = mesh_buffers(ctx, &mut DeviceCharges::unlimited(), &layout)?;
        let pass = BatchPass::new(ctx, KERNEL)?;
        let view = buffers.view();
        let meshes = pass.bind(
            ctx,
            &MESHES,
            &[
                buffers.info.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
            ],
        );
        Ok(Self {
            pass,
            layout,
            buffers,
            meshes,
        })
    }

    /// What was uploaded.
    pub fn layout(&self) -> &GpuMeshes {
        &self.layout
    }

    /// Moves the batch to reference point `reference`: rewrites the instance blocks only (the
    /// nodes, triangles and vertices stay as uploaded); returns the bytes written.
    pub fn rebase(&mut self, ctx: &GpuContext, reference: DVec3) -> Result<u64, GpuError> {
        let blocks = self.layout.instances_at(reference).map_err(layout_error)?;
        let bytes = self.buffers.write_instances(ctx, &blocks);
        self.layout.instances = blocks;
        Ok(bytes)
    }

    /// Casts `rays` (relative to the reference point; `t_hi` past `BIG` = 1e30 is clamped to
    /// it) against every instance: the nearest hit, the any-hit flag, the surface.
    pub fn cast(&self, ctx: &GpuContext, rays: &[GpuRay]) -> Result<Vec<GpuMeshHit>, GpuError> {
        let queries: Vec<[f32; 4]> = rays.iter().flatten().copied().collect();
        let instances = self.layout.instances.len() as u32;
        let words = self
            .pass
            .run(ctx, &queries, [instances, 0, 0], &[&self.meshes])?;
        Ok(words
            .chunks_exact(4)
            .map(|w| {
                let (a, b, c, d) = (floats(w[0]), w[1], floats(w[2]), floats(w[3]));
                GpuMeshHit {
                    t: a[0],
                    barycentric: [a[1], a[2], a[3]],
                    instance: b[0],
                    triangle: b[1],
                    any_hit: b[2] == 1,
                    normal: [c[0], c[1], c[2]],
                    shading_normal: [d[0], d[1], d[2]],
                    uv: [c[3], d[3]],
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_mesh::gpu_layout::{GpuMeshInstance, GpuMeshNode, GpuMeshTriangle, GpuMeshVertex};

    /// The mesh module (generated structs + shaders) parses and validates with naga, and every
    /// mesh struct's compiled layout is the Rust one.
    #[test]
    fn the_mesh_kernels_struct_layouts_match_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        assert!(source.contains("// ---- mesh.wgsl ----"), "composed");
        crate::shader::assert_validates_with_struct::<GpuMeshNode>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshTriangle>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshVertex>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshInstance>(&source);
    }
}
