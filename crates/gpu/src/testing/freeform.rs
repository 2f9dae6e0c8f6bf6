//! The free forms' batch kernel (`shaders/freeform_batch.wgsl`): `freeform.wgsl` casts rays
//! given by the caller against every solid — all its leaves and its whole CSG program, as shadow
//! rays do — and reads back per ray the nearest hit `t`, the outward normal and the deciding
//! leaf there, and the any-hit answer over the same range: the f32 twin of
//! `fray_geometry::RayCaster` (nearest and any hit) and `Solid::surface_at`.

use super::batch::{BatchPass, Kernel, floats};
use super::terrain::GpuRay;
use crate::bindings::FREE_FORMS;
use crate::shader::{ArraySizes, ModuleOptions};
use crate::{DeviceCharges, GpuContext, GpuError};
use fray_geometry::Solid;
use fray_geometry::gpu_layout::GpuSolids;
use glam::DVec3;

/// The kernel, at the sizes of a few small solids (a batch of solids is composed at its own).
pub const KERNEL: Kernel = kernel(ArraySizes {
    max_leaves: 8,
    max_perturbations: 16,
    max_stack: 4,
    ..ModuleOptions::BATCH.sizes
});

/// The kernel composed for solids of these sizes.
const fn kernel(sizes: ArraySizes) -> Kernel {
    Kernel {
        label: "free forms",
        module: "freeform_batch.wgsl",
        options: ModuleOptions {
            sizes,
            ..ModuleOptions::BATCH
        },
        data: &[FREE_FORMS],
        query_rows: 2,
        answer_rows: 2,
    }
}

/// What a batch ray hit, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuFreeFormHit {
    /// Distance along the ray (in units of its direction); negative for a miss.
    pub t: f32,
    /// The outward unit normal at the hit (zero for a miss).
    pub normal: [f32; 3],
    /// The solid hit, and the deciding leaf there (global over the batch's solids).
    pub solid: u32,
    pub leaf: u32,
    /// Whether the any-hit search over the same range found a solid.
    pub any_hit: bool,
}

impl GpuFreeFormHit {
    /// Whether the ray hit.
    pub fn is_hit(&self) -> bool {
        self.t >= 0.0
    }
}

/// Solids uploaded for the kernel, relative to a reference point.
#[derive(Debug)]
pub struct FreeFormBatch {
    pass: BatchPass,
    free_forms: wgpu::BindGroup,
    solids: u32,
}

impl FreeFormBatch {
    /// Uploads `solids` relative to `reference` (the rays' origin's neighbourhood: a camera).
    pub fn new(ctx: &GpuContext, solids: &[&Solid], reference: DVec3) -> Result<Self, GpuError> {
        let mut flat = GpuSolids::new(reference);
        for solid in solids {
            flat.push(solid, |_| 0);
        }
        let sizes = ArraySizes {
            max_leaves: flat.max_leaves.max(1),
            max_perturbations: flat.max_perturbations.max(1),
            max_stack: flat.max_stack.max(1),
            ..ModuleOptions::BATCH.sizes
        };
        let pass = BatchPass::new(ctx, kernel(sizes))?;
        use wgpu::BufferUsages as U;
        let mut charges = DeviceCharges::unlimited();
        let storage = U::STORAGE;
        let solid_buffer =
            charges.upload(ctx, "solids", &flat.solids, Default::default(), storage)?;
        let leaves = charges.upload(ctx, "leaves", &flat.leaves, Default::default(), storage)?;
        let perturbations = charges.upload(
            ctx,
            "perturbations",
            &flat.perturbations,
            Default::default(),
            storage,
        )?;
        let programs = charges.upload(ctx, "programs", &flat.program, 0u32, storage)?;
        let free_forms = pass.bind(
            ctx,
            &FREE_FORMS,
            &[
                solid_buffer.as_entire_binding(),
                leaves.as_entire_binding(),
                perturbations.as_entire_binding(),
                programs.as_entire_binding(),
            ],
        );
        Ok(Self {
            pass,
            free_forms,
            solids: flat.solids.len() as u32,
        })
    }

    /// Casts `rays` (relative to the reference point) against every solid with the search's
    /// tolerance `eps`: the nearest hit, its surface, the any-hit answer.
    pub fn cast(
        &self,
        ctx: &GpuContext,
        rays: &[GpuRay],
        eps: f32,
    ) -> Result<Vec<GpuFreeFormHit>, GpuError> {
        let queries: Vec<[f32; 4]> = rays.iter().flatten().copied().collect();
        let params = [self.solids, eps.to_bits(), 0];
        let words = self.pass.run(ctx, &queries, params, &[&self.free_forms])?;
        Ok(words
            .chunks_exact(2)
            .map(|w| {
                let (a, b) = (floats(w[0]), w[1]);
                GpuFreeFormHit {
                    t: a[0],
                    normal: [a[1], a[2], a[3]],
                    solid: b[0],
                    leaf: b[1],
                    any_hit: b[2] == 1,
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_geometry::gpu_layout::{GpuLeaf, GpuPerturbation, GpuSolid};

    /// The free-form kernel's structs are laid out as Rust's (every field in order, at Rust's
    /// offset).
    #[test]
    fn the_free_form_kernels_struct_layouts_match_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        crate::shader::assert_validates_with_struct::<GpuSolid>(&source);
        crate::shader::assert_validates_with_struct::<GpuLeaf>(&source);
        crate::shader::assert_validates_with_struct::<GpuPerturbation>(&source);
    }
}
