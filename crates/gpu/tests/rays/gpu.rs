//! The GPU backend: the batch kernels of `fray_gpu::testing`, in f32, positions relative to a
//! case's reference point (the camera), at the GPU's ε.

use crate::backend::CaseRay;
use crate::meshes::MeshAnswer;
use fray_gpu::GpuContext;
use fray_gpu::testing::{GpuRay, MeshBatch, SkyBatch};
use fray_mesh::{Instance, MeshBvh};
use glam::{DVec2, DVec3};
use std::sync::OnceLock;

/// The GPU backend on the machine's adapter.
pub struct Gpu {
    renderer: fray_gpu::GpuRenderer,
    /// The sky's kernel (any sky, any eye): built once.
    pub sky: OnceLock<SkyBatch>,
}

/// The one GPU backend of the run, opened by the first trial that needs it (a failure when it
/// cannot be: GPU trials are ignored without an adapter unless `FRAY_REQUIRE_GPU=1`).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu {
        renderer: crate::common::gpu("rays"),
        sky: OnceLock::new(),
    })
}

impl Gpu {
    pub fn context(&self) -> &GpuContext {
        self.renderer.context()
    }

    /// The mesh kernel over `instances`, each distinct mesh once (as the resident scene uploads
    /// them), positions relative to `reference`.
    pub fn mesh_batch(&self, instances: &[Instance], reference: DVec3) -> MeshBatch {
        let mut distinct: Vec<&MeshBvh> = Vec::new();
        let mut placements = Vec::new();
        for instance in instances {
            let index = distinct
                .iter()
                .position(|m| std::ptr::eq(*m, instance.mesh.as_ref()))
                .unwrap_or_else(|| {
                    distinct.push(instance.mesh.as_ref());
                    distinct.len() - 1
                });
            placements.push((index as u32, instance.to_world()));
        }
        MeshBatch::new(self.context(), &distinct, &placements, reference)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// `batch`'s answers to `rays` (relative to the reference point it was built or rebased at).
    pub fn mesh_answers(
        &self,
        batch: &MeshBatch,
        reference: DVec3,
        rays: &[CaseRay],
    ) -> Vec<MeshAnswer> {
        let v = |a: [f32; 3]| DVec3::from(a.map(f64::from));
        batch
            .cast(self.context(), &relative_rays(rays, reference))
            .unwrap_or_else(|e| panic!("{e}"))
            .iter()
            .map(|h| MeshAnswer {
                t: h.is_hit().then_some(f64::from(h.t)),
                instance: h.instance,
                triangle: h.triangle,
                barycentric: h.barycentric.map(f64::from),
                normal: v(h.normal),
                shading_normal: v(h.shading_normal),
                uv: DVec2::new(f64::from(h.uv[0]), f64::from(h.uv[1])),
                any: h.any_hit,
            })
            .collect()
    }
}

/// `rays` as the GPU's batches take them: f32, relative to `reference`, `t_hi` at most 1e30
/// (unbounded).
pub fn relative_rays(rays: &[CaseRay], reference: DVec3) -> Vec<GpuRay> {
    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32];
    rays.iter()
        .map(|r| {
            let o = f(r.ray.origin - reference);
            let d = f(r.ray.dir);
            let hi = r.range.hi.min(1e30) as f32;
            [
                [o[0], o[1], o[2], r.range.lo as f32],
                [d[0], d[1], d[2], hi],
            ]
        })
        .collect()
}

impl crate::backend::Named for Gpu {
    fn name(&self) -> &'static str {
        "gpu"
    }
}
