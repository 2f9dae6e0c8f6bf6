//! `fray-gpu`: the wgpu backend — a resident scene rendered in WGSL passes.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! The wgpu backend, in passes (one struct each, `passes`): the scene stays resident
//! on the device (`resident`), uploaded once relative to a fixed anchor and moved to each
//! frame's camera on the GPU (the rebase pass); per frame the quadtree work list, then ray
//! generation (with anti-aliasing samples), intersection per primitive kind — free forms by the
//! same halving search as `fray-geometry` (exact per-term bounds widened by their rounding,
//! monotone segments finished by Illinois, CSG by one evaluator over the postfix program),
//! terrains by the max-pyramid search of `fray-terrain`, triangle meshes by `fray-mesh`'s BVH and
//! watertight triangle test (every mesh's arrays in one texture) — narrowing each ray's nearest
//! hit, then surfaces and shading like `fray-trace` (ambient + Lambert albedo/π + normalised
//! Phong, shadow rays any-hit per kind, light through the fog and the air), then the media (Klassen's fog layer
//! and the physically based sky of `fray-atmosphere`, a media pass: `T · L + L_in`, misses
//! included, the sky's tables and the sun's disc as their background, the air's aerial
//! perspective marched per ray), then resolve into storage textures (tone mapped on the GPU),
//! read back only to make a [`fray_core::Frame`]. f32, every position camera-relative; pipelines
//! specialised to the scene (absent features compile to nothing) and cached. ε on the GPU is
//! `max(scene ε, 2⁻²⁰ · camera distance)` ([`gpu_epsilon`]).

pub mod bindings;
mod context;
pub mod counters;
mod device_charges;
mod error;
pub mod features;
pub mod kind_dispatch;
pub mod kinds;
pub mod media;
pub mod params;
pub mod passes;
mod readback;
mod render;
pub mod resident;
pub mod shader;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
pub mod texture_layout;
pub mod textures;
mod timestamps;
pub mod work;

pub use context::{AdapterProbe, GpuContext, probe_adapter};
pub use device_charges::DeviceCharges;
pub use error::GpuError;
pub use features::{Feature, Features};
pub use media::clouds::cloud_light;
pub use params::View;
pub use render::{
    EPSILON_FLOOR, FrameTextures, GpuRenderer, GpuScene, GpuSettings, HOST_BYTES_PER_PIXEL,
    SHADOW_OFFSET_EPSILONS, camera_distance, gpu_epsilon, gpu_epsilon_for, render,
    unsupported_feature,
};
pub use work::GpuWork;
