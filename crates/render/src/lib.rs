//! `fray-render`: the facade — pick a backend, render a scene, write PNG/EXR.
//!
#![doc = include_str!("../README.md")]

pub mod output;
mod renderer;

/// What of a scene the GPU backend does not draw yet (`Auto` renders such scenes on the CPU).
pub use fray_gpu::unsupported_feature as gpu_unsupported_feature;
pub use renderer::{Backend, RenderError, RenderOptions, Renderer, available_backends};
