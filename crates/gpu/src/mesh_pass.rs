//! The batch mesh pass (one struct, its pipeline and buffers): `shaders/mesh_batch.wgsl` casts a
//! batch of reference-relative rays against every mesh instance with `mesh.wgsl` — the f32 twin
//! of `fray_mesh::MeshBvh::nearest_hit`/`any_hit` under `fray_mesh::Instance` — and reads back
//! per ray the nearest hit `(t, instance, triangle, barycentrics)`, the any-hit flag over the
//! same range, and the hit's surface (world geometric and shading normals, uv). A parity test
//! (`tests/mesh_parity.rs`) bounds the difference.
//!
//! The arrays are `fray_mesh::gpu_layout::GpuMeshes` ([`mesh_layout`]: its refusals as
//! [`GpuError`]s) uploaded by [`mesh_buffers`] into the [`MESHES`] group, checked against the
//! device's limits; a frame pass that includes `mesh.wgsl` binds the same group. A camera that
//! moves rewrites only the instance blocks ([`MeshPass::rebase`]).

use crate::bindings::{self, MESH_BATCH, MESHES};
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::terrain_pass::GpuRay;
use crate::{GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_mesh::MeshBvh;
use fray_mesh::gpu_layout::{
    GpuMeshInstance, GpuMeshNode, GpuMeshTriangle, GpuMeshVertex, GpuMeshes, MESH_NO_HIT,
    MESH_NO_NODE, MeshLayoutError,
};
use glam::{DAffine3, DVec3};

const PASS: &str = "mesh";
const WORKGROUP: u32 = 64;

/// The complete mesh batch module: the generated prelude (with the mesh structs and constants,
/// from `fray_mesh::gpu_layout`), the batch and mesh bindings, ray.wgsl, mesh.wgsl and
/// mesh_batch.wgsl.
pub fn mesh_source() -> String {
    crate::shader::compose("mesh_batch.wgsl", &ModuleOptions::BATCH).unwrap_or_default()
}

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

/// A layout refusal as the backend reports it: a BVH too deep for the traversal's stack or
/// arrays past `u32` indices as [`GpuError::TooLarge`], a budget as [`GpuError::Budget`], bad
/// instances as [`GpuError::Mesh`].
pub fn layout_error(e: MeshLayoutError) -> GpuError {
    match e {
        MeshLayoutError::TooDeep { depth, limit, .. } => GpuError::TooLarge {
            what: "mesh BVH stack entries (depth + 1)",
            needed: u64::from(depth) + 1,
            limit: u64::from(limit),
        },
        MeshLayoutError::IndexOverflow { what, needed } => GpuError::TooLarge {
            what,
            needed,
            limit: u32::MAX.into(),
        },
        MeshLayoutError::Budget(b) => GpuError::Budget(b),
        other => GpuError::Mesh(other.to_string()),
    }
}

/// `meshes` and `instances` (mesh index, mesh-to-world) laid out for the GPU relative to
/// `reference` ([`GpuMeshes::build`]), refusals as [`GpuError`]s ([`layout_error`]).
pub fn mesh_layout(
    meshes: &[&MeshBvh],
    instances: &[(u32, DAffine3)],
    reference: DVec3,
    budget: &MemoryBudget,
) -> Result<GpuMeshes, GpuError> {
    GpuMeshes::build(meshes, instances, reference, budget).map_err(layout_error)
}

/// The buffers of the [`MESHES`] group, in its binding order.
#[derive(Debug)]
pub struct MeshBuffers {
    /// The instance blocks (`COPY_DST`: rewritten when the camera moves).
    pub instances: wgpu::Buffer,
    pub nodes: wgpu::Buffer,
    pub triangles: wgpu::Buffer,
    pub vertices: wgpu::Buffer,
}

impl MeshBuffers {
    /// The bind group of [`MESHES`] over these buffers.
    pub fn bind(&self, ctx: &GpuContext, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        MESHES.bind(
            &ctx.device,
            layout,
            &[
                self.instances.as_entire_binding(),
                self.nodes.as_entire_binding(),
                self.triangles.as_entire_binding(),
                self.vertices.as_entire_binding(),
            ],
        )
    }
}

/// Uploads `layout`'s arrays, each checked against the device's storage-buffer limits first
/// (an empty array becomes one inert element: WebGPU has no empty bindings).
pub fn mesh_buffers(ctx: &GpuContext, layout: &GpuMeshes) -> Result<MeshBuffers, GpuError> {
    use wgpu::BufferUsages as U;
    let empty_instance = GpuMeshInstance {
        root: MESH_NO_NODE,
        ..GpuMeshInstance::default()
    };
    Ok(MeshBuffers {
        instances: bindings::upload(
            ctx,
            "mesh instances",
            &layout.instances,
            empty_instance,
            U::STORAGE | U::COPY_DST,
        )?,
        nodes: bindings::upload(
            ctx,
            "mesh BVH nodes",
            &layout.nodes,
            GpuMeshNode::default(),
            U::STORAGE,
        )?,
        triangles: bindings::upload(
            ctx,
            "mesh triangles",
            &layout.triangles,
            GpuMeshTriangle::default(),
            U::STORAGE,
        )?,
        vertices: bindings::upload(
            ctx,
            "mesh vertices",
            &layout.vertices,
            GpuMeshVertex::default(),
            U::STORAGE,
        )?,
    })
}

/// The batch mesh pass over a set of meshes and instances.
#[derive(Debug)]
pub struct MeshPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
    layout: GpuMeshes,
    buffers: MeshBuffers,
    meshes: wgpu::BindGroup,
}

impl MeshPass {
    /// Builds the pipeline and uploads `meshes` with `instances` (mesh index, mesh-to-world
    /// transform) relative to `reference` (the camera), under the default memory budget.
    pub fn new(
        ctx: &GpuContext,
        meshes: &[&MeshBvh],
        instances: &[(u32, DAffine3)],
        reference: DVec3,
    ) -> Result<Self, GpuError> {
        let layout = mesh_layout(meshes, instances, reference, &MemoryBudget::default())?;
        Self::from_layout(ctx, layout)
    }

    /// Builds the pipeline and uploads `layout`.
    pub fn from_layout(ctx: &GpuContext, layout: GpuMeshes) -> Result<Self, GpuError> {
        let buffers = mesh_buffers(ctx, &layout)?;
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "mesh_batch.wgsl",
            &[MESH_BATCH, MESHES],
            &ModuleOptions::BATCH,
            &Specialisation::default(),
        )?;
        let meshes = buffers.bind(ctx, &cache.layout(ctx, &MESHES));
        Ok(Self {
            cache,
            pipeline,
            layout,
            buffers,
            meshes,
        })
    }

    /// What was uploaded.
    pub fn layout(&self) -> &GpuMeshes {
        &self.layout
    }

    /// Moves the pass to reference point `reference`: rewrites the instance blocks only (the
    /// nodes, triangles and vertices stay as uploaded); returns the bytes written.
    pub fn rebase(&mut self, ctx: &GpuContext, reference: DVec3) -> Result<u64, GpuError> {
        let blocks = self.layout.instances_at(reference).map_err(layout_error)?;
        if !blocks.is_empty() {
            ctx.queue
                .write_buffer(&self.buffers.instances, 0, bytemuck::cast_slice(&blocks));
        }
        self.layout.instances = blocks;
        Ok(std::mem::size_of_val(self.layout.instances.as_slice()) as u64)
    }

    /// Casts `rays` (relative to the reference point; `t_hi` past `BIG` = 1e30 is clamped to
    /// it) against every instance: the nearest hit, the any-hit flag, the surface.
    pub fn cast(&self, ctx: &GpuContext, rays: &[GpuRay]) -> Result<Vec<GpuMeshHit>, GpuError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let count = u32::try_from(rays.len()).map_err(|_| GpuError::TooLarge {
            what: "mesh batch rays",
            needed: rays.len() as u64,
            limit: u32::MAX.into(),
        })?;
        let instances = self.layout.instances.len() as u32;
        let batch = bindings::upload(
            ctx,
            "mesh batch",
            &[[count, instances, 0, 0]],
            [0; 4],
            wgpu::BufferUsages::UNIFORM,
        )?;
        let bytes = rays.len() as u64 * 64;
        let (ray_buffer, output) =
            batch_buffers(ctx, ("mesh batch rays", "mesh batch hits"), rays, bytes)?;
        let bind_group = MESH_BATCH.bind(
            device,
            &self.cache.layout(ctx, &MESH_BATCH),
            &[
                batch.as_entire_binding(),
                ray_buffer.as_entire_binding(),
                output.as_entire_binding(),
            ],
        );
        let raw: Vec<[[u32; 4]; 4]> = run_batch(
            ctx,
            &self.pipeline,
            &[&bind_group, &self.meshes],
            count,
            WORKGROUP,
            &output,
            bytes,
            PASS,
        )?;
        let f = f32::from_bits;
        Ok(raw
            .iter()
            .map(|[a, b, c, d]| GpuMeshHit {
                t: f(a[0]),
                barycentric: [f(a[1]), f(a[2]), f(a[3])],
                instance: b[0],
                triangle: b[1],
                any_hit: b[2] == 1,
                normal: [f(c[0]), f(c[1]), f(c[2])],
                shading_normal: [f(d[0]), f(d[1]), f(d[2])],
                uv: [f(c[3]), f(d[3])],
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_mesh::TriangleMesh;

    /// The mesh module (generated structs + shaders) parses and validates with naga, and every
    /// mesh struct's compiled layout is the Rust one.
    #[test]
    fn mesh_wgsl_validates_and_its_struct_layouts_match_rust() {
        let source = mesh_source();
        assert!(source.contains("// ---- mesh.wgsl ----"), "composed");
        crate::shader::assert_validates_with_struct::<GpuMeshNode>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshTriangle>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshVertex>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshInstance>(&source);
    }

    /// The stack-depth policy: a BVH deeper than the traversal's stack is refused, before
    /// anything is allocated, as `TooLarge` with what, how much and the limit; bad instances and
    /// budgets likewise, never a panic.
    #[test]
    fn layout_refusals_become_gpu_errors() {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..64u32 {
            let x = f64::from(i);
            positions.extend([
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 0.5, 0.0, 0.0),
                DVec3::new(x, 1.0, 0.0),
            ]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let bvh = MeshBvh::build(TriangleMesh::new(positions, triangles).unwrap());
        let depth = bvh.max_depth();
        let id = [(0, DAffine3::IDENTITY)];
        let budget = MemoryBudget::default();
        let e = GpuMeshes::build_with_stack(&[&bvh], &id, DVec3::ZERO, &budget, depth)
            .map_err(layout_error)
            .unwrap_err();
        assert_eq!(
            e,
            GpuError::TooLarge {
                what: "mesh BVH stack entries (depth + 1)",
                needed: u64::from(depth) + 1,
                limit: u64::from(depth),
            }
        );
        assert!(e.to_string().contains("mesh BVH stack entries"), "{e}");
        assert!(mesh_layout(&[&bvh], &id, DVec3::ZERO, &budget).is_ok());
        let singular = [(0, DAffine3::from_scale(DVec3::new(0.0, 1.0, 1.0)))];
        let e = mesh_layout(&[&bvh], &singular, DVec3::ZERO, &budget).unwrap_err();
        assert!(
            matches!(&e, GpuError::Mesh(m) if m.contains("invertible")),
            "{e}"
        );
        let e = mesh_layout(&[&bvh], &id, DVec3::ZERO, &MemoryBudget::new(64)).unwrap_err();
        assert!(matches!(e, GpuError::Budget(_)), "{e}");
        let e = mesh_layout(&[], &id, DVec3::ZERO, &budget).unwrap_err();
        assert!(
            matches!(&e, GpuError::Mesh(m) if m.contains("names mesh 0")),
            "{e}"
        );
    }
}
