//! `fray-gpu`: the wgpu backend. Each pixel's projector ray is cast against every free-form
//! solid by the same halving search as `fray-geometry` (exact per-term bounds, monotone segments
//! finished by Illinois, CSG by a small stack over the postfix program), shaded like
//! `fray-trace` (ambient + Lambert albedo/π + normalised Phong, shadow rays), in f32 with every
//! position relative to the camera. The pipeline is specialised to the scene (`override`
//! constants): absent features compile to nothing. ε on the GPU is
//! `max(scene ε, 2⁻²⁰ · camera distance)` ([`gpu_epsilon`]).
//!
//! ```no_run
//! let scene = fray_scene::parse(
//!     "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
//!     "inline.ron",
//! )?;
//! let frame = fray_gpu::render(&scene, &fray_gpu::GpuSettings::for_scene(&scene))?;
//! assert!(frame.stats.backend.starts_with("gpu"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod bindings;
mod context;
pub mod counters;
mod error;
pub mod freeform_pass;
pub mod params;
mod readback;
mod render;
pub mod shader;
pub mod terrain_pass;
mod timestamps;
pub mod work;

pub use context::{AdapterProbe, GpuContext, probe_adapter};
pub use error::GpuError;
pub use freeform_pass::{FreeFormPass, PassOutput};
pub use render::{
    EPSILON_FLOOR, GpuRenderer, GpuSettings, SHADOW_OFFSET_EPSILONS, camera_distance, gpu_epsilon,
    render,
};
pub use terrain_pass::TerrainPass;
pub use work::GpuWork;
