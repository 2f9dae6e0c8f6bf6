//! The GPU backend: the batch kernels of `fray_gpu::testing`, in f32, positions relative to a
//! case's reference point (the camera), at the GPU's ε.

use crate::backend::CaseRay;
use fray_gpu::GpuContext;
use fray_gpu::testing::GpuRay;
use glam::DVec3;
use std::sync::OnceLock;

/// The GPU backend on the machine's adapter.
pub struct Gpu {
    renderer: fray_gpu::GpuRenderer,
}

/// The one GPU backend of the run, opened by the first trial that needs it (a failure when it
/// cannot be: GPU trials are ignored without an adapter unless `FRAY_REQUIRE_GPU=1`).
pub fn gpu() -> &'static Gpu {
    static GPU: OnceLock<Gpu> = OnceLock::new();
    GPU.get_or_init(|| Gpu {
        renderer: crate::common::gpu("rays"),
    })
}

impl Gpu {
    pub fn context(&self) -> &GpuContext {
        self.renderer.context()
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
