//! `fray-render`: the facade — pick a backend, render a scene, write PNG/EXR.
//!
#![doc = include_str!("../README.md")]

mod assemble;
pub mod output;
mod renderer;

pub use assemble::{AssembleError, assemble_png_tiles};
/// What of a scene the GPU backend does not draw yet (`Auto` renders such scenes on the CPU).
pub use fray_gpu::unsupported_feature as gpu_unsupported_feature;
pub use renderer::{Backend, ImageTile, RenderError, RenderOptions, Renderer, available_backends};
