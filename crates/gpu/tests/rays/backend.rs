//! What every kind's and medium's checks share: the case rays, the tolerances, and the name a
//! backend goes by. Each kind and medium declares what a backend answers for it in its own
//! module (`free_forms::FreeFormBackend`, …); `crate::Backend` is all of them.

use fray_core::{Interval, Ray};

/// One ray of a case: world space, over `range`. Unit direction, except where a case says not
/// (the mesh rays aimed exactly at an f32 vertex).
#[derive(Clone, Copy, Debug)]
pub struct CaseRay {
    pub ray: Ray,
    pub range: Interval,
}

/// The tolerances a case is cast with: the scene's ε and the GPU's (`fray_gpu::gpu_epsilon`).
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    pub eps: f64,
    pub eps_gpu: f64,
}

/// A backend of the suite, by name.
pub trait Named {
    fn name(&self) -> &'static str;
}
